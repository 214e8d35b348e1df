// Motion files: every BVH in ../shared/data/motions, line endings, Euler orders, units, malformed
// files; joint names of the known skeletons and joint maps from files.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>

#include "drape/error.hpp"
#include "drape/motion.hpp"
#include "support/test_support.hpp"

namespace drape {
namespace {

std::string read_text(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

struct MotionFile {
  const char* path;
  size_t frames, joints;
  UpAxis up;
  const char* convention;
};

class EveryMotionFile : public ::testing::TestWithParam<MotionFile> {};

TEST_P(EveryMotionFile, ParsesWithItsFramesJointsAxesAndSkeleton) {
  const auto path = DRAPE_REQUIRE_SHARED(std::string("motions/") + GetParam().path);
  const Motion m = read_motion(path);
  EXPECT_EQ(m.frame_count, GetParam().frames);
  EXPECT_EQ(m.joint_count(), GetParam().joints);
  EXPECT_EQ(m.up, GetParam().up);
  EXPECT_EQ(find_joint_map(m.names, m.source).convention, GetParam().convention);
  // After the axis conversion the rest skeleton stands up +Y: the head above the hips.
  const JointMap map = find_joint_map(m.names, m.source);
  std::vector<Vec3f> p;
  std::vector<Quatf> r;
  m.world_pose(-1, p, r);
  EXPECT_GT(p[static_cast<size_t>(map.joint[4])].y() - p[static_cast<size_t>(map.joint[0])].y(), 0.0f);
  for (const Quatf& q : m.rotation) ASSERT_NEAR(q.norm(), 1.0f, 1e-4f);
  for (const Vec3f& t : m.translation) ASSERT_TRUE(t.allFinite());
}

INSTANTIATE_TEST_SUITE_P(
    SharedData, EveryMotionFile,
    ::testing::Values(MotionFile{"cmu/cmu_02_01_walk.bvh", 343, 31, UpAxis::Y, "cmu"},
                      MotionFile{"cmu/cmu_09_01_run.bvh", 149, 31, UpAxis::Y, "cmu"},
                      MotionFile{"cmu/cmu_10_01_soccer_kick.bvh", 201, 19, UpAxis::Y, "cmu_19"},
                      MotionFile{"synthetic/synthetic_arms_raise_cmu_skeleton.bvh", 121, 31, UpAxis::Y, "cmu"},
                      MotionFile{"makehuman_poses/tpose.bvh", 1, 173, UpAxis::Z, "makehuman"},
                      MotionFile{"makehuman_poses/sit01.bvh", 1, 163, UpAxis::Z, "makehuman"},
                      MotionFile{"makehuman_poses/run01.bvh", 1, 163, UpAxis::Z, "makehuman"},
                      MotionFile{"makehuman_poses/standing01.bvh", 1, 163, UpAxis::Z, "makehuman"}),
    [](const ::testing::TestParamInfo<MotionFile>& p) {
      std::string s = std::filesystem::path(p.param.path).stem().string();
      for (char& c : s)
        if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
      return s;
    });

TEST(Bvh, LineEndingsDoNotMatter) {
  const auto path = DRAPE_REQUIRE_SHARED("motions/cmu/cmu_02_01_walk.bvh");
  const std::string crlf = read_text(path);
  ASSERT_NE(crlf.find("\r\n"), std::string::npos);
  std::string lf;
  for (char c : crlf)
    if (c != '\r') lf += c;
  const Motion a = parse_bvh(crlf, "crlf"), b = parse_bvh(lf, "lf");
  ASSERT_EQ(a.rotation.size(), b.rotation.size());
  for (size_t i = 0; i < a.rotation.size(); ++i) ASSERT_TRUE(a.rotation[i].coeffs() == b.rotation[i].coeffs());
  for (size_t i = 0; i < a.translation.size(); ++i) ASSERT_TRUE(a.translation[i] == b.translation[i]);
}

// A two-joint chain: the child's offset (0, 1, 0) turned by the root's two rotations in the order
// the channels list them.
Vec3f child_position(const std::string& channels, const std::string& values) {
  const std::string text = "HIERARCHY\nROOT a\n{\n OFFSET 0 0 0\n CHANNELS 3 " + channels +
                           "\n JOINT b\n {\n  OFFSET 0 1 0\n  CHANNELS 0\n }\n}\nMOTION\nFrames: 1\nFrame Time: 0.1\n" + values + "\n";
  const Motion m = parse_bvh(text, "chain.bvh", {MotionUp::Y});
  std::vector<Vec3f> p;
  std::vector<Quatf> r;
  m.world_pose(0, p, r);
  return p[1];
}

TEST(Bvh, EulerOrderIsTheChannelOrder) {
  // R = Rz(90) Rx(90): (0,1,0) -> Rx -> (0,0,1) -> Rz -> (0,0,1).
  EXPECT_TRUE(child_position("Zrotation Xrotation Yrotation", "90 90 0").isApprox(Vec3f(0, 0, 1), 1e-5f));
  // R = Rx(90) Rz(90): (0,1,0) -> Rz -> (-1,0,0) -> Rx -> (-1,0,0).
  EXPECT_TRUE(child_position("Xrotation Zrotation Yrotation", "90 90 0").isApprox(Vec3f(-1, 0, 0), 1e-5f));
  // Tabs, a leading '+', exponents and a value without a leading zero read as numbers.
  EXPECT_TRUE(child_position("Zrotation\tXrotation Yrotation", "+9e1\t.0 -0").isApprox(Vec3f(-1, 0, 0), 1e-5f));
}

struct Malformed {
  const char* name;
  const char* text;
  const char* message;  // a part of the error message (line and what)
};

class MalformedBvh : public ::testing::TestWithParam<Malformed> {};
TEST_P(MalformedBvh, IsRefusedNamingTheLine) {
  try {
    parse_bvh(GetParam().text, "bad.bvh");
    FAIL() << "accepted";
  } catch (const InputError& e) {
    EXPECT_EQ(e.source(), "bad.bvh");
    EXPECT_NE(std::string(e.what()).find(GetParam().message), std::string::npos) << e.what();
  }
}
constexpr const char* kHead = "HIERARCHY\nROOT Hips\n{\n OFFSET 0 0 0\n CHANNELS 6 Xposition Yposition Zposition Zrotation Yrotation Xrotation\n";
INSTANTIATE_TEST_SUITE_P(
    Files, MalformedBvh,
    ::testing::Values(
        Malformed{"empty", "", "empty file"},
        Malformed{"not_bvh", "solid cube\n", "line 1: expected 'HIERARCHY'"},
        Malformed{"no_motion", "HIERARCHY\nROOT Hips\n{\n OFFSET 0 0 0\n CHANNELS 3 Zrotation Yrotation Xrotation\n}\n",
                  "no MOTION section"},
        Malformed{"bad_channel", "HIERARCHY\nROOT Hips\n{\n OFFSET 0 0 0\n CHANNELS 3 Zrotation Wrotation Xrotation\n}\n",
                  "line 5: unknown channel 'Wrotation'"},
        Malformed{"bad_channel_count", "HIERARCHY\nROOT Hips\n{\n OFFSET 0 0 0\n CHANNELS 4 Zrotation\n}\n",
                  "line 5: joint 'Hips' has 4 channels"},
        Malformed{"bad_offset", "HIERARCHY\nROOT Hips\n{\n OFFSET 0 zero 0\n", "line 4: joint 'Hips' OFFSET 'zero' is not a number"},
        Malformed{"nan_value", "HIERARCHY\nROOT Hips\n{\n OFFSET 0 0 0\n CHANNELS 3 Zrotation Yrotation Xrotation\n}\nMOTION\nFrames: 1\nFrame Time: 0.1\n0 nan 0\n",
                  "line 10: frame 0 value 2 'nan' is not finite"},
        Malformed{"huge_rotation", "HIERARCHY\nROOT Hips\n{\n OFFSET 0 0 0\n CHANNELS 3 Zrotation Yrotation Xrotation\n}\nMOTION\nFrames: 1\nFrame Time: 0.1\n0 7.2e67 0\n",
                  "line 10: frame 0 value 2 7.2e+67 is out of range"},
        Malformed{"huge_offset", "HIERARCHY\nROOT Hips\n{\n OFFSET 0 -1e39 0\n", "line 4: joint 'Hips' OFFSET -1e+39 is out of range"},
        Malformed{"short_frame", "HIERARCHY\nROOT Hips\n{\n OFFSET 0 0 0\n CHANNELS 3 Zrotation Yrotation Xrotation\n}\nMOTION\nFrames: 2\nFrame Time: 0.1\n0 0 0\n0 0\n",
                  "frame 1 ends after 2 of its 3 values"},
        Malformed{"extra_values", "HIERARCHY\nROOT Hips\n{\n OFFSET 0 0 0\n CHANNELS 3 Zrotation Yrotation Xrotation\n}\nMOTION\nFrames: 1\nFrame Time: 0.1\n0 0 0\n7\n",
                  "line 11: more values than 1 frames"},
        Malformed{"huge_frame_count", "HIERARCHY\nROOT Hips\n{\n OFFSET 0 0 0\n CHANNELS 3 Zrotation Yrotation Xrotation\n}\nMOTION\nFrames: 99999999999\nFrame Time: 0.1\n0 0 0\n",
                  "line 8: 99999999999 frames of 3 channels do not fit"},
        Malformed{"zero_frame_time", "HIERARCHY\nROOT Hips\n{\n OFFSET 0 0 0\n CHANNELS 3 Zrotation Yrotation Xrotation\n}\nMOTION\nFrames: 1\nFrame Time: 0\n0 0 0\n",
                  "line 9: frame time 0 s"},
        Malformed{"unclosed_joint", "HIERARCHY\nROOT Hips\n{\n OFFSET 0 0 0\n CHANNELS 3 Zrotation Yrotation Xrotation\nMOTION\n",
                  "line 6: MOTION before joint 'Hips' was closed"},
        Malformed{"duplicate_joint", "HIERARCHY\nROOT Hips\n{\n OFFSET 0 0 0\n CHANNELS 3 Zrotation Yrotation Xrotation\n JOINT Hips\n {\n",
                  "line 6: joint 'Hips' appears twice"},
        Malformed{"stray_brace", "HIERARCHY\nROOT Hips\n{\n OFFSET 0 0 0\n CHANNELS 0\n}\n}\n", "line 7: a '}' with no joint open"},
        Malformed{"unknown_keyword", "HIERARCHY\nROOT Hips\n{\n OFFSET 0 0 0\n CHANNELS 0\n ROTATION 1\n", "line 6: unexpected 'ROTATION'"}),
    [](const ::testing::TestParamInfo<Malformed>& p) { return std::string(p.param.name); });

TEST(Bvh, DeepNestingIsRefusedWithoutExhaustingTheStack) {
  std::string text = "HIERARCHY\nROOT j0\n{\nOFFSET 0 0 0\nCHANNELS 3 Zrotation Yrotation Xrotation\n";
  for (int i = 1; i < 5000; ++i) text += "JOINT j" + std::to_string(i) + "\n{\nOFFSET 0 1 0\nCHANNELS 3 Zrotation Yrotation Xrotation\n";
  EXPECT_THROW(parse_bvh(text, "deep.bvh"), InputError);
}

TEST(JointMaps, UnknownSkeletonIsRefusedNamingItsJoints) {
  const std::vector<std::string> names{"torso", "thigh_l", "thigh_r", "shin_l"};
  try {
    find_joint_map(names, "robot.bvh");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("unknown skeleton"), std::string::npos);
    EXPECT_NE(std::string(e.what()).find("thigh_l"), std::string::npos);
  }
}

TEST(JointMaps, KnownConventionsByName) {
  const std::vector<std::string> mixamo{"mixamorig:Hips", "mixamorig:Spine", "mixamorig:Spine1", "mixamorig:Spine2",
                                        "mixamorig:Neck", "mixamorig:Head", "mixamorig:LeftArm", "mixamorig:LeftForeArm",
                                        "mixamorig:RightArm", "mixamorig:RightForeArm", "mixamorig:LeftUpLeg",
                                        "mixamorig:LeftLeg", "mixamorig:LeftFoot", "mixamorig:RightUpLeg",
                                        "mixamorig:RightLeg", "mixamorig:RightFoot"};
  const JointMap m = find_joint_map(mixamo, "mixamo.glb");
  EXPECT_EQ(m.convention, "mixamo");
  EXPECT_EQ(m.joint[2], 3);  // chest <- Spine2
  const std::vector<std::string> smpl{"pelvis", "left_hip", "right_hip", "spine1", "left_knee", "right_knee", "spine2",
                                      "left_ankle", "right_ankle", "spine3", "left_foot", "right_foot", "neck",
                                      "left_collar", "right_collar", "head", "left_shoulder", "right_shoulder",
                                      "left_elbow", "right_elbow", "left_wrist", "right_wrist"};
  EXPECT_EQ(find_joint_map(smpl, "smpl.glb").convention, "smpl");
  const std::vector<std::string> daz{"hip", "abdomen", "chest", "neck", "head", "lCollar", "lShldr", "lForeArm", "lHand",
                                     "rCollar", "rShldr", "rForeArm", "rHand", "lThigh", "lShin", "lFoot", "rThigh",
                                     "rShin", "rFoot"};
  EXPECT_EQ(find_joint_map(daz, "daz.bvh").convention, "cmu_daz");
  const std::vector<std::string> max{"Hips", "LeftHip", "LeftKnee", "LeftAnkle", "RightHip", "RightKnee", "RightAnkle",
                                     "Chest", "Chest2", "LeftCollar", "LeftShoulder", "LeftElbow", "LeftWrist",
                                     "RightCollar", "RightShoulder", "RightElbow", "RightWrist", "Neck", "Head"};
  const JointMap b = find_joint_map(max, "max.bvh");
  EXPECT_EQ(b.convention, "cmu_3dsmax");
  EXPECT_EQ(b.joint[6], 10);  // upper arm <- LeftShoulder (Biped's name for it), not the clavicle
}

TEST(JointMaps, FromAFile) {
  const std::vector<std::string> names{"pelvis", "l_thigh", "r_thigh", "l_shin", "r_shin", "l_foot", "r_foot",
                                       "chest", "l_arm", "r_arm"};
  const JointMap m = parse_joint_map(
      R"({"Hips": "pelvis", "LeftUpLeg": "l_thigh", "RightUpLeg": "r_thigh", "LeftLeg": "l_shin", "RightLeg": "r_shin",
          "LeftFoot": "l_foot", "RightFoot": "r_foot", "Spine1": "chest", "LeftArm": "l_arm", "RightArm": "r_arm"})",
      "map.json", names);
  EXPECT_EQ(m.joint[0], 0);
  EXPECT_EQ(m.joint[13], 1);
  try {
    parse_joint_map(R"({"Hips": "pelvis", "LeftThigh": "l_thigh"})", "map.json", names);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("'LeftThigh' is not a joint drape drives"), std::string::npos) << e.what();
  }
  try {
    parse_joint_map(R"({"Hips": 1e999})", "map.json", names);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("not JSON"), std::string::npos) << e.what();
  }
  try {
    parse_joint_map(R"({"Hips": "root"})", "map.json", names);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("joint 'root' (for Hips) is not in the skeleton"), std::string::npos) << e.what();
  }
  EXPECT_THROW(parse_joint_map(R"({"Hips": "pelvis"})", "map.json", names), InputError);  // legs missing
  EXPECT_THROW(parse_joint_map("[1, 2", "map.json", names), InputError);
}

TEST(Motion, AnUnknownExtensionIsRefusedNamingTheFormatsRead) {
  try {
    read_motion("dance.c3d");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_EQ(e.source(), "dance.c3d");
    EXPECT_NE(std::string(e.what()).find(".bvh, .fbx, .glb, .gltf"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace drape
