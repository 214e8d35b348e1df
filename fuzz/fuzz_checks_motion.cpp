// The motion checks behind fuzz_bvh (see fuzz_checks.hpp).
#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "drape/error.hpp"
#include "drape/motion.hpp"
#include "fuzz_checks.hpp"

namespace drape::fuzz {
namespace {

// A skeleton with CMU's joint names (and two joints no convention drives), standing still for two
// frames: what a fuzzed joint map is read against and retargets.
constexpr std::string_view kMapSkeleton = R"(HIERARCHY
ROOT Hips { OFFSET 0 0 0 CHANNELS 6 Xposition Yposition Zposition Zrotation Yrotation Xrotation
 JOINT LeftUpLeg { OFFSET 1 -0.6 0 CHANNELS 3 Zrotation Yrotation Xrotation
  JOINT LeftLeg { OFFSET 0 -4.2 0 CHANNELS 3 Zrotation Yrotation Xrotation
   JOINT LeftFoot { OFFSET 0 -4 0 CHANNELS 3 Zrotation Yrotation Xrotation
    JOINT LeftToeBase { OFFSET 0 -0.6 1.4 CHANNELS 3 Zrotation Yrotation Xrotation End Site { OFFSET 0 0 0.5 } } } } }
 JOINT RightUpLeg { OFFSET -1 -0.6 0 CHANNELS 3 Zrotation Yrotation Xrotation
  JOINT RightLeg { OFFSET 0 -4.2 0 CHANNELS 3 Zrotation Yrotation Xrotation
   JOINT RightFoot { OFFSET 0 -4 0 CHANNELS 3 Zrotation Yrotation Xrotation
    JOINT RightToeBase { OFFSET 0 -0.6 1.4 CHANNELS 3 Zrotation Yrotation Xrotation End Site { OFFSET 0 0 0.5 } } } } }
 JOINT LowerBack { OFFSET 0 0.5 0 CHANNELS 3 Zrotation Yrotation Xrotation
  JOINT Spine { OFFSET 0 0.5 0 CHANNELS 3 Zrotation Yrotation Xrotation
   JOINT Spine1 { OFFSET 0 1.8 0 CHANNELS 3 Zrotation Yrotation Xrotation
    JOINT Neck { OFFSET 0 2 0 CHANNELS 3 Zrotation Yrotation Xrotation
     JOINT Head { OFFSET 0 0.9 0 CHANNELS 3 Zrotation Yrotation Xrotation End Site { OFFSET 0 1 0 } } }
    JOINT LeftShoulder { OFFSET 0.4 1.7 0 CHANNELS 3 Zrotation Yrotation Xrotation
     JOINT LeftArm { OFFSET 1.2 0 0 CHANNELS 3 Zrotation Yrotation Xrotation
      JOINT LeftForeArm { OFFSET 2.6 0 0 CHANNELS 3 Zrotation Yrotation Xrotation
       JOINT LeftHand { OFFSET 2.4 0 0 CHANNELS 3 Zrotation Yrotation Xrotation
        JOINT LThumb { OFFSET 0.5 0 0.3 CHANNELS 3 Zrotation Yrotation Xrotation End Site { OFFSET 0.3 0 0 } } } } } }
    JOINT RightShoulder { OFFSET -0.4 1.7 0 CHANNELS 3 Zrotation Yrotation Xrotation
     JOINT RightArm { OFFSET -1.2 0 0 CHANNELS 3 Zrotation Yrotation Xrotation
      JOINT RightForeArm { OFFSET -2.6 0 0 CHANNELS 3 Zrotation Yrotation Xrotation
       JOINT RightHand { OFFSET -2.4 0 0 CHANNELS 3 Zrotation Yrotation Xrotation End Site { OFFSET -0.8 0 0 } } } } } } } } }
MOTION
Frames: 2
Frame Time: 0.5
)";

const Motion& map_skeleton() {
  static const Motion motion = [] {
    size_t joints = 1;  // the root, and every JOINT
    for (size_t at = kMapSkeleton.find("JOINT"); at != std::string_view::npos;
         at = kMapSkeleton.find("JOINT", at + 1))
      ++joints;
    const size_t channels = 6 + 3 * (joints - 1);
    std::string text(kMapSkeleton);
    for (int frame = 0; frame < 2; ++frame) {
      for (size_t c = 0; c < channels; ++c) text += c == 1 ? "9.5 " : frame == 1 && c % 7 == 3 ? "20 " : "0 ";
      text += "\n";
    }
    return parse_bvh(text, "map_skeleton.bvh");
  }();
  return motion;
}

bool finite(const Quatf& q) {
  return q.coeffs().allFinite();
}

// Every array of a motion holds one entry per joint (per frame), parents precede their children,
// and every value is finite with unit rotations.
void expect_consistent(const Motion& m) {
  const size_t n = m.joint_count();
  if (n == 0 || m.frame_count == 0) throw Finding("a motion without joints or frames");
  if (m.parent.size() != n || m.rest_offset.size() != n || m.rest_rotation.size() != n)
    throw Finding(fmt::format("{} joints, {} parents, {} rest offsets, {} rest rotations", n, m.parent.size(),
                              m.rest_offset.size(), m.rest_rotation.size()));
  if (m.rotation.size() != n * m.frame_count || m.translation.size() != n * m.frame_count)
    throw Finding(fmt::format("{} frames of {} joints: {} rotations, {} translations", m.frame_count, n,
                              m.rotation.size(), m.translation.size()));
  for (size_t j = 0; j < n; ++j) {
    if (m.parent[j] < -1 || m.parent[j] >= static_cast<int>(j))
      throw Finding(fmt::format("joint {} has parent {}", j, m.parent[j]));
    if (!m.rest_offset[j].allFinite() || !finite(m.rest_rotation[j]))
      throw Finding(fmt::format("joint {}: a non-finite rest pose", j));
  }
  if (!(std::isfinite(m.frame_time) && m.frame_time > 0))
    throw Finding(fmt::format("frame time {}", m.frame_time));
  for (size_t i = 0; i < m.rotation.size(); ++i) {
    if (!m.translation[i].allFinite())
      throw Finding(fmt::format("frame {} joint {}: a non-finite translation", i / n, i % n));
    if (!finite(m.rotation[i]) || std::abs(m.rotation[i].norm() - 1.0f) > 1e-3f)
      throw Finding(fmt::format("frame {} joint {}: rotation ({}, {}, {}, {}) is not a unit quaternion",
                                i / n, i % n, m.rotation[i].w(), m.rotation[i].x(), m.rotation[i].y(),
                                m.rotation[i].z()));
  }
  // The world pose retargeting starts from: the rest pose and the first and last frames.
  std::vector<Vec3f> position;
  std::vector<Quatf> rotation;
  for (const long frame : {-1L, 0L, static_cast<long>(m.frame_count) - 1}) {
    m.world_pose(frame, position, rotation);
    for (size_t j = 0; j < n; ++j)
      if (!position[j].allFinite() || !finite(rotation[j]))
        throw Finding(fmt::format("frame {} joint {}: a non-finite world pose", frame, j));
  }
}

// Retargets at most 2 s of `motion` (at 30 frames per second) onto the default female body: either
// an InputError (a skeleton whose names no convention fits, a degenerate rest pose) or a finite pose
// of every body joint in every frame.
void expect_retargets(const Motion& motion, const JointMap* map) {
  RetargetOptions options;
  options.motion_map = map;
  options.last_frame =
      std::min(static_cast<long>(motion.frame_count) - 1, static_cast<long>(2.0 / motion.frame_time));
  BodyAnimation a;
  try {
    a = retarget(motion, default_body(Sex::Female), options);
  } catch (const InputError&) {
    return;
  }
  if (a.frame_count == 0 || a.rotation.size() != a.frame_count * a.joint_count ||
      a.position.size() != a.frame_count * a.joint_count)
    throw Finding(fmt::format("retargeted: {} frames of {} joints, {} rotations, {} positions", a.frame_count,
                              a.joint_count, a.rotation.size(), a.position.size()));
  for (size_t i = 0; i < a.rotation.size(); ++i)
    if (!finite(a.rotation[i]) || !a.position[i].allFinite())
      throw Finding(fmt::format("retargeted frame {} joint {}: a non-finite pose", i / a.joint_count,
                                i % a.joint_count));
}

}  // namespace

void prepare_motion_checks() {
  (void)default_body(Sex::Female);
  (void)map_skeleton();
}

bool is_joint_map(std::string_view text) {
  const size_t first = text.find_first_not_of(" \t\r\n");
  return first != std::string_view::npos && text[first] == '{';
}

bool check_motion_file(std::string_view text, const std::string& source) {
  Motion motion;
  try {
    motion = parse_bvh(text, source);
  } catch (const InputError&) {
    return false;
  }
  expect_consistent(motion);
  expect_retargets(motion, nullptr);
  return true;
}

bool check_joint_map(std::string_view text, const std::string& source) {
  const Motion& skeleton = map_skeleton();
  JointMap map;
  try {
    map = parse_joint_map(text, source, skeleton.names);
  } catch (const InputError&) {
    return false;
  }
  if (map.joint.size() != canonical_joints().size())
    throw Finding(
        fmt::format("{} entries for {} canonical joints", map.joint.size(), canonical_joints().size()));
  for (const int j : map.joint)
    if (j < -1 || j >= static_cast<int>(skeleton.joint_count()))
      throw Finding(fmt::format("joint {} out of range", j));
  expect_retargets(skeleton, &map);
  return true;
}

}  // namespace drape::fuzz
