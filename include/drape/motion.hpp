#pragma once
// Motion capture onto drape's bodies: motion files (BVH, FBX, glTF/GLB animations), the joint names of
// the skeletons people have, retargeting a motion onto a body's rig, and skinning the body's mesh
// to a pose (linear blend and dual quaternion). See docs/animation.md.
//
//   Motion m = read_motion("walk.bvh");                  // InputError naming the file and line
//   BodyAnimation a = retarget(m, body);                 // per frame: every body joint's pose
//   std::vector<Vec3f> x(body.mesh.vertex_count());
//   skin_mesh(body, a.pose(10), Skinning::Linear, x);    // the body's vertices in frame 10
//
// Frames: a motion is converted on load to drape's axes (+Y up, facing +Z, +X = the subject's
// left). Its lengths stay in the file's units (FBX's are converted to metres, the file says its
// unit): retargeting uses the motion's rotations and its root motion scaled by the ratio of the
// body's leg length to the motion skeleton's, so a motion's unit never has to be known (BVH has no
// unit field; CMU's is 0.056444 m, MakeHuman's decimetres).
#include <Eigen/Geometry>
#include <filesystem>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "drape/body.hpp"
#include "drape/io.hpp"
#include "drape/mesh.hpp"

namespace drape {

using Quatf = Eigen::Quaternionf;

// The motion file's up axis. Auto: FBX's own (its UpAxis), else measured from the rest skeleton
// (the axis from the hips to the head); BVH has no field for it (MakeHuman's poses are Z-up, CMU's
// Y-up).
enum class MotionUp : uint8_t { Auto, Y, Z };

struct MotionOptions {
  MotionUp up = MotionUp::Auto;
};

// A skeletal motion: joints with a rest pose, and per frame every joint's local transform.
// Everything is in drape's axes; lengths in the file's units (FBX: metres).
struct Motion {
  std::string source;                // the file, for messages
  std::string format;                // "bvh", "fbx" or "gltf"
  UpAxis up = UpAxis::Y;             // what the file used (converted from)
  std::vector<std::string> names;    // joint names as the file spells them
  std::vector<int> parent;           // -1 for a root; a parent precedes its children
  std::vector<Vec3f> rest_offset;    // rest translation from the parent (the root's: from the origin)
  std::vector<Quatf> rest_rotation;  // rest local rotation (identity for BVH)
  double frame_time = 0;             // s
  size_t frame_count = 0;
  // frame * joint_count() + joint: local rotation and translation in that frame.
  std::vector<Quatf> rotation;
  std::vector<Vec3f> translation;

