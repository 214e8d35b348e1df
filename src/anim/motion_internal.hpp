#pragma once
// Internal to src/anim: helpers shared by the motion readers, retargeting and skinning.
#include <filesystem>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "drape/motion.hpp"

namespace drape::motion_detail {

// A token from a file, quoted into a message: non-printable bytes become '?', long ones are cut.
std::string printable(std::string_view token);

// Converts a motion read in the file's axes to drape's (+Y up): measures the up axis from the rest
// skeleton when options say Auto (the hips-to-head direction, where the joint names are known),
// then rotates a Z-up motion (x, y, z) -> (x, z, -y) as LoadOptions does for meshes.
void convert_axes(Motion& motion, const MotionOptions& options);

// FBX through Assimp (fbx_motion.cpp): the first animation of the file, its helper nodes folded into
// their joints, lengths in metres, the file's up axis unless options give one. InputError(source, ...)
// for a file Assimp refuses (with its reason), one without animation or skeleton, or larger than
// drape reads.
Motion parse_fbx(std::span<const unsigned char> bytes, const std::string& source, const MotionOptions& options);
Motion read_fbx(const std::filesystem::path& path, const std::string& source, const MotionOptions& options);
// Refuses, before Assimp reads it, an FBX file that would make Assimp 5.2 take more memory than its
// size warrants, loop forever or recurse too deep (fbx_limits.cpp says how).
void check_fbx_limits(std::span<const unsigned char> bytes, const std::string& source);

// Index of a canonical joint (canonical_joints() order) by name; -1 when not canonical.
int canonical_index(std::string_view name);

// Shifts the animation's frames (from out.blend_frames on) vertically so that the lowest foot vertex of the
// clip is on y = 0 (out.feet.floor_shift_m), taking off a capture floor's tilt over time
// (out.feet.floor_slope_m_per_s).
void place_on_floor(const Body& body, const JointMap& body_map, BodyAnimation& out);
// Lifts frames [begin, end) whose lowest foot vertex is below y = 0 onto it (the lead-in: blending
// the bind pose into a stride bends the legs before they reach it).
void lift_above_floor(const Body& body, const JointMap& body_map, BodyAnimation& out, size_t begin, size_t end);
// Fills out.feet over every frame: the lowest foot vertex, contact and sliding.
void measure_feet(const Body& body, const JointMap& body_map, BodyAnimation& out);
// Fills out.limits: knee and elbow flexion and the neck's bend in every frame, against the ranges
// of docs/animation.md.
void check_joint_limits(const JointMap& body_map, BodyAnimation& out);

// The vertices of one foot: those whose weights on the foot joint and its descendants sum to 1/2
// or more.
std::vector<uint32_t> foot_vertices(const Body& body, int foot_joint);
// Skins only the listed vertices (out[i] for vertices[i]).
void skin_vertices(const Body& body, const PoseView& pose, Skinning method, std::span<const uint32_t> vertices,
                   std::span<Vec3f> out);
// The linear part of the listed vertices' skinning (out[i] for vertices[i]): a displacement d of
// the vertex in the bind pose moves its posed position by out[i] d (exactly for linear blend
// skinning, whose posed position is linear in the bind one; dual quaternions: the blended rotation).
void skinning_linear_parts(const Body& body, const PoseView& pose, Skinning method, std::span<const uint32_t> vertices,
                           std::span<Eigen::Matrix3f> out);

}  // namespace drape::motion_detail
