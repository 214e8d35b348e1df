#pragma once
// Analytic test and benchmark meshes: watertight, counter-clockwise seen from outside, with normals.
#include "drape/mesh.hpp"

namespace drape {

// A UV ellipsoid with semi-axes `radii` centred at `centre`: `slices` around +Y, `stacks` from
// pole to pole; 2 * slices * (stacks - 1) triangles.
Mesh uv_ellipsoid(const Vec3f& radii, const Vec3f& centre, int slices, int stacks);

inline Mesh uv_sphere(float radius, const Vec3f& centre, int slices, int stacks) {
  return uv_ellipsoid(Vec3f::Constant(radius), centre, slices, stacks);
}

}  // namespace drape
