// FBX motions (Mixamo's format), read through Assimp's FBX importer (libassimp-dev).
//
// Transform chains. An FBX node's local transform is the FBX SDK's chain
//   T * Roff * Rp * Rpre * R * Rpost^-1 * Rp^-1 * Soff * Sp * S * Sp^-1
// (pre-rotation: Maya's joint orient, which Mixamo's rigs carry). Where a node has more than T, R
// and S, Assimp makes one "<name>_$AssimpFbx$_<part>" helper node per part above the node and gives
// the animated parts their own channels. drape keeps those helpers (AI_CONFIG_IMPORT_FBX_PRESERVE_PIVOTS
// on, Assimp's default) and folds each chain back into its joint: the joint's local transform is the
// product of its helpers' transforms and its own, each taken from that node's channel where it has
// one. Turning the option off is not better: Assimp 5.2 then bakes the chain into the node but still
// names the channels of a node with pivots after helpers it no longer makes, and they would be lost.
// One case is Assimp's own: a node whose only extras are pre- and post-rotations gets the helpers
// *and* a channel on the node itself that already holds its whole local transform; that channel
// alone is then the joint's animated transform. Assimp bakes the post-rotation into those keys
// uninverted (R * Rpost, where its helper node rightly holds Rpost^-1), so the helper's rotation is
// applied twice more to turn it back. Geometric transforms (GeometricTranslation, ... and their
// inverses below the node) move only the node's mesh, never its children, and are left out.
//
// Joints: the nodes that deform a mesh (bones) or that the animation moves, and the nodes between
// them; nodes above the skeleton (an armature) are folded into the root. Every frame is evaluated as
// world transforms and written back as local rotations and translations, so a scale anywhere (an
// armature's 0.01 or 100) ends up in the lengths, and the lengths are converted to metres with the
// file's UnitScaleFactor (centimetres per file unit; Mixamo's files are in centimetres). Assimp does
// not apply the file's up axis: UpAxis and UpAxisSign say it (+Y or +Z), unless MotionOptions does.
//
// Time: Assimp gives keys in ticks of the file's frame rate, and adds keys between two Euler angles
// 180 degrees or more apart. The frames are sampled at the most common spacing of the keys (the
// smallest would mistake those added keys for the frame rate), at most 1/30 s and at least 1/120 s
// apart (to within 0.1 %), as the glTF reader does.
#include <assimp/config.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <fmt/format.h>

#include <algorithm>
#include <assimp/Importer.hpp>
#include <cmath>
#include <fstream>
#include <limits>
#include <map>
#include <new>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "anim/motion_internal.hpp"
#include "drape/error.hpp"
#include "drape/motion.hpp"

// Debian builds libassimp with its assertions on, and their handler prints a line and aborts the
// process (setAiAssertHandler, which would replace it, is not exported). The library calls the
// handler through this exported function, by way of its PLT, so the definition here takes the
// library's place: it throws instead, the importer turns the throw into its error string, and a
// malformed file that trips one of Assimp's assertions is an InputError like any other.
namespace Assimp {
ASSIMP_API void aiAssertViolation(const char* failed_expression, const char* file, int line);
void aiAssertViolation(const char* failed_expression, const char* file, int line) {
  throw std::runtime_error(fmt::format("its check '{}' failed ({}:{})", failed_expression, file, line));
}
}  // namespace Assimp

