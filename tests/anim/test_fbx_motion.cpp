// FBX motions. No FBX file is kept: each test makes its own from a BVH file of ../shared/data with
// Assimp (its BVH importer, edits to the scene, its ASCII FBX exporter) and checks that drape reads
// back the motion of the BVH file: the same frames and rate, the same world pose of every joint
// (in metres: the exporter's files say centimetres), the same animation on the default body.
// The edits make the files Mixamo's and Maya's exporters write: Mixamo's joint names, pre-rotations,
// rotation offsets and post-rotations (Assimp's "$AssimpFbx$" helper nodes), a Z-up armature scaled
// 0.01 in a file in metres.
#include <assimp/config.h>
#include <assimp/scene.h>
#include <gtest/gtest.h>

#include <assimp/Exporter.hpp>
#include <assimp/Importer.hpp>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <random>
#include <sstream>

#include "drape/body.hpp"
#include "drape/error.hpp"
#include "drape/motion.hpp"
#include "support/test_support.hpp"

namespace drape {
namespace {

constexpr const char* kWalk = "motions/cmu/cmu_02_01_walk.bvh";

const Body& default_female() {
  static std::once_flag once;
  static Body body;
  std::call_once(once, [] { body = default_body(Sex::Female); });
  return body;
}

struct FbxEdits {
  bool animation = true;
  bool skin = true;              // keep the skeleton mesh Assimp's BVH importer makes (its bones)
  bool mixamo_names = false;     // "mixamorig:Hips", ... with Mixamo's spine (Spine, Spine1, Spine2)
  bool pivots = false;           // pre-rotations, rotation offsets and post-rotations (add_pivots)
  bool z_up_armature = false;    // an armature above the hips: Y-up to Z-up, scaled 0.01, the file in metres
  bool only_mesh_moves = false;  // no bones; the animation moves the mesh's node alone
};

// Mixamo's names for the CMU skeleton's joints (others keep theirs, prefixed): CMU's LowerBack,
// Spine, Spine1 are Mixamo's Spine, Spine1, Spine2 from the hips up.
std::string mixamo_name(const std::string& cmu) {
  static const std::map<std::string, std::string> renamed{{"LowerBack", "Spine"},
                                                          {"Spine", "Spine1"},
                                                          {"Spine1", "Spine2"},
                                                          {"LHipJoint", "LeftHipJoint"},
                                                          {"RHipJoint", "RightHipJoint"}};
  const auto it = renamed.find(cmu);
  return "mixamorig:" + (it == renamed.end() ? cmu : it->second);
}

void for_each_node(aiNode* n, const std::function<void(aiNode*)>& f) {
  f(n);
  for (unsigned i = 0; i < n->mNumChildren; ++i) for_each_node(n->mChildren[i], f);
}

aiNodeAnim* channel_of(aiAnimation* a, const aiString& name) {
  for (unsigned c = 0; c < a->mNumChannels; ++c)
    if (a->mChannels[c]->mNodeName == name) return a->mChannels[c];
  return nullptr;
}

// Puts `chain` (top first, each with one child) between `node` and its parent.
void insert_above(aiNode* node, std::vector<aiNode*> chain) {
  aiNode* parent = node->mParent;
  for (unsigned i = 0; i < parent->mNumChildren; ++i)
    if (parent->mChildren[i] == node) parent->mChildren[i] = chain.front();
  chain.front()->mParent = parent;
  chain.push_back(node);
  for (size_t k = 0; k + 1 < chain.size(); ++k) {
    chain[k]->mNumChildren = 1;
    chain[k]->mChildren = new aiNode* [1] { chain[k + 1] };
    chain[k + 1]->mParent = chain[k];
  }
}

aiNode* helper(const aiNode* joint, const char* part, const aiMatrix4x4& m) {
  auto* h = new aiNode(std::string(joint->mName.C_Str()) + "_$AssimpFbx$_" + part);
  h->mTransformation = m;
  return h;
}

aiMatrix4x4 rotation(const aiQuaternion& q) {
  return aiMatrix4x4(q.GetMatrix());
}
aiMatrix4x4 translation(const aiVector3D& t) {
  aiMatrix4x4 m;
  return aiMatrix4x4::Translation(t, m);
}

// Pre-rotation P on every joint, rotation offset o on every other, post-rotation Q on every third,
// the joint's own transforms changed so that its local transform (FBX: T Roff Rpre R Rpost^-1) is
// what it was: T R = (T - o) o P (P^-1 R Q) Q^-1.
void add_pivots(aiScene* s, aiNode* hips) {
  aiAnimation* a = s->mAnimations[0];
  std::vector<aiNode*> joints;
  for_each_node(hips, [&](aiNode* n) { joints.push_back(n); });
  for (size_t i = 0; i < joints.size(); ++i) {
    aiNode* j = joints[i];
    const float angle = 0.3f + 0.07f * static_cast<float>(i);
    const aiQuaternion pre(aiVector3D(1.0f, static_cast<float>(i % 3), 2.0f).Normalize(), angle);
    aiQuaternion pre_inverse = pre;
    pre_inverse.Conjugate();
    const aiVector3D offset =
        i % 2 ? aiVector3D(0.5f, -1.0f, 0.25f * static_cast<float>(i % 5)) : aiVector3D();
    const aiQuaternion post =
        i % 3 ? aiQuaternion()
              : aiQuaternion(aiVector3D(0.0f, 1.0f, static_cast<float>(i % 4)).Normalize(), 0.4f);
    aiVector3D s3, t;
    aiQuaternion r;
    j->mTransformation.Decompose(s3, r, t);
    std::vector<aiNode*> chain{helper(j, "Translation", translation(t - offset))};
    if (i % 2) chain.push_back(helper(j, "RotationOffset", translation(offset)));
    chain.push_back(helper(j, "PreRotation", rotation(pre)));
    chain.push_back(helper(j, "Rotation", rotation(pre_inverse * r * post)));
    if (i % 3 == 0)
      chain.push_back(helper(j, "PostRotation", rotation(post)));  // the exporter writes its angles
    j->mTransformation = aiMatrix4x4();
    insert_above(j, chain);
    if (aiNodeAnim* c = channel_of(a, j->mName)) {
      for (unsigned k = 0; k < c->mNumRotationKeys; ++k)
        c->mRotationKeys[k].mValue = pre_inverse * c->mRotationKeys[k].mValue * post;
      for (unsigned k = 0; k < c->mNumPositionKeys; ++k) c->mPositionKeys[k].mValue -= offset;
    }
  }
}

// Writes an ASCII FBX made from `bvh` (Assimp 5.2 does not read back its own binary FBX). Besides
// the edits, the scene is put in the form Assimp's FBX exporter needs: it writes no node for the
// scene's root (the hips, in a BVH scene) nor for a mesh on it, it takes key times for seconds, and
// it cuts the animation at its duration in whole seconds (unless that is 0: no limit).
void make_fbx(const std::filesystem::path& bvh, const std::filesystem::path& out, const FbxEdits& e) {
  Assimp::Importer importer;
  ASSERT_NE(importer.ReadFile(bvh.string(), 0), nullptr) << importer.GetErrorString();
  std::unique_ptr<aiScene> s(importer.GetOrphanedScene());
  aiNode* hips = s->mRootNode;
  auto* root = new aiNode("Scene");
  auto* body = new aiNode("Body");
  std::swap(body->mMeshes, hips->mMeshes);
  std::swap(body->mNumMeshes, hips->mNumMeshes);
  aiNode* top = hips;
  if (e.z_up_armature) {
    top = new aiNode("Armature");
    aiMatrix4x4 turn, scale;
    top->mTransformation = aiMatrix4x4::RotationX(static_cast<float>(M_PI / 2), turn) *
                           aiMatrix4x4::Scaling(aiVector3D(0.01f), scale);
    top->addChildren(1, &hips);
  }
  aiNode* children[] = {top, body};
  root->addChildren(2, children);
  s->mRootNode = root;

  aiAnimation* a = s->mAnimations[0];
  const double tps = a->mTicksPerSecond;
  for (unsigned c = 0; c < a->mNumChannels; ++c) {
    aiNodeAnim* ch = a->mChannels[c];
    for (unsigned k = 0; k < ch->mNumPositionKeys; ++k) ch->mPositionKeys[k].mTime /= tps;
    for (unsigned k = 0; k < ch->mNumRotationKeys; ++k) ch->mRotationKeys[k].mTime /= tps;
    for (unsigned k = 0; k < ch->mNumScalingKeys; ++k) ch->mScalingKeys[k].mTime /= tps;
  }
  a->mDuration /= tps;
  a->mTicksPerSecond = 1e9;

  if (e.mixamo_names) {
    for_each_node(hips, [](aiNode* n) { n->mName.Set(mixamo_name(n->mName.C_Str())); });
    for (unsigned c = 0; c < a->mNumChannels; ++c)
      a->mChannels[c]->mNodeName.Set(mixamo_name(a->mChannels[c]->mNodeName.C_Str()));
    for (unsigned m = 0; m < s->mNumMeshes; ++m)
      for (unsigned b = 0; b < s->mMeshes[m]->mNumBones; ++b)
        s->mMeshes[m]->mBones[b]->mName.Set(mixamo_name(s->mMeshes[m]->mBones[b]->mName.C_Str()));
  }
  if (e.pivots) add_pivots(s.get(), hips);
  if (e.only_mesh_moves) {
    for (unsigned m = 0; m < s->mNumMeshes; ++m) {
      for (unsigned b = 0; b < s->mMeshes[m]->mNumBones; ++b) delete s->mMeshes[m]->mBones[b];
      delete[] s->mMeshes[m]->mBones;
      s->mMeshes[m]->mBones = nullptr;
      s->mMeshes[m]->mNumBones = 0;
    }
    // The mesh's node turns about +Y, half a radian each half second.
    auto* spin = new aiNodeAnim;
    spin->mNodeName = body->mName;
    spin->mNumRotationKeys = 3;
    spin->mRotationKeys = new aiQuatKey[3];
    for (unsigned k = 0; k < 3; ++k)
      spin->mRotationKeys[k] =
          aiQuatKey(0.5 * k, aiQuaternion(aiVector3D(0, 1, 0), 0.5f * static_cast<float>(k)));
    spin->mNumPositionKeys = 1;
    spin->mPositionKeys = new aiVectorKey[1]{aiVectorKey(0.0, aiVector3D())};
    spin->mNumScalingKeys = 1;
    spin->mScalingKeys = new aiVectorKey[1]{aiVectorKey(0.0, aiVector3D(1, 1, 1))};
    for (unsigned c = 0; c < a->mNumChannels; ++c) delete a->mChannels[c];
    a->mNumChannels = 1;
    a->mChannels[0] = spin;
  }
  if (!e.skin) {
    // Only the skeleton and the animation stay.
    for (unsigned m = 0; m < s->mNumMeshes; ++m) delete s->mMeshes[m];
    delete[] s->mMeshes;
    s->mMeshes = nullptr;
    s->mNumMeshes = 0;
    delete[] body->mMeshes;
    body->mMeshes = nullptr;
    body->mNumMeshes = 0;
  }
  if (!e.animation) {
    for (unsigned i = 0; i < s->mNumAnimations; ++i) delete s->mAnimations[i];
    delete[] s->mAnimations;
    s->mAnimations = nullptr;
    s->mNumAnimations = 0;
  }

  delete s->mMetaData;
  s->mMetaData = aiMetadata::Alloc(4);
  s->mMetaData->Set(0, "TimeMode", int32_t(14));  // custom, at the capture's rate
  s->mMetaData->Set(1, "CustomFrameRate", tps);
  s->mMetaData->Set(2, "UnitScaleFactor", e.z_up_armature ? 100.0 : 1.0);
  s->mMetaData->Set(3, "UpAxis", int32_t(e.z_up_armature ? 2 : 1));
  Assimp::Exporter exporter;
  ASSERT_EQ(exporter.Export(s.get(), "fbxa", out.string()), aiReturn_SUCCESS) << exporter.GetErrorString();
}

// World positions of a motion's joints in every frame, and their world rotations since the rest
// pose (what retargeting uses: a joint's frame may differ by a constant rotation, as a Z-up file's
// do once turned to Y-up), by joint name.
struct Poses {
  std::vector<std::string> names;
  std::vector<std::vector<Vec3f>> position;  // [frame][joint]
  std::vector<std::vector<Quatf>> rotation;
};
Poses poses(const Motion& m, const std::vector<std::string>& names, float length_scale) {
  Poses out;
  out.names = names;
  std::vector<Vec3f> p, rest_p;
  std::vector<Quatf> r, rest_r;
  m.world_pose(-1, rest_p, rest_r);
  for (long f = 0; f < static_cast<long>(m.frame_count); ++f) {
    m.world_pose(f, p, r);
    for (size_t j = 0; j < r.size(); ++j) r[j] = r[j] * rest_r[j].conjugate();
    out.position.emplace_back();
    out.rotation.emplace_back();
    for (const std::string& n : names) {
      const int j = m.find(n);
      EXPECT_GE(j, 0) << n;
      if (j < 0) return out;
      out.position.back().push_back(length_scale * p[static_cast<size_t>(j)]);
      out.rotation.back().push_back(r[static_cast<size_t>(j)]);
    }
  }
  return out;
}

// The FBX motion is the BVH motion: frames, rate, and every joint's world pose (BVH lengths in the
// file's centimetres, FBX's in metres), joints found by name (`rename` gives the FBX's name).
void expect_same_motion(const Motion& bvh, const Motion& fbx,
                        const std::function<std::string(const std::string&)>& rename) {
  EXPECT_EQ(fbx.format, "fbx");
  ASSERT_EQ(fbx.frame_count, bvh.frame_count);
  EXPECT_NEAR(fbx.frame_time, bvh.frame_time, 1e-7);
  std::vector<std::string> fbx_names;
  for (const std::string& n : bvh.names) fbx_names.push_back(rename(n));
  const Poses a = poses(bvh, bvh.names, 0.01f), b = poses(fbx, fbx_names, 1.0f);
  float worst_m = 0, worst_deg = 0;
  for (size_t f = 0; f < a.position.size(); ++f)
    for (size_t j = 0; j < a.names.size(); ++j) {
      worst_m = std::max(worst_m, (a.position[f][j] - b.position[f][j]).norm());
      worst_deg = std::max(
          worst_deg, a.rotation[f][j].angularDistance(b.rotation[f][j]) * 180.0f / static_cast<float>(M_PI));
    }
  EXPECT_LT(worst_m, 2e-4f) << "largest joint position difference, m";
  EXPECT_LT(worst_deg, 0.05f) << "largest joint rotation difference, degrees";
  std::printf("  %s: %zu frames, %zu joints; against the BVH at most %.4f mm, %.4f degrees apart\n",
              fbx.source.c_str(), fbx.frame_count, fbx.joint_count(), 1e3 * static_cast<double>(worst_m),
              static_cast<double>(worst_deg));
}

// Both motions give the default body the same animation.
void expect_same_animation(const Motion& bvh, const Motion& fbx, const std::string& fbx_convention) {
  const BodyAnimation a = retarget(bvh, default_female()), b = retarget(fbx, default_female());
  EXPECT_EQ(b.motion_convention, fbx_convention);
  ASSERT_EQ(a.frame_count, b.frame_count);
  EXPECT_NEAR(a.frame_time, b.frame_time, 1e-9);
  EXPECT_EQ(a.skipped_calibration, b.skipped_calibration);
  float worst_m = 0, worst_deg = 0;
  for (size_t i = 0; i < a.position.size(); ++i) {
    worst_m = std::max(worst_m, (a.position[i] - b.position[i]).norm());
    worst_deg =
        std::max(worst_deg, a.rotation[i].angularDistance(b.rotation[i]) * 180.0f / static_cast<float>(M_PI));
  }
  EXPECT_LT(worst_m, 1e-3f) << "largest body joint position difference, m";
  EXPECT_LT(worst_deg, 0.1f) << "largest body joint rotation difference, degrees";
  std::printf("  on the default body: %zu frames, at most %.4f mm, %.4f degrees from the BVH's animation\n",
              b.frame_count, 1e3 * static_cast<double>(worst_m), static_cast<double>(worst_deg));
}

std::string same(const std::string& n) {
  return n;
}

TEST(FbxMotion, TheCmuWalkReadsBackAsItsBvh) {
  const auto bvh = DRAPE_REQUIRE_SHARED(kWalk);
  const auto fbx = test::temp_dir("fbx_walk") / "walk.fbx";
  ASSERT_NO_FATAL_FAILURE(make_fbx(bvh, fbx, {}));
  const Motion a = read_motion(bvh), b = read_motion(fbx);
  EXPECT_EQ(b.up, UpAxis::Y);
  expect_same_motion(a, b, same);
  expect_same_animation(a, b, "cmu");
}

TEST(FbxMotion, WithoutSkinTheAnimatedNodesAreTheJoints) {
  const auto bvh = DRAPE_REQUIRE_SHARED(kWalk);
  const auto fbx = test::temp_dir("fbx_noskin") / "walk.FBX";
  ASSERT_NO_FATAL_FAILURE(make_fbx(bvh, fbx, {.skin = false}));
  const Motion a = read_motion(bvh), b = read_motion(fbx);
  EXPECT_EQ(b.joint_count(), a.joint_count());
  expect_same_motion(a, b, same);
}

TEST(FbxMotion, HelperNodesOfPreRotationsAndOffsetsAreFoldedIntoTheirJoints) {
  const auto bvh = DRAPE_REQUIRE_SHARED(kWalk);
  const auto fbx = test::temp_dir("fbx_pivots") / "walk.fbx";
  ASSERT_NO_FATAL_FAILURE(make_fbx(bvh, fbx, {.pivots = true}));
  {
    // Assimp reads the file into both kinds of helper chain: joints with a pre-rotation only keep a
    // channel of their own, joints with a rotation offset get channels on their helpers.
    Assimp::Importer importer;
    const aiScene* s = importer.ReadFile(fbx.string(), 0);
    ASSERT_NE(s, nullptr) << importer.GetErrorString();
    ASSERT_NE(s->mRootNode->FindNode("LeftLeg_$AssimpFbx$_PreRotation"), nullptr);
    bool own = false, on_helper = false;
    for (unsigned c = 0; c < s->mAnimations[0]->mNumChannels; ++c) {
      const std::string n = s->mAnimations[0]->mChannels[c]->mNodeName.C_Str();
      own |= n == "Hips" || n == "LeftUpLeg" || n == "LeftLeg";
      on_helper |= n.find("_$AssimpFbx$_Rotation") != std::string::npos;
    }
    EXPECT_TRUE(own);
    EXPECT_TRUE(on_helper);
  }
  const Motion a = read_motion(bvh), b = read_motion(fbx);
  for (const std::string& n : b.names) EXPECT_EQ(n.find("$AssimpFbx$"), std::string::npos) << n;
  expect_same_motion(a, b, same);
  expect_same_animation(a, b, "cmu");
}

TEST(FbxMotion, MixamoNamesZUpAndAScaledArmatureInMetres) {
  const auto bvh = DRAPE_REQUIRE_SHARED(kWalk);
  const auto fbx = test::temp_dir("fbx_mixamo") / "walk.fbx";
  ASSERT_NO_FATAL_FAILURE(make_fbx(bvh, fbx, {.mixamo_names = true, .pivots = true, .z_up_armature = true}));
  const Motion a = read_motion(bvh), b = read_motion(fbx);
  EXPECT_EQ(b.up, UpAxis::Z);
  EXPECT_EQ(b.find("Armature"), -1);  // above the skeleton: folded into the hips
  EXPECT_EQ(b.names.front(), "mixamorig:Hips");
  const JointMap map = find_joint_map(b.names, b.source);
  EXPECT_EQ(map.convention, "mixamo");
  EXPECT_EQ(b.names[static_cast<size_t>(map.joint[2])], "mixamorig:Spine2");  // the chest
  expect_same_motion(a, b, mixamo_name);
  expect_same_animation(a, b, "mixamo");
}

// What is not a motion is an InputError naming the file, and never a crash.
void expect_refused(const std::filesystem::path& file, const std::string& why) {
  try {
    read_motion(file);
    ADD_FAILURE() << file << " was read";
  } catch (const InputError& e) {
    EXPECT_EQ(e.source(), file.string());
    EXPECT_NE(std::string(e.what()).find(why), std::string::npos) << e.what();
  }
}

TEST(FbxMotion, WhatIsNotAnFbxMotionIsRefusedNamingTheFile) {
  const auto dir = test::temp_dir("fbx_bad");
  std::ofstream(dir / "empty.fbx");
  expect_refused(dir / "empty.fbx", "empty file");
  std::mt19937 random(7);
  std::string noise(4096, '\0');
  for (char& c : noise) c = static_cast<char>(random());
  std::ofstream(dir / "noise.fbx", std::ios::binary) << noise;
  expect_refused(dir / "noise.fbx", "not a readable FBX file (Assimp: ");
  std::ofstream(dir / "binary_noise.fbx", std::ios::binary)
      << std::string("Kaydara FBX Binary  \0\x1a\0", 23) << noise;
  expect_refused(dir / "binary_noise.fbx", "not a readable FBX file (byte 27: ");
  expect_refused(dir / "absent.fbx", "no such motion file");

  const auto bvh = DRAPE_REQUIRE_SHARED(kWalk);
  ASSERT_NO_FATAL_FAILURE(make_fbx(bvh, dir / "walk.fbx", {}));
  std::stringstream text;
  text << std::ifstream(dir / "walk.fbx", std::ios::binary).rdbuf();
  const std::string whole = text.str();
  for (size_t eighth = 1; eighth < 8; ++eighth) {
    const auto cut = dir / ("cut_" + std::to_string(eighth) + ".fbx");
    std::ofstream(cut, std::ios::binary) << whole.substr(0, whole.size() * eighth / 8);
    try {
      read_motion(cut);
      ADD_FAILURE() << cut << " was read";
    } catch (const InputError& e) {
      EXPECT_EQ(e.source(), cut.string()) << e.what();
    }
  }

  ASSERT_NO_FATAL_FAILURE(make_fbx(bvh, dir / "still.fbx", {.animation = false}));
  expect_refused(dir / "still.fbx", "has no animation");
  ASSERT_NO_FATAL_FAILURE(make_fbx(bvh, dir / "prop.fbx", {.only_mesh_moves = true}));
  expect_refused(dir / "prop.fbx", "has no skeleton");
}

std::string u32(uint32_t v) {
  std::string s(4, '\0');
  std::memcpy(s.data(), &v, 4);
  return s;
}

// A binary FBX (version 7400) record starting at byte `at`: its end, property count and bytes,
// name, properties, then the records `children` makes at the byte given and a null record.
std::string record(size_t at, const std::string& name, uint32_t count, const std::string& props,
                   const std::function<std::string(size_t)>& children = {}) {
  const size_t body = at + 13 + name.size() + props.size();
  std::string kids = children ? children(body) : "";
  if (!kids.empty()) kids += std::string(13, '\0');
  return u32(static_cast<uint32_t>(body + kids.size())) + u32(count) +
         u32(static_cast<uint32_t>(props.size())) + static_cast<char>(name.size()) + name + props + kids;
}
// `levels` records named A, each inside the one before.
std::string nested(size_t at, int levels) {
  if (levels == 1) return record(at, "A", 0, "");
  return record(at, "A", 0, "", [=](size_t inner) { return nested(inner, levels - 1); });
}
std::string binary_fbx(const std::function<std::string(size_t)>& records) {
  return std::string("Kaydara FBX Binary  \0\x1a\0", 23) + u32(7400) + records(27) + std::string(13, '\0');
}

// What Assimp 5.2 cannot be trusted with is refused before it reads the file: nesting deep enough
// to overflow its stack (100000 levels of ASCII braces do), a compressed array claiming more than
// deflate can hold, a rotation key it would split into billions of keys.
TEST(FbxMotion, FilesThatWouldOverwhelmAssimpAreRefusedBeforeIt) {
  const auto dir = test::temp_dir("fbx_limits");
  std::string deep = "; FBX 7.4.0 project file\nObjects: {\n";
  for (int i = 0; i < 100000; ++i) deep += "A: {\n";
  std::ofstream(dir / "deep.fbx") << deep << std::string(100001, '}');
  expect_refused(dir / "deep.fbx", "nested deeper than 64 levels");

  std::ofstream(dir / "deep_binary.fbx", std::ios::binary)
      << binary_fbx([](size_t at) { return nested(at, 100); });
  expect_refused(dir / "deep_binary.fbx", "nested deeper than 64 levels");

  // 128 Mi doubles said to be in 10 compressed bytes.
  const std::string bomb = std::string("d") + u32(1u << 27) + u32(1) + u32(10) + std::string(10, 'x');
  std::ofstream(dir / "bomb.fbx", std::ios::binary) << binary_fbx([&](size_t at) {
    return record(at, "Objects", 0, "", [&](size_t inner) { return record(inner, "Vertices", 1, bomb); });
  });
  expect_refused(dir / "bomb.fbx", "a compressed array of 10 bytes says it holds 1073741824 bytes");

  // One rotation key of 4e11 degrees: Assimp would add 2e9 keys between it and the next.
  const auto bvh = DRAPE_REQUIRE_SHARED(kWalk);
  ASSERT_NO_FATAL_FAILURE(make_fbx(bvh, dir / "walk.fbx", {}));
  std::stringstream text;
  text << std::ifstream(dir / "walk.fbx", std::ios::binary).rdbuf();
  std::string spun = text.str();
  const size_t values = spun.find("a: ", spun.find("KeyValueFloat: *", spun.find("AnimationCurve: ")));
  ASSERT_NE(values, std::string::npos);
  spun.replace(values + 3, spun.find(',', values) - values - 3, "399999999999");
  std::ofstream(dir / "spun.fbx", std::ios::binary) << spun;
  expect_refused(dir / "spun.fbx", "keys 0 and 1 jump from 4e+11 to ");
}

// Debian's Assimp checks its own invariants and aborts the process when one fails (here: a skin
// weight on a vertex the mesh does not have); in drape that is an InputError. (An Assimp built
// without its checks reads the file, the weight ignored.)
TEST(FbxMotion, AnAssimpCheckThatFailsIsAnInputErrorNotAnAbort) {
  const auto bvh = DRAPE_REQUIRE_SHARED(kWalk);
  const auto dir = test::temp_dir("fbx_check");
  ASSERT_NO_FATAL_FAILURE(make_fbx(bvh, dir / "walk.fbx", {}));
  std::stringstream text;
  text << std::ifstream(dir / "walk.fbx", std::ios::binary).rdbuf();
  std::string file = text.str();
  const size_t indexes = file.find("a: ", file.find("Indexes: *", file.find("\"Cluster\"")));
  ASSERT_NE(indexes, std::string::npos);
  file.replace(indexes + 3, file.find(',', indexes) - indexes - 3, "99999");
  std::ofstream(dir / "stray_weight.fbx", std::ios::binary) << file;
  try {
    read_motion(dir / "stray_weight.fbx");
  } catch (const InputError& e) {
    EXPECT_EQ(e.source(), (dir / "stray_weight.fbx").string());
    EXPECT_NE(
        std::string(e.what()).find("not a readable FBX file (Assimp: its check 'out_idx != nullptr' failed"),
        std::string::npos)
        << e.what();
  }
}

TEST(AnimateCli, AnFbxThatIsNotAMotionExits2WritingNothing) {
  const auto dir = test::temp_dir("animate_bad_fbx");
  std::ofstream(dir / "dance.fbx") << "; FBX 7.4.0 project file\nFBXHeaderExtension: {\n";
  const auto res = test::run_drape("animate --motion '" + (dir / "dance.fbx").string() + "' --out '" +
                                   (dir / "out").string() + "'");
  EXPECT_EQ(res.exit_code, 2);
  EXPECT_NE(res.err.find("dance.fbx: "), std::string::npos) << res.err;
  EXPECT_FALSE(std::filesystem::exists(dir / "out"));
}

}  // namespace
}  // namespace drape
