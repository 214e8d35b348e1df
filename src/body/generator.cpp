// Bodies from measurements: drape's own parametric generator (no data files).
//
// The surface is implicit: lofted cross-sections (torso, legs, arms, neck) and ellipsoids (head,
// breasts, hands, feet, shoulder caps) arranged around a skeleton in the A-pose and joined with a
// smooth minimum, after the metaball bodies of Cordier, Volino & Magnenat-Thalmann (sec. 3, the
// "reference shape generated with metaballs"). Lofts replace most metaballs because a loft's
// cross-section is a curve whose girth can be set exactly. The surface is polygonised with surface
// nets (body/surface_nets.hpp), which gives a watertight mesh by construction, and the shape is
// fitted to the request by measuring the mesh with the same code that measures any body
// (find_landmarks + measure_body) and correcting each control (ring sizes, heights, lengths) in
// proportion to its error, a few times over. docs/bodies.md explains the choice.
#include <algorithm>
#include <charconv>
#include <limits>
#include <cmath>
#include <utility>
#include <variant>

#include "body/loft.hpp"
#include "body/surface_nets.hpp"
#include "drape/body.hpp"
#include "drape/error.hpp"

namespace drape {

namespace {

using body::Ellipsoid;
using body::Loft;
using body::Ring;
using body::RoundBox;

constexpr float kPi = 3.14159265f;

// The average adults the defaults describe (ISO 8559-1 style measurements, metres).
MeasurementRequest average(Sex sex) {
  if (sex == Sex::Female)
    return {{"height", 1.65f},   {"neck", 0.335f},     {"bust", 0.92f},       {"underbust", 0.78f},
            {"waist", 0.74f},    {"hips", 0.99f},      {"thigh", 0.57f},      {"upper_arm", 0.28f},
            {"wrist", 0.155f},   {"inseam", 0.75f},    {"arm_length", 0.55f}, {"shoulder_width", 0.365f},
            {"back_length", 0.40f}};
  return {{"height", 1.78f},    {"neck", 0.39f},      {"bust", 1.00f},       {"underbust", 0.90f},
          {"waist", 0.86f},     {"hips", 0.99f},      {"thigh", 0.57f},      {"upper_arm", 0.31f},
          {"wrist", 0.175f},    {"inseam", 0.82f},    {"arm_length", 0.60f}, {"shoulder_width", 0.405f},
          {"back_length", 0.45f}};
}

// Plausible ranges per key (metres): outside them the request is refused, not clamped.
struct Range {
  float lo, hi;
};
Range plausible(std::string_view key) {
  if (key == "height") return {1.0f, 2.3f};
  if (key == "neck") return {0.22f, 0.60f};
  if (key == "bust" || key == "underbust" || key == "waist" || key == "hips") return {0.45f, 1.90f};
  if (key == "thigh") return {0.30f, 1.10f};
  if (key == "upper_arm") return {0.16f, 0.60f};
  if (key == "wrist") return {0.10f, 0.30f};
  if (key == "inseam") return {0.40f, 1.10f};
  if (key == "arm_length") return {0.35f, 0.85f};
  if (key == "shoulder_width") return {0.25f, 0.60f};
  return {0.25f, 0.70f};  // back_length
}

// Everything the fitting loop adjusts, plus the fixed choices.
struct Shape {
  Sex sex = Sex::Female;
  float height = 1.65f;
  float crotch_y = 0.75f;
  float waist_y = 1.0f;
  float hip_girth = 0.99f, waist_girth = 0.74f, underbust_girth = 0.78f, chest_girth = 0.92f;
  float bust_protrusion = 0.03f;  // women: how far the breasts stand out of the rib cage
  float shoulder_offset = 0.0f;   // moves the shoulder joints out (+) or in from the chest's side
  float neck_radius = 0.053f;
  float thigh_girth = 0.57f, upper_arm_girth = 0.28f, wrist_girth = 0.155f;
  float arm_scale = 1.0f;
};

// A ring of the given shape (a : front : back) scaled so its perimeter is `girth`.
Ring ring_with_girth(float t, float girth, float a, float front, float back, float shift, float exponent) {
  Ring r{t, a, front, back, shift};
  const float k = girth / body::ring_perimeter(r, exponent);
  return Ring{t, a * k, front * k, back * k, shift};
}

using Primitive = std::variant<Loft, Ellipsoid, RoundBox>;

struct Model {
  std::vector<Primitive> parts;
  std::vector<Bounds> reach;  // each part's bounds grown by its blend radius and a margin
  Bounds box;