namespace drape {
namespace {

// Assimp holds the whole file in memory while it reads (fbx_limits.cpp bounds the rest).
constexpr size_t kMaxFbxBytes = size_t{256} << 20;
// Joint-frames a motion may hold (about 600 MB of rotations and translations).
constexpr size_t kMaxSamples = 20'000'000;
constexpr size_t kMaxFrames = 100000;
constexpr std::string_view kHelperTag = "_$AssimpFbx$_";

using Mat4d = Eigen::Matrix4d;

struct Helper {
  std::string_view joint;  // the node the helper belongs to
  std::string_view part;   // "Translation", "PreRotation", "GeometricScalingInverse", ...
};

bool helper_of(std::string_view name, Helper& h) {
  const size_t at = name.find(kHelperTag);
  if (at == std::string_view::npos) return false;
  h = {name.substr(0, at), name.substr(at + kHelperTag.size())};
  return true;
}

// Assimp's message, one printable line of at most 300 characters.
std::string assimp_reason(std::string_view what) {
  std::string out;
  for (char c : what.substr(0, 300)) out += (c >= 32 && c < 127) ? c : ' ';
  while (!out.empty() && out.back() == ' ') out.pop_back();
  if (what.size() > 300) out += "...";
  return out.empty() ? "no reason given" : out;
}

std::string name_of(const aiNode& node) {
  return std::string(node.mName.C_Str(), node.mName.length);
}

Mat4d to_eigen(const aiMatrix4x4& m) {
  Mat4d e;
  e << m.a1, m.a2, m.a3, m.a4, m.b1, m.b2, m.b3, m.b4, m.c1, m.c2, m.c3, m.c4, m.d1, m.d2, m.d3, m.d4;
  return e;
}

// Index of the key at or before `t` in keys sorted by time (0 before the first).
template <typename Key>
size_t key_before(const Key* keys, size_t n, double t) {
  const Key* it = std::upper_bound(keys, keys + n, t, [](double v, const Key& k) { return v < k.mTime; });
  return it == keys ? 0 : static_cast<size_t>(it - keys) - 1;
}

// A channel's transform at tick t: keys interpolated linearly (slerp for rotations), held outside
// their range; a part without keys keeps the node's rest value.
Mat4d channel_at(const aiNodeAnim& c, const aiMatrix4x4& rest, double t) {
  aiVector3D rest_s, rest_p;
  aiQuaternion rest_q;
  rest.Decompose(rest_s, rest_q, rest_p);
  Eigen::Vector3d p(rest_p.x, rest_p.y, rest_p.z), s(rest_s.x, rest_s.y, rest_s.z);
  Eigen::Quaterniond q(rest_q.w, rest_q.x, rest_q.y, rest_q.z);
  auto lerp = [&](const aiVectorKey* keys, size_t n, Eigen::Vector3d& out) {
    if (n == 0) return;
    const size_t k = key_before(keys, n, t);
    const aiVector3D& a = keys[k].mValue;
    out = Eigen::Vector3d(a.x, a.y, a.z);
    if (k + 1 < n && t > keys[k].mTime && keys[k + 1].mTime > keys[k].mTime) {
      const double w = std::min(1.0, (t - keys[k].mTime) / (keys[k + 1].mTime - keys[k].mTime));
      const aiVector3D& b = keys[k + 1].mValue;
      out = (1 - w) * out + w * Eigen::Vector3d(b.x, b.y, b.z);
    }
  };
  lerp(c.mPositionKeys, c.mNumPositionKeys, p);
  lerp(c.mScalingKeys, c.mNumScalingKeys, s);
  if (c.mNumRotationKeys > 0) {
    const size_t k = key_before(c.mRotationKeys, c.mNumRotationKeys, t);
    const aiQuaternion& a = c.mRotationKeys[k].mValue;
    q = Eigen::Quaterniond(a.w, a.x, a.y, a.z).normalized();
    if (k + 1 < c.mNumRotationKeys && t > c.mRotationKeys[k].mTime &&
        c.mRotationKeys[k + 1].mTime > c.mRotationKeys[k].mTime) {
      const double w = std::min(
          1.0, (t - c.mRotationKeys[k].mTime) / (c.mRotationKeys[k + 1].mTime - c.mRotationKeys[k].mTime));
      const aiQuaternion& b = c.mRotationKeys[k + 1].mValue;
      q = q.slerp(w, Eigen::Quaterniond(b.w, b.x, b.y, b.z).normalized()).normalized();
    }
  }
  Mat4d m = Mat4d::Identity();
  m.block<3, 3>(0, 0) = q.toRotationMatrix() * s.asDiagonal();
  m.block<3, 1>(0, 3) = p;
  return m;
}

// The orientation of a frame whose axes may be scaled: its x axis, its y axis made square to it,
// and their cross product (exact for a rotation times a scale along its own axes).
// Not finite where the frame has no x axis or no y axis apart from it.
Eigen::Matrix3d orientation_of(const Eigen::Matrix3d& a) {
  const Eigen::Vector3d x = a.col(0) / a.col(0).norm();
  const Eigen::Vector3d y_in_plane = a.col(1) - x.dot(a.col(1)) * x;
  const double y_length = y_in_plane.norm();
  const Eigen::Vector3d y = y_in_plane / (y_length > 1e-12 * a.col(1).norm() ? y_length : 0.0);
  Eigen::Matrix3d r;
  r << x, y, x.cross(y);
  return r;
}

// One node of the file that is not a helper: its helper chain (top first, geometric parts left
// out), its channel and its parent among such nodes.
struct FbxNode {
  const aiNode* node = nullptr;
  std::string name;
  int parent = -1;
  std::vector<const aiNode*> chain;
  const aiNodeAnim* channel = nullptr;
  std::vector<const aiNodeAnim*> chain_channels;  // per chain node, or nullptr
  const aiNode* post_rotation = nullptr;          // the chain's PostRotation helper (Rpost^-1)
  bool animated = false;
};

class FbxReader {
 public:
  FbxReader(const aiScene& scene, std::string source) : scene_(scene), source_(std::move(source)) {}