  size_t joint_count() const { return names.size(); }
  int find(std::string_view name) const;  // -1 when absent
  // World positions and rotations of every joint in a frame (frame = -1: the rest pose).
  void world_pose(long frame, std::vector<Vec3f>& position, std::vector<Quatf>& rotation) const;
};

// BVH text (any line endings, tabs or spaces, any Euler order per joint, position channels on any
// joint). Refuses, with InputError(source, "line N: ..."), what is malformed: unknown keywords,
// unbalanced braces, channel counts that are not 3 or 6 (or 0 on end sites), unknown channel names,
// missing or non-finite numbers, offsets and channel values beyond ±1e9, a frame count that does not
// match the values, more than 4096 joints or frames of motion with no joints. `source` names the
// input in messages.
Motion parse_bvh(std::string_view text, const std::string& source, const MotionOptions& options = {});

// A motion from the first animation of a glTF scene: the joints of its first skin (or, without a
// skin, the nodes the animation moves and their ancestors), sampled at the animation's own key times
// (at most 1/120 s apart). InputError(source, ...) when the scene has no animation of nodes.
Motion motion_from_scene(const Scene& scene, const std::string& source, const MotionOptions& options = {});

// Reads .bvh, .fbx, .glb or .gltf by extension (case-insensitive). FBX (Mixamo's format, binary or
// ASCII) is read through Assimp: the first animation, sampled at the most common spacing of its keys
// (1/120 to 1/30 s); the joints are the nodes that deform a mesh or that the animation moves;
// Assimp's "$AssimpFbx$" helper nodes (pre-rotations, pivots) are folded into their joints; lengths
// are converted to metres with the file's UnitScaleFactor and the file's up axis is used (see
// src/anim/fbx_motion.cpp). InputError(path, ...) for a file Assimp refuses (with its reason), one
// without animation or skeleton, or one beyond what drape lets Assimp read (fbx_limits.cpp).
Motion read_motion(const std::filesystem::path& path, const MotionOptions& options = {});

// ---- Skeletons people have, and joint maps ------------------------------------------------------

// The joints retargeting drives, named as drape's own rig names them (rig_body): Hips, Spine (waist),
// Spine1 (chest), Neck, Head, and per side Shoulder (clavicle), Arm, ForeArm, Hand, UpLeg, Leg, Foot,
// ToeBase. Other joints of a body follow their parent.
std::span<const std::string_view> canonical_joints();

// Which joint of a skeleton plays each canonical joint.
struct JointMap {
  std::string convention;  // "cmu" (cgspeed MotionBuilder / 3ds Max), "cmu_daz", "cmu_19", "mixamo",
                           // "makehuman", "makehuman_cmu_mb", "smpl", "drape" or "file"
  std::vector<int> joint;  // per canonical joint (canonical_joints() order): the skeleton's joint, -1 none
};

// Recognises the skeleton from its joint names (docs/animation.md lists every convention's names).
// A name prefix such as Mixamo's "mixamorig:" is ignored. InputError(source, ...) naming the joints
// it looked for when no convention fits (the hips, both thighs, knees and feet, a spine joint and
// both upper arms must be found).
JointMap find_joint_map(std::span<const std::string> names, const std::string& source);

// A joint map from a JSON file {"Hips": "pelvis", "LeftUpLeg": "l_thigh", ...}: canonical joint ->
// the skeleton's joint name. Unknown canonical names, and joints the skeleton does not have, are
// refused naming them (InputError(file, ...)); canonical joints not given stay unmapped, but the
// legs, hips, a spine joint and the upper arms are required as for find_joint_map.
JointMap read_joint_map(const std::filesystem::path& file, std::span<const std::string> names);
JointMap parse_joint_map(std::string_view json, const std::string& source, std::span<const std::string> names);

// ---- Retargeting --------------------------------------------------------------------------------

// A body pose: per joint of the body's skeleton its world rotation relative to the bind pose and its
// world position. A vertex bound to joint j moves to rotation[j] (x - bind_j) + position[j].
struct PoseView {
  std::span<const Quatf> rotation;
  std::span<const Vec3f> position;
};

struct RetargetOptions {
  double fps = 30;                  // frames per second of the result (the motion is resampled)
  long first_frame = 0;             // in the motion's frames, after a skipped calibration frame
  long last_frame = -1;             // inclusive; -1: the last
  bool skip_calibration = true;     // drop a calibration T-pose in the motion's first frame
  double blend_seconds = 0.5;       // lead-in: the motion's weight against the bind pose (the dressed pose)
                                    // rises from 0 to 1 over this time while the motion plays
  const JointMap* motion_map = nullptr;  // nullptr: find_joint_map on the motion's names
};

// Foot contact and sliding, measured on the skinned feet (vertices bound mostly to foot and toe joints).
struct FootReport {
  float lowest_y = 0;            // m, the lowest foot vertex over every frame
  float floor_shift_m = 0;       // m, the vertical shift that put the lowest foot of the clip on y = 0
  float floor_slope_m_per_s = 0; // m/s, the capture floor's rise over time, taken off (clips of 1 s or more)
  double contact_fraction = 0;   // frames with a foot within 3 cm of the floor
  float sliding_m = 0;           // m, horizontal travel of a foot while it stays within 1 cm of the floor
  float max_sliding_speed = 0;   // m/s
};

struct JointLimitReport {
  float max_knee_flexion_deg = 0, min_knee_flexion_deg = 0;    // knee: 0 straight, > 0 bent backwards (the normal way)
  float max_elbow_flexion_deg = 0, min_elbow_flexion_deg = 0;  // elbow: 0 straight, > 0 bent forwards
  float max_neck_bend_deg = 0;   // head direction against the chest direction
  std::vector<std::string> violations;  // "frame 12: LeftLeg knee flexion -25 deg (limit -15)"
};

// The body's skeleton posed in every frame of the animation.
struct BodyAnimation {
  double frame_time = 0;    // s
  size_t frame_count = 0;
  size_t joint_count = 0;
  std::vector<Quatf> rotation;  // frame * joint_count + joint
  std::vector<Vec3f> position;  // frame * joint_count + joint
  // What retargeting did.
  std::string motion_convention, body_convention;
  std::vector<std::string> mapped;  // "Hips <- Hips", per canonical joint found on both sides
  float root_scale = 1;              // body leg length / motion leg length (motion units -> m)
  size_t blend_frames = 0;           // first frames blended from the bind pose (the motion plays under them)
  bool skipped_calibration = false;  // the motion's first frame was a calibration T-pose
  long motion_first = 0, motion_last = 0;  // the motion frames used (of the file's)
  FootReport feet;
  JointLimitReport limits;

  PoseView pose(size_t frame) const;
  double duration() const { return frame_time * static_cast<double>(frame_count); }
};

// Retargets the motion onto the body's skeleton by joint names, with rest-pose offsets (each bone's
// rest direction in the motion against the body's bind pose: T-pose, A-pose, CMU's zero pose), root
// motion scaled to the body's leg length and the clip put on the floor. InputError(motion.source, ...)
// for a skeleton with no known names (find_joint_map); InputError("body", ...) for a body without a rig.
BodyAnimation retarget(const Motion& motion, const Body& body, const RetargetOptions& options = {});

// ---- Skinning -----------------------------------------------------------------------------------

enum class Skinning : uint8_t { Linear, DualQuaternion };
std::string_view to_string(Skinning skinning);

// The body's vertices in a pose, written to `out` (one per vertex). Both cores; the same result for
// any thread count. Vertices without weights stay where they are.
void skin_mesh(const Body& body, const PoseView& pose, Skinning method, std::span<Vec3f> out);

// The bind pose: identity rotations, the skeleton's joint positions.
void bind_pose(const Body& body, std::vector<Quatf>& rotation, std::vector<Vec3f>& position);

}  // namespace drape
