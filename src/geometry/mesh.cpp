#include "drape/mesh.hpp"

#include <Eigen/Geometry>

namespace drape {

Bounds bounds(const std::vector<Vec3f>& points) {
  Bounds b;
  for (const auto& p : points) b.extend(p);
  return b;
}

std::vector<Vec3f> vertex_normals(const std::vector<Vec3f>& positions, const std::vector<Tri>& triangles) {
  std::vector<Vec3f> n(positions.size(), Vec3f::Zero());
  for (const auto& t : triangles) {
    // The cross product's length is twice the area: area weighting for free.
    const Vec3f fn = (positions[t[1]] - positions[t[0]]).cross(positions[t[2]] - positions[t[0]]);
    for (uint32_t v : t) n[v] += fn;
  }
  for (auto& v : n) {
    const float len = v.norm();
    v = len > 0.0f ? Vec3f(v / len) : Vec3f::Zero();
  }
  return n;
}

}  // namespace drape
