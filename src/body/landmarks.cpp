// Landmarks on any standing body (A- or T-pose) in drape's frame: Y up, facing +Z, feet on y = 0.
//
// Everything is found from cross-sections (body/slicing.hpp), the way an anthropometrist reads a
// body scan: the crotch is where the section stops straddling the midline, the armpits are where
// the torso section suddenly takes in an arm, the neck is the narrowest section between the
// shoulders and the head, the waist the narrowest torso section between hips and bust, and so on.
// Limb landmarks use sections perpendicular to the limb's axis, so the same code reads A- and
// T-poses. Where anatomy gives no section feature (knee, elbow) a standard proportion of the limb
// is used; docs/bodies.md lists each rule.
#include <algorithm>
#include <cmath>
#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <optional>
#include <vector>

#include "body/analysis.hpp"
#include "body/slicing.hpp"
#include "drape/body.hpp"
#include "drape/error.hpp"

namespace drape {

using body::SectionPiece;

std::vector<std::pair<std::string_view, Vec3f>> Landmarks::named() const {
  return {{"crown", crown},
          {"neck_base", neck_base},
          {"neck", neck},
          {"left_shoulder", left_shoulder},
          {"right_shoulder", right_shoulder},
          {"left_armpit", left_armpit},
          {"right_armpit", right_armpit},
          {"left_bust", left_bust},
          {"right_bust", right_bust},
          {"underbust", underbust},
          {"waist", waist},
          {"hip", hip},
          {"crotch", crotch},
          {"left_knee", left_knee},
          {"right_knee", right_knee},
          {"left_ankle", left_ankle},
          {"right_ankle", right_ankle},
          {"left_elbow", left_elbow},
          {"right_elbow", right_elbow},
          {"left_wrist", left_wrist},
          {"right_wrist", right_wrist},
          {"left_fingertip", left_fingertip},
          {"right_fingertip", right_fingertip}};
}

namespace body {

std::optional<SectionPiece> torso_section(const Slicer& mesh, float y) { return straddling_piece(mesh, y); }

float torso_girth(const Slicer& mesh, float y) {
  auto s = straddling_outline(mesh, y);
  return s ? hull_perimeter(std::move(s->points)) : 0.0f;
}

namespace {

// Of a section's pieces, the leg on one side: the piece on that side nearest the midline (hands
// hang further out); -1 when none.
int leg_piece(const std::vector<SectionPiece>& pieces, int side) {
  int best = -1;
  for (size_t i = 0; i < pieces.size(); ++i) {
    const float cx = pieces[i].centroid.x() * static_cast<float>(side);
    if (cx <= 0 || pieces[i].min.x() * static_cast<float>(side) < -0.02f) continue;
    if (best < 0 || cx < pieces[static_cast<size_t>(best)].centroid.x() * static_cast<float>(side)) best = static_cast<int>(i);
  }
  return best;
}

}  // namespace

std::optional<SectionPiece> leg_section(const Slicer& mesh, float y, int side) {
  auto pieces = slice(mesh, horizontal_plane(y));
  const int best = leg_piece(pieces, side);
  if (best < 0) return std::nullopt;
  return std::move(pieces[static_cast<size_t>(best)]);
}

std::array<std::optional<SectionPiece>, 2> leg_sections(const Slicer& mesh, float y) {
  auto pieces = slice(mesh, horizontal_plane(y));
  std::array<std::optional<SectionPiece>, 2> legs;
  const int left = leg_piece(pieces, +1), right = leg_piece(pieces, -1);
  if (left >= 0) legs[0] = pieces[static_cast<size_t>(left)];
  if (right >= 0) legs[1] = std::move(pieces[static_cast<size_t>(right)]);
  return legs;
}

SlicePlane limb_plane(const Vec3f& point, const Vec3f& axis) {
  const Vec3f n = axis.normalized();
  Vec3f u = n.cross(Vec3f::UnitZ());
  if (u.norm() < 1e-3f) u = n.cross(Vec3f::UnitX());
  return SlicePlane{point, n, u.normalized()};
}

std::optional<SectionPiece> limb_section(const Slicer& mesh, const Vec3f& point, const Vec3f& axis) {
  const SlicePlane plane = limb_plane(point, axis);
  auto pieces = slice(mesh, plane);
  const int i = nearest_piece(pieces, Vec2f::Zero());
  if (i < 0) return std::nullopt;
  return std::move(pieces[static_cast<size_t>(i)]);
}

float limb_girth(const Slicer& mesh, const Vec3f& point, const Vec3f& axis) {
  auto s = limb_section(mesh, point, axis);
  return s ? hull_perimeter(s->points) : 0.0f;
}

bool torso_below_bust(const Slicer& mesh, const Landmarks& lm, float height) {
  const float bust_y = 0.5f * (lm.left_bust.y() + lm.right_bust.y());
  for (float y = bust_y; y > bust_y - 0.1f * height; y -= 0.002f)  // find_underbust's levels
    if (straddling_outline(mesh, y)) return true;
  return false;
}

bool find_underbust(const Slicer& mesh, Landmarks& lm, float height) {
  const float bust_y = 0.5f * (lm.left_bust.y() + lm.right_bust.y());
  // Underbust: going down from the bust, the first dip of the front profile (the fold under the
  // breasts, or where the front stops receding), then 1 cm lower to clear the breast tissue. A flat
  // chest (the front recedes by less than 5 mm before the dip) has no fold to find: its underbust
  // is 4 % of the height under the bust points, where the pectorals end.
  {
    float min_front = 1e9f, min_y = -1.0f, top_front = -1e9f;
    for (float y = bust_y; y > bust_y - 0.1f * height; y -= 0.002f) {
      auto s = straddling_outline(mesh, y);
      if (!s) continue;
      top_front = std::max(top_front, s->max.y());
      if (s->max.y() < min_front) {
        min_front = s->max.y();
        min_y = y;
      } else if (s->max.y() > min_front + 0.002f) {
        break;
      }
    }
    if (min_y < 0) return false;
    if (top_front - min_front < 0.005f) {
      min_y = bust_y - 0.04f * height + 0.01f;
      if (auto s = straddling_outline(mesh, min_y - 0.01f)) min_front = s->max.y();
    }
    lm.underbust = Vec3f(0.0f, min_y - 0.01f, min_front);
  }
  return true;
}

namespace {

// The torso's outline at each level from `from` up to (not including) `to`, 3 mm apart: its hull
// girth and the extent of its depth. The levels are independent: on every core, in level order.
struct Level {
  float y, girth, front, back;
  bool found;
};
std::vector<Level> torso_levels(const Slicer& mesh, float from, float to) {
  std::vector<Level> levels;
  for (float y = from; y < to; y += 0.003f) levels.push_back({y, 0.0f, 0.0f, 0.0f, false});
#pragma omp parallel for schedule(dynamic, 4)
  for (size_t i = 0; i < levels.size(); ++i) {
    auto s = straddling_outline(mesh, levels[i].y);
    if (!s) continue;
    levels[i] = {levels[i].y, hull_perimeter(std::move(s->points)), s->max.y(), s->min.y(), true};
  }
  return levels;
}

}  // namespace

WaistAndHip find_waist_and_hip(const Slicer& mesh, Landmarks& lm) {
  const float crotch_y = lm.crotch.y();
  const float low_armpit = std::min(lm.left_armpit.y(), lm.right_armpit.y());
  // Waist: the narrowest torso section from 30 % to 70 % of the way crotch -> armpit (independent of
  // the bust and underbust landmarks, which a man's chest or a belly can move).
  {
    float best = 1e9f;
    for (const Level& l : torso_levels(mesh, crotch_y + 0.3f * (low_armpit - crotch_y), crotch_y + 0.7f * (low_armpit - crotch_y)))
      if (l.found && l.girth < best) {
        best = l.girth;
        lm.waist = Vec3f(0.0f, l.y, l.front);
      }
    if (best > 1e8f) return WaistAndHip::kNoWaist;
  }
  // Hip: the fullest torso section between the crotch and the waist.
  {
    float best = 0;
    for (const Level& l : torso_levels(mesh, crotch_y + 0.015f, lm.waist.y()))
      if (l.found && l.girth > best) {
        best = l.girth;
        lm.hip = Vec3f(0.0f, l.y, l.back);
      }
    if (best <= 0) return WaistAndHip::kNoHips;
  }

  return WaistAndHip::kFound;
}

}  // namespace body

namespace {

using namespace body;

[[noreturn]] void fail(const std::string& source, const std::string& what) {
  throw InputError(source, "not a standing person in A- or T-pose: " + what);
}

// Arm landmarks on one side (+1 left, -1 right).
struct ArmLandmarks {
  Vec3f shoulder, armpit, elbow, wrist, fingertip;
};

ArmLandmarks find_arm(const Slicer& mesh, int side, float armpit_y, const SectionPiece& below_armpit_torso,
                      float neck_y, const std::string& source) {
  const float s = static_cast<float>(side);
  ArmLandmarks arm{};
  // Armpit: the top of the gap between torso and arm, just below where they merge.
  {
    const float torso_edge = s > 0 ? below_armpit_torso.max.x() : below_armpit_torso.min.x();
    float edge_z = below_armpit_torso.centroid.y();
    for (const auto& q : below_armpit_torso.points)
      if (q.x() == torso_edge) edge_z = q.y();
    float gap = 0.0f;  // to the arm's inner edge; 0 when the arm is not a separate piece (T-pose)
    float nearest = 1e9f;
    for (const auto& piece : slice(mesh, horizontal_plane(armpit_y))) {
      const float beyond = ((s > 0 ? piece.min.x() : -piece.max.x())) - torso_edge * s;
      if (beyond > 0 && beyond < nearest) nearest = beyond;
    }
    if (nearest < 0.1f) gap = nearest;
    arm.armpit = Vec3f(torso_edge + 0.5f * gap * s, armpit_y, edge_z);
  }
  // Fingertip: the most lateral vertex below the neck.
  float best = -1;
  for (const auto& p : mesh.positions) {
    if (p.y() > neck_y) continue;
    if (p.x() * s > best) {
      best = p.x() * s;
      arm.fingertip = p;
    }
  }
  if (best < std::abs(arm.armpit.x()) + 0.2f) fail(source, "no arm found beyond the armpit");

  // Arm axis: centroids of sections perpendicular to the rough armpit->fingertip line, then a
  // least-squares line through them.
  const Vec3f rough_start = arm.armpit + Vec3f(0.0f, 0.03f, 0.0f);
  Vec3f axis = (arm.fingertip - rough_start).normalized();
  const float reach = (arm.fingertip - rough_start).norm();
  std::vector<Vec3f> centres;
  for (float t = 0.15f; t <= 0.62f; t += 0.04f) {
    const Vec3f at = rough_start + t * reach * axis;
    auto sec = limb_section(mesh, at, axis);
    if (sec) centres.push_back(limb_plane(at, axis).to_world(sec->centroid));
  }
  if (centres.size() < 4) fail(source, "cannot follow the arm");
  Vec3f mean = Vec3f::Zero();
  for (const auto& c : centres) mean += c;
  mean /= static_cast<float>(centres.size());
  Eigen::Matrix3f cov = Eigen::Matrix3f::Zero();
  for (const auto& c : centres) cov += (c - mean) * (c - mean).transpose();
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3f> eig(cov);
  Vec3f dir = eig.eigenvectors().col(2);
  if (dir.dot(axis) < 0) dir = -dir;
  axis = dir;
  // Axis origin: where the axis passes the armpit height's horizontal level (the shoulder joint
  // lies a little above it).
  auto on_axis = [&](float t) { return Vec3f(mean + t * axis); };
  const float t_tip = (arm.fingertip - mean).dot(axis);
  const float t_armpit = (arm.armpit - mean).dot(axis);

  // Wrist: the narrowest perpendicular section between 50 % and 80 % of armpit -> fingertip.
  float wrist_girth = 1e9f, t_wrist = 0;
  for (float f = 0.5f; f <= 0.8f; f += 0.01f) {
    const float t = t_armpit + f * (t_tip - t_armpit);
    const float g = limb_girth(mesh, on_axis(t), axis);
    if (g > 0 && g < wrist_girth) {
      wrist_girth = g;
      t_wrist = t;
    }
  }
  arm.wrist = on_axis(t_wrist);

  // Shoulder point (acromion): the top of the surface straight above the armpit.
  const Vec3f joint(arm.armpit.x(), on_axis(t_armpit).y(), on_axis(t_armpit).z());
  float top = -1e9f;
  for (const auto& p : mesh.positions) {
    if (std::abs(p.x() - joint.x()) < 0.01f && std::abs(p.z() - joint.z()) < 0.04f && p.y() < neck_y && p.y() > top)
      top = p.y();
  }
  if (top < joint.y()) fail(source, "cannot find the shoulder");
  arm.shoulder = Vec3f(joint.x(), top, joint.z());
  // Elbow: 57 % of the way from the shoulder point to the wrist (upper arm : forearm ~ 4 : 3).
  arm.elbow = arm.shoulder + 0.57f * (arm.wrist - arm.shoulder);
  arm.elbow = on_axis((arm.elbow - mean).dot(axis));
  return arm;
}

}  // namespace

Landmarks find_landmarks(const Mesh& input, const std::string& source) {
  return body::find_landmarks(Slicer(input), source);  // indexed once: the search slices it thousands of times
}

Landmarks body::find_landmarks(const Slicer& mesh, const std::string& source) {
  if (mesh.positions.empty() || mesh.triangles.empty()) throw InputError(source, "no mesh");
  Landmarks lm;
  const Bounds box = bounds(mesh.positions);
  const float height = box.max.y();
  for (const auto& p : mesh.positions)
    if (p.y() >= height) lm.crown = p;

  // Crotch: scanning down from above the hips, the last height whose section straddles x = 0.
  // (Where only whether there is a section, or its girth or extent, matters, its outline will do.)
  float y_straddle = 0.58f * height;
  if (!straddling_outline(mesh, y_straddle)) fail(source, "no torso section at hip height");
  float y_free = y_straddle;
  while (y_free > 0.25f * height && straddling_outline(mesh, y_free)) y_free -= 0.005f;
  if (y_free <= 0.25f * height) fail(source, "no gap between the legs");
  y_straddle = y_free + 0.005f;
  for (int i = 0; i < 12; ++i) {
    const float mid = 0.5f * (y_free + y_straddle);
    (straddling_outline(mesh, mid) ? y_straddle : y_free) = mid;
  }
  const float crotch_y = y_straddle;
  {
    auto s = torso_section(mesh, crotch_y + 0.002f);
    lm.crotch = Vec3f(0.0f, crotch_y, s ? s->centroid.y() : 0.0f);
  }

  // Armpits: scanning up from the waist region, the height where the torso section's lateral extent
  // jumps (an arm joins it). Each side separately.
  float armpit_y[2] = {0, 0};
  std::optional<SectionPiece> below[2];
  {
    float previous_y = crotch_y + 0.3f * (height - crotch_y);
    std::optional<SectionPiece> previous = straddling_outline(mesh, previous_y);
    for (float y = crotch_y + 0.3f * (height - crotch_y) + 0.002f; y < 0.92f * height; y += 0.002f) {
      auto s = straddling_outline(mesh, y);
      if (!s || !previous) break;
      for (int k = 0; k < 2; ++k) {
        if (armpit_y[k] > 0) continue;
        const bool left = k == 0;
        const float jump = left ? s->max.x() - previous->max.x() : previous->min.x() - s->min.x();
        if (jump > 0.025f) {
          armpit_y[k] = y - 0.002f;
          below[k] = torso_section(mesh, previous_y);  // the piece itself: find_arm reads its points
        }
      }
      if (armpit_y[0] > 0 && armpit_y[1] > 0) break;
      previous = std::move(s);
      previous_y = y;
    }
  }
  if (armpit_y[0] <= 0 || armpit_y[1] <= 0) fail(source, "cannot find the armpits");
  const float top_armpit = std::max(armpit_y[0], armpit_y[1]);

  // Neck: the narrowest section between the armpits and 90 % of the height.
  float neck_girth = 1e9f, neck_y = 0.0f;
  for (float y = top_armpit + 0.02f; y < 0.9f * height; y += 0.003f) {
    auto s = straddling_outline(mesh, y);
    if (!s) continue;
    const float g = hull_perimeter(std::move(s->points));
    if (g < neck_girth) {
      neck_girth = g;
      neck_y = y;
    }
  }
  if (neck_girth > 1e8f) fail(source, "cannot find the neck");
  {
    const auto s = torso_section(mesh, neck_y);  // its centroid
    lm.neck = Vec3f(s->centroid.x(), neck_y, s->centroid.y());
  }
  // Neck base: going down from the narrowest neck, where the section has grown by a quarter (the
  // shoulders begin); the cervicale is the back of the midline there.
  {
    float y = lm.neck.y();
    std::optional<SectionPiece> s;
    for (; y > top_armpit; y -= 0.003f) {
      s = straddling_outline(mesh, y);
      if (s && hull_perimeter(s->points) > 1.25f * neck_girth) break;
    }
    float back_z = s ? s->min.y() : lm.neck.z();
    if (s)
      for (const auto& q : s->points)
        if (std::abs(q.x()) < 0.015f) back_z = std::min(back_z, q.y());
    lm.neck_base = Vec3f(0.0f, y, back_z);
  }

  const ArmLandmarks left = find_arm(mesh, +1, armpit_y[0], *below[0], lm.neck.y(), source);
  const ArmLandmarks right = find_arm(mesh, -1, armpit_y[1], *below[1], lm.neck.y(), source);
  lm.left_shoulder = left.shoulder;
  lm.left_armpit = left.armpit;
  lm.left_elbow = left.elbow;
  lm.left_wrist = left.wrist;
  lm.left_fingertip = left.fingertip;
  lm.right_shoulder = right.shoulder;
  lm.right_armpit = right.armpit;
  lm.right_elbow = right.elbow;
  lm.right_wrist = right.wrist;
  lm.right_fingertip = right.fingertip;

  // Bust points: going down from the armpits, the most forward point of each half of the chest
  // until the front has fallen back by 1 cm (under the breast); for a flat chest, the most forward
  // point within 9 % of the height below the armpits.
  const float low_armpit = std::min(armpit_y[0], armpit_y[1]);
  for (int side : {+1, -1}) {
    const float s = static_cast<float>(side);
    const float arm_x = std::abs(side > 0 ? lm.left_armpit.x() : lm.right_armpit.x());
    Vec3f best(0, 0, -1e9f);
    for (float y = low_armpit - 0.01f; y > low_armpit - 0.09f * height; y -= 0.002f) {
      auto sec = torso_section(mesh, y);
      if (!sec) continue;
      Vec3f front(0, 0, -1e9f);
      for (const auto& q : sec->points)
        if (q.x() * s > 0.01f && q.x() * s < arm_x - 0.02f && q.y() > front.z()) front = Vec3f(q.x(), y, q.y());
      if (front.z() > best.z()) best = front;
      if (front.z() < best.z() - 0.01f) break;
    }
    if (best.z() < -1e8f) fail(source, "cannot find the chest");
    (side > 0 ? lm.left_bust : lm.right_bust) = best;
  }
  if (!find_underbust(mesh, lm, height)) fail(source, "no torso below the bust");

  switch (find_waist_and_hip(mesh, lm)) {
    case WaistAndHip::kFound: break;
    case WaistAndHip::kNoWaist: fail(source, "cannot find the waist");
    case WaistAndHip::kNoHips: fail(source, "cannot find the hips");
  }

  // Ankles: the narrowest leg section between 3 % and 12 % of the height; knees at 57 % of the way
  // from ankle to crotch (tibia : femur proportions).
  // Both legs from the same sections.
  std::array<float, 2> best_girth{1e9f, 1e9f};
  std::array<Vec3f, 2> ankles{Vec3f::Zero(), Vec3f::Zero()};
  for (float y = 0.03f * height; y < 0.12f * height; y += 0.003f) {
    auto legs = leg_sections(mesh, y);
    for (size_t k = 0; k < 2; ++k) {
      if (!legs[k]) continue;
      const float g = hull_perimeter(legs[k]->points);
      if (g < best_girth[k]) {
        best_girth[k] = g;
        ankles[k] = Vec3f(legs[k]->centroid.x(), y, legs[k]->centroid.y());
      }
    }
  }
  for (int side : {+1, -1}) {
    const float best = best_girth[side > 0 ? 0 : 1];
    const Vec3f ankle = ankles[side > 0 ? 0 : 1];
    if (best > 1e8f) fail(source, "cannot find the ankles");
    const float knee_y = ankle.y() + 0.57f * (crotch_y - ankle.y());
    auto k = leg_section(mesh, knee_y, side);
    if (!k) fail(source, "cannot find the knees");
    const Vec3f knee(k->centroid.x(), knee_y, k->centroid.y());
    (side > 0 ? lm.left_ankle : lm.right_ankle) = ankle;
    (side > 0 ? lm.left_knee : lm.right_knee) = knee;
  }
  return lm;
}

}  // namespace drape
