// Retargeting a motion onto a body's rig.
//
// The body's bind pose and the motion's rest pose differ (an A-posed body, a T-posed capture, CMU's
// zero pose with the legs splayed 21 degrees, the old CMU files' arms-down rest), and their joints
// differ in number (five spine links against two). So local rotations are not copied. Per canonical
// joint c (found on both skeletons by their names), with the body's bind pose at rotation identity:
//
//   offset_c   the shortest rotation taking the body's bone direction (c to the next canonical joint
//              down its chain) to the motion's rest direction of the same bone;
//   W_c(t)   = D_c(t) offset_c, D_c(t) = G_c(t) G_c(rest)^-1 the motion joint's world rotation
//              since its rest pose: the body's bone turns to the motion's rest direction, then as the
//              motion's bone turns;
//   then a swing that puts the body's bone on the motion's bone direction at t (joint to the next
//   canonical joint's position), which the links skipped between them (spine, twist bones) moved.
//
// Joints with no canonical counterpart keep their bind pose relative to their parent. Root motion is
// the motion's hips travel scaled by the ratio of leg lengths (thigh + shin), so the motion's unit
// never matters; the whole clip is shifted vertically so that its lowest foot vertex touches y = 0.
// The motion's facing is measured from its rest pose (left thigh minus right thigh along +X).
#include <algorithm>
#include <array>
#include <cmath>

#include <fmt/format.h>

#include "anim/motion_internal.hpp"
#include "drape/error.hpp"
#include "drape/motion.hpp"

