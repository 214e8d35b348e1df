#pragma once
// Signed distance field body collider: a sparse narrow-band grid. Space is cut into bricks of 8^3
// voxels; only bricks within `band` of a body triangle store samples (9^3 corner samples each, so a
// trilinear lookup never leaves its brick), every other brick stores one flag: far outside or far
// inside. Samples are exact signed distances from the BVH (pseudo-normal sign, generalized winding
// number where the mesh is open, so scans with small holes get the right sign) together with the
// nearest triangle, which gives the surface velocity of a moving body. A query is a brick lookup,
// a trilinear interpolation and its gradient (the normal). A moving body re-samples only the bricks
// near vertices that moved more than an eighth of a voxel since (see update_field).
// Hand-written rather than OpenVDB: OpenVDB would bring a large dependency for one level of bricks,
// and a flat brick table answers faster than a VDB tree's three-level descent.
#include <memory>

#include "collision/body_surface.hpp"
#include "collision/triangle_bvh.hpp"
#include "drape/collision.hpp"

namespace drape::collision {

class SdfCollider final : public BodyCollider {
 public:
  SdfCollider(const Mesh& body, float voxel_size, float band);
  std::string_view name() const override { return "sdf"; }
  void set_surface(std::span<const Vec3f> positions, double t) override;
  void query(std::span<const Vec3f> points, float radius, std::span<ContactSample> out) const override;
  BodyColliderBuildStats build_stats() const override { return stats_; }
  size_t vertex_count() const override { return surface_.vertex_count(); }

 private:
  static constexpr int kBrick = 8;                 // voxels per brick edge
  static constexpr int kSide = kBrick + 1;         // samples per brick edge
  static constexpr int kSamples = kSide * kSide * kSide;
  static constexpr int32_t kFarOutside = -1, kFarInside = -2, kNewlyStored = -3;

  void build_field();
  void update_field();
  void sample_bricks(const std::vector<size_t>& cells);
  void judge_far_bricks(const std::vector<size_t>& cells);
  ContactSample sample(const Vec3f& p, float radius) const;
  template <class Visit>
  void for_each_brick(const Vec3f& lo, const Vec3f& hi, Visit&& visit) const;
  size_t memory_bytes() const;

  BodySurface surface_;
  std::unique_ptr<TriangleBvh> bvh_;
  float voxel_, band_;
  Vec3f origin_ = Vec3f::Zero();
  int dims_[3] = {0, 0, 0};                 // bricks per axis
  std::vector<int32_t> brick_of_;           // per brick cell: sample block index, or kFarOutside / kFarInside
  std::vector<float> distance_;             // kSamples per stored brick
  std::vector<uint32_t> nearest_triangle_;  // kSamples per stored brick
  size_t stored_bricks_ = 0;
  std::vector<Vec3f> sampled_positions_;    // vertex positions the samples near each vertex were taken at
  float longest_edge_ = 0;
  BodyColliderBuildStats stats_;
};

}  // namespace drape::collision
