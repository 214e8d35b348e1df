#pragma once
// The CGAL constrained Delaunay triangulation both panel meshers build on. Vertices carry their
// index in the panel mesh (-1 for points the refinement inserts); faces carry the in-domain mark.
// CGAL's handles trip GCC's -Wnull-dereference after inlining; the warning is off for its headers only.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wnull-dereference"
#include <CGAL/Constrained_Delaunay_triangulation_2.h>
#include <CGAL/Delaunay_mesh_face_base_2.h>
#include <CGAL/Delaunay_mesh_vertex_base_2.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Triangulation_vertex_base_with_info_2.h>
#pragma GCC diagnostic pop

#include "pattern/meshing.hpp"

namespace drape::pattern {

using CdtKernel = CGAL::Exact_predicates_inexact_constructions_kernel;
// A mesh vertex index that starts out as "none" (CGAL default-constructs vertex info).
struct CdtIndex {
  int64_t value = -1;
};
using CdtVertexBase = CGAL::Triangulation_vertex_base_with_info_2<CdtIndex, CdtKernel, CGAL::Delaunay_mesh_vertex_base_2<CdtKernel>>;
using CdtFaceBase = CGAL::Delaunay_mesh_face_base_2<CdtKernel>;
using CdtData = CGAL::Triangulation_data_structure_2<CdtVertexBase, CdtFaceBase>;
using Cdt = CGAL::Constrained_Delaunay_triangulation_2<CdtKernel, CdtData, CGAL::Exact_predicates_tag>;

// Inserts the outline as a closed chain of constraints; vertex info = loop index.
void insert_outline(Cdt& cdt, const BoundaryLoop& boundary);
// Marks faces inside the outline (odd nesting depth from the infinite face) as in the domain.
void mark_domain(Cdt& cdt);
// Collects the in-domain triangles (counter-clockwise) and any points the CDT added after `points`.
PanelTriangulation collect_triangulation(Cdt& cdt, std::vector<Vec2d> points);

}  // namespace drape::pattern
