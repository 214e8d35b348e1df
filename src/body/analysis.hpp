#pragma once
// Sections of a body used by landmarks, measurements and segmentation.
#include <optional>

#include "body/slicing.hpp"
#include "drape/mesh.hpp"

namespace drape::body {

// The horizontal section piece that straddles the midline x = 0 (the torso, neck or head).
std::optional<SectionPiece> torso_section(const Slicer& mesh, float y);
float torso_girth(const Slicer& mesh, float y);  // its convex-hull perimeter; 0 when absent
// The leg's horizontal section on one side (+1 left, -1 right): the piece nearest the midline.
std::optional<SectionPiece> leg_section(const Slicer& mesh, float y, int side);
// Sections perpendicular to a limb axis through `point`; the piece nearest the point.
SlicePlane limb_plane(const Vec3f& point, const Vec3f& axis);
std::optional<SectionPiece> limb_section(const Slicer& mesh, const Vec3f& point, const Vec3f& axis);
float limb_girth(const Slicer& mesh, const Vec3f& point, const Vec3f& axis);

}  // namespace drape::body
