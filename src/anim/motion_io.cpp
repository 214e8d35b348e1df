// Motion files by extension, the up-axis conversion, and motions from glTF animations. BVH is
// parsed in bvh.cpp, FBX (Mixamo's format) read through Assimp in fbx_motion.cpp.
#include <algorithm>
#include <cmath>
#include <fstream>
#include <map>
#include <set>
#include <sstream>

#include <fmt/format.h>

#include "anim/motion_internal.hpp"
#include "drape/error.hpp"
#include "drape/motion.hpp"

namespace drape {

int Motion::find(std::string_view name) const {
  for (size_t i = 0; i < names.size(); ++i)
    if (names[i] == name) return static_cast<int>(i);
  return -1;
}

void Motion::world_pose(long frame, std::vector<Vec3f>& position, std::vector<Quatf>& world) const {
  const size_t n = joint_count();
  position.resize(n);
  world.resize(n);
  for (size_t j = 0; j < n; ++j) {
    const Quatf q = frame < 0 ? rest_rotation[j] : rotation[static_cast<size_t>(frame) * n + j];
    const Vec3f t = frame < 0 ? rest_offset[j] : translation[static_cast<size_t>(frame) * n + j];
    if (parent[j] < 0) {
      position[j] = t;
      world[j] = q;
    } else {
      const size_t p = static_cast<size_t>(parent[j]);
      position[j] = position[p] + world[p] * t;
      world[j] = (world[p] * q).normalized();
    }
  }
}

namespace motion_detail {

std::string printable(std::string_view token) {
  std::string out;
  for (char c : token.substr(0, 64)) out += (c >= 32 && c < 127) ? c : '?';
  if (token.size() > 64) out += "...";
  return out;
}

void convert_axes(Motion& m, const MotionOptions& options) {
  UpAxis up = options.up == MotionUp::Z ? UpAxis::Z : UpAxis::Y;
  if (options.up == MotionUp::Auto) {
    // The hips-to-head direction in the rest pose, where the names are known.
    try {
      const JointMap map = find_joint_map(m.names, m.source);
      const int hips = map.joint[0];
      int top = map.joint[4] >= 0 ? map.joint[4] : map.joint[3] >= 0 ? map.joint[3] : map.joint[2];
      std::vector<Vec3f> p;
      std::vector<Quatf> r;
      m.world_pose(-1, p, r);
      const Vec3f d = p[static_cast<size_t>(top)] - p[static_cast<size_t>(hips)];
      if (std::abs(d.z()) > std::abs(d.y()) && d.z() > 0) up = UpAxis::Z;
    } catch (const InputError&) {
      // Unknown names: Y, BVH's usual axis (MotionUp::Z says otherwise).
    }
  }
  m.up = up;
  if (up == UpAxis::Y) return;
  const Quatf c(Eigen::AngleAxisf(static_cast<float>(-M_PI / 2), Vec3f::UnitX()));  // (x, y, z) -> (x, z, -y)
  const Quatf ci = c.conjugate();
  for (Vec3f& o : m.rest_offset) o = c * o;
  for (Quatf& q : m.rest_rotation) q = (c * q * ci).normalized();
  for (Vec3f& t : m.translation) t = c * t;
  for (Quatf& q : m.rotation) q = (c * q * ci).normalized();
}

}  // namespace motion_detail

namespace {

// Value of a sampler at time t: linear (slerp for rotations), step, or the value of a cubic spline's
// keys (the tangents ignored: motion capture is keyed densely).
void sample(const AnimationChannel& c, float t, size_t width, float* out) {
  const size_t keys = c.times.size();
  const size_t stride = c.interpolation == Interpolation::CubicSpline ? 3 * width : width;
  const size_t offset = c.interpolation == Interpolation::CubicSpline ? width : 0;
  auto value = [&](size_t k) { return c.values.data() + k * stride + offset; };
  if (keys == 0) return;
  size_t k = static_cast<size_t>(std::upper_bound(c.times.begin(), c.times.end(), t) - c.times.begin());
  if (k == 0 || k >= keys) {
    std::copy_n(value(k == 0 ? 0 : keys - 1), width, out);
    return;
  }
  const float t0 = c.times[k - 1], t1 = c.times[k];
  const float a = c.interpolation == Interpolation::Step || t1 <= t0 ? 0.0f : (t - t0) / (t1 - t0);
  if (width == 4) {
    const Quatf q0(value(k - 1)[3], value(k - 1)[0], value(k - 1)[1], value(k - 1)[2]);
    const Quatf q1(value(k)[3], value(k)[0], value(k)[1], value(k)[2]);
    const Quatf q = q0.slerp(a, q1).normalized();
    out[0] = q.x(), out[1] = q.y(), out[2] = q.z(), out[3] = q.w();
    return;
  }
  for (size_t i = 0; i < width; ++i) out[i] = (1 - a) * value(k - 1)[i] + a * value(k)[i];
}

}  // namespace

Motion motion_from_scene(const Scene& scene, const std::string& source, const MotionOptions& options) {
  if (scene.animations.empty()) throw InputError(source, "has no animation");
  const Animation& anim = scene.animations.front();
  // The joints: the first skin's, else every node the animation moves and their ancestors.
  std::set<int> nodes;
  if (!scene.skins.empty()) {
    nodes.insert(scene.skins.front().joints.begin(), scene.skins.front().joints.end());
  } else {
    for (const AnimationChannel& c : anim.channels)
      if (c.path != AnimationPath::Weights)
        for (int n = c.node; n >= 0; n = scene.nodes[static_cast<size_t>(n)].parent) nodes.insert(n);
  }
  if (nodes.empty()) throw InputError(source, fmt::format("animation 0 '{}' moves no joints", motion_detail::printable(anim.name)));
  // Parents before children: order by depth, then index.
  auto depth = [&](int n) {
    int d = 0;
    while ((n = scene.nodes[static_cast<size_t>(n)].parent) >= 0) ++d;
    return d;
  };
  std::vector<int> order(nodes.begin(), nodes.end());
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) { return depth(a) < depth(b); });
  std::map<int, int> joint_of;
  for (size_t i = 0; i < order.size(); ++i) joint_of[order[i]] = static_cast<int>(i);

  Motion m;
  m.source = source;
  m.format = "gltf";
  float end = 0, step = 1.0f / 30.0f;
  bool any = false;
  for (const AnimationChannel& c : anim.channels) {
    if (c.path == AnimationPath::Weights || !nodes.count(c.node) || c.times.empty()) continue;
    any = true;
    end = std::max(end, c.times.back());
    for (size_t k = 1; k < c.times.size(); ++k)
      if (c.times[k] > c.times[k - 1]) step = std::min(step, c.times[k] - c.times[k - 1]);
  }
  if (!any) throw InputError(source, "its animation moves no joint (only morph weights or other nodes)");
  step = std::max(step, 1.0f / 120.0f);
  m.frame_time = step;
  m.frame_count = static_cast<size_t>(std::floor(end / step + 0.5f)) + 1;
  if (m.frame_count > 100000) throw InputError(source, fmt::format("an animation of {} s is too long (at most 100000 frames)", end));
  const size_t n = order.size();
  for (int node : order) {
    const Node& nd = scene.nodes[static_cast<size_t>(node)];
    m.names.push_back(nd.name.empty() ? fmt::format("node{}", node) : nd.name);
    const auto it = joint_of.find(nd.parent);
    m.parent.push_back(it == joint_of.end() ? -1 : it->second);
    // A root's ancestors outside the skeleton (an armature node) are folded into it.
    Quatf r = nd.rotation.normalized();
    Vec3f t = nd.translation;
    if (it == joint_of.end() && nd.parent >= 0) {
      const Mat4f w = scene.world_transform(nd.parent);
      const Eigen::Matrix3f rot = w.block<3, 3>(0, 0);
      const Eigen::Matrix3f unscaled = rot.colwise().normalized();
      // Rotation only: the skeleton's lengths stay in its own units (an armature's 0.01 scale would
      // make the root's travel disagree with its legs).
      r = (Quatf(unscaled) * r).normalized();
      t = Quatf(unscaled) * t;
    }
    m.rest_rotation.push_back(r);
    m.rest_offset.push_back(t);
  }
  m.rotation.resize(m.frame_count * n);
  m.translation.resize(m.frame_count * n);
  for (size_t f = 0; f < m.frame_count; ++f)
    for (size_t j = 0; j < n; ++j) {
      m.rotation[f * n + j] = m.rest_rotation[j];
      m.translation[f * n + j] = m.rest_offset[j];
    }
  for (const AnimationChannel& c : anim.channels) {
    const auto it = joint_of.find(c.node);
    if (it == joint_of.end() || c.path == AnimationPath::Weights || c.path == AnimationPath::Scale) continue;
    const size_t j = static_cast<size_t>(it->second);
    const Node& nd = scene.nodes[static_cast<size_t>(c.node)];
    Quatf pre = Quatf::Identity();
    if (m.parent[j] < 0 && nd.parent >= 0) {
      const Mat4f w = scene.world_transform(nd.parent);
      const Eigen::Matrix3f rot = w.block<3, 3>(0, 0);
      pre = Quatf(Eigen::Matrix3f(rot.colwise().normalized()));
    }
    for (size_t f = 0; f < m.frame_count; ++f) {
      const float t = static_cast<float>(static_cast<double>(f) * m.frame_time);
      float v[4] = {0, 0, 0, 1};
      if (c.path == AnimationPath::Rotation) {
        sample(c, t, 4, v);
        const Quatf q = Quatf(v[3], v[0], v[1], v[2]).normalized();
        m.rotation[f * n + j] = (pre * q).normalized();
      } else {
        sample(c, t, 3, v);
        const Vec3f p(v[0], v[1], v[2]);
        m.translation[f * n + j] = pre * p;
      }
    }
  }
  motion_detail::convert_axes(m, options);
  return m;
}

Motion read_motion(const std::filesystem::path& path, const MotionOptions& options) {
  std::string ext = path.extension().string();
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  const std::string source = path.string();
  if (ext != ".bvh" && ext != ".glb" && ext != ".gltf" && ext != ".fbx")
    throw InputError(source, "not a motion file drape reads (.bvh, .fbx, .glb, .gltf)");
  if (!std::filesystem::is_regular_file(path)) throw InputError(source, "no such motion file");
  if (ext == ".fbx") return motion_detail::read_fbx(path, source, options);
  if (ext == ".bvh") {
    std::ifstream in(path, std::ios::binary);
    if (!in) throw InputError(source, "cannot open the motion file");
    std::stringstream ss;
    ss << in.rdbuf();
    return parse_bvh(ss.str(), source, options);
  }
  return motion_from_scene(read_scene(path), source, options);
}

}  // namespace drape
