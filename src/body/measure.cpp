// Tape measurements from landmarks. Circumferences are convex-hull perimeters of one section piece
// (a tape bridges hollows, e.g. between the breasts); torso sections take only the piece that
// straddles the midline, so arms never count. Limb girths use sections perpendicular to the limb.
#include <algorithm>
#include <cmath>

#include "body/analysis.hpp"
#include "drape/body.hpp"

namespace drape {

const std::vector<MeasurementInfo>& measurement_table() {
  static const std::vector<MeasurementInfo> table{
      {"height", "stature (5.1.1)", &Measurements::height, false},
      {"neck", "neck girth (5.3.2)", &Measurements::neck, true},
      {"bust", "bust girth (5.3.4) / chest girth (5.3.5)", &Measurements::bust, true},
      {"underbust", "underbust girth (5.3.6)", &Measurements::underbust, true},
      {"waist", "waist girth (5.3.10)", &Measurements::waist, true},
      {"hips", "hip girth (5.3.13)", &Measurements::hips, true},
      {"thigh", "thigh girth (5.3.20)", &Measurements::thigh, true},
      {"upper_arm", "upper arm girth (5.3.16)", &Measurements::upper_arm, true},
      {"wrist", "wrist girth (5.3.19)", &Measurements::wrist, true},
      {"inseam", "crotch height (5.1.15)", &Measurements::inseam, false},
      {"arm_length", "arm length (5.4.14)", &Measurements::arm_length, false},
      {"shoulder_width", "biacromial shoulder width (5.4.1)", &Measurements::shoulder_width, false},
      {"back_length", "back waist length (5.4.5)", &Measurements::back_length, false},
  };
  return table;
}

namespace {

using namespace body;

float torso_girth_at(const Slicer& mesh, float y) { return torso_girth(mesh, y); }

// Length of the back midline profile (the section x = 0, back half) between two heights.
float back_profile_length(const Slicer& mesh, float from_y, float to_y, float front_of_back_z) {
  // Plane x = 0 with u = +Y, v = normal x u = (1,0,0) x (0,1,0) = +Z.
  const SlicePlane plane{Vec3f::Zero(), Vec3f::UnitX(), Vec3f::UnitY()};
  std::vector<Vec2f> back;  // (y, z) of the back surface
  for (const auto& piece : slice(mesh, plane))
    for (const auto& q : piece.points)
      if (q.x() >= from_y && q.x() <= to_y && q.y() < front_of_back_z) back.push_back(q);
  if (back.size() < 2) return std::abs(to_y - from_y);
  // Per 5 mm band keep the rearmost point; the profile is the polyline through them.
  std::sort(back.begin(), back.end(), [](const Vec2f& a, const Vec2f& b) { return a.x() < b.x(); });
  std::vector<Vec2f> profile;
  for (const auto& q : back) {
    if (!profile.empty() && q.x() - profile.back().x() < 0.005f) {
      if (q.y() < profile.back().y()) profile.back().y() = q.y();
    } else {
      profile.push_back(q);
    }
  }
  if (profile.empty()) return std::abs(to_y - from_y);
  float length = profile.front().x() - from_y;
  for (size_t i = 1; i < profile.size(); ++i) length += (profile[i] - profile[i - 1]).norm();
  length += to_y - profile.back().x();
  return length;
}

// Mean of both legs' girths: each the fullest leg section in the 8 cm below the crotch.
float thigh_girth(const Slicer& mesh, float crotch_y) {
  std::array<float, 2> best{0.0f, 0.0f};
  for (float y = crotch_y - 0.003f; y > crotch_y - 0.08f; y -= 0.003f) {
    auto legs = leg_sections(mesh, y);
    for (size_t k = 0; k < 2; ++k)
      if (legs[k]) best[k] = std::max(best[k], hull_perimeter(std::move(legs[k]->points)));
  }
  return 0.5f * (best[0] + best[1]);
}

}  // namespace

Measurements body::measure_body(const Slicer& mesh, const Landmarks& lm, MeasurementSet which) {
  // Bits in measurement_table()'s order.
  enum : size_t { kHeight, kNeck, kBust, kUnderbust, kWaist, kHips, kThigh, kUpperArm, kWrist, kInseam, kArmLength,
                  kShoulderWidth, kBackLength };
  Measurements m;
  if (which[kHeight]) m.height = lm.crown.y() - bounds(mesh.positions).min.y();
  if (which[kNeck]) m.neck = torso_girth_at(mesh, lm.neck.y());
  if (which[kBust]) {
    const float bust_y = 0.5f * (lm.left_bust.y() + lm.right_bust.y());
    // Bust (women) or chest (men) girth: the fullest torso section from the bust points up to 2 cm
    // under the armpits, so it reads the bust of a woman and the chest under the arms of a man.
    const float chest_top = std::min(lm.left_armpit.y(), lm.right_armpit.y()) - 0.02f;
    m.bust = torso_girth_at(mesh, bust_y);
    for (float y = bust_y + 0.003f; y <= chest_top; y += 0.003f) m.bust = std::max(m.bust, torso_girth_at(mesh, y));
  }
  if (which[kUnderbust]) m.underbust = torso_girth_at(mesh, lm.underbust.y());
  if (which[kWaist]) m.waist = torso_girth_at(mesh, lm.waist.y());
  if (which[kHips]) m.hips = torso_girth_at(mesh, lm.hip.y());
  if (which[kThigh]) m.thigh = thigh_girth(mesh, lm.crotch.y());
  if (which[kInseam]) m.inseam = lm.crotch.y();

  // Arms: girths perpendicular to the shoulder->elbow and elbow->wrist directions.
  auto upper = [&](const Vec3f& shoulder, const Vec3f& elbow) {
    return limb_girth(mesh, 0.5f * (shoulder + elbow), elbow - shoulder);
  };
  auto wrist = [&](const Vec3f& elbow, const Vec3f& at, const Vec3f& tip) { return limb_girth(mesh, at, tip - elbow); };
  if (which[kUpperArm])
    m.upper_arm = 0.5f * (upper(lm.left_shoulder, lm.left_elbow) + upper(lm.right_shoulder, lm.right_elbow));
  if (which[kWrist])
    m.wrist = 0.5f * (wrist(lm.left_elbow, lm.left_wrist, lm.left_fingertip) +
                      wrist(lm.right_elbow, lm.right_wrist, lm.right_fingertip));
  if (which[kArmLength])
    m.arm_length = 0.5f * ((lm.left_wrist - lm.left_shoulder).norm() + (lm.right_wrist - lm.right_shoulder).norm());
  if (which[kShoulderWidth]) m.shoulder_width = (lm.left_shoulder - lm.right_shoulder).norm();
  if (which[kBackLength])
    m.back_length = back_profile_length(mesh, lm.waist.y(), lm.neck_base.y(), lm.neck_base.z() + 0.08f);
  return m;
}

Measurements measure_body(const Mesh& input, const Landmarks& lm) {
  const body::Slicer mesh(input);  // indexed once for the many sections below
  return body::measure_body(mesh, lm, body::MeasurementSet().set());
}

}  // namespace drape
