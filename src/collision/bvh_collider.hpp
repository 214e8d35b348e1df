#pragma once
// Object-space body collider (Vassilev & Spanlang sec. 4.1): per cloth vertex, the exact nearest
// point on the body triangles through the BVH; signed by pseudo-normals (winding number at holes);
// normal interpolated from the vertex normals at that point; surface velocity interpolated likewise.
#include <memory>

#include "collision/body_surface.hpp"
#include "collision/triangle_bvh.hpp"
#include "drape/collision.hpp"

namespace drape::collision {

// One exact signed sample at p: the answer of the BVH method, shared by the others' fallbacks.
// False when the body is farther than radius.
bool exact_sample(const TriangleBvh& bvh, const Vec3f& p, float radius, ContactSample& out);
// The sample at p whose nearest body point is `hit` (nullptr: nothing within the radius).
void sample_from_hit(const BodySurface& surface, const SurfaceHit* hit, const Vec3f& p, ContactSample& out);

class BvhCollider final : public BodyCollider {
 public:
  explicit BvhCollider(const Mesh& body, bool candidate_grid = true);
  std::string_view name() const override { return "bvh"; }
  void set_surface(std::span<const Vec3f> positions, double t) override;
  void query(std::span<const Vec3f> points, float radius, std::span<ContactSample> out) const override;
  BodyColliderBuildStats build_stats() const override { return stats_; }
  size_t vertex_count() const override { return surface_.vertex_count(); }

 private:
  BodySurface surface_;
  std::unique_ptr<TriangleBvh> bvh_;
  BodyColliderBuildStats stats_;
};

}  // namespace drape::collision
