#pragma once
// A hand-made binary bounding volume hierarchy for closest-point queries: axis-aligned boxes,
// median splits, nearest child first, pruned by the best distance so far; leaves keep their
// triangles' corners inline. Kept as the measured alternative to Embree's rtcPointQuery
// (triangle_bvh.hpp), which was faster here; bench_collision runs both.
#include <vector>

#include "collision/body_surface.hpp"

namespace drape::collision {

class BoxBvh {
 public:
  explicit BoxBvh(const BodySurface& surface);

  // The surface changed pose (same topology): refit the boxes bottom-up.
  void update();

  // Nearest point of the body to p within `radius`; false when there is none. Thread-safe.
  bool closest(const Vec3f& p, float radius, SurfaceHit& hit) const;

  const BodySurface& surface() const { return surface_; }
  size_t memory_bytes() const {
    return nodes_.size() * sizeof(Node) + order_.size() * sizeof(uint32_t) + corners_.size() * sizeof(Vec3f);
  }

 private:
  struct Node {
    Vec3f lo, hi;
    uint32_t first = 0;  // leaf: first index into order_; inner: index of the left child (right = first + 1)
    uint32_t count = 0;  // leaf: number of triangles; 0 for an inner node
  };
  static constexpr uint32_t kLeafSize = 4;

  void build(uint32_t node, uint32_t begin, uint32_t end, std::vector<Vec3f>& centroids);
  void fit(Node& node) const;

  const BodySurface& surface_;
  std::vector<Node> nodes_;
  std::vector<uint32_t> order_;  // triangle indices, each leaf's contiguous
  std::vector<Vec3f> corners_;   // the three corners of order_[i] at 3i..3i+2: leaves read no index
};

}  // namespace drape::collision