  Motion read(const MotionOptions& options) {
    if (scene_.mNumAnimations == 0 || !scene_.mAnimations[0])
      throw InputError(source_,
                       "has no animation (an FBX motion has an animation stack that moves a skeleton)");
    anim_ = scene_.mAnimations[0];
    tick_ = anim_->mTicksPerSecond;
    if (!(std::isfinite(tick_) && tick_ > 0 && tick_ <= 1e6))
      throw InputError(
          source_,
          fmt::format("its frame rate ({} frames per second, FBX TimeMode and CustomFrameRate) is not usable",
                      tick_));
    for (unsigned i = 0; i < anim_->mNumChannels; ++i) {
      const aiNodeAnim* c = anim_->mChannels[i];
      if (c) channels_.emplace(std::string(c->mNodeName.C_Str(), c->mNodeName.length), c);
    }
    collect(*scene_.mRootNode, -1);
    select_joints();
    Motion m = sample();
    convert_units(m);
    motion_detail::convert_axes(m, resolve_up(options));
    return m;
  }

 private:
  // Every node that is not a helper, parents first, with its helper chain.
  void collect(const aiNode& node, int parent) {
    Helper h;
    if (helper_of(node.mName.C_Str(), h)) {
      for (unsigned i = 0; i < node.mNumChildren; ++i)
        if (node.mChildren[i]) collect(*node.mChildren[i], parent);
      return;
    }
    FbxNode n;
    n.node = &node;
    n.name = name_of(node);
    n.parent = parent;
    for (const aiNode* up = node.mParent; up && helper_of(up->mName.C_Str(), h) && h.joint == n.name;
         up = up->mParent) {
      if (!h.part.starts_with("Geometric")) n.chain.push_back(up);
      if (h.part == "PostRotation") n.post_rotation = up;
    }
    std::reverse(n.chain.begin(), n.chain.end());
    const auto own = channels_.find(n.name);
    n.channel = own == channels_.end() ? nullptr : own->second;
    n.animated = n.channel != nullptr;
    for (const aiNode* c : n.chain) {
      const auto it = channels_.find(name_of(*c));
      n.chain_channels.push_back(it == channels_.end() ? nullptr : it->second);
      n.animated |= n.chain_channels.back() != nullptr;
    }
    nodes_.push_back(std::move(n));
    const int self = static_cast<int>(nodes_.size()) - 1;
    for (unsigned i = 0; i < node.mNumChildren; ++i)
      if (node.mChildren[i]) collect(*node.mChildren[i], self);
  }

