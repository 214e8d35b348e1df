#include "geometry/topology.hpp"
#include "geometry/disjoint_sets.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cstdint>
#include <numeric>
#include <unordered_map>

namespace drape::geometry {

bool is_degenerate(const std::vector<Vec3f>& positions, const Tri& tri) {
  if (tri[0] == tri[1] || tri[1] == tri[2] || tri[0] == tri[2]) return true;
  const Vec3f& a = positions[tri[0]];
  const Vec3f e1 = positions[tri[1]] - a;
  const Vec3f e2 = positions[tri[2]] - a;
  // Zero area relative to the triangle's own size, so the test does not depend on units.
  const float longest = std::max({e1.squaredNorm(), e2.squaredNorm(), (e2 - e1).squaredNorm()});
  return e1.cross(e2).norm() <= 1e-10f * longest || longest == 0.0f;
}

namespace {

// Twice the signed area of the 2D triangle (a, b, c).
float cross2(const Eigen::Vector2f& a, const Eigen::Vector2f& b, const Eigen::Vector2f& c) {
  const Eigen::Vector2f u = b - a, v = c - a;
  return u.x() * v.y() - u.y() * v.x();
}

bool inside_triangle(const Eigen::Vector2f& p, const Eigen::Vector2f& a, const Eigen::Vector2f& b,
                     const Eigen::Vector2f& c) {
  return cross2(a, b, p) >= 0.0f && cross2(b, c, p) >= 0.0f && cross2(c, a, p) >= 0.0f;
}

// Ear clipping on the polygon projected to its Newell plane; false when no ear is found.
bool ear_clip(const std::vector<Vec3f>& positions, std::span<const uint32_t> corners, std::vector<Tri>& out) {
  const size_t n = corners.size();
  Vec3f normal = Vec3f::Zero();
  for (size_t i = 0; i < n; ++i) {
    const Vec3f& p = positions[corners[i]];
    const Vec3f& q = positions[corners[(i + 1) % n]];
    normal += Vec3f((p.y() - q.y()) * (p.z() + q.z()), (p.z() - q.z()) * (p.x() + q.x()),
                    (p.x() - q.x()) * (p.y() + q.y()));
  }
  if (normal.norm() == 0.0f) return false;
  normal.normalize();
  const Vec3f u = normal.unitOrthogonal();
  const Vec3f v = normal.cross(u);
  std::vector<Eigen::Vector2f> p2(n);
  for (size_t i = 0; i < n; ++i) p2[i] = {positions[corners[i]].dot(u), positions[corners[i]].dot(v)};

  std::vector<size_t> ring(n);
  std::iota(ring.begin(), ring.end(), size_t{0});
  std::vector<Tri> tris;
  while (ring.size() > 3) {
    bool clipped = false;
    for (size_t i = 0; i < ring.size() && !clipped; ++i) {
      const size_t a = ring[(i + ring.size() - 1) % ring.size()], b = ring[i],
                   c = ring[(i + 1) % ring.size()];
      if (cross2(p2[a], p2[b], p2[c]) <= 0.0f) continue;  // reflex corner
      bool empty = true;
      for (size_t k : ring)
        if (k != a && k != b && k != c && inside_triangle(p2[k], p2[a], p2[b], p2[c])) empty = false;
      if (!empty) continue;
      tris.push_back({corners[a], corners[b], corners[c]});
      ring.erase(ring.begin() + static_cast<std::ptrdiff_t>(i));
      clipped = true;
    }
    if (!clipped) return false;
  }
  tris.push_back({corners[ring[0]], corners[ring[1]], corners[ring[2]]});
  out.insert(out.end(), tris.begin(), tris.end());
  return true;
}

}  // namespace

void triangulate_polygon(const std::vector<Vec3f>& positions, std::span<const uint32_t> corners,
                         std::vector<Tri>& out) {
  const size_t n = corners.size();
  if (n < 3) return;
  if (n == 3) {
    out.push_back({corners[0], corners[1], corners[2]});
    return;
  }
  if (n == 4) {
    // The shorter diagonal gives the better-shaped pair of triangles.
    const float d02 = (positions[corners[0]] - positions[corners[2]]).squaredNorm();
    const float d13 = (positions[corners[1]] - positions[corners[3]]).squaredNorm();
    if (d02 <= d13) {
      out.push_back({corners[0], corners[1], corners[2]});
      out.push_back({corners[0], corners[2], corners[3]});
    } else {
      out.push_back({corners[0], corners[1], corners[3]});
      out.push_back({corners[1], corners[2], corners[3]});
    }
    return;
  }
  if (ear_clip(positions, corners, out)) return;
  for (size_t i = 1; i + 1 < n; ++i) out.push_back({corners[0], corners[i], corners[i + 1]});
}

EdgeTopology edge_topology(const std::vector<Vec3f>& positions, const std::vector<Tri>& triangles) {
  // Weld bit-identical positions: seam copies of a vertex share one id.
  struct Key {
    float x, y, z;
    bool operator==(const Key& o) const { return x == o.x && y == o.y && z == o.z; }
  };
  struct KeyHash {
    size_t operator()(const Key& k) const {
      return std::hash<float>()(k.x) * 73856093u ^ std::hash<float>()(k.y) * 19349663u ^
             std::hash<float>()(k.z) * 83492791u;
    }
  };
  std::unordered_map<Key, uint32_t, KeyHash> first;
  first.reserve(positions.size());
  std::vector<uint32_t> weld(positions.size());
  for (size_t i = 0; i < positions.size(); ++i) {
    const Key k{positions[i].x(), positions[i].y(), positions[i].z()};
    weld[i] = first.try_emplace(k, static_cast<uint32_t>(i)).first->second;
  }

  // Undirected edges as sorted 64-bit keys; equal runs give each edge's use count.
  std::vector<uint64_t> edges;
  edges.reserve(triangles.size() * 3);
  for (const Tri& t : triangles)
    for (int e = 0; e < 3; ++e) {
      const uint64_t a = weld[t[e]], b = weld[t[(e + 1) % 3]];
      if (a != b) edges.push_back(std::min(a, b) << 32 | std::max(a, b));
    }
  std::sort(edges.begin(), edges.end());

  EdgeTopology topo;
  DisjointSets sets(positions.size());
  std::vector<uint32_t> boundary_vertices;
  for (size_t i = 0; i < edges.size();) {
    size_t j = i;
    while (j < edges.size() && edges[j] == edges[i]) ++j;
    const size_t uses = j - i;
    if (uses == 1) {
      ++topo.boundary_edges;
      const auto a = static_cast<uint32_t>(edges[i] >> 32), b = static_cast<uint32_t>(edges[i] & 0xffffffffu);
      sets.unite(a, b);
      boundary_vertices.push_back(a);
    } else if (uses >= 3) {
      ++topo.non_manifold_edges;
    }
    i = j;
  }
  // One loop per connected set of boundary edges.
  std::vector<uint32_t> roots;
  roots.reserve(boundary_vertices.size());
  for (uint32_t v : boundary_vertices) roots.push_back(sets.find(v));
  std::sort(roots.begin(), roots.end());
  topo.boundary_loops = static_cast<size_t>(std::unique(roots.begin(), roots.end()) - roots.begin());
  return topo;
}

}  // namespace drape::geometry
