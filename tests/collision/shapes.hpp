#pragma once
// Analytic test shapes for the collision tests and benchmark: tessellated spheres and capsules
// whose exact signed distance is known in closed form.
#include <algorithm>
#include <cmath>
#include <map>
#include <numbers>
#include <utility>

#include "drape/mesh.hpp"

namespace drape::test {

// Icosphere: an icosahedron subdivided `levels` times, projected onto the sphere; CCW from outside.
inline Mesh icosphere(const Vec3f& centre, float radius, int levels) {
  const float t = (1.0f + std::sqrt(5.0f)) / 2.0f;
  std::vector<Vec3f> v = {{-1, t, 0}, {1, t, 0}, {-1, -t, 0}, {1, -t, 0}, {0, -1, t}, {0, 1, t},
                          {0, -1, -t}, {0, 1, -t}, {t, 0, -1}, {t, 0, 1}, {-t, 0, -1}, {-t, 0, 1}};
  for (auto& p : v) p.normalize();
  std::vector<Tri> f = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
                        {11, 10, 2}, {10, 7, 6}, {7, 1, 8},  {3, 9, 4},  {3, 4, 2},   {3, 2, 6}, {3, 6, 8},
                        {3, 8, 9},  {4, 9, 5},  {2, 4, 11}, {6, 2, 10}, {8, 6, 7},   {9, 8, 1}};
  for (int level = 0; level < levels; ++level) {
    std::map<std::pair<uint32_t, uint32_t>, uint32_t> midpoints;
    auto mid = [&](uint32_t a, uint32_t b) {
      const auto key = std::minmax(a, b);
      auto it = midpoints.find(key);
      if (it != midpoints.end()) return it->second;
      v.push_back((v[a] + v[b]).normalized());
      const auto index = static_cast<uint32_t>(v.size() - 1);
      midpoints.emplace(key, index);
      return index;
    };
    std::vector<Tri> next;
    for (const Tri& tri : f) {
      const uint32_t a = mid(tri[0], tri[1]), b = mid(tri[1], tri[2]), c = mid(tri[2], tri[0]);
      next.push_back({tri[0], a, c});
      next.push_back({tri[1], b, a});
      next.push_back({tri[2], c, b});
      next.push_back({a, b, c});
    }
    f = std::move(next);
  }
  Mesh mesh;
  mesh.name = "sphere";
  for (const auto& p : v) mesh.positions.push_back(centre + radius * p);
  mesh.triangles = f;
  return mesh;
}

// Capsule around the segment from centre - (0, half_length, 0) to centre + (0, half_length, 0).
inline Mesh capsule(const Vec3f& centre, float radius, float half_length, int segments, int rings) {
  Mesh mesh;
  mesh.name = "capsule";
  // Latitude rings from the top pole to the bottom pole; the cylinder is the gap between equators.
  std::vector<std::pair<float, float>> ring_y_r;  // (y offset, ring radius)
  for (int k = 1; k < rings; ++k) {
    const float phi = std::numbers::pi_v<float> / 2 * static_cast<float>(k) / static_cast<float>(rings);
    ring_y_r.emplace_back(half_length + radius * std::cos(phi), radius * std::sin(phi));
  }
  ring_y_r.emplace_back(half_length, radius);
  const int cylinder_rings = std::max(1, static_cast<int>(2 * half_length / (radius * 2 * std::numbers::pi_v<float> / static_cast<float>(segments))));
  for (int k = 1; k < cylinder_rings; ++k)
    ring_y_r.emplace_back(half_length - 2 * half_length * static_cast<float>(k) / static_cast<float>(cylinder_rings), radius);
  ring_y_r.emplace_back(-half_length, radius);
  for (int k = rings - 1; k >= 1; --k) {
    const float phi = std::numbers::pi_v<float> / 2 * static_cast<float>(k) / static_cast<float>(rings);
    ring_y_r.emplace_back(-half_length - radius * std::cos(phi), radius * std::sin(phi));
  }
  mesh.positions.push_back(centre + Vec3f(0, half_length + radius, 0));
  for (const auto& [y, r] : ring_y_r)
    for (int s = 0; s < segments; ++s) {
      const float theta = 2 * std::numbers::pi_v<float> * static_cast<float>(s) / static_cast<float>(segments);
      mesh.positions.push_back(centre + Vec3f(r * std::sin(theta), y, r * std::cos(theta)));
    }
  mesh.positions.push_back(centre - Vec3f(0, half_length + radius, 0));
  const auto seg = static_cast<uint32_t>(segments);
  const auto ring_count = static_cast<uint32_t>(ring_y_r.size());
  auto at = [&](uint32_t ring, uint32_t s) { return 1 + ring * seg + s % seg; };
  for (uint32_t s = 0; s < seg; ++s) mesh.triangles.push_back({0, at(0, s), at(0, s + 1)});
  for (uint32_t r = 0; r + 1 < ring_count; ++r)
    for (uint32_t s = 0; s < seg; ++s) {
      mesh.triangles.push_back({at(r, s), at(r + 1, s), at(r + 1, s + 1)});
      mesh.triangles.push_back({at(r, s), at(r + 1, s + 1), at(r, s + 1)});
    }
  const auto bottom = static_cast<uint32_t>(mesh.positions.size() - 1);
  for (uint32_t s = 0; s < seg; ++s) mesh.triangles.push_back({bottom, at(ring_count - 1, s + 1), at(ring_count - 1, s)});
  return mesh;
}

inline float capsule_distance(const Vec3f& p, const Vec3f& centre, float radius, float half_length) {
  Vec3f q = p - centre;
  q.y() -= std::clamp(q.y(), -half_length, half_length);
  return q.norm() - radius;
}

}  // namespace drape::test