  // Bones and animated nodes, and the nodes between two of them.
  void select_joints() {
    std::map<std::string, bool> bones;
    for (unsigned m = 0; m < scene_.mNumMeshes; ++m)
      for (unsigned b = 0; scene_.mMeshes[m] && b < scene_.mMeshes[m]->mNumBones; ++b)
        if (scene_.mMeshes[m]->mBones[b]) bones[scene_.mMeshes[m]->mBones[b]->mName.C_Str()] = true;
    selected_.assign(nodes_.size(), 0);
    bool any_animated = false;
    for (size_t i = 0; i < nodes_.size(); ++i) {
      selected_[i] = nodes_[i].animated || bones.count(nodes_[i].name);
      any_animated |= nodes_[i].animated;
    }
    if (!any_animated)
      throw InputError(source_, fmt::format("its animation '{}' moves no node of the file",
                                            motion_detail::printable(anim_->mName.C_Str())));
    for (size_t i = 0; i < nodes_.size(); ++i) {
      if (!selected_[i]) continue;
      std::vector<int> path;
      int p = nodes_[i].parent;
      while (p >= 0 && !selected_[static_cast<size_t>(p)])
        path.push_back(p), p = nodes_[static_cast<size_t>(p)].parent;
      if (p >= 0)
        for (int q : path) selected_[static_cast<size_t>(q)] = 1;
    }
    for (size_t i = 0; i < nodes_.size(); ++i)
      if (selected_[i]) {
        joint_of_[i] = static_cast<int>(joints_.size());
        joints_.push_back(i);
      }
    size_t linked = 0;
    for (size_t i : joints_)
      linked += nodes_[i].parent >= 0 && selected_[static_cast<size_t>(nodes_[i].parent)];
    if (linked == 0) {
      std::string moved;
      for (size_t k = 0; k < joints_.size() && k < 4; ++k)
        moved += (k ? ", " : "") + motion_detail::printable(nodes_[joints_[k]].name);
      throw InputError(
          source_,
          fmt::format("has no skeleton: its animation moves {} (no node with a moving or deforming parent)",
                      moved));
    }
  }

  // A node's local transform at tick t (none: its rest transform), its helper chain folded in.
  Mat4d local(const FbxNode& n, std::optional<double> t) const {
    if (t && n.channel) {
      Mat4d m = channel_at(*n.channel, n.node->mTransformation, *t);
      if (n.post_rotation) {
        const Mat4d undo = to_eigen(n.post_rotation->mTransformation);
        m = m * undo * undo;
      }
      return m;
    }
    Mat4d m = Mat4d::Identity();
    for (size_t k = 0; k < n.chain.size(); ++k)
      m = m * (t && n.chain_channels[k] ? channel_at(*n.chain_channels[k], n.chain[k]->mTransformation, *t)
                                        : to_eigen(n.chain[k]->mTransformation));
    return m * to_eigen(n.node->mTransformation);
  }

  // The world transform of a node that does not move (above the skeleton).
  Mat4d static_world(int i) const {
    Mat4d m = Mat4d::Identity();
    for (; i >= 0; i = nodes_[static_cast<size_t>(i)].parent)
      m = local(nodes_[static_cast<size_t>(i)], std::nullopt) * m;
    return m;
  }

