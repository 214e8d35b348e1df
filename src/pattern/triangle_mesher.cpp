// Unstructured panel meshes: CGAL's Delaunay refinement (Shewchuk/Ruppert, as CGAL's Mesh_2
// implements it) of the constrained triangulation of the sampled outline, to a 20.7 degree minimum
// angle and a longest edge of about the target length. The outline's own points are never split
// (Delaunay_mesher_no_edge_refinement_2), so the seam vertices stay matched across panels.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wnull-dereference"  // inside CGAL/Boost after inlining (see cdt.hpp)
#include <CGAL/Delaunay_mesh_size_criteria_2.h>
#include <CGAL/Delaunay_mesher_no_edge_refinement_2.h>
#pragma GCC diagnostic pop

#include "pattern/cdt.hpp"

namespace drape::pattern {

namespace {
// CGAL bounds the longest edge; this factor makes the mean edge length close to the target.
constexpr double kLongestEdgeFactor = 1.3;
constexpr double kShapeBound = 0.125;  // circumradius-to-shortest-edge bound for 20.7 degrees
}  // namespace

PanelTriangulation triangulate_refined(const BoundaryLoop& boundary, double h) {
  Cdt cdt;
  insert_outline(cdt, boundary);
  using Criteria = CGAL::Delaunay_mesh_size_criteria_2<Cdt>;
  CGAL::Delaunay_mesher_no_edge_refinement_2<Cdt, Criteria> mesher(cdt, Criteria(kShapeBound, kLongestEdgeFactor * h));
  // CGAL 5.5 leaves the mesher's seeds_mark flag uninitialised (UBSan: invalid bool load);
  // clear_seeds() sets it before refine_mesh() reads it.
  mesher.clear_seeds();
  mesher.refine_mesh();
  mark_domain(cdt);
  return collect_triangulation(cdt, boundary.points);
}

}  // namespace drape::pattern
