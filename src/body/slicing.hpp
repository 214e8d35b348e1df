#pragma once
// Cross-sections of a triangle mesh by a plane, split into connected pieces (torso, arms, legs), and
// the convex-hull perimeter a tape measure would follow around one piece.
#include <cstdint>
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

// A mesh indexed for slicing: body analysis slices one mesh thousands of times, mostly by
// horizontal planes, and only a few hundred triangles cross any one of them. Triangles are listed
// per 5 mm band of height they span, so a horizontal slice looks at one band. A Mesh converts to
// one implicitly (a one-off slice indexes on the way); analyses that slice often make one up front.
class Slicer {
 public:
  Slicer(const Mesh& mesh);  // NOLINT(google-explicit-constructor)
  const std::vector<Vec3f>& positions;
  const std::vector<Tri>& triangles;
  // The triangles (ascending) whose height range may hold y.
  std::span<const uint32_t> band(float y) const;

 private:
  float y0_ = 0, inv_band_ = 0;
  std::vector<uint32_t> start_;  // band b lists tris_[start_[b], start_[b + 1])
  std::vector<uint32_t> tris_;
};

// Pieces of the section, connected through shared mesh edges. Pieces with fewer than 3 points are
// dropped (grazing contacts). The same pieces, in the same order, whether the plane is horizontal
// (one band of the index) or not (every triangle).
std::vector<SectionPiece> slice(const Slicer& mesh, const SlicePlane& plane);

// Perimeter of the convex hull of 2D points (0 for fewer than 2).
float hull_perimeter(std::vector<Vec2f> points);

// Index of the piece whose points come nearest to `uv` (-1 when there are none).
int nearest_piece(const std::vector<SectionPiece>& pieces, const Vec2f& uv);
// Index of the piece that straddles u = `u` and contains the widest span there (torso at the
// midline); -1 when no piece straddles it.
int piece_straddling(const std::vector<SectionPiece>& pieces, float u);

}  // namespace drape::body
