// Self-intersections of a closed body mesh, and their repair. MakeHuman's toes are modelled one by
// one and touch: on the base mesh and more so on heavy bodies the little toes' surfaces pass
// through each other. Crossing triangles are found with a uniform grid (each pair tested once, in
// the cell holding the low corner of the overlap of their boxes) and a segment-triangle test both
// ways; the repair pulls the vertices of crossing triangles inwards along their normals in small
// steps until nothing crosses (the toes come apart by a millimetre or two).
#include <algorithm>
#include <cmath>
#include <span>

#include "body/makehuman.hpp"

namespace drape::body {
namespace {

// Whether segment pq crosses triangle abc strictly inside the segment (Möller-Trumbore).
bool segment_crosses(const Vec3f& p, const Vec3f& q, const Vec3f& a, const Vec3f& b, const Vec3f& c) {
  const Vec3f d = q - p, e1 = b - a, e2 = c - a;
  const Vec3f h = d.cross(e2);
  const float det = e1.dot(h);
  if (std::abs(det) < 1e-14f) return false;
  const Vec3f s = p - a;
  const float u = s.dot(h) / det;
  if (u < 0 || u > 1) return false;
  const Vec3f qv = s.cross(e1);
  const float v = d.dot(qv) / det;
  if (v < 0 || u + v > 1) return false;
  const float t = e2.dot(qv) / det;
  return t > 0 && t < 1;
}

// Whether all three vertices of `a` lie strictly on one side of the plane of `b`.
bool one_side(const std::vector<Vec3f>& p, const Tri& a, const Tri& b) {
  const Vec3f n = (p[b[1]] - p[b[0]]).cross(p[b[2]] - p[b[0]]);
  const float d0 = n.dot(p[a[0]] - p[b[0]]), d1 = n.dot(p[a[1]] - p[b[0]]), d2 = n.dot(p[a[2]] - p[b[0]]);
  return (d0 > 0 && d1 > 0 && d2 > 0) || (d0 < 0 && d1 < 0 && d2 < 0);
}

bool triangles_cross(const Mesh& m, const Tri& a, const Tri& b) {
  const auto& p = m.positions;
  if (one_side(p, a, b) || one_side(p, b, a)) return false;
  for (int e = 0; e < 3; ++e) {
    if (segment_crosses(p[a[e]], p[a[(e + 1) % 3]], p[b[0]], p[b[1]], p[b[2]])) return true;
    if (segment_crosses(p[b[e]], p[b[(e + 1) % 3]], p[a[0]], p[a[1]], p[a[2]])) return true;
  }
  return false;
}

}  // namespace

std::vector<std::pair<uint32_t, uint32_t>> crossing_triangles(const Mesh& mesh, std::span<const uint32_t> focus) {
  constexpr float kCell = 0.01f;
  const size_t t_count = mesh.triangles.size();
  std::vector<Eigen::Vector3i> lo(t_count), hi(t_count);
  std::vector<Vec3f> box_lo(t_count), box_hi(t_count);
  std::vector<std::pair<uint64_t, uint32_t>> cells;  // (cell key, triangle)
  cells.reserve(4 * t_count);
  auto key = [](int x, int y, int z) {
    return (static_cast<uint64_t>(static_cast<uint32_t>(x + 32768) & 0xFFFFF) << 40) |
           (static_cast<uint64_t>(static_cast<uint32_t>(y + 32768) & 0xFFFFF) << 20) |
           static_cast<uint64_t>(static_cast<uint32_t>(z + 32768) & 0xFFFFF);
  };
  // With a focus, only the cells around the focus triangles (one cell of margin) are looked at.
  std::vector<uint64_t> wanted;
  auto cell_range = [&](uint32_t t, int margin, auto&& visit) {
    for (int x = lo[t].x() - margin; x <= hi[t].x() + margin; ++x)
      for (int y = lo[t].y() - margin; y <= hi[t].y() + margin; ++y)
        for (int z = lo[t].z() - margin; z <= hi[t].z() + margin; ++z) visit(key(x, y, z));
  };
  for (uint32_t t = 0; t < t_count; ++t) {
    const Tri& tri = mesh.triangles[t];
    Vec3f a = mesh.positions[tri[0]], b = a;
    for (int k = 1; k < 3; ++k) {
      a = a.cwiseMin(mesh.positions[tri[k]]);
      b = b.cwiseMax(mesh.positions[tri[k]]);
    }
    box_lo[t] = a;
    box_hi[t] = b;
    lo[t] = (a / kCell).array().floor().cast<int>();
    hi[t] = (b / kCell).array().floor().cast<int>();
  }
  for (uint32_t t : focus) cell_range(t, 1, [&](uint64_t k) { wanted.push_back(k); });
  std::sort(wanted.begin(), wanted.end());
  // (cell, triangle) entries, sorted by cell then triangle. Where the cells' coordinates fit 16 bits
  // and the triangles' indices too (a body's always do), an entry is one integer, which sorts several
  // times faster than a pair; the order is the same.
  bool packed = t_count < (size_t{1} << 16);
  for (uint32_t t = 0; t < t_count && packed; ++t)
    packed = lo[t].minCoeff() >= -32768 && hi[t].maxCoeff() < 32768;
  auto key16 = [](int x, int y, int z) {
    return (static_cast<uint64_t>(x + 32768) << 32) | (static_cast<uint64_t>(y + 32768) << 16) |
           static_cast<uint64_t>(z + 32768);
  };
  std::vector<uint64_t> entries;  // packed: key16 << 16 | triangle
  if (packed) {
    entries.reserve(4 * t_count);
    for (uint32_t t = 0; t < t_count; ++t)
      for (int x = lo[t].x(); x <= hi[t].x(); ++x)
        for (int y = lo[t].y(); y <= hi[t].y(); ++y)
          for (int z = lo[t].z(); z <= hi[t].z(); ++z)
            if (focus.empty() || std::binary_search(wanted.begin(), wanted.end(), key(x, y, z)))
              entries.push_back((key16(x, y, z) << 16) | t);
    std::sort(entries.begin(), entries.end());
  } else {
    for (uint32_t t = 0; t < t_count; ++t)
      cell_range(t, 0, [&](uint64_t k) {
        if (focus.empty() || std::binary_search(wanted.begin(), wanted.end(), k)) cells.emplace_back(k, t);
      });
    std::sort(cells.begin(), cells.end());
  }
  const size_t count = packed ? entries.size() : cells.size();
  auto cell_of = [&](size_t i) { return packed ? entries[i] >> 16 : cells[i].first; };
  auto triangle_of = [&](size_t i) { return packed ? static_cast<uint32_t>(entries[i] & 0xFFFF) : cells[i].second; };
  std::vector<std::pair<uint32_t, uint32_t>> out;
  for (size_t begin = 0; begin < count;) {
    const uint64_t cell = cell_of(begin);
    size_t end = begin;
    while (end < count && cell_of(end) == cell) ++end;
    for (size_t i = begin; i < end; ++i)
      for (size_t j = i + 1; j < end; ++j) {
        const uint32_t s = triangle_of(i), t = triangle_of(j);
        // Boxes overlap, and this cell holds the low corner of the overlap: each pair once.
        const Eigen::Vector3i l = lo[s].cwiseMax(lo[t]), h = hi[s].cwiseMin(hi[t]);
        if ((l.array() > h.array()).any() || (packed ? key16(l.x(), l.y(), l.z()) : key(l.x(), l.y(), l.z())) != cell)
          continue;
        if ((box_lo[s].array() > box_hi[t].array()).any() || (box_lo[t].array() > box_hi[s].array()).any()) continue;
        const Tri& a = mesh.triangles[s];
        const Tri& b = mesh.triangles[t];
        bool shared = false;
        for (uint32_t u : a)
          for (uint32_t v : b) shared |= u == v;
        if (!shared && triangles_cross(mesh, a, b)) out.emplace_back(std::min(s, t), std::max(s, t));
      }
    begin = end;
  }
  return out;
}

size_t untangle(Mesh& mesh, int max_rounds) {
  constexpr float kStep = 0.0005f;  // metres per round
  auto crossings = crossing_triangles(mesh);
  // Later rounds look only where something crossed: nothing else moves.
  std::vector<uint32_t> focus;
  for (const auto& [s, t] : crossings) focus.insert(focus.end(), {s, t});
  std::vector<std::vector<uint32_t>> neighbours;
  for (int round = 0; round < max_rounds && !crossings.empty(); ++round) {
    if (neighbours.empty()) {
      neighbours.resize(mesh.positions.size());
      for (const Tri& t : mesh.triangles)
        for (int e = 0; e < 3; ++e) neighbours[t[e]].push_back(t[(e + 1) % 3]);
    }
    const std::vector<Vec3f> normals = vertex_normals(mesh.positions, mesh.triangles);
    std::vector<uint32_t> moved;
    for (const auto& [s, t] : crossings)
      for (uint32_t tri : {s, t})
        for (uint32_t v : mesh.triangles[tri]) moved.push_back(v);
    std::sort(moved.begin(), moved.end());
    moved.erase(std::unique(moved.begin(), moved.end()), moved.end());
    // Inwards, and halfway to the neighbours' mean: a crease where two sheets pass through each
    // other (a heavy body's gluteal cleft) is both pulled back and filled.
    std::vector<Vec3f> next(moved.size());
    for (size_t i = 0; i < moved.size(); ++i) {
      const uint32_t v = moved[i];
      Vec3f mean = Vec3f::Zero();
      for (uint32_t u : neighbours[v]) mean += mesh.positions[u];
      mean /= static_cast<float>(std::max<size_t>(1, neighbours[v].size()));
      next[i] = 0.5f * (mesh.positions[v] + mean) - kStep * normals[v];
    }
    for (size_t i = 0; i < moved.size(); ++i) mesh.positions[moved[i]] = next[i];
    crossings = crossing_triangles(mesh, focus);
    for (const auto& [s, t] : crossings) focus.insert(focus.end(), {s, t});
  }
  // Vertices move half a millimetre a round, so what they can newly cross lies within the focus.
  return crossings.size();
}

}  // namespace drape::body