  void add(Primitive p) {
    Bounds b = std::visit([](const auto& x) { return x.bounds(); }, p);
    const float blend = std::visit([](const auto& x) { return x.blend; }, p);
    box.extend(b.min);
    box.extend(b.max);
    b.min -= Vec3f::Constant(blend + 0.03f);
    b.max += Vec3f::Constant(blend + 0.03f);
    reach.push_back(b);
    parts.push_back(std::move(p));
  }

  float field(const Vec3f& p) const {
    float f = 1.0f;
    for (size_t i = 0; i < parts.size(); ++i) {
      const Bounds& b = reach[i];
      if ((p.array() < b.min.array()).any() || (p.array() > b.max.array()).any()) continue;
      const float d = std::visit([&](const auto& x) { return x.distance(p); }, parts[i]);
      const float k = std::visit([](const auto& x) { return x.blend; }, parts[i]);
      f = i == 0 ? d : body::smooth_min(f, d, k);
    }
    return f;
  }
};

Ellipsoid sphere(const Vec3f& centre, float radius, float blend) {
  return Ellipsoid{centre, Eigen::Matrix3f::Identity(), Vec3f::Constant(radius), blend};
}

// Lays the primitives out for a shape. All proportions are fractions of the height H unless they
// come from a measurement; they follow standard anthropometric body proportions.
Model build_model(const Shape& s) {
  const float H = s.height;
  const bool female = s.sex == Sex::Female;
  Model model;

  // ---- Heights along the body.
  const float neck_base_y = 0.845f * H;
  const float acromion_y = neck_base_y - 0.035f * H;
  const float armpit_y = acromion_y - 0.075f * H;
  const float bust_y = armpit_y - (female ? 0.035f : 0.045f) * H;
  const float underbust_y = bust_y - (female ? 0.05f : 0.045f) * H;
  const float hip_y = s.crotch_y + 0.055f * H;
  const float crotch_y = s.crotch_y;
  const float waist_y = std::clamp(s.waist_y, hip_y + 0.04f, underbust_y - 0.03f);

  // ---- Torso: a vertical loft from below the crotch to the neck.
  constexpr float kTorsoExponent = 2.3f;
  Loft torso{Vec3f::Zero(), Vec3f::UnitY(), Vec3f::UnitX(), Vec3f::UnitZ(), kTorsoExponent, {}, 0.0f};
  const Ring hip = ring_with_girth(hip_y, s.hip_girth, 1.0f, 0.60f, female ? 0.80f : 0.72f, -0.01f, kTorsoExponent);
  const Ring seat = ring_with_girth(crotch_y + 0.03f, 0.9f * s.hip_girth, 1.0f, 0.58f, female ? 0.74f : 0.68f,
                                    -0.008f, kTorsoExponent);
  // Between hip and waist: the mean girth and an in-between shape, so nothing bulges between them.
  const Ring low = ring_with_girth(0.5f * (hip_y + waist_y), 0.5f * (s.hip_girth + s.waist_girth), 1.0f, 0.66f,
                                   female ? 0.74f : 0.70f, 0.004f, kTorsoExponent);
  // The waist sits forward of the hips and chest (the lumbar curve): the small of the back is
  // hollow and the front under the rib cage comes forward again below the bust.
  // A waist nearly as full as the rib cage is a belly, not a hollow back: it stays over the hips.
  const float lordosis = std::clamp((s.underbust_girth - s.waist_girth) / 0.04f, 0.0f, 1.0f);
  const Ring waist =
      ring_with_girth(waist_y, s.waist_girth, 1.0f, 0.68f, 0.68f, lordosis * 0.016f * H / 1.65f, kTorsoExponent);
  const Ring underbust = ring_with_girth(underbust_y, s.underbust_girth, 1.0f, 0.72f, 0.72f, 0.004f, kTorsoExponent);
  const float rib_girth = female ? 1.03f * s.underbust_girth : 0.98f * s.chest_girth;
  const Ring chest = ring_with_girth(bust_y, rib_girth, 1.0f, female ? 0.70f : 0.76f, 0.72f, -0.01f, kTorsoExponent);
  const float top_girth = female ? std::max(1.04f * s.underbust_girth, 0.9f * s.chest_girth) : s.chest_girth;
  const Ring armpit = ring_with_girth(armpit_y - 0.015f, top_girth, 1.1f, 0.62f, 0.68f, -0.015f,
                                      kTorsoExponent);
  const float rn = s.neck_radius;
  torso.rings = {
      Ring{crotch_y - 0.015f, 0.25f * seat.a, 0.25f * seat.front, 0.25f * seat.back, seat.shift},
      Ring{crotch_y, 0.6f * seat.a, 0.6f * seat.front, 0.65f * seat.back, seat.shift},
      seat,
      hip,
      low,
      waist,
      underbust,
      chest,
      armpit,
      Ring{acromion_y - 0.015f, armpit.a * 0.9f, 0.05f * H / 1.65f, 0.058f * H / 1.65f, -0.03f},
      Ring{neck_base_y - 0.01f, 1.3f * rn, 1.0f * rn, 1.2f * rn, -0.03f},
  };
  model.add(torso);

  // ---- Shoulder girdle: a loft across the body at acromion height, thicker towards the neck, so the
  // shoulder line slopes from the neck to the arms (trapezius) instead of ending square.
  {
    const float half = armpit.a + std::max(0.0f, s.shoulder_offset) + 0.005f;
    Loft girdle{Vec3f(-half, acromion_y - 0.02f, -0.03f), Vec3f::UnitX(), Vec3f::UnitY(), Vec3f::UnitZ(), 2.0f, {}, 0.04f};
    const float k = H / 1.65f;
    girdle.rings = {Ring{0.0f, 0.036f * k, 0.045f * k, 0.05f * k}, Ring{0.35f * half, 0.04f * k, 0.05f * k, 0.055f * k},
                    Ring{half, 0.05f * k, 0.05f * k, 0.06f * k}, Ring{1.65f * half, 0.04f * k, 0.05f * k, 0.055f * k},
                    Ring{2.0f * half, 0.036f * k, 0.045f * k, 0.05f * k}};
    model.add(girdle);
  }

  // ---- Breasts.
  if (female) {
    // Their base grows with the rib cage (the underbust girth), not the height.
    const float front = chest.shift + chest.front;
    const float rib = s.underbust_girth / 0.78f;
    const Vec3f radii = Vec3f(0.075f, 0.06f, 0.05f) * rib;
    for (float side : {1.0f, -1.0f}) {
      const Vec3f centre(side * 0.082f * rib, bust_y, front + s.bust_protrusion - radii.z());
      model.add(Ellipsoid{centre, Eigen::Matrix3f::Identity(), radii, 0.035f});
    }
  }

  // ---- Neck and head.
  const float chin_y = H - 0.135f * H;
  Loft neck{Vec3f(0, neck_base_y - 0.03f, -0.022f), Vec3f::UnitY(), Vec3f::UnitX(), Vec3f::UnitZ(), 2.0f, {}, 0.03f};
  const float neck_len = chin_y + 0.04f * H - neck.origin.y();
  neck.rings = {Ring{0, 1.15f * rn, 1.1f * rn, 1.15f * rn}, Ring{0.045f, rn, rn, rn},
                Ring{neck_len * 0.8f, rn, rn, rn}, Ring{neck_len, 1.05f * rn, 1.05f * rn, 1.05f * rn}};
  model.add(neck);
  model.add(Ellipsoid{Vec3f(0, H - 0.058f * H, -0.004f * H), Eigen::Matrix3f::Identity(),
                      Vec3f(0.046f, 0.058f, 0.056f) * H, 0.03f});
  model.add(Ellipsoid{Vec3f(0, H - 0.103f * H, 0.014f * H), Eigen::Matrix3f::Identity(),
                      Vec3f(0.034f, 0.032f, 0.036f) * H, 0.03f});
  model.add(Ellipsoid{Vec3f(0, H - 0.075f * H, 0.048f * H), Eigen::Matrix3f::Identity(),
                      Vec3f(0.008f, 0.017f, 0.011f) * H, 0.012f});

  // ---- Legs: from the hip joints to the ankles, slightly apart (A-pose stance).
  // Thighs narrower side to side than front to back; their outer sides stay inside the hips (so the
  // hip ring, not the thighs, sets the hip girth) and a small gap is left between them at the crotch.
  const float thigh_half_width = ring_with_girth(0.0f, s.thigh_girth, 0.82f, 1.0f, 1.08f, 0.0f, 2.0f).a;
  const float leg_x = std::max(thigh_half_width + 0.008f, hip.a - 1.05f * thigh_half_width);
  const float ankle_y = 0.065f * H;
  const float knee_y = ankle_y + 0.57f * (crotch_y - ankle_y);
  for (float side : {1.0f, -1.0f}) {
    const Vec3f top(side * leg_x, crotch_y + 0.07f, hip.shift + 0.005f);
    const Vec3f bottom(side * (leg_x + 0.02f), 0.03f * H, -0.02f);
    const Vec3f axis = (bottom - top).normalized();
    const Vec3f lateral = Vec3f::UnitZ().cross(axis).normalized() * side;
    Loft leg{top, axis, lateral, Vec3f::UnitZ(), 2.0f, {}, 0.04f};
    auto t_at = [&](float y) { return (top.y() - y) / -axis.y(); };
    const float T = s.thigh_girth;
    leg.rings = {
        ring_with_girth(0.0f, 0.85f * T, 0.85f, 1.0f, 1.1f, 0.0f, 2.0f),
        ring_with_girth(t_at(crotch_y - 0.02f), T, 0.82f, 1.0f, 1.08f, 0.0f, 2.0f),
        ring_with_girth(t_at(0.5f * (crotch_y + knee_y)), 0.82f * T, 1.0f, 1.0f, 1.05f, 0.0f, 2.0f),
        ring_with_girth(t_at(knee_y + 0.04f), 0.64f * T, 1.0f, 1.0f, 0.95f, 0.0f, 2.0f),
        ring_with_girth(t_at(knee_y - 0.02f), 0.62f * T, 1.0f, 0.95f, 1.0f, -0.005f, 2.0f),
        ring_with_girth(t_at(knee_y - 0.11f), 0.64f * T, 0.9f, 0.8f, 1.15f, -0.01f, 2.0f),
        ring_with_girth(t_at(ankle_y + 0.05f), 0.42f * T, 0.9f, 0.85f, 1.0f, -0.005f, 2.0f),
        ring_with_girth(t_at(ankle_y), 0.38f * T, 1.0f, 1.0f, 1.0f, 0.0f, 2.0f),
        ring_with_girth(t_at(0.035f * H), 0.42f * T, 1.0f, 1.0f, 1.1f, 0.0f, 2.0f),
    };
    model.add(leg);
    // Foot: an ellipsoid with a flat sole on y = 0, toes forward.
    const Vec3f foot_centre(side * (leg_x + 0.025f), 0.018f * H, -0.02f + 0.033f * H);
    Ellipsoid foot{foot_centre, Eigen::Matrix3f::Identity(), Vec3f(0.024f, 0.036f, 0.078f) * H, 0.03f, 0.0f};
    model.add(foot);
  }

  // ---- Arms: 45 degrees down in the coronal plane, palms towards the thighs.
  const float ua_r = s.upper_arm_girth / (2 * kPi);
  const float top_r = 1.2f * ua_r;
  const float upper_len = 0.172f * H * s.arm_scale;
  const float fore_len = 0.150f * H * s.arm_scale;
  const float hand_len = 0.108f * H;
  const float c45 = std::sqrt(0.5f);
  for (float side : {1.0f, -1.0f}) {
    const Vec3f joint(side * (armpit.a + 0.75f * top_r + s.shoulder_offset), armpit_y + 0.75f * top_r, armpit.shift);
    const Vec3f axis(side * c45, -c45, 0.0f);
    const Vec3f lateral = Vec3f::UnitZ().cross(axis).normalized() * side;
    Loft arm{joint, axis, lateral, Vec3f::UnitZ(), 2.0f, {}, 0.03f};
    const float U = s.upper_arm_girth, W = s.wrist_girth;
    arm.rings = {
        ring_with_girth(0.0f, 2 * kPi * top_r, 1.0f, 1.0f, 1.0f, 0.0f, 2.0f),
        ring_with_girth(0.5f * upper_len, U, 1.0f, 1.0f, 1.05f, 0.0f, 2.0f),
        // The elbow and forearm stay fuller than the wrist, so the wrist remains the narrowest section.
        ring_with_girth(upper_len, std::max(0.8f * U, 1.2f * W), 1.0f, 1.0f, 1.0f, 0.0f, 2.0f),
        ring_with_girth(upper_len + 0.3f * fore_len, std::max(0.87f * U, 1.3f * W), 0.95f, 1.0f, 1.0f, 0.0f, 2.0f),
        ring_with_girth(upper_len + fore_len, W, 0.75f, 1.0f, 1.0f, 0.0f, 2.0f),
        ring_with_girth(upper_len + fore_len + 0.02f, 1.05f * W, 0.7f, 1.0f, 1.0f, 0.0f, 2.0f),
    };
    model.add(arm);
    model.add(sphere(joint + 0.1f * top_r * Vec3f(side, 0.0f, 0.0f), 1.0f * top_r, 0.05f));
    // Hand: a flattened ellipsoid, thin across the palm (lateral), wide front to back.
    Eigen::Matrix3f frame;
    frame.col(0) = lateral;
    frame.col(1) = axis;
    frame.col(2) = Vec3f::UnitZ();
    const Vec3f wrist = joint + (upper_len + fore_len) * axis;
    model.add(RoundBox{wrist + 0.5f * hand_len * axis, frame,
                       Vec3f(0.017f * H / 1.65f, 0.5f * hand_len, 0.043f * H / 1.65f), 0.016f * H / 1.65f, 0.02f});
  }
  return model;
}

Shape initial_shape(Sex sex, const MeasurementRequest& r) {
  Shape s;
  s.sex = sex;
  s.height = r.at("height");
  s.crotch_y = r.at("inseam");
  s.waist_y = 0.845f * s.height - 0.97f * r.at("back_length");
  s.hip_girth = r.at("hips");
  s.waist_girth = r.at("waist");
  s.underbust_girth = r.at("underbust");
  s.chest_girth = r.at("bust");
  s.bust_protrusion = sex == Sex::Female ? std::max(0.004f, 0.5f * (r.at("bust") - 1.03f * r.at("underbust"))) : 0.0f;
  s.neck_radius = r.at("neck") / (2 * kPi);
  s.thigh_girth = r.at("thigh");
  s.upper_arm_girth = r.at("upper_arm");
  s.wrist_girth = r.at("wrist");
  s.arm_scale = r.at("arm_length") / (0.345f * s.height);
  return s;
}

// One correction of the controls of the requested measurements from the measured body. Girths
// scale their rings by target / measured, lengths move by the difference; each step is clamped so
// that one odd measurement cannot throw the shape off.
void correct(Shape& s, const MeasurementRequest& full, const MeasurementRequest& given, const Measurements& m) {
  // Shoulder width and back length move the chest and waist rings; they are only fitted on request.
  auto wanted = [&](std::string_view key) {
    return (key != "shoulder_width" && key != "back_length" && key != "underbust") ? full.count(key) > 0
                                                                                    : given.count(key) > 0;
  };
  const MeasurementRequest& target = full;
  auto ratio = [&](const char* key, float measured) {
    return wanted(key) && measured > 0 ? std::clamp(target.at(key) / measured, 0.9f, 1.1f) : 1.0f;
  };
  auto shift = [&](const char* key, float measured) {
    return wanted(key) ? std::clamp(target.at(key) - measured, -0.03f, 0.03f) : 0.0f;
  };
  s.neck_radius *= ratio("neck", m.neck);
  if (s.sex == Sex::Female) {
    s.bust_protrusion = std::max(0.002f, s.bust_protrusion + 0.3f * shift("bust", m.bust));
  } else {
    s.chest_girth *= ratio("bust", m.bust);
  }
  s.underbust_girth *= ratio("underbust", m.underbust);
  s.waist_girth *= ratio("waist", m.waist);
  s.hip_girth *= ratio("hips", m.hips);
  s.thigh_girth *= ratio("thigh", m.thigh);
  s.upper_arm_girth *= ratio("upper_arm", m.upper_arm);
  s.wrist_girth *= ratio("wrist", m.wrist);
  s.crotch_y += shift("inseam", m.inseam);
  s.arm_scale *= ratio("arm_length", m.arm_length);
  // Both shoulders move. Narrower than the chest allows would push the arms into the torso: the
  // shoulders come in by at most half the deltoid's radius.
  s.shoulder_offset = std::max(s.shoulder_offset + shift("shoulder_width", m.shoulder_width),
                               -0.5f * 1.2f * s.upper_arm_girth / (2 * kPi));
  s.waist_y -= 0.7f * shift("back_length", m.back_length);
}

Mesh polygonise_model(const Model& model, float step) {
  const body::ScalarField field = [&model](const Vec3f& p) { return model.field(p); };
  // A grid that happens to pinch the surface somewhere gives a non-manifold mesh; a slightly
  // shifted grid does not.
  for (int attempt = 0; attempt < 6; ++attempt) {
    Bounds box = model.box;
    box.min -= Vec3f::Constant(0.37f * step * static_cast<float>(attempt));
    Mesh mesh = body::polygonise(field, box, {step, 3, 2});
    if (!mesh.positions.empty()) return mesh;
  }
  throw std::runtime_error("body generator: could not polygonise a closed surface");
}

// How far a body is from the request: the worst key, and the sum of what each key misses beyond
// 8 mm. Shapes are ranked by the sum first, so that one key the shape cannot reach (it stays off
// whatever the controls do) does not hide the others.
struct FitError {
  float worst = 0;
  float excess = 0;
  bool operator<(const FitError& o) const { return excess != o.excess ? excess < o.excess : worst < o.worst; }
};

FitError fit_error(const MeasurementRequest& given, const Measurements& m) {
  FitError e;
  for (const auto& row : measurement_table()) {
    const auto it = given.find(row.key);
    if (it == given.end()) continue;
    const float off = std::abs(it->second - m.*row.field);
    e.worst = std::max(e.worst, off);
    e.excess += std::max(0.0f, off - 0.008f);
  }
  return e;
}

}  // namespace

MeasurementRequest default_measurements(Sex sex) { return average(sex); }

MeasurementRequest parse_measurements(std::string_view text) {
  MeasurementRequest out;
  size_t start = 0;
  while (start <= text.size()) {
    const size_t end = std::min(text.find(',', start), text.size());
    const std::string_view item = text.substr(start, end - start);
    start = end + 1;
    if (item.empty()) {
      if (end == text.size()) break;
      continue;
    }
    const size_t eq = item.find('=');
    if (eq == std::string_view::npos)
      throw InputError("--measurements", "expected key=value, got '" + std::string(item) + "'");
    // `chest` is what a man's size label calls the girth drape measures as `bust` (ISO 8559-1 5.3.5).
    const std::string typed(item.substr(0, eq));
    const std::string key = typed == "chest" ? std::string("bust") : typed;
    const std::string_view number = item.substr(eq + 1);
    const auto& table = measurement_table();
    if (std::none_of(table.begin(), table.end(), [&](const MeasurementInfo& m) { return m.key == key; })) {
      std::string known;
      for (const auto& m : table) known += (known.empty() ? "" : ", ") + std::string(m.key);
      throw InputError("--measurements", "unknown measurement '" + key + "' (known: " + known + "; chest = bust)");
    }
    float value = 0;
    const auto [ptr, ec] = std::from_chars(number.data(), number.data() + number.size(), value);
    if (ec != std::errc() || ptr != number.data() + number.size() || !std::isfinite(value))
      throw InputError("--measurements", "'" + typed + "' is not a number: '" + std::string(number) + "'");
    const Range range = plausible(key);
    if (value < range.lo || value > range.hi)
      throw InputError("--measurements", typed + "=" + std::string(number) + " is outside " + std::to_string(range.lo) +
                                             "-" + std::to_string(range.hi) + " m (values are in metres)");
    if (out.count(key))
      throw InputError("--measurements", "'" + key + "' given twice" + (key == "bust" ? " (chest is bust)" : ""));
    out[key] = value;
  }
  return out;
}

Body make_body(Sex sex, const MeasurementRequest& given, const BodyBuildOptions& options) {
  // Complete the request: lengths scale with the height, girths with the given torso girths.
  const MeasurementRequest base = average(sex);
  MeasurementRequest r = given;
  const float height_ratio = given.count("height") ? given.at("height") / base.at("height") : 1.0f;
  float girth_ratio = 0;
  int girths = 0;
  for (const char* key : {"bust", "waist", "hips"})
    if (given.count(key)) {
      girth_ratio += given.at(key) / base.at(key);
      ++girths;
    }
  girth_ratio = girths ? girth_ratio / static_cast<float>(girths) : height_ratio;
  for (const auto& row : measurement_table()) {
    const std::string key(row.key);
    if (r.count(key)) continue;
    float ratio = row.circumference ? girth_ratio : height_ratio;
    if (key == "underbust" && given.count("bust")) ratio = given.at("bust") / base.at("bust");
    if (key == "thigh" && given.count("hips")) ratio = given.at("hips") / base.at("hips");
    r[key] = base.at(key) * ratio;
  }
  // An unrequested underbust stays above the waist: a rib cage narrower than the belly would move
  // the waist (the narrowest section) up under the chest.
  if (!given.count("underbust")) r["underbust"] = std::max(r.at("underbust"), std::min(r.at("bust"), r.at("waist") + 0.02f));
  if (r.at("underbust") > r.at("bust"))
    throw InputError("--measurements", "underbust is larger than bust");
  if (r.at("waist") > 1.5f * r.at("hips") || r.at("hips") > 2.2f * r.at("waist"))
    throw InputError("--measurements", "waist and hips are too far apart to build a body");
  if (r.at("inseam") > 0.56f * r.at("height") || r.at("inseam") < 0.36f * r.at("height"))
    throw InputError("--measurements", "inseam must be 36-56 % of the height");

  // Fit on a coarse grid (fast), keep the best shape, then polygonise finely and correct once more
  // if the fine mesh measures differently.
  Shape shape = initial_shape(sex, r);
  Shape best_shape = shape;
  FitError best_error{std::numeric_limits<float>::max(), std::numeric_limits<float>::max()};
  const float coarse = std::max(options.grid_step, 0.014f);
  for (int it = 0; it < options.max_fit_iterations; ++it) {
    const Mesh mesh = polygonise_model(build_model(shape), coarse);
    const Measurements m = measure_body(mesh, find_landmarks(mesh, "generated body"));
    const FitError error = fit_error(given, m);
    if (error < best_error) {
      best_error = error;
      best_shape = shape;
    }
    if (error.worst < 0.002f) break;
    correct(shape, r, given, m);
  }
  Mesh best_mesh;
  shape = best_shape;
  best_error = {std::numeric_limits<float>::max(), std::numeric_limits<float>::max()};
  for (int pass = 0; pass < 2; ++pass) {
    Mesh mesh = polygonise_model(build_model(shape), options.grid_step);
    const Measurements m = measure_body(mesh, find_landmarks(mesh, "generated body"));
    const FitError error = fit_error(given, m);
    if (error < best_error) {
      best_error = error;
      best_mesh = std::move(mesh);
    }
    if (error.worst < 0.004f) break;
    correct(shape, r, given, m);
  }
  return finish_generated_body(sex, std::move(best_mesh));
}

Body finish_generated_body(Sex sex, Mesh mesh) {
  Body body;
  body.sex = sex;
  body.mesh = std::move(mesh);
  body.mesh.name = "body";
  analyse_body(body, "generated body");
  rig_body(body);
  return body;
}

Body generate_default_body(Sex sex, const BodyBuildOptions& options) {
  return make_body(sex, default_body_request(sex), options);
}

}  // namespace drape
