// Hand-made closest-point BVH; see triangle_bvh.hpp.
#include "collision/box_bvh.hpp"

#include <algorithm>
#include <cmath>

namespace drape::collision {
namespace {

float box_distance_squared(const Vec3f& p, const Vec3f& lo, const Vec3f& hi) {
  const Vec3f d = (lo - p).cwiseMax(p - hi).cwiseMax(0.0f);
  return d.squaredNorm();
}

}  // namespace

BoxBvh::BoxBvh(const BodySurface& surface) : surface_(surface) {
  const auto n = static_cast<uint32_t>(surface_.triangle_count());
  order_.resize(n);
  std::vector<Vec3f> centroids(n);
  for (uint32_t t = 0; t < n; ++t) {
    order_[t] = t;
    const Tri& tri = surface_.triangle(t);
    centroids[t] = (surface_.position(tri[0]) + surface_.position(tri[1]) + surface_.position(tri[2])) / 3.0f;
  }
  nodes_.reserve(2 * (n / kLeafSize + 1));
  nodes_.emplace_back();
  if (n > 0) build(0, 0, n, centroids);
  update();
}

// Median split along the longest axis of the centroids; both children are allocated together.
void BoxBvh::build(uint32_t node, uint32_t begin, uint32_t end, std::vector<Vec3f>& centroids) {
  if (end - begin <= kLeafSize) {
    nodes_[node].first = begin;
    nodes_[node].count = end - begin;
    return;
  }
  Bounds box;
  for (uint32_t i = begin; i < end; ++i) box.extend(centroids[order_[i]]);
  int axis = 0;
  box.size().maxCoeff(&axis);
  const uint32_t mid = begin + (end - begin) / 2;
  std::nth_element(order_.begin() + begin, order_.begin() + mid, order_.begin() + end,
                   [&](uint32_t a, uint32_t b) { return centroids[a][axis] < centroids[b][axis]; });
  const auto left = static_cast<uint32_t>(nodes_.size());
  nodes_.emplace_back();
  nodes_.emplace_back();
  nodes_[node].first = left;
  nodes_[node].count = 0;
  build(left, begin, mid, centroids);
  build(left + 1, mid, end, centroids);
}

void BoxBvh::fit(Node& node) const {
  Bounds box;
  if (node.count > 0) {
    for (uint32_t i = node.first; i < node.first + node.count; ++i)
      for (size_t k = 0; k < 3; ++k) box.extend(corners_[3 * i + k]);
  } else {
    for (uint32_t c = node.first; c < node.first + 2; ++c) {
      box.extend(nodes_[c].lo);
      box.extend(nodes_[c].hi);
    }
  }
  node.lo = box.min;
  node.hi = box.max;
}

void BoxBvh::update() {
  corners_.resize(3 * order_.size());
  for (size_t i = 0; i < order_.size(); ++i)
    for (size_t k = 0; k < 3; ++k) corners_[3 * i + k] = surface_.position(surface_.triangle(order_[i])[k]);
  // Children always have higher indices than their parent: fit from the back.
  for (size_t i = nodes_.size(); i-- > 0;) fit(nodes_[i]);
}

bool BoxBvh::closest(const Vec3f& p, float radius, SurfaceHit& hit) const {
  if (order_.empty()) return false;
  float best = radius * radius;  // squared distance to beat
  bool found = false;
  struct Entry {
    uint32_t node;
    float distance_squared;
  };
  Entry stack[64];
  int top = 0;
  const float root = box_distance_squared(p, nodes_[0].lo, nodes_[0].hi);
  if (root < best) stack[top++] = {0, root};
  while (top > 0) {
    const Entry entry = stack[--top];
    if (entry.distance_squared >= best) continue;
    const Node& node = nodes_[entry.node];
    if (node.count > 0) {
      for (uint32_t i = node.first; i < node.first + node.count; ++i) {
        const TrianglePoint where = closest_on_triangle(p, corners_[3 * i], corners_[3 * i + 1], corners_[3 * i + 2]);
        const float d2 = (where.point - p).squaredNorm();
        if (d2 < best) {
          best = d2;
          hit.triangle = order_[i];
          hit.where = where;
          found = true;
        }
      }
      continue;
    }
    // Visit the nearer child first: push it last.
    const Node& left = nodes_[node.first];
    const Node& right = nodes_[node.first + 1];
    const float dl = box_distance_squared(p, left.lo, left.hi);
    const float dr = box_distance_squared(p, right.lo, right.hi);
    const bool left_first = dl <= dr;
    const Entry near{left_first ? node.first : node.first + 1, left_first ? dl : dr};
    const Entry far{left_first ? node.first + 1 : node.first, left_first ? dr : dl};
    if (far.distance_squared < best) stack[top++] = far;
    if (near.distance_squared < best) stack[top++] = near;
  }
  if (found) hit.distance = std::sqrt(best);
  return found;
}

}  // namespace drape::collision