namespace drape {

PoseView BodyAnimation::pose(size_t frame) const {
  return {std::span<const Quatf>(rotation).subspan(frame * joint_count, joint_count),
          std::span<const Vec3f>(position).subspan(frame * joint_count, joint_count)};
}

namespace {

enum Canon : int {
  kHips, kSpine, kSpine1, kNeck, kHead, kLShoulder, kLArm, kLForeArm, kLHand, kRShoulder, kRArm, kRForeArm, kRHand,
  kLUpLeg, kLLeg, kLFoot, kLToe, kRUpLeg, kRLeg, kRFoot, kRToe, kCanonCount
};

// Canonical parent and the joints down each canonical joint's chain (its bone points at the first).
constexpr std::array<int, kCanonCount> kCanonParent{-1,        kHips,  kSpine, kSpine1, kNeck,  kSpine1, kLShoulder,
                                                    kLArm,     kLForeArm, kSpine1, kRShoulder, kRArm, kRForeArm, kHips,
                                                    kLUpLeg,   kLLeg,  kLFoot, kHips,   kRUpLeg, kRLeg,  kRFoot};
const std::array<std::vector<int>, kCanonCount>& chains() {
  static const std::array<std::vector<int>, kCanonCount> c{
      std::vector<int>{},  {kSpine1, kNeck, kHead}, {kNeck, kHead}, {kHead}, {},
      {kLArm},             {kLForeArm, kLHand},     {kLHand},       {},
      {kRArm},             {kRForeArm, kRHand},     {kRHand},       {},
      {kLLeg, kLFoot},     {kLFoot},                {kLToe},        {},
      {kRLeg, kRFoot},     {kRFoot},                {kRToe},        {}};
  return c;
}

Quatf swing(const Vec3f& from, const Vec3f& to) {
  return Quatf::FromTwoVectors(from.normalized(), to.normalized()).normalized();
}

// Local pose of a motion between two frames (slerp / lerp), then the world pose.
void motion_world(const Motion& m, double frame, const Quatf& facing, std::vector<Vec3f>& p, std::vector<Quatf>& g,
                  std::vector<Quatf>& local_r, std::vector<Vec3f>& local_t) {
  const size_t n = m.joint_count();
  const double last = static_cast<double>(m.frame_count - 1);
  frame = std::clamp(frame, 0.0, last);
  const size_t f0 = static_cast<size_t>(std::floor(frame));
  const size_t f1 = std::min(f0 + 1, m.frame_count - 1);
  const float a = static_cast<float>(frame - static_cast<double>(f0));
  local_r.resize(n), local_t.resize(n), p.resize(n), g.resize(n);
  for (size_t j = 0; j < n; ++j) {
    local_r[j] = m.rotation[f0 * n + j].slerp(a, m.rotation[f1 * n + j]).normalized();
    local_t[j] = (1 - a) * m.translation[f0 * n + j] + a * m.translation[f1 * n + j];
  }
  for (size_t j = 0; j < n; ++j) {
    if (m.parent[j] < 0) {
      p[j] = facing * local_t[j];
      g[j] = (facing * local_r[j]).normalized();
    } else {
      const size_t pj = static_cast<size_t>(m.parent[j]);
      p[j] = p[pj] + g[pj] * local_t[j];
      g[j] = (g[pj] * local_r[j]).normalized();
    }
  }
}

// Body joints in an order where parents come first.
std::vector<size_t> topological_order(const Skeleton& sk) {
  std::vector<size_t> order;
  std::vector<char> done(sk.joints.size(), 0);
  while (order.size() < sk.joints.size()) {
    const size_t before = order.size();
    for (size_t j = 0; j < sk.joints.size(); ++j) {
      const int p = sk.joints[j].parent;
      if (!done[j] && (p < 0 || done[static_cast<size_t>(p)])) order.push_back(j), done[j] = 1;
    }
    if (order.size() == before) throw InputError("body", "its skeleton's parents form a cycle");
  }
  return order;
}

float leg_length(const std::vector<Vec3f>& p, const JointMap& map, int upleg, int leg, int foot) {
  const int a = map.joint[static_cast<size_t>(upleg)], b = map.joint[static_cast<size_t>(leg)], c = map.joint[static_cast<size_t>(foot)];
  return (p[static_cast<size_t>(a)] - p[static_cast<size_t>(b)]).norm() + (p[static_cast<size_t>(b)] - p[static_cast<size_t>(c)]).norm();
}

// The motion's first frame is a calibration T-pose: upper arms level and sideways, thighs straight
// down, and the next frame a different pose (a jump of more than 10 degrees at some joint).
bool is_calibration_frame(const Motion& m, const JointMap& map, const Quatf& facing) {
  if (m.frame_count < 3) return false;
  std::vector<Vec3f> p0, p1;
  std::vector<Quatf> g0, g1, lr;
  std::vector<Vec3f> lt;
  motion_world(m, 0, facing, p0, g0, lr, lt);
  motion_world(m, 1, facing, p1, g1, lr, lt);
  auto dir = [&](int a, int b) {
    const int ja = map.joint[static_cast<size_t>(a)], jb = map.joint[static_cast<size_t>(b)];
    if (ja < 0 || jb < 0) return Vec3f(Vec3f::Zero());
    return Vec3f((p0[static_cast<size_t>(jb)] - p0[static_cast<size_t>(ja)]).normalized());
  };
  const Vec3f la = dir(kLArm, kLForeArm), ra = dir(kRArm, kRForeArm), ll = dir(kLUpLeg, kLLeg), rl = dir(kRUpLeg, kRLeg);
  const float cos20 = std::cos(20.0f * static_cast<float>(M_PI) / 180.0f);
  const bool tpose = la.x() > cos20 && ra.x() < -cos20 && ll.y() < -cos20 && rl.y() < -cos20;
  if (!tpose) return false;
  float jump = 0;
  for (size_t k = 0; k < kCanonCount; ++k) {
    const int j = map.joint[k];
    if (j >= 0) jump = std::max(jump, g0[static_cast<size_t>(j)].angularDistance(g1[static_cast<size_t>(j)]));
  }
  return jump > 10.0f * static_cast<float>(M_PI) / 180.0f;
}

// A body wider at the hips than the captured person (or in an A-pose it was rigged in) puts its
// hanging arms through its sides. The upper arm is turned outwards, about the chest's forward axis,
// until it hangs at least kMinArmAbduction from the chest's down direction, seen from the front.
constexpr float kMinArmAbduction = 20.0f * static_cast<float>(M_PI) / 180.0f;
void keep_arm_off_torso(Quatf& arm, const Vec3f& bind_dir, const Quatf& chest, float side) {
  const Vec3f d = arm * bind_dir;
  const Vec3f out = chest * Vec3f(side, 0, 0), down = chest * Vec3f(0, -1, 0), forward = chest * Vec3f::UnitZ();
  if (d.dot(down) <= 0) return;
  const float angle = std::atan2(d.dot(out), d.dot(down));
  if (angle >= kMinArmAbduction) return;
  arm = (Quatf(Eigen::AngleAxisf(kMinArmAbduction - angle, side * forward)) * arm).normalized();
}

}  // namespace

BodyAnimation retarget(const Motion& m, const Body& body, const RetargetOptions& o) {
  if (body.skeleton.empty() || body.mesh.joints.empty() || body.mesh.weights.size() != body.mesh.vertex_count())
    throw InputError("body", "has no rig (skeleton and skin weights) to animate");
  if (m.frame_count == 0 || m.joint_count() == 0) throw InputError(m.source, "has no frames");
  if (!(o.fps >= 1 && o.fps <= 240)) throw InputError(m.source, fmt::format("cannot be resampled at {} frames per second (1-240)", o.fps));
  const JointMap src = o.motion_map ? *o.motion_map : find_joint_map(m.names, m.source);
  std::vector<std::string> body_names;
  for (const Joint& j : body.skeleton.joints) body_names.push_back(j.name);
  const JointMap tgt = find_joint_map(body_names, "body");
  const Skeleton& sk = body.skeleton;
  const size_t nt = sk.joints.size();

  BodyAnimation out;
  out.motion_convention = src.convention;
  out.body_convention = tgt.convention;
  out.joint_count = nt;
  out.frame_time = 1.0 / o.fps;
  for (size_t c = 0; c < kCanonCount; ++c)
    if (src.joint[c] >= 0 && tgt.joint[c] >= 0)
      out.mapped.push_back(fmt::format("{} <- {}", sk.joints[static_cast<size_t>(tgt.joint[c])].name, m.names[static_cast<size_t>(src.joint[c])]));

  // The motion's rest pose, turned to face +Z.
  std::vector<Vec3f> rest_p;
  std::vector<Quatf> rest_g;
  m.world_pose(-1, rest_p, rest_g);
  Vec3f lateral = rest_p[static_cast<size_t>(src.joint[kLUpLeg])] - rest_p[static_cast<size_t>(src.joint[kRUpLeg])];
  lateral.y() = 0;
  if (lateral.norm() < 1e-6f) {
    lateral = rest_p[static_cast<size_t>(src.joint[kLArm])] - rest_p[static_cast<size_t>(src.joint[kRArm])];
    lateral.y() = 0;
  }
  if (lateral.norm() < 1e-6f) throw InputError(m.source, "its rest pose has the left and right thighs and arms at the same place");
  const Quatf facing = swing(lateral, Vec3f::UnitX());
  for (Vec3f& p : rest_p) p = facing * p;
  for (Quatf& g : rest_g) g = (facing * g).normalized();

  // Bind pose of the body.
  std::vector<Vec3f> bind_p(nt);
  for (size_t j = 0; j < nt; ++j) bind_p[j] = sk.joints[j].position;
  const float body_leg = 0.5f * (leg_length(bind_p, tgt, kLUpLeg, kLLeg, kLFoot) + leg_length(bind_p, tgt, kRUpLeg, kRLeg, kRFoot));
  const float motion_leg = 0.5f * (leg_length(rest_p, src, kLUpLeg, kLLeg, kLFoot) + leg_length(rest_p, src, kRUpLeg, kRLeg, kRFoot));
  if (!(motion_leg > 0)) throw InputError(m.source, "its legs have no length in the rest pose");
  out.root_scale = body_leg / motion_leg;

  // Rest offsets and the bone each canonical joint aims (the next joint down its chain found on both).
  std::array<Quatf, kCanonCount> offset;
  std::array<int, kCanonCount> aim;
  std::array<Vec3f, kCanonCount> body_dir;
  for (size_t c = 0; c < kCanonCount; ++c) {
    offset[c] = kCanonParent[c] < 0 ? Quatf::Identity() : offset[static_cast<size_t>(kCanonParent[c])];
    aim[c] = -1;
    if (c == kHips || src.joint[c] < 0 || tgt.joint[c] < 0) continue;
    for (int next : chains()[c]) {
      const int sn = src.joint[static_cast<size_t>(next)], tn = tgt.joint[static_cast<size_t>(next)];
      if (sn < 0 || tn < 0) continue;
      const Vec3f ds = rest_p[static_cast<size_t>(sn)] - rest_p[static_cast<size_t>(src.joint[c])];
      const Vec3f dt = bind_p[static_cast<size_t>(tn)] - bind_p[static_cast<size_t>(tgt.joint[c])];
      if (ds.norm() < 1e-3f * motion_leg || dt.norm() < 1e-3f * body_leg) continue;
      aim[c] = next;
      body_dir[c] = dt.normalized();
      offset[c] = swing(dt, ds);
      break;
    }
  }
  // Which canonical joint drives each body joint.
  std::vector<int> canon_of(nt, -1);
  for (size_t c = 0; c < kCanonCount; ++c)
    if (tgt.joint[c] >= 0 && src.joint[c] >= 0) canon_of[static_cast<size_t>(tgt.joint[c])] = static_cast<int>(c);
  const std::vector<size_t> order = topological_order(sk);

  // Motion frames used.
  out.skipped_calibration = o.skip_calibration && is_calibration_frame(m, src, facing);
  const long first_available = out.skipped_calibration ? 1 : 0;
  const long available = static_cast<long>(m.frame_count) - first_available;
  const long first = o.first_frame, last = o.last_frame < 0 ? available - 1 : o.last_frame;
  if (first < 0 || first >= available || last < first || last >= available)
    throw InputError(m.source, fmt::format("has frames 0 to {}{}; frames {} to {} were asked for", available - 1,
                                           out.skipped_calibration ? " after its calibration frame" : "", first, last));
  out.motion_first = first + first_available;
  out.motion_last = last + first_available;
  const double duration = static_cast<double>(out.motion_last - out.motion_first) * m.frame_time;
  const size_t blend_frames = static_cast<size_t>(std::lround(std::max(0.0, o.blend_seconds) * o.fps));
  // A motion shorter than the lead-in (a single pose) is held at its last frame until the lead-in ends.
  const size_t motion_frames = std::max(static_cast<size_t>(std::floor(duration * o.fps + 1e-3)) + 1, blend_frames + 1);
  out.frame_count = motion_frames;
  out.rotation.resize(out.frame_count * nt);
  out.position.resize(out.frame_count * nt);

  // Hips travel measured from the first frame used.
  std::vector<Vec3f> sp;
  std::vector<Quatf> sg, lr;
  std::vector<Vec3f> lt;
  motion_world(m, static_cast<double>(out.motion_first), facing, sp, sg, lr, lt);
  const size_t src_hips = static_cast<size_t>(src.joint[kHips]);
  const Vec3f hips_start = sp[src_hips];
  const int body_hips = tgt.joint[kHips];

  for (size_t k = 0; k < motion_frames; ++k) {
    const double frame = std::min(static_cast<double>(out.motion_last),
                                  static_cast<double>(out.motion_first) + static_cast<double>(k) / o.fps / m.frame_time);
    motion_world(m, frame, facing, sp, sg, lr, lt);
    Quatf* w = out.rotation.data() + k * nt;
    Vec3f* x = out.position.data() + k * nt;
    for (size_t j : order) {
      const int pj = sk.joints[j].parent;
      const int c = canon_of[j];
      if (c < 0) {
        w[j] = pj < 0 ? Quatf::Identity() : w[pj];
      } else {
        const size_t sj = static_cast<size_t>(src.joint[static_cast<size_t>(c)]);
        const Quatf d = (sg[sj] * rest_g[sj].conjugate()).normalized();
        w[j] = (d * offset[static_cast<size_t>(c)]).normalized();
        if (aim[static_cast<size_t>(c)] >= 0) {
          const size_t sn = static_cast<size_t>(src.joint[static_cast<size_t>(aim[static_cast<size_t>(c)])]);
          const Vec3f now = w[j] * body_dir[static_cast<size_t>(c)];
          const Vec3f want = sp[sn] - sp[sj];
          if (want.norm() > 1e-6f) w[j] = (swing(now, want) * w[j]).normalized();
        }
        if ((c == kLArm || c == kRArm) && aim[static_cast<size_t>(c)] >= 0 && tgt.joint[kSpine1] >= 0)
          keep_arm_off_torso(w[j], body_dir[static_cast<size_t>(c)], w[static_cast<size_t>(tgt.joint[kSpine1])], c == kLArm ? 1.0f : -1.0f);
      }
      if (static_cast<int>(j) == body_hips)
        x[j] = bind_p[j] + out.root_scale * (sp[src_hips] - hips_start);
      else
        x[j] = pj < 0 ? bind_p[j] : Vec3f(x[pj] + w[pj] * (bind_p[j] - bind_p[static_cast<size_t>(pj)]));
    }
  }
  motion_detail::place_on_floor(body, tgt, out);
  // The lead-in: the motion plays from its first frame while its weight against the bind pose
  // (where the garments were dressed) rises from 0 to 1 by smoothstep, so the body starts at rest
  // and ends the lead-in at the motion's own velocities: no joint stops or starts in one frame.
  out.blend_frames = std::min(blend_frames, out.frame_count);
  for (size_t k = 0; k < out.blend_frames; ++k) {
    const float s = static_cast<float>(k) / static_cast<float>(blend_frames);
    const float a = s * s * (3 - 2 * s);
    Quatf* w = out.rotation.data() + k * nt;
    Vec3f* x = out.position.data() + k * nt;
    const std::vector<Vec3f> motion_x(x, x + nt);
    for (size_t j : order) {
      const int pj = sk.joints[j].parent;
      w[j] = Quatf::Identity().slerp(a, w[j]).normalized();
      if (static_cast<int>(j) == body_hips || pj < 0)
        x[j] = (1 - a) * bind_p[j] + a * motion_x[j];
      else
        x[j] = x[pj] + w[pj] * (bind_p[j] - bind_p[static_cast<size_t>(pj)]);
    }
  }
  motion_detail::lift_above_floor(body, tgt, out, 0, out.blend_frames);
  motion_detail::measure_feet(body, tgt, out);
  motion_detail::check_joint_limits(tgt, out);
  return out;
}

}  // namespace drape
