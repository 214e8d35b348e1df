// Retargeting every motion onto every rigged body (feet on the floor, joints within their ranges),
// rest-pose offsets, the calibration frame, units, and skinning (linear and dual quaternion).
#include <gtest/gtest.h>
#include <omp.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <mutex>
#include <regex>
#include <sstream>

#include "drape/animate.hpp"
#include "drape/body.hpp"
#include "drape/io.hpp"
#include "drape/error.hpp"
#include "drape/motion.hpp"
#include "support/test_support.hpp"

namespace drape {
namespace {

enum class RigBody { DefaultFemale, MakeHumanCmuMb, MakeHumanGlb };

const Body& rig_body_of(RigBody which) {
  static std::map<RigBody, Body> cache;
  static std::mutex mutex;
  std::lock_guard lock(mutex);
  auto it = cache.find(which);
  if (it != cache.end()) return it->second;
  Body b;
  if (which == RigBody::DefaultFemale) b = default_body(Sex::Female);
  if (which == RigBody::MakeHumanCmuMb) {
    BodyBuildOptions o;
    o.skeleton = BodySkeleton::CmuMb;
    b = make_human_body(Sex::Male, {}, o);
  }
  if (which == RigBody::MakeHumanGlb) {
    const auto path = test::shared_file("bodies/makehuman/derived/mh_female_average_cmu_mb.glb");
    b = load_body(path);
  }
  return cache.emplace(which, std::move(b)).first->second;
}

const char* kMotions[] = {"cmu/cmu_02_01_walk.bvh",
                          "cmu/cmu_09_01_run.bvh",
                          "cmu/cmu_10_01_soccer_kick.bvh",
                          "synthetic/synthetic_arms_raise_cmu_skeleton.bvh",
                          "makehuman_poses/tpose.bvh",
                          "makehuman_poses/sit01.bvh",
                          "makehuman_poses/run01.bvh",
                          "makehuman_poses/standing01.bvh"};

struct Case {
  const char* motion;
  RigBody body;
};
class EveryMotionOnEveryBody : public ::testing::TestWithParam<Case> {};

TEST_P(EveryMotionOnEveryBody, FeetOnTheFloorJointsWithinRange) {
  const auto path = DRAPE_REQUIRE_SHARED(std::string("motions/") + GetParam().motion);
  if (GetParam().body == RigBody::MakeHumanGlb && test::shared_file("bodies/makehuman/derived/mh_female_average_cmu_mb.glb").empty())
    GTEST_SKIP() << "shared test data not found: the rigged MakeHuman GLB";
  const Body& body = rig_body_of(GetParam().body);
  const Motion m = read_motion(path);
  const BodyAnimation a = retarget(m, body);
  ASSERT_GT(a.frame_count, a.blend_frames);
  EXPECT_EQ(a.joint_count, body.skeleton.joints.size());
  for (const Vec3f& p : a.position) ASSERT_TRUE(p.allFinite());
  for (const Quatf& q : a.rotation) ASSERT_NEAR(q.norm(), 1.0f, 1e-3f);
  // No foot below the floor; a motion that stands (not the jumps of a run) has a foot on it in most frames.
  EXPECT_GE(a.feet.lowest_y, -0.01f) << "frame shift " << a.feet.floor_shift_m;
  EXPECT_LE(a.feet.lowest_y, 0.001f);
  EXPECT_TRUE(a.limits.violations.empty()) << a.limits.violations.front();
  // Bones keep their lengths: a rigid skeleton (thigh of the left leg).
  const JointMap map = find_joint_map([&] {
    std::vector<std::string> n;
    for (const Joint& j : body.skeleton.joints) n.push_back(j.name);
    return n;
  }(), "body");
  const size_t hip = static_cast<size_t>(map.joint[13]), knee = static_cast<size_t>(map.joint[14]);
  const float thigh = (body.skeleton.joints[hip].position - body.skeleton.joints[knee].position).norm();
  for (size_t f = 0; f < a.frame_count; ++f) {
    const PoseView p = a.pose(f);
    ASSERT_NEAR((p.position[hip] - p.position[knee]).norm(), thigh, 1e-4f);
  }
  std::printf("%s: %s -> %s, %zu frames, root scale %.4f, lowest foot %.4f m, contact %.2f, sliding %.3f m (max %.2f m/s), "
              "knee %.0f..%.0f deg, elbow up to %.0f deg\n",
              GetParam().motion, a.motion_convention.c_str(), a.body_convention.c_str(), a.frame_count,
              static_cast<double>(a.root_scale), static_cast<double>(a.feet.lowest_y), a.feet.contact_fraction,
              static_cast<double>(a.feet.sliding_m), static_cast<double>(a.feet.max_sliding_speed),
              static_cast<double>(a.limits.min_knee_flexion_deg), static_cast<double>(a.limits.max_knee_flexion_deg),
              static_cast<double>(a.limits.max_elbow_flexion_deg));
}

std::string body_label(RigBody b) {
  return b == RigBody::DefaultFemale ? "default_female" : b == RigBody::MakeHumanCmuMb ? "makehuman_cmu_mb" : "makehuman_glb";
}

std::vector<Case> all_cases() {
  std::vector<Case> out;
  for (const char* m : kMotions)
    for (RigBody b : {RigBody::DefaultFemale, RigBody::MakeHumanCmuMb, RigBody::MakeHumanGlb}) out.push_back({m, b});
  return out;
}
INSTANTIATE_TEST_SUITE_P(SharedData, EveryMotionOnEveryBody, ::testing::ValuesIn(all_cases()),
                         [](const ::testing::TestParamInfo<Case>& p) {
                           std::string s = std::filesystem::path(p.param.motion).stem().string();
                           for (char& c : s)
                             if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
                           return s + "_on_" + body_label(p.param.body);
                         });

// A walk keeps a foot on the floor: the root's vertical motion was scaled to the body's legs.
TEST(Retarget, WalkKeepsAFootOnTheFloor) {
  const auto path = DRAPE_REQUIRE_SHARED("motions/cmu/cmu_02_01_walk.bvh");
  for (RigBody b : {RigBody::DefaultFemale, RigBody::MakeHumanCmuMb}) {
    const BodyAnimation a = retarget(read_motion(path), rig_body_of(b));
    EXPECT_GE(a.feet.contact_fraction, 0.9);
    EXPECT_FALSE(a.skipped_calibration);
    // The walk travels: the hips move forward by more than a metre in 2.8 s.
    const Vec3f start = a.pose(0).position[0], end = a.pose(a.frame_count - 1).position[0];
    EXPECT_GT(Vec2f(end.x() - start.x(), end.z() - start.z()).norm(), 1.0f);
  }
}

TEST(Retarget, CalibrationTPoseIsSkipped) {
  const auto run = DRAPE_REQUIRE_SHARED("motions/cmu/cmu_09_01_run.bvh");
  const BodyAnimation a = retarget(read_motion(run), rig_body_of(RigBody::DefaultFemale));
  EXPECT_TRUE(a.skipped_calibration);
  EXPECT_EQ(a.motion_first, 1);
  RetargetOptions keep;
  keep.skip_calibration = false;
  EXPECT_EQ(retarget(read_motion(run), rig_body_of(RigBody::DefaultFemale), keep).motion_first, 0);
  const auto arms = DRAPE_REQUIRE_SHARED("motions/synthetic/synthetic_arms_raise_cmu_skeleton.bvh");
  EXPECT_FALSE(retarget(read_motion(arms), rig_body_of(RigBody::DefaultFemale)).skipped_calibration);
}

// The CMU T-pose rest against the body's A-pose: with the arms 80 degrees down from the T-pose the
// body's hands hang beside the hips; raised 85 degrees above it they are over the head.
TEST(Retarget, RestPoseOffsetsArmsDownAndUp) {
  const auto path = DRAPE_REQUIRE_SHARED("motions/synthetic/synthetic_arms_raise_cmu_skeleton.bvh");
  const Body& body = rig_body_of(RigBody::DefaultFemale);
  const BodyAnimation a = retarget(read_motion(path), body);
  const int hand = body.skeleton.find("LeftHand"), shoulder = body.skeleton.find("LeftArm"), head = body.skeleton.find("Head");
  ASSERT_GE(hand, 0);
  const PoseView down = a.pose(a.blend_frames);
  EXPECT_LT(down.position[static_cast<size_t>(hand)].y(), down.position[static_cast<size_t>(shoulder)].y() - 0.35f);
  float highest = -1;
  for (size_t f = 0; f < a.frame_count; ++f) highest = std::max(highest, a.pose(f).position[static_cast<size_t>(hand)].y() - a.pose(f).position[static_cast<size_t>(head)].y());
  EXPECT_GT(highest, 0.15f);
  // Frame 0 is the bind pose (the dressed pose), exactly.
  for (size_t j = 0; j < a.joint_count; ++j) {
    EXPECT_LT((a.pose(0).position[j] - body.skeleton.joints[j].position).norm(), 1e-5f);
    EXPECT_NEAR(a.pose(0).rotation[j].angularDistance(Quatf::Identity()), 0.0f, 1e-4f);
  }
}

// BVH has no unit: the same file in ten times larger units retargets to the same animation.
TEST(Retarget, MotionUnitsCancel) {
  const auto path = DRAPE_REQUIRE_SHARED("motions/cmu/cmu_02_01_walk.bvh");
  Motion m = read_motion(path);
  Motion big = m;
  for (Vec3f& o : big.rest_offset) o *= 10;
  for (Vec3f& t : big.translation) t *= 10;
  const Body& body = rig_body_of(RigBody::DefaultFemale);
  const BodyAnimation a = retarget(m, body), b = retarget(big, body);
  ASSERT_EQ(a.position.size(), b.position.size());
  for (size_t i = 0; i < a.position.size(); ++i) ASSERT_TRUE(a.position[i].isApprox(b.position[i], 1e-4f)) << i;
}

TEST(Retarget, UnknownSkeletonAndBadFramesAreRefused) {
  Motion m = parse_bvh("HIERARCHY\nROOT torso\n{\n OFFSET 0 0 0\n CHANNELS 3 Zrotation Yrotation Xrotation\n JOINT thigh_l\n {\n  OFFSET 1 -1 0\n  CHANNELS 3 Zrotation Yrotation Xrotation\n }\n}\nMOTION\nFrames: 1\nFrame Time: 0.1\n0 0 0 0 0 0\n",
                       "robot.bvh");
  try {
    retarget(m, rig_body_of(RigBody::DefaultFemale));
    FAIL();
  } catch (const InputError& e) {
    EXPECT_EQ(e.source(), "robot.bvh");
    EXPECT_NE(std::string(e.what()).find("thigh_l"), std::string::npos);
  }
  const auto path = DRAPE_REQUIRE_SHARED("motions/cmu/cmu_02_01_walk.bvh");
  RetargetOptions o;
  o.first_frame = 400;
  EXPECT_THROW(retarget(read_motion(path), rig_body_of(RigBody::DefaultFemale), o), InputError);
  Body unrigged = rig_body_of(RigBody::DefaultFemale);
  unrigged.skeleton.joints.clear();
  EXPECT_THROW(retarget(read_motion(path), unrigged), InputError);
}

// ---- Skinning ----

TEST(Skinning, BindPoseAndRigidMotionsAreExact) {
  const Body& body = rig_body_of(RigBody::DefaultFemale);
  std::vector<Quatf> r;
  std::vector<Vec3f> p;
  bind_pose(body, r, p);
  std::vector<Vec3f> x(body.mesh.vertex_count());
  for (Skinning s : {Skinning::Linear, Skinning::DualQuaternion}) {
    skin_mesh(body, {r, p}, s, x);
    for (size_t v = 0; v < x.size(); ++v) ASSERT_TRUE(x[v].isApprox(body.mesh.positions[v], 1e-5f) || (x[v] - body.mesh.positions[v]).norm() < 1e-5f);
    // Every joint turned by the same rotation about the origin and moved: the mesh moves rigidly.
    const Quatf q(Eigen::AngleAxisf(0.7f, Vec3f(0.3f, 1.0f, -0.2f).normalized()));
    const Vec3f t(0.4f, 0.1f, -1.2f);
    std::vector<Quatf> rq(r.size(), q);
    std::vector<Vec3f> pq(p.size());
    for (size_t j = 0; j < p.size(); ++j) pq[j] = q * p[j] + t;
    skin_mesh(body, {rq, pq}, s, x);
    for (size_t v = 0; v < x.size(); ++v) ASSERT_LT((x[v] - (q * body.mesh.positions[v] + t)).norm(), 1e-4f) << to_string(s);
  }
}

// A vertex bound half to each of two joints, the second twisted half a turn about the bone: linear
// blending collapses it onto the bone's axis, dual quaternions keep its distance from the axis.
TEST(Skinning, DualQuaternionsKeepVolumeUnderTwist) {
  Body body;
  body.skeleton.joints = {{"a", -1, Vec3f(0, 0, 0)}, {"b", 0, Vec3f(0, 1, 0)}};
  body.mesh.positions = {Vec3f(0.1f, 1.0f, 0.0f)};
  body.mesh.joints = {{0, 1, 0, 0}};
  body.mesh.weights = {Vec4f(0.5f, 0.5f, 0, 0)};
  const std::vector<Quatf> r{Quatf::Identity(), Quatf(Eigen::AngleAxisf(static_cast<float>(M_PI) * 0.9f, Vec3f::UnitY()))};
  const std::vector<Vec3f> p{Vec3f(0, 0, 0), Vec3f(0, 1, 0)};
  std::vector<Vec3f> lbs(1), dqs(1);
  skin_mesh(body, {r, p}, Skinning::Linear, lbs);
  skin_mesh(body, {r, p}, Skinning::DualQuaternion, dqs);
  const auto radius = [](const Vec3f& x) { return Vec2f(x.x(), x.z()).norm(); };
  EXPECT_LT(radius(lbs[0]), 0.02f);
  EXPECT_NEAR(radius(dqs[0]), 0.1f, 1e-4f);
  EXPECT_NEAR(dqs[0].y(), 1.0f, 1e-4f);
}

TEST(Skinning, SameResultOnAnyThreadCount) {
  const auto path = DRAPE_REQUIRE_SHARED("motions/cmu/cmu_02_01_walk.bvh");
  const Body& body = rig_body_of(RigBody::DefaultFemale);
  const BodyAnimation a = retarget(read_motion(path), body);
  std::vector<Vec3f> one(body.mesh.vertex_count()), two(body.mesh.vertex_count());
  const int threads = omp_get_max_threads();
  for (Skinning s : {Skinning::Linear, Skinning::DualQuaternion}) {
    omp_set_num_threads(1);
    skin_mesh(body, a.pose(40), s, one);
    omp_set_num_threads(2);
    skin_mesh(body, a.pose(40), s, two);
    ASSERT_TRUE(one == two);
  }
  omp_set_num_threads(threads);
}

}  // namespace
}  // namespace drape

