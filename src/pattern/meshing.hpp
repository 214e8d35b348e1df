#pragma once
// Internal pieces of panel meshing: the sampled outline shared by both meshers, and the meshers.
#include <Eigen/Geometry>
#include <vector>

#include "drape/garment.hpp"

namespace drape::pattern {

// A panel's outline as the mesh boundary: points in loop order (the outline's own direction), the
// edge each point starts or lies on, and VertexFlag bits.
struct BoundaryLoop {
  std::vector<Vec2d> points;
  std::vector<uint32_t> edge;
  std::vector<uint8_t> flags;
};

// A triangulated panel: points[0 .. boundary size) are the BoundaryLoop's points in order, then the
// interior points. Triangles are counter-clockwise in the panel plane.
struct PanelTriangulation {
  std::vector<Vec2d> points;
  std::vector<Tri> triangles;
};

// The paper's rectangular grid (sec. 6.2): lattice points of spacing h along the grain inside the
// outline, joined to the outline by a constrained Delaunay triangulation of the band between.
PanelTriangulation triangulate_grid(const BoundaryLoop& boundary, const Vec2d& grain, double h, GridTopology& topology);

// CGAL constrained Delaunay refinement to edge length h; the outline's points are kept as they are
// (no boundary splitting), so seam vertex pairs stay matched.
PanelTriangulation triangulate_refined(const BoundaryLoop& boundary, double h);

// Uniform bucket grid over the outline's segments: distance and crossing queries.
class SegmentGrid {
 public:
  SegmentGrid(const std::vector<Vec2d>& loop, double cell);
  double distance(const Vec2d& p, double max_distance) const;  // min(distance to outline, max_distance)
  bool crosses(const Vec2d& a, const Vec2d& b) const;           // segment ab crosses the outline

 private:
  template <class F>
  void visit(const Vec2d& lo, const Vec2d& hi, F&& f) const;
  std::vector<Vec2d> loop_;
  Vec2d origin_;
  double cell_;
  int nx_ = 1, ny_ = 1;
  std::vector<std::vector<uint32_t>> cells_;
};

}  // namespace drape::pattern
