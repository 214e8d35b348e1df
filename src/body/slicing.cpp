#include "body/slicing.hpp"
#include "geometry/disjoint_sets.hpp"

#include <algorithm>
#include <array>
#include <cstdint>
#include <cmath>
#include <numeric>

namespace drape::body {

SlicePlane horizontal_plane(float height) {
  // normal x u = v: (0,-1,0) x (1,0,0) = (0,0,1).
  return SlicePlane{Vec3f(0, height, 0), Vec3f(0, -1, 0), Vec3f(1, 0, 0)};
}

Slicer::Slicer(const Mesh& mesh) : positions(mesh.positions), triangles(mesh.triangles) {
  constexpr float kBand = 0.005f;
  if (positions.empty()) return;
  float lo = positions[0].y(), hi = lo;
  for (const auto& p : positions) {
    lo = std::min(lo, p.y());
    hi = std::max(hi, p.y());
  }
  y0_ = lo;
  inv_band_ = 1.0f / kBand;
  const auto bands = static_cast<size_t>((hi - lo) * inv_band_) + 2;
  // A triangle's bands run from its lowest vertex's band to its highest's.
  std::vector<uint32_t> vertex_band(positions.size());
  for (size_t i = 0; i < positions.size(); ++i) vertex_band[i] = static_cast<uint32_t>((positions[i].y() - y0_) * inv_band_);
  auto range = [&](const Tri& t) {
    const uint32_t a = vertex_band[t[0]], b = vertex_band[t[1]], c = vertex_band[t[2]];
    return std::pair<uint32_t, uint32_t>(std::min({a, b, c}), std::max({a, b, c}));
  };
  // Counting sort into bands, triangles ascending within each.
  start_.assign(bands + 1, 0);
  for (const Tri& t : triangles) {
    const auto [b0, b1] = range(t);
    for (uint32_t b = b0; b <= b1; ++b) ++start_[b + 1];
  }
  for (size_t b = 0; b < bands; ++b) start_[b + 1] += start_[b];
  tris_.resize(start_[bands]);
  std::vector<uint32_t> fill(start_.begin(), start_.end() - 1);
  for (uint32_t i = 0; i < triangles.size(); ++i) {
    const auto [b0, b1] = range(triangles[i]);
    for (uint32_t b = b0; b <= b1; ++b) tris_[fill[b]++] = i;
  }
}

std::span<const uint32_t> Slicer::band(float y) const {
  const float at = (y - y0_) * inv_band_;
  if (!(at >= 0) || start_.empty() || at >= static_cast<float>(start_.size() - 1)) return {};
  const auto b = static_cast<size_t>(at);
  return std::span<const uint32_t>(tris_).subspan(start_[b], start_[b + 1] - start_[b]);
}

std::vector<SectionPiece> slice(const Slicer& mesh, const SlicePlane& plane) {
  const auto& p = mesh.positions;
  auto side = [&](uint32_t v) { return (p[v] - plane.origin).dot(plane.normal); };

  // Each crossing edge gives one point, shared by the two triangles on it. Edges are collected in
  // the order met (two per cut triangle); a table keyed by edge finds each edge's first meeting,
  // and points are numbered in that order, whatever the table's layout.
  std::vector<uint64_t> edges;                     // per order met: the edge's key
  std::vector<std::array<uint32_t, 2>> edge_ends;  // per order met: the edge's vertices
  edges.reserve(512);
  edge_ends.reserve(512);
  auto cut = [&](const Tri& t) {
    const bool b0 = side(t[0]) < 0, b1 = side(t[1]) < 0, b2 = side(t[2]) < 0;
    if (b0 == b1 && b1 == b2) return;  // all on one side
    const bool below[3] = {b0, b1, b2};
    for (int e = 0; e < 3; ++e)
      if (below[e] != below[(e + 1) % 3]) {
        uint32_t a = t[e], c = t[(e + 1) % 3];
        if (a > c) std::swap(a, c);
        edges.push_back((uint64_t{a} << 32) | c);
        edge_ends.push_back({a, c});
      }
  };
  const bool horizontal = plane.normal.x() == 0 && plane.normal.z() == 0 && std::abs(plane.normal.y()) == 1;
  if (horizontal) {
    for (uint32_t i : mesh.band(plane.origin.y())) cut(mesh.triangles[i]);
  } else {
    // Every triangle; signs first so that the triangles on one side cost three byte loads.
    std::vector<uint8_t> below(p.size());
    for (uint32_t i = 0; i < p.size(); ++i) below[i] = side(i) < 0 ? 1 : 0;
    for (const Tri& t : mesh.triangles) {
      const unsigned signs = below[t[0]] | (below[t[1]] << 1) | (below[t[2]] << 2);
      if (signs != 0 && signs != 7) cut(t);
    }
  }
  // First meeting of each edge (open addressing, linear probing; a sort of the keys costs several
  // times more, and slicing is most of what measuring a body costs).
  const size_t met = edges.size();
  size_t capacity = 64;
  while (capacity < 2 * met) capacity *= 2;
  constexpr uint64_t kEmpty = ~uint64_t{0};  // no edge: vertex indices are below 2^32 - 1
  std::vector<uint64_t> slot_key(capacity, kEmpty);
  std::vector<uint32_t> slot_first(capacity);
  std::vector<uint32_t> first(met);  // per order met: the order its edge was first met
  for (uint32_t i = 0; i < met; ++i) {
    const uint64_t key = edges[i];
    size_t h = static_cast<size_t>((key * 0x9E3779B97F4A7C15ull) >> 32) & (capacity - 1);
    while (slot_key[h] != kEmpty && slot_key[h] != key) h = (h + 1) & (capacity - 1);
    if (slot_key[h] == kEmpty) {
      slot_key[h] = key;
      slot_first[h] = i;
    }
    first[i] = slot_first[h];
  }
  std::vector<uint32_t> point_of(met, 0);
  std::vector<Vec2f> points;
  const Vec3f v_axis = plane.v_axis();
  for (uint32_t i = 0; i < met; ++i) {
    if (first[i] != i) {
      point_of[i] = point_of[first[i]];
      continue;
    }
    point_of[i] = static_cast<uint32_t>(points.size());
    const uint32_t a = edge_ends[i][0], b = edge_ends[i][1];
    const float sa = side(a), sb = side(b);
    const float t = sa / (sa - sb);
    const Vec3f q = p[a] + t * (p[b] - p[a]) - plane.origin;
    points.emplace_back(q.dot(plane.u_axis), q.dot(v_axis));
  }
  // A cut triangle met its two crossing edges one after the other.
  std::vector<std::pair<uint32_t, uint32_t>> links;
  for (uint32_t i = 0; i + 1 < met; i += 2) links.emplace_back(point_of[i], point_of[i + 1]);

  // Connected pieces through the segments.
  DisjointSets sets(points.size());
  for (auto [a, b] : links) sets.unite(a, b);
  std::vector<int32_t> piece_of_root(points.size(), -1);
  std::vector<SectionPiece> pieces;
  for (uint32_t i = 0; i < points.size(); ++i) {
    int32_t& piece = piece_of_root[sets.find(i)];
    if (piece < 0) {
      piece = static_cast<int32_t>(pieces.size());
      pieces.emplace_back();
    }
    pieces[static_cast<size_t>(piece)].points.push_back(points[i]);
  }
  std::erase_if(pieces, [](const SectionPiece& s) { return s.points.size() < 3; });
  for (auto& s : pieces) {
    s.min = s.max = s.points[0];
    Vec2f sum = Vec2f::Zero();
    for (const auto& q : s.points) {
      s.min = s.min.cwiseMin(q);
      s.max = s.max.cwiseMax(q);
      sum += q;
    }
    s.centroid = sum / static_cast<float>(s.points.size());
  }
  // A stable order (by u of the centroid) so results never depend on hash order.
  std::sort(pieces.begin(), pieces.end(), [](const SectionPiece& a, const SectionPiece& b) {
    return a.centroid.x() < b.centroid.x() || (a.centroid.x() == b.centroid.x() && a.centroid.y() < b.centroid.y());
  });
  return pieces;
}

float hull_perimeter(std::vector<Vec2f> pts) {
  if (pts.size() < 2) return 0.0f;
  // Andrew's monotone chain.
  std::sort(pts.begin(), pts.end(), [](const Vec2f& a, const Vec2f& b) {
    return a.x() < b.x() || (a.x() == b.x() && a.y() < b.y());
  });
  auto cross = [](const Vec2f& o, const Vec2f& a, const Vec2f& b) {
    return (a.x() - o.x()) * (b.y() - o.y()) - (a.y() - o.y()) * (b.x() - o.x());
  };
  std::vector<Vec2f> hull(2 * pts.size());
  size_t k = 0;
  for (size_t i = 0; i < pts.size(); ++i) {
    while (k >= 2 && cross(hull[k - 2], hull[k - 1], pts[i]) <= 0) --k;
    hull[k++] = pts[i];
  }
  for (size_t i = pts.size() - 1, lower = k + 1; i-- > 0;) {
    while (k >= lower && cross(hull[k - 2], hull[k - 1], pts[i]) <= 0) --k;
    hull[k++] = pts[i];
  }
  hull.resize(k - 1);
  double perimeter = 0;
  for (size_t i = 0; i < hull.size(); ++i) perimeter += (hull[(i + 1) % hull.size()] - hull[i]).norm();
  return static_cast<float>(perimeter);
}

int nearest_piece(const std::vector<SectionPiece>& pieces, const Vec2f& uv) {
  int best = -1;
  float best_d = std::numeric_limits<float>::max();
  for (size_t i = 0; i < pieces.size(); ++i) {
    for (const auto& q : pieces[i].points) {
      const float d = (q - uv).squaredNorm();
      if (d < best_d) {
        best_d = d;
        best = static_cast<int>(i);
      }
    }
  }
  return best;
}

int piece_straddling(const std::vector<SectionPiece>& pieces, float u) {
  int best = -1;
  float best_span = 0;
  for (size_t i = 0; i < pieces.size(); ++i) {
    const auto& s = pieces[i];
    if (s.min.x() < u && s.max.x() > u && s.max.x() - s.min.x() > best_span) {
      best_span = s.max.x() - s.min.x();
      best = static_cast<int>(i);
    }
  }
  return best;
}

}  // namespace drape::body
