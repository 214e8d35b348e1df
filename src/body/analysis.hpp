#pragma once
// Sections of a body used by landmarks, measurements and segmentation.
#include <array>
#include <bitset>
#include <optional>
#include <string>

#include "body/slicing.hpp"
#include "drape/body.hpp"
#include "drape/mesh.hpp"

namespace drape::body {

// The horizontal section piece that straddles the midline x = 0 (the torso, neck or head).
std::optional<SectionPiece> torso_section(const Slicer& mesh, float y);
float torso_girth(const Slicer& mesh, float y);  // its convex-hull perimeter; 0 when absent
// The leg's horizontal section on one side (+1 left, -1 right): the piece nearest the midline.
std::optional<SectionPiece> leg_section(const Slicer& mesh, float y, int side);
// Both legs' sections at once (left, right), from one slice.
std::array<std::optional<SectionPiece>, 2> leg_sections(const Slicer& mesh, float y);
// Sections perpendicular to a limb axis through `point`; the piece nearest the point.
SlicePlane limb_plane(const Vec3f& point, const Vec3f& axis);
std::optional<SectionPiece> limb_section(const Slicer& mesh, const Vec3f& point, const Vec3f& axis);
float limb_girth(const Slicer& mesh, const Vec3f& point, const Vec3f& axis);

// The underbust of a body whose bust points are known (`height`: its crown's height): sets
// lm.underbust; false when there is no torso below the bust.
bool find_underbust(const Slicer& mesh, Landmarks& lm, float height);
// Whether find_underbust would find one (some torso section in its range), without the search.
bool torso_below_bust(const Slicer& mesh, const Landmarks& lm, float height);
// The waist (narrowest torso section from 30 % to 70 % of the way crotch -> lower armpit) and the
// hip (fullest torso section between the crotch and the waist), found on a body whose crotch and
// armpits are known: sets lm.waist and lm.hip.
enum class WaistAndHip { kFound, kNoWaist, kNoHips };
WaistAndHip find_waist_and_hip(const Slicer& mesh, Landmarks& lm);

// find_landmarks on an indexed mesh.
Landmarks find_landmarks(const Slicer& mesh, const std::string& source);

// Which measurements to take: bit i is measurement_table()[i].
using MeasurementSet = std::bitset<13>;
// measure_body on an indexed mesh, taking only the measurements in `which` (the others stay 0):
// the maker measures a candidate body dozens of times for the few keys a request names.
Measurements measure_body(const Slicer& mesh, const Landmarks& landmarks, MeasurementSet which);

// analyse_body on one index of the body's mesh for both the landmark search and the measurements;
// `topology` (may be null) must be the mesh's triangles' (the maker's bodies share MakeHuman's).
void analyse_body(Body& body, const std::string& source, const SliceTopology* topology);

}  // namespace drape::body