namespace drape {
namespace {

// anim.glb's joint animation read back as a motion (glTF input) and retargeted onto the same body
// gives the same joint positions: the writer's local rotations and the glTF motion reader agree.
TEST(GltfMotion, AnimationRoundTripsThroughGlb) {
  const auto path = DRAPE_REQUIRE_SHARED("motions/cmu/cmu_02_01_walk.bvh");
  const Body& body = rig_body_of(RigBody::DefaultFemale);
  RetargetOptions o;
  o.last_frame = 120;
  AnimationResult r;
  r.body = retarget(read_motion(path), body, o);
  r.frames.resize(r.body.frame_count);
  const auto dir = test::temp_dir("gltf_motion");
  write_scene(dir / "walk.glb", animation_scene(body, r));
  const Motion m = read_motion(dir / "walk.glb");
  EXPECT_EQ(m.format, "gltf");
  EXPECT_EQ(m.frame_count, r.body.frame_count);
  RetargetOptions again;
  again.blend_seconds = 0;
  const BodyAnimation b = retarget(m, body, again);
  ASSERT_EQ(b.frame_count, r.body.frame_count);
  EXPECT_EQ(b.motion_convention, "drape");
  // The pose of every frame (joints against the hips) comes back within 1 mm; the clip as a whole may
  // sit differently on the floor, as the floor is fitted again to the clip read back (within 1.5 cm).
  float worst_pose = 0, worst_root = 0;
  for (size_t f = 0; f < b.frame_count; ++f) {
    const Vec3f root_b = b.pose(f).position[0], root_a = r.body.pose(f).position[0];
    worst_root = std::max(worst_root, (root_b - root_a).norm());
    for (size_t j = 0; j < b.joint_count; ++j)
      worst_pose = std::max(worst_pose, ((b.pose(f).position[j] - root_b) - (r.body.pose(f).position[j] - root_a)).norm());
  }
  EXPECT_LT(worst_pose, 0.001f);
  EXPECT_LT(worst_root, 0.015f);
}

}  // namespace
}  // namespace drape
