// Stage 6: a dressed garment as a solid for the next layer (paper sec. 6: "the existing clothing is
// considered as a solid object in the scene"). The garment's final surface goes into a BVH body
// collider (exact closest point, sign from the angle-weighted pseudo-normals, which on the open
// garment surface tell its outer side from its inner side); distances are reduced by the inner
// garment's physical thickness so the next layer rests on its outer face.
#include "drape/dress.hpp"

namespace drape {
namespace {

class LayerCollider final : public Collider {
 public:
  LayerCollider(const Mesh& surface, float thickness)
      : surface_(make_body_collider(surface, CollisionMethod::bvh)), thickness_(thickness) {}
  std::string_view name() const override { return "garment layer"; }
  void query(std::span<const Vec3f> points, float radius, std::span<ContactSample> out) const override {
    surface_->query(points, radius + thickness_, out);
    for (ContactSample& c : out) c.distance -= thickness_;
  }

 private:
  std::unique_ptr<BodyCollider> surface_;
  float thickness_;
};

}  // namespace

std::unique_ptr<Collider> garment_collider(const DressedGarment& garment) {
  return std::make_unique<LayerCollider>(garment.mesh(), std::max(garment.model.fabric.thickness, 0.001f));
}

Mesh DressedGarment::mesh() const {
  Mesh m = cloth_mesh(model, state, name);
  return m;
}

}  // namespace drape
