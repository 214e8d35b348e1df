#pragma once
// Polygonising an implicit surface (field < 0 inside) into a closed triangle mesh.
#include <functional>

#include "drape/mesh.hpp"

namespace drape::body {

using ScalarField = std::function<float(const Vec3f&)>;

struct PolygoniseOptions {
  float step = 0.01f;        // grid spacing (metres)
  int projection_steps = 3;  // Newton steps that put each vertex on the zero set
  int relax_iterations = 2;  // tangential smoothing rounds (evener triangles), each re-projected
};

// Naive surface nets (Gibson 1998): one vertex per grid cell the surface crosses, one quad per grid
// edge it crosses, split into two triangles; then vertices are projected onto the exact zero set.
// Output triangles are counter-clockwise seen from outside. `box` must enclose the surface. Returns
// an empty mesh when the result is not a closed 2-manifold (the caller retries with a shifted grid).
Mesh polygonise(const ScalarField& field, const Bounds& box, const PolygoniseOptions& options);

// True when every edge is shared by exactly two triangles with opposite directions (closed,
// consistently oriented) and every vertex's triangles form a single fan.
bool is_closed_manifold(const Mesh& mesh);

}  // namespace drape::body