  Motion sample() {
    // Key times, and the most common spacing between two keys of a channel.
    double first = std::numeric_limits<double>::infinity(), last = -first;
    std::map<long long, std::pair<size_t, double>> spacings;  // by microseconds: count, sum in seconds
    auto keys = [&](const aiNodeAnim* c) {
      if (!c) return;
      auto add = [&](const auto* k, unsigned n, const char* what) {
        for (unsigned i = 0; i < n; ++i) {
          if (!std::isfinite(k[i].mTime) || (i > 0 && k[i].mTime < k[i - 1].mTime))
            throw InputError(source_, fmt::format("the {} keys of '{}' are not in time order", what,
                                                  motion_detail::printable(c->mNodeName.C_Str())));
          first = std::min(first, k[i].mTime), last = std::max(last, k[i].mTime);
          if (i > 0 && k[i].mTime > k[i - 1].mTime) {
            const double dt = (k[i].mTime - k[i - 1].mTime) / tick_;
            auto& [count, sum] = spacings[std::llround(dt * 1e6)];
            ++count, sum += dt;
          }
        }
      };
      add(c->mPositionKeys, c->mNumPositionKeys, "position");
      add(c->mRotationKeys, c->mNumRotationKeys, "rotation");
      add(c->mScalingKeys, c->mNumScalingKeys, "scaling");
    };
    for (size_t i : joints_) {
      keys(nodes_[i].channel);
      for (const aiNodeAnim* c : nodes_[i].chain_channels) keys(c);
    }
    if (!(first <= last)) first = last = 0;
    double step = 1.0 / 30.0;
    size_t most = 0;
    for (const auto& [us, bucket] : spacings)
      if (bucket.first > most)
        most = bucket.first, step = std::min(1.0 / 30.0, bucket.second / static_cast<double>(bucket.first));
    // 1/120 s to within 0.1 %: 120 Hz captures are written 0.008333 s apart.
    if (step < 0.999 / 120.0) step = 1.0 / 120.0;

    Motion m;
    m.source = source_;
    m.format = "fbx";
    m.frame_time = step;
    const double duration = (last - first) / tick_;
    if (duration / step + 1 > static_cast<double>(kMaxFrames))
      throw InputError(source_, fmt::format("an animation of {:.1f} s is too long (at most {} frames)",
                                            duration, kMaxFrames));
    m.frame_count = static_cast<size_t>(std::floor(duration / step + 0.5)) + 1;
    const size_t n = joints_.size();
    if (m.frame_count * n > kMaxSamples)
      throw InputError(source_, fmt::format("{} frames of {} joints are too many (at most {} joint-frames)",
                                            m.frame_count, n, kMaxSamples));
    for (size_t i : joints_) {
      m.names.push_back(nodes_[i].name.empty() ? fmt::format("node{}", i) : nodes_[i].name);
      const int p = nodes_[i].parent;
      m.parent.push_back(p >= 0 && selected_[static_cast<size_t>(p)] ? joint_of_.at(static_cast<size_t>(p))
                                                                     : -1);
    }
    m.rest_offset.resize(n);
    m.rest_rotation.resize(n);
    m.rotation.resize(m.frame_count * n);
    m.translation.resize(m.frame_count * n);
    // Above the skeleton nothing moves.
    std::vector<Mat4d> above(n);
    for (size_t j = 0; j < n; ++j)
      if (m.parent[j] < 0) above[j] = static_world(nodes_[joints_[j]].parent);
    std::vector<Mat4d> world(n);
    std::vector<Eigen::Matrix3d> orientation(n);
    for (long f = -1; f < static_cast<long>(m.frame_count); ++f) {
      const std::optional<double> t =
          f < 0 ? std::nullopt : std::optional<double>(first + static_cast<double>(f) * step * tick_);
      Quatf* rotation = f < 0 ? m.rest_rotation.data() : m.rotation.data() + static_cast<size_t>(f) * n;
      Vec3f* translation = f < 0 ? m.rest_offset.data() : m.translation.data() + static_cast<size_t>(f) * n;
      for (size_t j = 0; j < n; ++j) {
        const int p = m.parent[j];
        world[j] = (p < 0 ? above[j] : world[static_cast<size_t>(p)]) * local(nodes_[joints_[j]], t);
        orientation[j] = orientation_of(world[j].block<3, 3>(0, 0));
        if (!world[j].allFinite() || !orientation[j].allFinite())
          throw InputError(source_,
                           fmt::format("joint '{}' has a transform that is not finite or scales to nothing{}",
                                       motion_detail::printable(m.names[j]),
                                       f < 0 ? " in its rest pose" : fmt::format(" in frame {}", f)));
        Eigen::Matrix3d r = orientation[j];
        Eigen::Vector3d d = world[j].block<3, 1>(0, 3);
        if (p >= 0) {
          const Eigen::Matrix3d& g = orientation[static_cast<size_t>(p)];
          r = g.transpose() * r;
          d = g.transpose() * (d - world[static_cast<size_t>(p)].block<3, 1>(0, 3));
        }
        rotation[j] = Quatf(Eigen::Quaterniond(r).normalized().cast<float>());
        translation[j] = d.cast<float>();
      }
    }
    return m;
  }

  // FBX lengths are UnitScaleFactor centimetres.
  void convert_units(Motion& m) const {
    float unit_cm = 1;
    if (scene_.mMetaData && scene_.mMetaData->Get("UnitScaleFactor", unit_cm) &&
        !(std::isfinite(unit_cm) && unit_cm > 0))
      throw InputError(source_,
                       fmt::format("its UnitScaleFactor {} is not a length (centimetres per unit)", unit_cm));
    const float to_m = unit_cm * 0.01f;
    for (Vec3f& o : m.rest_offset) o *= to_m;
    for (Vec3f& t : m.translation) t *= to_m;
  }

