#pragma once
// Object-space closest-point queries on the body triangles (Vassilev & Spanlang sec. 4.1) through
// Embree 3's bounding volume hierarchy and rtcPointQuery. The paper built a quad tree of bounding
// boxes per scanned body part; Embree's BVH does the same job for any triangle mesh and refits in
// place when the body moves (RTC_BUILD_QUALITY_REFIT). A hand-made binary BVH (box_bvh.hpp)
// measured about 1.7x slower per query on this machine (bench_collision), so the colliders use this. The paper built a quad tree of bounding
// boxes per scanned body part; Embree's SAH BVH does the same job for any triangle mesh and refits
// in place when the body moves (RTC_BUILD_QUALITY_REFIT), which is what an animated body needs.
#include <embree3/rtcore.h>

#include "collision/body_surface.hpp"

namespace drape::collision {

class TriangleBvh {
 public:
  // Builds over the surface's current pose. `refit`: later update() calls refit the tree instead of
  // rebuilding it (faster per frame, looser boxes after large deformations).
  TriangleBvh(const BodySurface& surface, bool refit);
  ~TriangleBvh();
  TriangleBvh(const TriangleBvh&) = delete;
  TriangleBvh& operator=(const TriangleBvh&) = delete;

  // The surface changed pose: refit or rebuild.
  void update();

  // Nearest point of the body to p within `radius`; false when there is none. Thread-safe.
  bool closest(const Vec3f& p, float radius, SurfaceHit& hit) const;

  const BodySurface& surface() const { return surface_; }

 private:
  void upload_vertices();

  const BodySurface& surface_;
  RTCDevice device_ = nullptr;
  RTCScene scene_ = nullptr;
  RTCGeometry geometry_ = nullptr;
  float* vertices_ = nullptr;  // Embree-owned vertex buffer (x, y, z per vertex)
};

}  // namespace drape::collision
