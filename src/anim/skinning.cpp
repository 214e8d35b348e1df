// Skinning a body's mesh to a pose. Linear blend skinning (a weighted sum of the joints' rigid
// transforms: fast, but a twisted or sharply bent joint collapses the skin, the "candy wrapper") and
// dual quaternion skinning (Kavan et al. 2008: the weighted sum of unit dual quaternions, normalised,
// is a rigid transform, so a twisted forearm keeps its volume). A joint j moves a bind-pose point x
// to q_j (x - b_j) + p_j: rotation q_j about its bind position b_j, carried to its posed position p_j.
#include <omp.h>

#include <cmath>
#include <vector>

#include "anim/motion_internal.hpp"
#include "drape/motion.hpp"

namespace drape {
namespace {

struct JointTransform {
  Eigen::Matrix3f r;
  Vec3f t;            // x' = r x + t
  Quatf real, dual;   // the same as a unit dual quaternion
};

std::vector<JointTransform> joint_transforms(const Body& body, const PoseView& pose) {
  const size_t n = body.skeleton.joints.size();
  std::vector<JointTransform> out(n);
  for (size_t j = 0; j < n; ++j) {
    const Quatf q = pose.rotation[j].normalized();
    JointTransform& jt = out[j];
    jt.r = q.toRotationMatrix();
    jt.t = pose.position[j] - q * body.skeleton.joints[j].position;
    jt.real = q;
    const Quatf tq(0.0f, jt.t.x(), jt.t.y(), jt.t.z());
    const Quatf d = tq * q;
    jt.dual = Quatf(0.5f * d.w(), 0.5f * d.x(), 0.5f * d.y(), 0.5f * d.z());
  }
  return out;
}

Vec3f skin_one(const Body& body, const std::vector<JointTransform>& jt, Skinning method, size_t v) {
  const Vec3f& x = body.mesh.positions[v];
  const auto& joints = body.mesh.joints[v];
  const Vec4f& weights = body.mesh.weights[v];
  const size_t n = jt.size();
  if (method == Skinning::Linear) {
    Vec3f sum = Vec3f::Zero();
    float total = 0;
    for (int k = 0; k < 4; ++k) {
      const float w = weights[k];
      if (w <= 0 || joints[static_cast<size_t>(k)] >= n) continue;
      const JointTransform& t = jt[joints[static_cast<size_t>(k)]];
      sum += w * (t.r * x + t.t);
      total += w;
    }
    return total > 0 ? Vec3f(sum / total) : x;
  }
  Eigen::Vector4f real = Eigen::Vector4f::Zero(), dual = Eigen::Vector4f::Zero();
  Eigen::Vector4f pivot = Eigen::Vector4f::Zero();
  bool any = false;
  for (int k = 0; k < 4; ++k) {
    const float w = weights[k];
    if (w <= 0 || joints[static_cast<size_t>(k)] >= n) continue;
    const JointTransform& t = jt[joints[static_cast<size_t>(k)]];
    const Eigen::Vector4f r = t.real.coeffs(), d = t.dual.coeffs();
    if (!any) pivot = r, any = true;
    // Shortest path: every influence in the first one's hemisphere.
    const float s = r.dot(pivot) < 0 ? -w : w;
    real += s * r;
    dual += s * d;
  }
  const float len = real.norm();
  if (!any || !(len > 0)) return x;
  real /= len;
  dual /= len;
  const Quatf qr(real[3], real[0], real[1], real[2]);
  const Quatf qd(dual[3], dual[0], dual[1], dual[2]);
  // Translation of the normalised dual quaternion: 2 (d r*); the dual part's component along r
  // (non-rigid after blending) is removed by using only the vector part.
  const Quatf tq = qd * qr.conjugate();
  const Vec3f t = 2.0f * Vec3f(tq.x(), tq.y(), tq.z());
  return qr * x + t;
}

}  // namespace

std::string_view to_string(Skinning skinning) { return skinning == Skinning::Linear ? "linear" : "dual_quaternion"; }

void bind_pose(const Body& body, std::vector<Quatf>& rotation, std::vector<Vec3f>& position) {
  const size_t n = body.skeleton.joints.size();
  rotation.assign(n, Quatf::Identity());
  position.resize(n);
  for (size_t j = 0; j < n; ++j) position[j] = body.skeleton.joints[j].position;
}

void skin_mesh(const Body& body, const PoseView& pose, Skinning method, std::span<Vec3f> out) {
  const size_t nv = body.mesh.vertex_count();
  const bool rigged = body.mesh.joints.size() == nv && body.mesh.weights.size() == nv &&
                      pose.rotation.size() == body.skeleton.joints.size() && pose.position.size() == pose.rotation.size();
  if (!rigged) {
    for (size_t v = 0; v < nv && v < out.size(); ++v) out[v] = body.mesh.positions[v];
    return;
  }
  const std::vector<JointTransform> jt = joint_transforms(body, pose);
  const long n = static_cast<long>(std::min(nv, out.size()));
#pragma omp parallel for schedule(static)
  for (long v = 0; v < n; ++v) out[static_cast<size_t>(v)] = skin_one(body, jt, method, static_cast<size_t>(v));
}

void motion_detail::skin_vertices(const Body& body, const PoseView& pose, Skinning method,
                                  std::span<const uint32_t> vertices, std::span<Vec3f> out) {
  const std::vector<JointTransform> jt = joint_transforms(body, pose);
  for (size_t i = 0; i < vertices.size(); ++i) out[i] = skin_one(body, jt, method, vertices[i]);
}

void motion_detail::skinning_linear_parts(const Body& body, const PoseView& pose, Skinning method,
                                          std::span<const uint32_t> vertices, std::span<Eigen::Matrix3f> out) {
  const std::vector<JointTransform> jt = joint_transforms(body, pose);
  const size_t nv = body.mesh.vertex_count();
  const bool rigged = body.mesh.joints.size() == nv && body.mesh.weights.size() == nv && jt.size() == body.skeleton.joints.size();
  for (size_t i = 0; i < vertices.size(); ++i) {
    out[i].setIdentity();
    if (!rigged) continue;
    const auto& joints = body.mesh.joints[vertices[i]];
    const Vec4f& weights = body.mesh.weights[vertices[i]];
    Eigen::Matrix3f sum = Eigen::Matrix3f::Zero();
    Eigen::Vector4f real = Eigen::Vector4f::Zero(), pivot = Eigen::Vector4f::Zero();
    float total = 0;
    bool any = false;
    for (int k = 0; k < 4; ++k) {
      const float w = weights[k];
      if (w <= 0 || joints[static_cast<size_t>(k)] >= jt.size()) continue;
      const JointTransform& t = jt[joints[static_cast<size_t>(k)]];
      sum += w * t.r;
      total += w;
      const Eigen::Vector4f r = t.real.coeffs();
      if (!any) pivot = r, any = true;
      real += (r.dot(pivot) < 0 ? -w : w) * r;
    }
    if (method == Skinning::Linear) {
      if (total > 0) out[i] = sum / total;
    } else if (any && real.norm() > 0) {
      real.normalize();
      out[i] = Quatf(real[3], real[0], real[1], real[2]).toRotationMatrix();
    }
  }
}

std::vector<uint32_t> motion_detail::foot_vertices(const Body& body, int foot_joint) {
  const size_t nj = body.skeleton.joints.size();
  std::vector<char> in_foot(nj, 0);
  if (foot_joint < 0) return {};
  // The foot joint and its descendants (parents may come after children in a glTF skin).
  in_foot[static_cast<size_t>(foot_joint)] = 1;
  for (bool changed = true; changed;) {
    changed = false;
    for (size_t j = 0; j < nj; ++j) {
      const int p = body.skeleton.joints[j].parent;
      if (!in_foot[j] && p >= 0 && in_foot[static_cast<size_t>(p)]) in_foot[j] = 1, changed = true;
    }
  }
  std::vector<uint32_t> out;
  for (size_t v = 0; v < body.mesh.vertex_count(); ++v) {
    float w = 0;
    for (int k = 0; k < 4; ++k)
      if (body.mesh.joints[v][static_cast<size_t>(k)] < nj && in_foot[body.mesh.joints[v][static_cast<size_t>(k)]])
        w += body.mesh.weights[v][k];
    if (w >= 0.5f) out.push_back(static_cast<uint32_t>(v));
  }
  return out;
}

}  // namespace drape
