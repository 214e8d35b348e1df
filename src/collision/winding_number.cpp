// Hierarchical generalized winding number; see winding_number.hpp.
#include "collision/winding_number.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace drape::collision {

double solid_angle(const Vec3d& q, const Vec3d& a, const Vec3d& b, const Vec3d& c) {
  const Vec3d x = a - q, y = b - q, z = c - q;
  const double lx = x.norm(), ly = y.norm(), lz = z.norm();
  const double numerator = x.dot(y.cross(z));
  const double denominator = lx * ly * lz + x.dot(y) * lz + x.dot(z) * ly + y.dot(z) * lx;
  return 2.0 * std::atan2(numerator, denominator);
}

WindingNumberTree::WindingNumberTree(std::span<const Vec3f> positions, std::span<const Tri> triangles)
    : tris_(triangles.begin(), triangles.end()), positions_(positions.begin(), positions.end()) {
  if (tris_.empty()) return;
  std::vector<Vec3f> centroids(tris_.size());
  for (size_t t = 0; t < tris_.size(); ++t)
    centroids[t] = (positions_[tris_[t][0]] + positions_[tris_[t][1]] + positions_[tris_[t][2]]) / 3.0f;
  nodes_.reserve(2 * tris_.size() / kLeafSize + 2);
  build(0, static_cast<uint32_t>(tris_.size()), centroids);
  refit(positions);
}

// Median split of the triangle range along the longest axis of its centroids' bounds.
uint32_t WindingNumberTree::build(uint32_t begin, uint32_t end, std::vector<Vec3f>& centroids) {
  const auto index = static_cast<uint32_t>(nodes_.size());
  nodes_.push_back(Node{});
  nodes_[index].begin = begin;
  nodes_[index].end = end;
  if (end - begin <= kLeafSize) return index;

  Bounds box;
  for (uint32_t t = begin; t < end; ++t) box.extend(centroids[t]);
  int axis = 0;
  box.size().maxCoeff(&axis);
  const uint32_t mid = begin + (end - begin) / 2;
  // Sort a permutation of the range, then apply it to triangles and centroids together.
  std::vector<uint32_t> order(end - begin);
  for (uint32_t i = 0; i < order.size(); ++i) order[i] = begin + i;
  std::nth_element(order.begin(), order.begin() + (mid - begin), order.end(),
                   [&](uint32_t l, uint32_t r) { return centroids[l][axis] < centroids[r][axis]; });
  std::vector<Tri> tris(order.size());
  std::vector<Vec3f> cents(order.size());
  for (size_t i = 0; i < order.size(); ++i) {
    tris[i] = tris_[order[i]];
    cents[i] = centroids[order[i]];
  }
  std::copy(tris.begin(), tris.end(), tris_.begin() + begin);
  std::copy(cents.begin(), cents.end(), centroids.begin() + begin);

  const uint32_t left = build(begin, mid, centroids);
  const uint32_t right = build(mid, end, centroids);
  nodes_[index].left = static_cast<int32_t>(left);
  nodes_[index].right = static_cast<int32_t>(right);
  return index;
}

// Moments of one node from its triangles (leaf) or its children (children are already fitted).
void WindingNumberTree::fit_node(Node& node) const {
  node.center.setZero();
  node.area_normal.setZero();
  node.area = 0;
  node.radius = 0;
  if (node.left < 0) {
    for (uint32_t t = node.begin; t < node.end; ++t) {
      const Vec3d a = positions_[tris_[t][0]].cast<double>(), b = positions_[tris_[t][1]].cast<double>(),
                  c = positions_[tris_[t][2]].cast<double>();
      const Vec3d area_vector = 0.5 * (b - a).cross(c - a);
      const double area = area_vector.norm();
      node.area_normal += area_vector;
      node.center += area * (a + b + c) / 3.0;
      node.area += area;
    }
    if (node.area > 0) {
      node.center /= node.area;
    } else {
      node.center = positions_[tris_[node.begin][0]].cast<double>();
    }
    for (uint32_t t = node.begin; t < node.end; ++t)
      for (uint32_t k : tris_[t]) node.radius = std::max(node.radius, (positions_[k].cast<double>() - node.center).norm());
    return;
  }
  const Node& l = nodes_[static_cast<size_t>(node.left)];
  const Node& r = nodes_[static_cast<size_t>(node.right)];
  node.area = l.area + r.area;
  node.area_normal = l.area_normal + r.area_normal;
  node.center = node.area > 0 ? Vec3d((l.area * l.center + r.area * r.center) / node.area) : l.center;
  node.radius = std::max((l.center - node.center).norm() + l.radius, (r.center - node.center).norm() + r.radius);
}

void WindingNumberTree::refit(std::span<const Vec3f> positions) {
  std::copy(positions.begin(), positions.end(), positions_.begin());
  // Children have higher indices than their parent: fit from the back.
  for (size_t i = nodes_.size(); i-- > 0;) fit_node(nodes_[i]);
}

double WindingNumberTree::winding_number(const Vec3f& qf) const {
  if (nodes_.empty()) return 0.0;
  const Vec3d q = qf.cast<double>();
  double omega = 0.0;
  uint32_t stack[128];
  int top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const Node& node = nodes_[stack[--top]];
    const Vec3d d = node.center - q;
    const double dist = d.norm();
    if (dist > kFarFactor * node.radius) {
      // Far cluster: dipole approximation of the summed solid angles.
      omega += d.dot(node.area_normal) / (dist * dist * dist);
    } else if (node.left < 0) {
      for (uint32_t t = node.begin; t < node.end; ++t)
        omega += solid_angle(q, positions_[tris_[t][0]].cast<double>(), positions_[tris_[t][1]].cast<double>(),
                             positions_[tris_[t][2]].cast<double>());
    } else {
      stack[top++] = static_cast<uint32_t>(node.left);
      stack[top++] = static_cast<uint32_t>(node.right);
    }
  }
  return omega / (4.0 * std::numbers::pi);
}

}  // namespace drape::collision
