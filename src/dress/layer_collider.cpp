// Stage 6: a dressed garment as a solid for the next layer (paper sec. 6: "the existing clothing is
// considered as a solid object in the scene"). The garment's final surface goes into a BVH body
// collider (exact closest point, sign from the angle-weighted pseudo-normals, which on the open
// garment surface tell its outer side from its inner side); distances are reduced by the inner
// garment's physical thickness so the next layer rests on its outer face.
#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "drape/dress.hpp"

namespace drape {
namespace {

class LayerCollider final : public Collider {
 public:
  LayerCollider(const Mesh& surface, float thickness)
      : surface_(make_body_collider(surface, CollisionMethod::bvh)), thickness_(thickness) {}
  // In motion: the surface follows the garment's particles, read at each new time (the garment
  // beneath steps first), with their velocity since the last; several layers above share it, and
  // a second update to the same time would leave it no velocity.
  LayerCollider(const Mesh& surface, float thickness, const std::vector<Vec3f>& follow)
      : LayerCollider(surface, thickness) {
    surface_->set_motion([&follow](double, std::span<Vec3f> x) { std::copy(follow.begin(), follow.end(), x.begin()); });
  }
  std::string_view name() const override { return "garment layer"; }
  void update(double t) override {
    if (t == time_) return;
    surface_->update(t);
    time_ = t;
  }
  void query(std::span<const Vec3f> points, float radius, std::span<ContactSample> out) const override {
    surface_->query(points, radius + thickness_, out);
    for (ContactSample& c : out) c.distance -= thickness_;
  }

 private:
  std::unique_ptr<BodyCollider> surface_;
  float thickness_;
  double time_ = std::numeric_limits<double>::quiet_NaN();
};

constexpr float kBeneathReach = 0.02f;

float layer_thickness(const DressedGarment& garment) { return std::max(garment.model.fabric.thickness, 0.001f); }

}  // namespace

std::unique_ptr<Collider> garment_collider(const DressedGarment& garment) {
  return std::make_unique<LayerCollider>(garment.mesh(), layer_thickness(garment));
}

std::unique_ptr<Collider> moving_garment_collider(const DressedGarment& garment, const std::vector<Vec3f>& positions) {
  if (positions.size() != garment.model.particle_count())
    throw std::invalid_argument("moving_garment_collider: positions not the garment's particles");
  return std::make_unique<LayerCollider>(garment.mesh(), layer_thickness(garment), positions);
}

size_t vertices_beneath(const DressedGarment& inner, std::span<const Vec3f> inner_positions,
                        std::span<const Vec3f> outer, float tolerance) {
  if (inner_positions.size() != inner.model.particle_count())
    throw std::invalid_argument("vertices_beneath: positions not the inner garment's particles");
  Mesh surface;
  surface.positions.assign(inner_positions.begin(), inner_positions.end());
  surface.triangles = inner.model.triangles;
  const std::unique_ptr<BodyCollider> mid = make_body_collider(surface, CollisionMethod::bvh);
  std::vector<ContactSample> samples(outer.size());
  // Signed distances to the inner garment's mid-surface, within 2 cm of it: what lies past it by
  // more than the tolerance, on the body's side, went through it.
  mid->query(outer, kBeneathReach, samples);
  size_t beneath = 0;
  for (const ContactSample& c : samples) beneath += std::isfinite(c.distance) && c.distance < -tolerance;
  return beneath;
}

Mesh DressedGarment::mesh() const {
  Mesh m = cloth_mesh(model, state, name);
  return m;
}

}  // namespace drape
