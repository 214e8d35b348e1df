#pragma once
// Changing a scene's length unit and axes on load (DESIGN.md: metres, +Y up, the body faces +Z).
#include <Eigen/Core>

#include "drape/scene.hpp"

namespace drape::geometry {

// The axis map that turns a Z-up file into Y-up: (x, y, z) -> (x, z, -y). A rotation (det +1), so the
// frame stays right-handed and a Z-up scan facing -Y ends up facing +Z.
Eigen::Matrix3f z_up_to_y_up();

// Applies p -> scale * axis_map * p to everything in the scene: vertex positions, normals, morph deltas,
// node transforms (conjugated, so the hierarchy and skinning still compose), inverse bind matrices and
// animation keys. `axis_map` must be a signed permutation with determinant +1 (it keeps node scales
// axis-aligned); `scale` must be positive.
void change_frame(Scene& scene, float scale, const Eigen::Matrix3f& axis_map);

}  // namespace drape::geometry
