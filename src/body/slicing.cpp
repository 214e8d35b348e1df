#include "body/slicing.hpp"
#include "geometry/disjoint_sets.hpp"

#include <algorithm>
#include <array>
#include <cstdint>
#include <cmath>
#include <limits>
#include <numeric>

namespace drape::body {

namespace {

// Pieces of a section in a stable order: by u of the centroid, then v.
bool piece_before(const SectionPiece& a, const SectionPiece& b) {
  return a.centroid.x() < b.centroid.x() || (a.centroid.x() == b.centroid.x() && a.centroid.y() < b.centroid.y());
}

}  // namespace

SlicePlane horizontal_plane(float height) {
  // normal x u = v: (0,-1,0) x (1,0,0) = (0,0,1).
  return SlicePlane{Vec3f(0, height, 0), Vec3f(0, -1, 0), Vec3f(1, 0, 0)};
}

SliceTopology::SliceTopology(const std::vector<Tri>& triangles) {
  // Half-edges sorted by their undirected edge: a closed manifold edge has exactly two.
  std::vector<std::pair<uint64_t, uint32_t>> half(3 * triangles.size());
  for (uint32_t t = 0; t < triangles.size(); ++t)
    for (uint32_t e = 0; e < 3; ++e) {
      const uint32_t a = std::min(triangles[t][e], triangles[t][(e + 1) % 3]);
      const uint32_t b = std::max(triangles[t][e], triangles[t][(e + 1) % 3]);
      half[3 * t + e] = {(uint64_t{a} << 32) | b, 3 * t + e};
    }
  std::sort(half.begin(), half.end());
  across.resize(triangles.size());
  for (size_t i = 0; i < half.size(); i += 2) {
    const bool pair = i + 1 < half.size() && half[i].first == half[i + 1].first &&
                      (i + 2 == half.size() || half[i + 2].first != half[i].first);
    if (!pair) {
      across.clear();
      return;
    }
    const uint32_t h0 = half[i].second, h1 = half[i + 1].second;
    across[h0 / 3][h0 % 3] = h1 / 3;
    across[h1 / 3][h1 % 3] = h0 / 3;
  }
}

Slicer::Slicer(const Mesh& mesh, const SliceTopology* topology_)
    : positions(mesh.positions),
      triangles(mesh.triangles),
      topology(topology_ && topology_->across.size() == mesh.triangles.size() ? topology_ : nullptr) {
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
  // A triangle's bands run from its lowest vertex's band to its highest's. Its height range and
  // its chunk's box are taken on the same pass.
  std::vector<uint32_t> vertex_band(positions.size());
  for (size_t i = 0; i < positions.size(); ++i) vertex_band[i] = static_cast<uint32_t>((positions[i].y() - y0_) * inv_band_);
  std::vector<std::array<uint32_t, 2>> tri_bands(triangles.size());
  std::vector<Vec2f> tri_heights(triangles.size());
  start_.assign(bands + 1, 0);
  chunk_boxes_.resize((triangles.size() + kChunk - 1) / kChunk);
  for (size_t c = 0; c < chunk_boxes_.size(); ++c) {
    Vec3f box_lo = Vec3f::Constant(std::numeric_limits<float>::max()), box_hi = -box_lo;
    for (size_t i = c * kChunk; i < std::min(triangles.size(), (c + 1) * kChunk); ++i) {
      const Tri& t = triangles[i];
      const uint32_t a = vertex_band[t[0]], b = vertex_band[t[1]], d = vertex_band[t[2]];
      tri_bands[i] = {std::min({a, b, d}), std::max({a, b, d})};
      for (uint32_t k = tri_bands[i][0]; k <= tri_bands[i][1]; ++k) ++start_[k + 1];
      const Vec3f& p0 = positions[t[0]];
      const Vec3f& p1 = positions[t[1]];
      const Vec3f& p2 = positions[t[2]];
      tri_heights[i] = Vec2f(std::min({p0.y(), p1.y(), p2.y()}), std::max({p0.y(), p1.y(), p2.y()}));
      box_lo = box_lo.cwiseMin(p0).cwiseMin(p1).cwiseMin(p2);
      box_hi = box_hi.cwiseMax(p0).cwiseMax(p1).cwiseMax(p2);
    }
    chunk_boxes_[c] = {0.5f * (box_lo + box_hi), 0.5f * (box_hi - box_lo)};
  }
  // Counting sort into bands, triangles ascending within each.
  for (size_t b = 0; b < bands; ++b) start_[b + 1] += start_[b];
  tris_.resize(start_[bands]);
  heights_.resize(start_[bands]);
  std::vector<uint32_t> fill(start_.begin(), start_.end() - 1);
  for (uint32_t i = 0; i < triangles.size(); ++i)
    for (uint32_t b = tri_bands[i][0]; b <= tri_bands[i][1]; ++b) {
      heights_[fill[b]] = tri_heights[i];
      tris_[fill[b]++] = i;
    }
}

bool Slicer::chunk_uncut(size_t chunk, const Vec3f& origin, const Vec3f& normal) const {
  // Every vertex is further than the margin from the plane, on one side: its side() has that sign
  // whatever the rounding (coordinates of a metre or two round at 1e-7).
  constexpr float kMargin = 1e-4f;
  const auto& [centre, half] = chunk_boxes_[chunk];
  const float d = (centre - origin).dot(normal);
  const float r = half.dot(normal.cwiseAbs());
  return d - r > kMargin || d + r < -kMargin;
}

size_t Slicer::band_index(float y) const {
  const float at = (y - y0_) * inv_band_;
  if (!(at >= 0) || start_.empty() || at >= static_cast<float>(start_.size() - 1)) return start_.empty() ? 0 : start_.size() - 1;
  return static_cast<size_t>(at);
}

std::span<const uint32_t> Slicer::band(float y) const {
  const size_t b = band_index(y);
  if (b + 1 >= start_.size()) return {};
  return std::span<const uint32_t>(tris_).subspan(start_[b], start_[b + 1] - start_[b]);
}

std::span<const Vec2f> Slicer::band_heights(float y) const {
  const size_t b = band_index(y);
  if (b + 1 >= start_.size()) return {};
  return std::span<const Vec2f>(heights_).subspan(start_[b], start_[b + 1] - start_[b]);
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
    const std::span<const uint32_t> band = mesh.band(plane.origin.y());
    const std::span<const Vec2f> heights = mesh.band_heights(plane.origin.y());
    const float y = plane.origin.y();
    for (size_t j = 0; j < band.size(); ++j)
      if (heights[j].x() <= y && heights[j].y() > y) cut(mesh.triangles[band[j]]);
  } else {
    // Every triangle, but whole chunks of them that lie clear of the plane are skipped.
    for (size_t c = 0; c < mesh.chunk_count(); ++c) {
      if (mesh.chunk_uncut(c, plane.origin, plane.normal)) continue;
      const size_t end = std::min(mesh.triangles.size(), (c + 1) * Slicer::kChunk);
      for (size_t i = c * Slicer::kChunk; i < end; ++i) cut(mesh.triangles[i]);
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
  std::sort(pieces.begin(), pieces.end(), piece_before);
  return pieces;
}

namespace {

// straddling_piece and straddling_outline: the pieces that reach the midline are followed, from the
// cut triangles whose x range touches x = 0 (a piece with points on both sides has a segment, so a
// triangle, that does; the margin covers rounding of the points), as closed loops of cut
// triangles (the mesh is closed and manifold): leave each triangle by its other cut edge until
// back at the seed. Each point is computed as slice computes it, from the edge's ends in
// ascending order. In slice order, a piece then numbers its points as slice does (ascending
// triangles, edges in order, each edge where it is first met), so its points, their order and its
// centroid are slice's to the bit; otherwise its points are in the loop's order, without centroid.
std::optional<SectionPiece> straddling(const Slicer& mesh, float y, bool in_slice_order) {
  auto whole_band = [&]() -> std::optional<SectionPiece> {
    auto pieces = slice(mesh, horizontal_plane(y));
    const int i = piece_straddling(pieces, 0.0f);
    if (i < 0) return std::nullopt;
    return std::move(pieces[static_cast<size_t>(i)]);
  };
  if (!mesh.topology) return whole_band();
  const SlicePlane plane = horizontal_plane(y);
  const Vec3f v_axis = plane.v_axis();
  const auto& p = mesh.positions;
  const auto& across = mesh.topology->across;
  auto side = [&](uint32_t v) { return (p[v] - plane.origin).dot(plane.normal); };
  auto bits_of = [&](uint32_t tri) {
    const Tri& t = mesh.triangles[tri];
    return (side(t[0]) < 0 ? 1u : 0u) | (side(t[1]) < 0 ? 2u : 0u) | (side(t[2]) < 0 ? 4u : 0u);
  };
  auto cut_edge = [](unsigned bits, int e) { return ((bits >> e) & 1u) != ((bits >> ((e + 1) % 3)) & 1u); };
  auto point = [&](uint32_t a, uint32_t b) {
    if (a > b) std::swap(a, b);
    const float sa = side(a), sb = side(b);
    const float f = sa / (sa - sb);
    const Vec3f q = p[a] + f * (p[b] - p[a]) - plane.origin;
    return Vec2f(q.dot(plane.u_axis), q.dot(v_axis));
  };

  // Seeds: cut triangles (lowest <= y < highest is side()'s test on finite heights) at x = 0.
  const std::span<const uint32_t> band = mesh.band(y);
  const std::span<const Vec2f> heights = mesh.band_heights(y);
  std::vector<uint32_t> seeds;
  for (size_t j = 0; j < band.size(); ++j) {
    if (!(heights[j].x() <= y && heights[j].y() > y)) continue;
    const Tri& t = mesh.triangles[band[j]];
    constexpr float kMargin = 1e-5f;
    const float lo = std::min({p[t[0]].x(), p[t[1]].x(), p[t[2]].x()});
    const float hi = std::max({p[t[0]].x(), p[t[1]].x(), p[t[2]].x()});
    if (lo <= kMargin && hi >= -kMargin) seeds.push_back(band[j]);
  }
  std::vector<std::vector<uint32_t>> loops;  // per piece: its triangles (in slice order ascending)
  std::vector<SectionPiece> pieces;
  for (const uint32_t first : seeds) {
    bool known = false;
    for (const auto& tris : loops)
      known = known || (in_slice_order ? std::binary_search(tris.begin(), tris.end(), first)
                                       : std::find(tris.begin(), tris.end(), first) != tris.end());
    if (known) continue;
    unsigned bits = bits_of(first);
    if (bits == 0 || bits == 7) return whole_band();  // heights and sides disagree (not finite)
    std::vector<uint32_t> tris{first};
    SectionPiece piece;
    uint32_t at = first;
    int out = cut_edge(bits, 0) ? 0 : 1;  // leave by the first cut edge
    for (;;) {
      const Tri& t = mesh.triangles[at];
      const uint32_t a = t[static_cast<size_t>(out)], b = t[static_cast<size_t>((out + 1) % 3)];
      if (!in_slice_order) piece.points.push_back(point(a, b));
      const uint32_t next = across[at][static_cast<size_t>(out)];
      if (next == first) break;
      if (tris.size() > band.size()) return whole_band();  // not a loop: cut it all
      bits = bits_of(next);
      const Tri& n = mesh.triangles[next];
      int in = -1;
      for (int e = 0; e < 3; ++e) {
        const uint32_t c = n[static_cast<size_t>(e)], d = n[static_cast<size_t>((e + 1) % 3)];
        if ((c == a && d == b) || (c == b && d == a)) in = e;
      }
      if (in < 0 || !cut_edge(bits, in)) return whole_band();
      out = -1;
      for (int e = 0; e < 3; ++e)
        if (e != in && cut_edge(bits, e)) out = e;
      tris.push_back(next);
      at = next;
    }
    if (in_slice_order) {
      std::sort(tris.begin(), tris.end());
      for (const uint32_t i : tris) {
        const Tri& t = mesh.triangles[i];
        const unsigned cut = bits_of(i);
        for (int e = 0; e < 3; ++e)
          if (cut_edge(cut, e) && !(across[i][static_cast<size_t>(e)] < i))  // else met first on the one across
            piece.points.push_back(point(t[static_cast<size_t>(e)], t[static_cast<size_t>((e + 1) % 3)]));
      }
    }
    loops.push_back(std::move(tris));
    if (piece.points.size() < 3) continue;
    piece.min = piece.max = piece.points[0];
    Vec2f sum = Vec2f::Zero();
    for (const auto& q : piece.points) {
      piece.min = piece.min.cwiseMin(q);
      piece.max = piece.max.cwiseMax(q);
      if (in_slice_order) sum += q;
    }
    if (in_slice_order) piece.centroid = sum / static_cast<float>(piece.points.size());
    pieces.push_back(std::move(piece));
  }
  if (in_slice_order) {
    std::sort(pieces.begin(), pieces.end(), piece_before);
  } else {
    // Without centroids the order of pieces is unknown: only a tie for the widest span needs it.
    int widest = -1;
    bool tie = false;
    for (size_t i = 0; i < pieces.size(); ++i) {
      const auto& s = pieces[i];
      if (!(s.min.x() < 0.0f && s.max.x() > 0.0f)) continue;
      const float span = s.max.x() - s.min.x();
      if (widest >= 0) {
        const auto& w = pieces[static_cast<size_t>(widest)];
        const float best = w.max.x() - w.min.x();
        tie = tie || span == best;
        if (span <= best) continue;
        tie = false;
      }
      widest = static_cast<int>(i);
    }
    if (tie) return straddling(mesh, y, true);
    if (widest < 0) return std::nullopt;
    return std::move(pieces[static_cast<size_t>(widest)]);
  }
  const int i = piece_straddling(pieces, 0.0f);
  if (i < 0) return std::nullopt;
  return std::move(pieces[static_cast<size_t>(i)]);
}

}  // namespace

std::optional<SectionPiece> straddling_piece(const Slicer& mesh, float y) { return straddling(mesh, y, true); }

std::optional<SectionPiece> straddling_outline(const Slicer& mesh, float y) { return straddling(mesh, y, false); }

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
