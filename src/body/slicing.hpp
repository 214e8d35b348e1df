#pragma once
// Cross-sections of a triangle mesh by a plane, split into connected pieces (torso, arms, legs), and
// the convex-hull perimeter a tape measure would follow around one piece.
#include <array>
#include <cstdint>
#include <optional>
#include <span>
#include <vector>

#include <Eigen/Geometry>

#include "drape/mesh.hpp"

namespace drape::body {

// One connected piece of a cross-section, in the plane's 2D coordinates (u, v).
struct SectionPiece {
  std::vector<Vec2f> points;  // where mesh edges cross the plane (unordered)
  Vec2f centroid = Vec2f::Zero();
  Vec2f min = Vec2f::Zero();
  Vec2f max = Vec2f::Zero();
};

// A plane through `origin` with unit `normal`; `u_axis` (unit, perpendicular to normal) and
// v = normal x u span it.
struct SlicePlane {
  Vec3f origin;
  Vec3f normal;
  Vec3f u_axis;
  Vec3f v_axis() const { return normal.cross(u_axis); }
  Vec3f to_world(const Vec2f& uv) const { return origin + uv.x() * u_axis + uv.y() * v_axis(); }
};

// The horizontal plane y = height, with u = +X and v = +Z... (normal -Y so that v = +Z).
SlicePlane horizontal_plane(float height);

// Which triangle lies across each edge of each triangle of a closed manifold mesh: across[t][e] is
// the other triangle on the edge (t[e], t[e + 1]). It depends on the triangles only, so a mesh whose
// vertices move (the maker's candidate bodies) builds it once. `across` is empty when some edge
// does not have exactly two triangles.
struct SliceTopology {
  SliceTopology() = default;
  explicit SliceTopology(const std::vector<Tri>& triangles);
  std::vector<std::array<uint32_t, 3>> across;
};

// A mesh indexed for slicing: body analysis slices one mesh thousands of times, mostly by
// horizontal planes, and only a few hundred triangles cross any one of them. Triangles are listed
// per 5 mm band of height they span, so a horizontal slice looks at one band. A Mesh converts to
// one implicitly (a one-off slice indexes on the way); analyses that slice often make one up front.
// With a topology (which must be the mesh's), the torso's section follows the pieces that reach
// the midline through the triangles' neighbours and leaves the rest of the band (arms, hands) uncut.
class Slicer {
 public:
  Slicer(const Mesh& mesh, const SliceTopology* topology = nullptr);  // NOLINT(google-explicit-constructor)
  const std::vector<Vec3f>& positions;
  const std::vector<Tri>& triangles;
  const SliceTopology* topology;  // null or closed manifold
  // The triangles (ascending) whose height range may hold y.
  std::span<const uint32_t> band(float y) const;
  // Their height ranges (lowest, highest vertex), in the same order: a triangle is cut by the
  // plane at y when lowest <= y < highest, which this tells without reading its vertices.
  std::span<const Vec2f> band_heights(float y) const;
  // Other planes look at chunks of kChunk consecutive triangles, skipping those whose bounding box
  // lies clear of the plane (true: no triangle of that chunk is cut).
  static constexpr size_t kChunk = 64;
  size_t chunk_count() const { return chunk_boxes_.size(); }
  bool chunk_uncut(size_t chunk, const Vec3f& origin, const Vec3f& normal) const;

 private:
  size_t band_index(float y) const;  // start_.size() - 1 when y is outside
  float y0_ = 0, inv_band_ = 0;
  std::vector<uint32_t> start_;  // band b lists tris_[start_[b], start_[b + 1])
  std::vector<uint32_t> tris_;
  std::vector<Vec2f> heights_;  // per entry of tris_
  std::vector<std::array<Vec3f, 2>> chunk_boxes_;  // centre, half extent
};

// Pieces of the section, connected through shared mesh edges. Pieces with fewer than 3 points are
// dropped (grazing contacts). The same pieces, in the same order, whether the plane is horizontal
// (one band of the index) or not (every triangle).
std::vector<SectionPiece> slice(const Slicer& mesh, const SlicePlane& plane);

// The piece of the horizontal section at height y that straddles x = 0 with the widest span there
// (piece_straddling of slice), the same points in the same order; nullopt when none straddles.
std::optional<SectionPiece> straddling_piece(const Slicer& mesh, float y);
// The same piece's outline for a girth or an extent: the same points, min and max, but the points
// in no particular order and no centroid (cheaper; hull_perimeter sorts the points anyway).
std::optional<SectionPiece> straddling_outline(const Slicer& mesh, float y);

// Perimeter of the convex hull of 2D points (0 for fewer than 2).
float hull_perimeter(std::vector<Vec2f> points);

// Index of the piece whose points come nearest to `uv` (-1 when there are none).
int nearest_piece(const std::vector<SectionPiece>& pieces, const Vec2f& uv);
// Index of the piece that straddles u = `u` and contains the widest span there (torso at the
// midline); -1 when no piece straddles it.
int piece_straddling(const std::vector<SectionPiece>& pieces, float u);

}  // namespace drape::body