  // The up axis: MotionOptions', else the file's (UpAxis 1 = Y, 2 = Z, with UpAxisSign).
  MotionOptions resolve_up(const MotionOptions& options) const {
    MotionOptions o = options;
    int32_t axis = 1, sign = 1;
    if (o.up != MotionUp::Auto || !scene_.mMetaData || !scene_.mMetaData->Get("UpAxis", axis)) return o;
    scene_.mMetaData->Get("UpAxisSign", sign);
    if (axis == 1 && sign == 1)
      o.up = MotionUp::Y;
    else if (axis == 2 && sign == 1)
      o.up = MotionUp::Z;
    else
      throw InputError(source_,
                       fmt::format("its up axis is {}{} (UpAxis {}, UpAxisSign {}); drape reads +Y and +Z up",
                                   sign < 0 ? '-' : '+',
                                   axis == 0   ? 'X'
                                   : axis == 1 ? 'Y'
                                   : axis == 2 ? 'Z'
                                               : '?',
                                   axis, sign));
    return o;
  }

  const aiScene& scene_;
  std::string source_;
  const aiAnimation* anim_ = nullptr;
  double tick_ = 0;  // ticks per second
  std::map<std::string, const aiNodeAnim*> channels_;
  std::vector<FbxNode> nodes_;
  std::vector<char> selected_;
  std::vector<size_t> joints_;      // nodes_ indices of the joints, parents first
  std::map<size_t, int> joint_of_;  // nodes_ index -> joint
};

}  // namespace

Motion motion_detail::parse_fbx(std::span<const unsigned char> bytes, const std::string& source,
                                const MotionOptions& options) {
  if (bytes.empty()) throw InputError(source, "empty file (not FBX)");
  if (bytes.size() > kMaxFbxBytes)
    throw InputError(source, fmt::format("an FBX file of {} MiB is larger than drape reads ({} MiB)",
                                         bytes.size() >> 20, kMaxFbxBytes >> 20));
  check_fbx_limits(bytes, source);
  Assimp::Importer importer;
  // Only the node tree, the skins' bones and the animation are needed.
  importer.SetPropertyBool(AI_CONFIG_IMPORT_FBX_PRESERVE_PIVOTS, true);
  importer.SetPropertyBool(AI_CONFIG_IMPORT_FBX_READ_ANIMATIONS, true);
  importer.SetPropertyBool(AI_CONFIG_IMPORT_FBX_READ_WEIGHTS, true);
  importer.SetPropertyBool(AI_CONFIG_IMPORT_FBX_READ_MATERIALS, false);
  importer.SetPropertyBool(AI_CONFIG_IMPORT_FBX_READ_TEXTURES, false);
  importer.SetPropertyBool(AI_CONFIG_IMPORT_FBX_READ_CAMERAS, false);
  importer.SetPropertyBool(AI_CONFIG_IMPORT_FBX_READ_LIGHTS, false);
  importer.SetPropertyBool(AI_CONFIG_IMPORT_FBX_READ_ALL_GEOMETRY_LAYERS, false);
  importer.SetPropertyBool(AI_CONFIG_FBX_CONVERT_TO_M, false);  // drape converts the units itself
  const aiScene* scene = nullptr;
  try {
    // The "fbx" hint makes Assimp use its FBX importer and no other; the validation refuses a scene
    // whose references (bones, channels) do not hold together before it is read.
    scene = importer.ReadFileFromMemory(bytes.data(), bytes.size(), aiProcess_ValidateDataStructure, "fbx");
  } catch (const std::bad_alloc&) {
    throw;
  } catch (const std::exception& e) {
    throw InputError(source, fmt::format("not a readable FBX file (Assimp: {})", assimp_reason(e.what())));
  }
  if (!scene || !scene->mRootNode)
    throw InputError(source, fmt::format("not a readable FBX file (Assimp: {})",
                                         assimp_reason(importer.GetErrorString())));
  return FbxReader(*scene, source).read(options);
}

Motion motion_detail::read_fbx(const std::filesystem::path& path, const std::string& source,
                               const MotionOptions& options) {
  std::error_code ec;
  const uintmax_t size = std::filesystem::file_size(path, ec);
  if (ec) throw InputError(source, "cannot open the motion file");
  if (size > kMaxFbxBytes)
    throw InputError(source, fmt::format("an FBX file of {} MiB is larger than drape reads ({} MiB)",
                                         size >> 20, kMaxFbxBytes >> 20));
  std::ifstream in(path, std::ios::binary);
  std::vector<unsigned char> bytes(static_cast<size_t>(size));
  if (!in || !in.read(reinterpret_cast<char*>(bytes.data()), static_cast<std::streamsize>(bytes.size())))
    throw InputError(source, "cannot read the motion file");
  return parse_fbx(bytes, source, options);
}

}  // namespace drape
