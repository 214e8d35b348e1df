#pragma once
// Triangle-mesh topology checks used when loading files: degenerate triangles, polygon triangulation,
// boundary loops (holes) and non-manifold edges.
#include <cstddef>
#include <span>
#include <vector>

#include "drape/mesh.hpp"

namespace drape::geometry {

// A triangle with a repeated corner or (numerically) zero area.
bool is_degenerate(const std::vector<Vec3f>& positions, const Tri& tri);

// Splits a planar-ish polygon (corner vertex indices, in order) into corners.size() - 2 triangles with
// the polygon's winding: quads along their shorter diagonal, larger polygons by ear clipping in the
// polygon's best-fit plane (Newell normal), falling back to a fan when the outline self-intersects.
void triangulate_polygon(const std::vector<Vec3f>& positions, std::span<const uint32_t> corners,
                         std::vector<Tri>& out);

struct EdgeTopology {
  size_t boundary_edges = 0;      // used by one triangle
  size_t boundary_loops = 0;      // connected chains of boundary edges
  size_t non_manifold_edges = 0;  // used by three or more triangles
};

// Edge use counts after welding vertices with bit-identical positions, so that vertices split at UV
// or normal seams do not show up as holes.
EdgeTopology edge_topology(const std::vector<Vec3f>& positions, const std::vector<Tri>& triangles);

}  // namespace drape::geometry
