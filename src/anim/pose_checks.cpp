// What a retargeted animation is checked against: the feet on the floor (measured on the skinned
// foot vertices, not on joints: a joint sits inside the foot), how far a foot slides while it
// carries weight, and anatomical ranges of the knees, elbows and neck.
//
// Ranges (degrees; 0 = the bone straight on from its parent): knee flexion -15 (hyperextension) to
// 165, elbow bend at most 165 (its direction is not measured: the forearm's twist makes "forwards"
// ambiguous), the head at most 80 from the chest's direction.
#include <algorithm>
#include <cmath>
#include <limits>

#include <fmt/format.h>

#include "anim/motion_internal.hpp"
#include "drape/motion.hpp"

namespace drape::motion_detail {
namespace {

constexpr float kDeg = 180.0f / static_cast<float>(M_PI);
constexpr float kKneeMin = -15, kKneeMax = 165, kElbowMax = 165, kNeckMax = 80;
constexpr float kContact = 0.01f;       // m: a foot this near the floor carries weight
constexpr float kNearFloor = 0.03f;     // m: contact_fraction

enum { kHips = 0, kSpine1 = 2, kHead = 4, kLArm = 6, kLForeArm = 7, kLHand = 8, kRArm = 10, kRForeArm = 11, kRHand = 12,
       kLUpLeg = 13, kLLeg = 14, kLFoot = 15, kRUpLeg = 17, kRLeg = 18, kRFoot = 19 };

float lowest_y(std::span<const Vec3f> x) {
  float low = std::numeric_limits<float>::infinity();
  for (const Vec3f& p : x) low = std::min(low, p.y());
  return low;
}

}  // namespace

void place_on_floor(const Body& body, const JointMap& map, BodyAnimation& out) {
  const std::vector<uint32_t> left = foot_vertices(body, map.joint[kLFoot]), right = foot_vertices(body, map.joint[kRFoot]);
  std::vector<uint32_t> feet = left;
  feet.insert(feet.end(), right.begin(), right.end());
  if (feet.empty() || out.frame_count <= out.blend_frames) return;
  std::vector<Vec3f> x(feet.size());
  const size_t n = out.frame_count - out.blend_frames;
  std::vector<double> low(n), time(n);
  for (size_t k = 0; k < n; ++k) {
    skin_vertices(body, out.pose(out.blend_frames + k), Skinning::Linear, feet, x);
    low[k] = lowest_y(x);
    time[k] = static_cast<double>(k) * out.frame_time;
  }
  // A capture's floor is seldom level with its axes: the stance foot of CMU's walk rises 4 cm over
  // 2.8 s. A line is fitted to the lowest foot over time (to the frames within 1 cm of the last fit
  // or below it: the stance phases, not the swings) and taken off, for clips of a second or more.
  double slope = 0, level = std::numeric_limits<double>::infinity();
  for (double l : low) level = std::min(level, l);
  if (static_cast<double>(n) * out.frame_time >= 1.0) {
    std::vector<char> use(n, 1);
    for (int round = 0; round < 3; ++round) {
      double st = 0, sy = 0, stt = 0, sty = 0, count = 0;
      for (size_t k = 0; k < n; ++k)
        if (use[k]) st += time[k], sy += low[k], stt += time[k] * time[k], sty += time[k] * low[k], count += 1;
      const double det = count * stt - st * st;
      if (count < 2 || det <= 0) break;
      slope = (count * sty - st * sy) / det;
      const double intercept = (sy - slope * st) / count;
      for (size_t k = 0; k < n; ++k) use[k] = low[k] <= intercept + slope * time[k] + 0.01;
    }
    level = std::numeric_limits<double>::infinity();
    for (size_t k = 0; k < n; ++k) level = std::min(level, low[k] - slope * time[k]);
  }
  out.feet.floor_shift_m = static_cast<float>(-level);
  out.feet.floor_slope_m_per_s = static_cast<float>(slope);
  for (size_t k = 0; k < n; ++k) {
    const float shift = static_cast<float>(level + slope * time[k]);
    for (size_t j = 0; j < out.joint_count; ++j) out.position[(out.blend_frames + k) * out.joint_count + j].y() -= shift;
  }
}

void lift_above_floor(const Body& body, const JointMap& map, BodyAnimation& out, size_t begin, size_t end) {
  const std::vector<uint32_t> left = foot_vertices(body, map.joint[kLFoot]), right = foot_vertices(body, map.joint[kRFoot]);
  std::vector<uint32_t> feet = left;
  feet.insert(feet.end(), right.begin(), right.end());
  std::vector<Vec3f> x(feet.size());
  for (size_t f = begin; f < end && !feet.empty(); ++f) {
    skin_vertices(body, out.pose(f), Skinning::Linear, feet, x);
    const float low = lowest_y(x);
    if (low < -1e-4f)
      for (size_t j = 0; j < out.joint_count; ++j) out.position[f * out.joint_count + j].y() -= low;
  }
}

void measure_feet(const Body& body, const JointMap& map, BodyAnimation& out) {
  const std::vector<uint32_t> feet[2] = {foot_vertices(body, map.joint[kLFoot]), foot_vertices(body, map.joint[kRFoot])};
  FootReport& r = out.feet;
  r.lowest_y = std::numeric_limits<float>::infinity();
  size_t near = 0;
  Vec3f previous[2];
  bool was_in_contact[2] = {false, false};
  for (size_t f = 0; f < out.frame_count; ++f) {
    float frame_low = std::numeric_limits<float>::infinity();
    for (int side = 0; side < 2; ++side) {
      if (feet[side].empty()) continue;
      std::vector<Vec3f> x(feet[side].size());
      skin_vertices(body, out.pose(f), Skinning::Linear, feet[side], x);
      const float low = lowest_y(x);
      frame_low = std::min(frame_low, low);
      Vec3f centre = Vec3f::Zero();
      for (const Vec3f& p : x) centre += p;
      centre /= static_cast<float>(x.size());
      centre.y() = 0;
      const bool contact = low < kContact;
      if (contact && was_in_contact[side]) {
        const float d = (centre - previous[side]).norm();
        r.sliding_m += d;
        r.max_sliding_speed = std::max(r.max_sliding_speed, static_cast<float>(d / out.frame_time));
      }
      previous[side] = centre;
      was_in_contact[side] = contact;
    }
    r.lowest_y = std::min(r.lowest_y, frame_low);
    near += frame_low < kNearFloor;
  }
  r.contact_fraction = out.frame_count ? static_cast<double>(near) / static_cast<double>(out.frame_count) : 0;
}

void check_joint_limits(const JointMap& map, BodyAnimation& out) {
  JointLimitReport& r = out.limits;
  r.min_knee_flexion_deg = r.min_elbow_flexion_deg = std::numeric_limits<float>::infinity();
  r.max_knee_flexion_deg = r.max_elbow_flexion_deg = -std::numeric_limits<float>::infinity();
  auto joint = [&](int c) { return map.joint[static_cast<size_t>(c)]; };
  auto note = [&](size_t f, const std::string& what) {
    if (r.violations.size() < 20) r.violations.push_back(fmt::format("frame {}: {}", f, what));
  };
  for (size_t f = 0; f < out.frame_count; ++f) {
    const PoseView pose = out.pose(f);
    auto p = [&](int c) { return pose.position[static_cast<size_t>(joint(c))]; };
    for (const auto& [up, knee, foot, name] : {std::tuple{kLUpLeg, kLLeg, kLFoot, "LeftLeg"}, std::tuple{kRUpLeg, kRLeg, kRFoot, "RightLeg"}}) {
      if (joint(up) < 0 || joint(knee) < 0 || joint(foot) < 0) continue;
      const Vec3f a = p(knee) - p(up), b = p(foot) - p(knee);
      const Vec3f lateral = pose.rotation[static_cast<size_t>(joint(up))] * Vec3f::UnitX();
      const float angle = std::atan2(a.cross(b).norm(), a.dot(b)) * kDeg;
      const float flexion = a.cross(b).dot(lateral) >= 0 ? angle : -angle;
      r.min_knee_flexion_deg = std::min(r.min_knee_flexion_deg, flexion);
      r.max_knee_flexion_deg = std::max(r.max_knee_flexion_deg, flexion);
      if (flexion < kKneeMin || flexion > kKneeMax) note(f, fmt::format("{} knee flexion {:.0f} deg (range {:.0f} to {:.0f})", name, flexion, kKneeMin, kKneeMax));
    }
    for (const auto& [arm, elbow, hand, name] : {std::tuple{kLArm, kLForeArm, kLHand, "LeftForeArm"}, std::tuple{kRArm, kRForeArm, kRHand, "RightForeArm"}}) {
      if (joint(arm) < 0 || joint(elbow) < 0 || joint(hand) < 0) continue;
      const Vec3f a = p(elbow) - p(arm), b = p(hand) - p(elbow);
      const float angle = std::atan2(a.cross(b).norm(), a.dot(b)) * kDeg;
      r.min_elbow_flexion_deg = std::min(r.min_elbow_flexion_deg, angle);
      r.max_elbow_flexion_deg = std::max(r.max_elbow_flexion_deg, angle);
      if (angle > kElbowMax) note(f, fmt::format("{} elbow bent {:.0f} deg (at most {:.0f})", name, angle, kElbowMax));
    }
    if (joint(kSpine1) >= 0 && joint(kHead) >= 0) {
      const Vec3f chest = pose.rotation[static_cast<size_t>(joint(kSpine1))] * Vec3f::UnitY();
      const Vec3f head = pose.rotation[static_cast<size_t>(joint(kHead))] * Vec3f::UnitY();
      const float angle = std::atan2(chest.cross(head).norm(), chest.dot(head)) * kDeg;
      r.max_neck_bend_deg = std::max(r.max_neck_bend_deg, angle);
      if (angle > kNeckMax) note(f, fmt::format("Head bent {:.0f} deg from the chest (at most {:.0f})", angle, kNeckMax));
    }
  }
}

}  // namespace drape::motion_detail
