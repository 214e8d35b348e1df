#pragma once
// Object-space closest-point queries on the body triangles (Vassilev & Spanlang sec. 4.1) through
// Embree 3's bounding volume hierarchy and rtcPointQuery. The paper built a quad tree of bounding
// boxes per scanned body part; Embree's SAH BVH does the same job for any triangle mesh and refits
// in place when the body moves (RTC_BUILD_QUALITY_REFIT), which is what an animated body needs. A
// hand-made binary BVH (box_bvh.hpp) measured about 1.8x slower per query (bench_collision).
//
// Near a static body, queries go first to a CandidateGrid (candidate_grid.hpp): per-cell lists of
// the triangles that can be nearest, about 3x faster than the tree descent (batched). A moving
// body's update() drops the grid (its lists hold for the pose they were built for) and the tree
// answers.
#include <embree3/rtcore.h>

#include <memory>
#include <span>
#include <vector>

#include "collision/body_surface.hpp"
#include "collision/candidate_grid.hpp"

namespace drape::collision {

class TriangleBvh {
 public:
  // Builds over the surface's current pose. `refit`: later update() calls refit the tree instead of
  // rebuilding it (faster per frame, looser boxes after large deformations).
  TriangleBvh(const BodySurface& surface, bool refit);
  ~TriangleBvh();
  TriangleBvh(const TriangleBvh&) = delete;
  TriangleBvh& operator=(const TriangleBvh&) = delete;

  // The surface changed pose: refit or rebuild; drops the candidate grid.
  void update();

  // Builds the candidate grid for the current pose (cells of `cell` metres within `band` of the surface).
  // `wanted`: see CandidateGrid (lists only where queries will come).
  static constexpr float kGridCell = 0.007f, kGridBand = 0.016f;
  void build_candidate_grid(float cell = kGridCell, float band = kGridBand, const CandidateGrid::CellFilter& wanted = {});
  const CandidateGrid* candidate_grid() const { return grid_.get(); }

  // Nearest point of the body to p within `radius`; false when there is none. Thread-safe.
  bool closest(const Vec3f& p, float radius, SurfaceHit& hit) const;
  // closest() for a batch of points: found[i] and hits[i] as closest(points[i], ...) gives them,
  // faster, since the candidate grid's cache misses of many points overlap (CandidateGrid::cell_of).
  void closest_batch(std::span<const Vec3f> points, float radius, std::span<SurfaceHit> hits, std::span<uint8_t> found) const;
  // Nearest point through the tree only (no candidate grid).
  bool closest_in_tree(const Vec3f& p, float radius, SurfaceHit& hit) const;
  // Distance along the ray from `origin` in the unit `direction` to the first triangle it meets
  // within `max_distance` (either side of a triangle counts); false when none. Thread-safe.
  bool first_hit(const Vec3f& origin, const Vec3f& direction, float max_distance, float& distance) const;
  // Every triangle within `radius` of p with its point nearest p (cleared first), by triangle id.
  void within(const Vec3f& p, float radius, std::vector<SurfaceHit>& hits) const;

  const BodySurface& surface() const { return surface_; }

 private:
  void upload_vertices();
  // Completes the candidate grid's answer for p (asks the tree where the grid cannot tell).
  bool finish(CandidateGrid::Answer answer, const Vec3f& p, float radius, SurfaceHit& hit) const;

  const BodySurface& surface_;
  RTCDevice device_ = nullptr;
  RTCScene scene_ = nullptr;
  RTCGeometry geometry_ = nullptr;
  float* vertices_ = nullptr;  // Embree-owned vertex buffer (x, y, z per vertex)
  std::unique_ptr<CandidateGrid> grid_;
};

}  // namespace drape::collision
