// A skeleton placed from landmarks, and smooth skin weights. Joint names follow the CMU (cgspeed)
// skeleton so that motion capture retargets by name. Weights: each vertex is bound to the bones of
// its body part and the neighbouring parts, with weight 1 / (d^2 + e^2)^2 for its distance d to each
// bone segment, then smoothed over the mesh and cut to the largest four (glTF's JOINTS_0/WEIGHTS_0).
#include <algorithm>
#include <array>
#include <cmath>
#include <numeric>

#include <Eigen/Geometry>

#include "body/analysis.hpp"
#include "drape/body.hpp"

namespace drape {

int Skeleton::find(std::string_view name) const {
  for (size_t i = 0; i < joints.size(); ++i)
    if (joints[i].name == name) return static_cast<int>(i);
  return -1;
}

namespace {

enum JointId : int {
  kHips, kLeftUpLeg, kLeftLeg, kLeftFoot, kLeftToeBase, kRightUpLeg, kRightLeg, kRightFoot, kRightToeBase,
  kSpine, kSpine1, kNeck, kHead, kLeftShoulder, kLeftArm, kLeftForeArm, kLeftHand, kRightShoulder, kRightArm,
  kRightForeArm, kRightHand, kJointCount
};

float segment_distance(const Vec3f& p, const Vec3f& a, const Vec3f& b) {
  const Vec3f ab = b - a;
  const float len2 = ab.squaredNorm();
  const float t = len2 > 0 ? std::clamp((p - a).dot(ab) / len2, 0.0f, 1.0f) : 0.0f;
  return (p - (a + t * ab)).norm();
}

Vec3f section_centre(const Mesh& mesh, float y, float fallback_z) {
  auto s = body::torso_section(mesh, y);
  return Vec3f(0.0f, y, s ? s->centroid.y() : fallback_z);
}

}  // namespace

void rig_body(Body& body) {
  const Mesh& mesh = body.mesh;
  const Landmarks& lm = body.landmarks;
  const float height = lm.crown.y();
  Skeleton sk;
  sk.joints.resize(kJointCount);
  auto set = [&](JointId id, const char* name, JointId parent, const Vec3f& at) {
    sk.joints[id] = Joint{name, parent == kJointCount ? -1 : static_cast<int>(parent), at};
  };
  const float hip_joint_y = lm.crotch.y() + 0.04f * height;
  const Vec3f pelvis = section_centre(mesh, hip_joint_y, lm.crotch.z());
  set(kHips, "Hips", kJointCount, pelvis);
  for (int side : {+1, -1}) {
    const bool left = side > 0;
    auto leg = body::leg_section(mesh, lm.crotch.y() - 0.03f, side);
    const float x = leg ? leg->centroid.x() : 0.09f * static_cast<float>(side);
    const Vec3f knee = left ? lm.left_knee : lm.right_knee;
    const Vec3f ankle = left ? lm.left_ankle : lm.right_ankle;
    // Toe: the front of the foot.
    Vec3f toe = ankle;
    for (const auto& p : mesh.positions)
      if (p.y() < 0.05f * height && std::abs(p.x() - ankle.x()) < 0.05f && p.z() > toe.z()) toe = Vec3f(ankle.x(), 0.02f * height, p.z());
    set(left ? kLeftUpLeg : kRightUpLeg, left ? "LeftUpLeg" : "RightUpLeg", kHips, Vec3f(x, hip_joint_y, pelvis.z()));
    set(left ? kLeftLeg : kRightLeg, left ? "LeftLeg" : "RightLeg", left ? kLeftUpLeg : kRightUpLeg, knee);
    set(left ? kLeftFoot : kRightFoot, left ? "LeftFoot" : "RightFoot", left ? kLeftLeg : kRightLeg, ankle);
    set(left ? kLeftToeBase : kRightToeBase, left ? "LeftToeBase" : "RightToeBase", left ? kLeftFoot : kRightFoot,
        ankle + 0.7f * (toe - ankle));
  }
  const float bust_y = 0.5f * (lm.left_bust.y() + lm.right_bust.y());
  set(kSpine, "Spine", kHips, section_centre(mesh, lm.waist.y(), pelvis.z()));
  set(kSpine1, "Spine1", kSpine, section_centre(mesh, bust_y, pelvis.z()));
  const Vec3f neck_base = section_centre(mesh, lm.neck_base.y(), lm.neck.z());
  set(kNeck, "Neck", kSpine1, neck_base);
  set(kHead, "Head", kNeck, Vec3f(lm.neck.x(), lm.neck.y() + 0.02f * height, lm.neck.z()));
  for (int side : {+1, -1}) {
    const bool left = side > 0;
    const Vec3f shoulder = left ? lm.left_shoulder : lm.right_shoulder;
    const Vec3f elbow = left ? lm.left_elbow : lm.right_elbow;
    const Vec3f wrist = left ? lm.left_wrist : lm.right_wrist;
    const Vec3f dir = (wrist - elbow).normalized();
    const Vec3f arm_joint = elbow - dir * (shoulder - elbow).norm() * 0.92f;
    set(left ? kLeftShoulder : kRightShoulder, left ? "LeftShoulder" : "RightShoulder", kSpine1,
        neck_base + Vec3f(0.02f * static_cast<float>(side), -0.02f, 0.0f));
    set(left ? kLeftArm : kRightArm, left ? "LeftArm" : "RightArm", left ? kLeftShoulder : kRightShoulder, arm_joint);
    set(left ? kLeftForeArm : kRightForeArm, left ? "LeftForeArm" : "RightForeArm", left ? kLeftArm : kRightArm, elbow);
    set(left ? kLeftHand : kRightHand, left ? "LeftHand" : "RightHand", left ? kLeftForeArm : kRightForeArm, wrist);
  }

  // Bone segments: joint -> its (first) child, or to an end landmark for leaves.
  std::array<Vec3f, kJointCount> bone_end;
  for (int j = 0; j < kJointCount; ++j) bone_end[j] = sk.joints[j].position;
  for (int j = kJointCount - 1; j >= 0; --j)
    if (sk.joints[j].parent >= 0) bone_end[sk.joints[j].parent] = sk.joints[j].position;
  bone_end[kHips] = sk.joints[kSpine].position;
  bone_end[kSpine1] = neck_base;
  bone_end[kHead] = lm.crown;
  bone_end[kLeftHand] = lm.left_fingertip;
  bone_end[kRightHand] = lm.right_fingertip;

  // Which bones a vertex of each part may follow (its own and its neighbours').
  const std::vector<std::vector<int>> allowed{
      /*head*/ {kHead, kNeck},
      /*torso*/ {kHips, kSpine, kSpine1, kNeck, kLeftShoulder, kRightShoulder, kLeftArm, kRightArm, kLeftUpLeg, kRightUpLeg},
      /*left arm*/ {kLeftShoulder, kLeftArm, kLeftForeArm, kLeftHand, kSpine1},
      /*right arm*/ {kRightShoulder, kRightArm, kRightForeArm, kRightHand, kSpine1},
      /*left leg*/ {kHips, kLeftUpLeg, kLeftLeg, kLeftFoot, kLeftToeBase},
      /*right leg*/ {kHips, kRightUpLeg, kRightLeg, kRightFoot, kRightToeBase}};

  const size_t n = mesh.positions.size();
  const float eps = 0.02f;
  std::vector<std::array<float, kJointCount>> w(n);
  for (size_t v = 0; v < n; ++v) {
    w[v].fill(0.0f);
    const auto part = body.parts.empty() ? 1 : static_cast<size_t>(body.parts[v]);
    for (int j : allowed[part]) {
      const float d = segment_distance(mesh.positions[v], sk.joints[j].position, bone_end[j]);
      const float q = d * d + eps * eps;
      w[v][j] = 1.0f / (q * q);
    }
    const float sum = std::accumulate(w[v].begin(), w[v].end(), 0.0f);
    for (float& x : w[v]) x /= sum;
  }
  // Smooth over the mesh (removes the seams where the allowed bone sets change between parts).
  std::vector<std::vector<uint32_t>> neighbours(n);
  for (const Tri& t : mesh.triangles)
    for (int e = 0; e < 3; ++e) neighbours[t[e]].push_back(t[(e + 1) % 3]);
  for (int round = 0; round < 4; ++round) {
    std::vector<std::array<float, kJointCount>> next(n);
    for (size_t v = 0; v < n; ++v) {
      next[v] = w[v];
      if (neighbours[v].empty()) continue;
      for (float& x : next[v]) x *= 0.5f;
      const float share = 0.5f / static_cast<float>(neighbours[v].size());
      for (uint32_t u : neighbours[v])
        for (int j = 0; j < kJointCount; ++j) next[v][j] += share * w[u][j];
    }
    w.swap(next);
  }
  body.mesh.joints.assign(n, {0, 0, 0, 0});
  body.mesh.weights.assign(n, Vec4f::Zero());
  for (size_t v = 0; v < n; ++v) {
    std::array<int, kJointCount> order;
    std::iota(order.begin(), order.end(), 0);
    std::partial_sort(order.begin(), order.begin() + 4, order.end(), [&](int a, int b) { return w[v][a] > w[v][b]; });
    float sum = 0;
    for (int k = 0; k < 4; ++k) sum += w[v][order[k]];
    for (int k = 0; k < 4; ++k) {
      body.mesh.joints[v][k] = static_cast<uint16_t>(order[k]);
      body.mesh.weights[v][k] = w[v][order[k]] / sum;
    }
  }
  body.skeleton = std::move(sk);
}

Scene body_scene(const Body& body) {
  Scene scene;
  scene.meshes.push_back(body.mesh);
  const bool rigged = !body.skeleton.empty() && !body.mesh.joints.empty();
  scene.nodes.resize(1 + (rigged ? body.skeleton.joints.size() : 0));
  scene.nodes[0].name = "body";
  scene.nodes[0].mesh = 0;
  if (!rigged) return scene;
  // Joint nodes follow the body node: joint j is node 1 + j.
  scene.nodes[0].skin = 0;
  Skin skin;
  skin.name = "body_skeleton";
  skin.skeleton = 1;
  for (size_t j = 0; j < body.skeleton.joints.size(); ++j) {
    const Joint& joint = body.skeleton.joints[j];
    Node& jn = scene.nodes[1 + j];
    jn.name = joint.name;
    jn.parent = joint.parent < 0 ? -1 : 1 + joint.parent;
    jn.translation = joint.parent < 0 ? joint.position
                                      : Vec3f(joint.position - body.skeleton.joints[static_cast<size_t>(joint.parent)].position);
    skin.joints.push_back(1 + static_cast<int>(j));
    Mat4f ibm = Mat4f::Identity();
    ibm.block<3, 1>(0, 3) = -joint.position;
    skin.inverse_bind_matrices.push_back(ibm);
  }
  scene.skins.push_back(std::move(skin));
  return scene;
}

}  // namespace drape
