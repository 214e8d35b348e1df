// Fit per body region (drape/fit_map.hpp, docs/fit.md): girth lines at the body's bust/chest,
// waist, hips, thigh and upper arm, where the garment's girth is measured on its pattern (the flat
// length of the garment cut by the body's line) against the body's girth; zones at the neck and the
// shoulders, judged by the strain the body holds the cloth at; and lengths (sleeve, leg, garment).
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <optional>

#include <nlohmann/json.hpp>

#include "body/analysis.hpp"
#include "drape/fit_map.hpp"

namespace drape {

std::string_view to_string(FitVerdict verdict) {
  switch (verdict) {
    case FitVerdict::tight: return "tight";
    case FitVerdict::good: return "good";
    case FitVerdict::loose: return "loose";
    case FitVerdict::short_: return "short";
    case FitVerdict::long_: return "long";
  }
  return "good";
}

namespace {

constexpr float kBand = 0.03f;            // m either side of a line: the region's triangles and skin
constexpr float kContactMargin = 0.008f;  // m beyond the collision thickness that still counts as contact

// A horizontal or limb girth line on the body.
struct Line {
  const char* region;
  Vec3f centre, normal;
  float reach;        // m around the centre that belongs to the line
  float body_girth;   // m
  size_t loose_index; // into FitThresholds::loose_fraction
  int side;           // 0: torso (sleeves excluded), +1: the left limb (x > 0) only
  BodyPart part;      // body vertices whose pressure counts
};

float peak_pressure(const Body& body, const PressureMap& map, const Vec3f& centre, const Vec3f& normal, float reach,
                    BodyPart part) {
  float peak = 0;
  for (size_t v = 0; v < body.mesh.positions.size(); ++v) {
    if (!body.parts.empty() && body.parts[v] != part) continue;
    const Vec3f d = body.mesh.positions[v] - centre;
    if (std::abs(d.dot(normal)) > kBand || d.norm() > reach) continue;
    peak = std::max(peak, map.pressure[v]);
  }
  return peak;
}

float percentile(std::vector<float>& v, double q) {
  if (v.empty()) return 0.0f;
  const auto k = static_cast<size_t>(q * static_cast<double>(v.size() - 1));
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(k), v.end());
  return v[k];
}

std::string cm(float metres) { return fmt::format("{:.1f} cm", 100.0f * metres); }


// The body's girth lines (bust, waist, hips, thighs, upper arm) with the body's girth at each, as
// a tape lies round it (body analysis: the convex hull of the section). The thighs' line is moved
// per garment (cut_at_line).
std::array<Line, 5> girth_lines(const Body& body, const body::Slicer& slicer) {
  const Landmarks& lm = body.landmarks;
  const Vec3f up = Vec3f::UnitY();
  const float bust_y = 0.5f * (lm.left_bust.y() + lm.right_bust.y());
  const Vec3f arm_mid = 0.5f * (lm.left_shoulder + lm.left_elbow);
  const Vec3f arm_axis = (lm.left_elbow - lm.left_shoulder).normalized();
  const float thigh_y = lm.crotch.y() - 0.06f;
  return {{
      {"bust", Vec3f(0, bust_y, 0), up, 0.45f, body::torso_girth(slicer, bust_y), 0, 0, BodyPart::Torso},
      {"waist", Vec3f(0, lm.waist.y(), 0), up, 0.45f, body::torso_girth(slicer, lm.waist.y()), 1, 0, BodyPart::Torso},
      {"hips", Vec3f(0, lm.hip.y(), 0), up, 0.45f, body::torso_girth(slicer, lm.hip.y()), 2, 0, BodyPart::Torso},
      {"thighs", Vec3f(lm.left_knee.x(), thigh_y, lm.left_knee.z()), up, 0.2f, 0.0f, 3, 1, BodyPart::LeftLeg},
      {"upper_arm", arm_mid, arm_axis, 0.12f, body::limb_girth(slicer, arm_mid, arm_axis), 4, 1, BodyPart::LeftArm},
  }};
}

struct GirthCut {
  RegionFit region;
  Line line;                      // where it was cut
  std::vector<uint8_t> selected;  // the garment's triangles the line's region counts
};

// The garment cut at one girth line, with its ease and verdict (tight / good / loose); nullopt
// where the garment does not go round the body there. `judge_seams`: a seam open across the line
// makes it tight (a dressed garment; not the placed panels, whose seams are all open).
std::optional<GirthCut> cut_at_line(const body::Slicer& slicer, const FitGarment& in, Line line, const FitThresholds& th,
                                    float strain_limit, bool judge_seams) {
  const ClothModel& model = *in.model;
  const size_t tris = model.triangles.size();
  if (std::string_view(line.region) == "thighs") {
    // Trousers only (panels on the legs): 6 cm below the body's crotch, or 2 cm below the
    // garment's own crotch (the lowest pair sewing a left-leg panel to a right-leg one) when it
    // hangs lower, so that the cut goes round one leg, not across the seat.
    if (in.on_leg.empty()) return std::nullopt;
    bool legs = false;
    for (uint8_t leg : in.on_leg) legs = legs || leg == 1;
    if (!legs) return std::nullopt;
    float garment_crotch = std::numeric_limits<float>::infinity();
    for (const auto& [a, b] : in.seam_pairs)
      if (in.on_leg[a] != 0 && in.on_leg[b] != 0 && in.on_leg[a] != in.on_leg[b])
        garment_crotch = std::min(garment_crotch, std::min(in.x[a].y(), in.x[b].y()));
    const float y = std::min(line.centre.y(), garment_crotch - 0.02f);
    const auto section = body::leg_section(slicer, y, +1);
    if (!section) return std::nullopt;
    line.centre.y() = y;
    line.body_girth = body::hull_perimeter(section->points);
  }
  GirthCut out{{}, line, std::vector<uint8_t>(tris)};
  const auto arm = [&](uint32_t v) { return !in.on_arm.empty() && in.on_arm[v] != 0; };
  for (size_t t = 0; t < tris; ++t) {
    const Tri& tri = model.triangles[t];
    const bool left_leg = !in.on_leg.empty() && in.on_leg[tri[0]] == 1 && in.on_leg[tri[1]] == 1 && in.on_leg[tri[2]] == 1;
    const Vec3f centroid = (in.x[tri[0]] + in.x[tri[1]] + in.x[tri[2]]) / 3.0f;
    out.selected[t] = line.side == 0                             ? !(arm(tri[0]) || arm(tri[1]) || arm(tri[2]))
                      : std::string_view(line.region) == "thighs" ? left_leg
                                                                  : centroid.x() > 0;
  }
  const GarmentCut cut = cut_garment(model, in.x, line.centre, line.normal, line.reach, out.selected);
  // The garment must go all the way round the body there (a hem just at the line does not).
  if (cut.segments == 0 || line.body_girth <= 0 || cut.draped_m < 0.9f * line.body_girth) return std::nullopt;
  RegionFit& r = out.region;
  r.region = line.region;
  r.girth = true;
  r.body_m = line.body_girth;
  r.garment_m = cut.pattern_m;
  r.draped_m = cut.draped_m;
  r.ease_m = cut.pattern_m - line.body_girth;
  r.hoop_strain = cut.pattern_m > 0 ? cut.draped_m / cut.pattern_m - 1.0f : 0.0f;
  if (judge_seams) {
    for (const auto& [a, b] : in.seam_pairs) {
      const Vec3f mid = 0.5f * (in.x[a] + in.x[b]);
      if (std::abs((mid - line.centre).dot(line.normal)) > th.open_seam_band || (mid - line.centre).norm() > line.reach) continue;
      if (line.side != 0 && mid.x() <= 0) continue;
      if (line.side == 0 && (arm(a) || arm(b))) continue;
      r.open_seam_m = std::max(r.open_seam_m, (in.x[a] - in.x[b]).norm());
    }
    if (r.open_seam_m <= th.open_seam_m) r.open_seam_m = 0;
  }
  const float loose = th.loose_fraction[line.loose_index] * line.body_girth;
  if (r.open_seam_m > 0) {
    r.verdict = FitVerdict::tight;
    r.reason = fmt::format("{} is tight: the garment does not close round the body there (a seam stays {:.0f} mm open; ease {})",
                           r.region, 1e3f * r.open_seam_m, cm(r.ease_m));
  } else if (r.ease_m < 0) {
    r.verdict = FitVerdict::tight;
    r.reason = judge_seams
                   ? fmt::format("{} is tight: the garment is {} smaller than the body ({} round) and is stretched {:.1f} % there (limit {:.0f} %)",
                                 r.region, cm(-r.ease_m), cm(r.body_m), 100 * r.hoop_strain, 100 * strain_limit)
                   : fmt::format("{} is tight: the pattern is {} smaller than the body ({} round)", r.region, cm(-r.ease_m),
                                 cm(r.body_m));
  } else if (r.ease_m > loose) {
    r.verdict = FitVerdict::loose;
    r.reason = fmt::format("{} is loose: ease {} (more than {})", r.region, cm(r.ease_m), cm(loose));
  } else {
    r.reason = fmt::format("{}: ease {}", r.region, cm(r.ease_m));
  }
  return out;
}

// Sleeve, leg and garment lengths of a garment where it lies (`regions` already has its girth
// lines: a garment with a thighs line has legs).
void add_lengths(const Body& body, const FitGarment& in, std::vector<RegionFit>& regions) {
  const Landmarks& lm = body.landmarks;
  const Measurements& m = body.measurements;
    const Vec3f wrist_axis = (lm.left_wrist - lm.left_shoulder).normalized();
    float sleeve = -1;
    bool any_arm = false;
    for (size_t i = 0; i < in.x.size(); ++i)
      if (!in.on_arm.empty() && in.on_arm[i] && in.x[i].x() > 0) {
        any_arm = true;
        sleeve = std::max(sleeve, (in.x[i] - lm.left_shoulder).dot(wrist_axis));
      }
    if (any_arm && m.arm_length > 0) {
      RegionFit r;
      r.region = "sleeve_length";
      r.body_m = m.arm_length;
      r.garment_m = sleeve;
      r.ease_m = sleeve - m.arm_length;
      const float hand = (lm.left_fingertip - lm.left_shoulder).dot(wrist_axis);
      r.verdict = sleeve > hand ? FitVerdict::long_ : FitVerdict::good;
      r.reason = sleeve > hand ? fmt::format("sleeves are long: they cover the hand ({} past the wrist)", cm(r.ease_m))
                 : r.ease_m >= 0 ? fmt::format("sleeves end {} past the wrist", cm(r.ease_m))
                                 : fmt::format("sleeves end {} above the wrist", cm(-r.ease_m));
      regions.push_back(std::move(r));
    }
    float top = -1e9f, bottom = 1e9f, leg_bottom = 1e9f;
    for (const Vec3f& p : in.x) {
      top = std::max(top, p.y());
      bottom = std::min(bottom, p.y());
    }
    const bool legged = std::any_of(regions.begin(), regions.end(), [](const RegionFit& r) { return r.region == "thighs"; });
    if (legged) {
      for (const Vec3f& p : in.x)
        if (p.x() > 0 && p.y() < lm.crotch.y()) leg_bottom = std::min(leg_bottom, p.y());
      RegionFit r;
      r.region = "leg_length";
      r.body_m = m.inseam;
      r.garment_m = lm.crotch.y() - leg_bottom;
      r.ease_m = r.garment_m - m.inseam;
      r.verdict = leg_bottom < 0.01f ? FitVerdict::long_ : FitVerdict::good;
      r.reason = leg_bottom < 0.01f ? std::string("legs are long: the hems lie on the floor")
                                    : fmt::format("legs end {} above the floor", cm(leg_bottom));
      regions.push_back(std::move(r));
    }
    if (top > bottom) {
      RegionFit r;
      r.region = "garment_length";
      r.garment_m = top - bottom;
      r.body_m = m.height;
      r.ease_m = 0;
      // Where the hem ends, by the nearest landmark at or below it.
      const std::array<std::pair<const char*, float>, 6> marks{{{"the waist", lm.waist.y()},
                                                                 {"the hips", lm.hip.y()},
                                                                 {"the crotch", lm.crotch.y()},
                                                                 {"the knee", lm.left_knee.y()},
                                                                 {"the ankle", lm.left_ankle.y()},
                                                                 {"the floor", 0.0f}}};
      const auto& mark = *std::min_element(marks.begin(), marks.end(), [&](const auto& a, const auto& b) {
        return std::abs(a.second - bottom) < std::abs(b.second - bottom);
      });
      const float off = bottom - mark.second;
      r.verdict = bottom < 0.01f ? FitVerdict::long_ : FitVerdict::good;
      r.reason = r.verdict == FitVerdict::long_ ? std::string("long: the garment lies on the floor")
                 : fmt::format("{} long, the hem {} {} {}", cm(r.garment_m), cm(std::abs(off)),
                               off >= 0 ? "above" : "below", mark.first);
      regions.push_back(std::move(r));
    }
}
}  // namespace

std::vector<const RegionFit*> FitAnalysis::worst_first() const {
  std::vector<const RegionFit*> out;
  for (const GarmentFit& g : garments)
    for (const RegionFit& r : g.regions) out.push_back(&r);
  const auto rank = [](FitVerdict v) {
    switch (v) {
      case FitVerdict::tight: return 0;
      case FitVerdict::loose: return 1;
      case FitVerdict::short_:
      case FitVerdict::long_: return 2;
      case FitVerdict::good: return 3;
    }
    return 3;
  };
  std::stable_sort(out.begin(), out.end(), [&](const RegionFit* a, const RegionFit* b) { return rank(a->verdict) < rank(b->verdict); });
  return out;
}

FitAnalysis analyse_fit(const Body& body, std::span<const FitGarment> garments, const Collider& body_collider,
                        const FitThresholds& th) {
  FitAnalysis fit;
  fit.pressure = empty_pressure_map(body.mesh);
  const Landmarks& lm = body.landmarks;
  const Vec3f gravity(0.0f, -9.81f, 0.0f);

  // A garment whose simulation went non-finite has no fit to measure.
  const auto finite = [](const FitGarment& in) {
    return std::all_of(in.x.begin(), in.x.end(), [](const Vec3f& p) { return p.allFinite(); });
  };
  // Maps first: the pressure of every garment adds up on the body.
  for (const FitGarment& in : garments) {
    GarmentFit g;
    g.name = in.name;
    g.size = in.size;
    const ClothModel& model = *in.model;
    g.strain_limit = model.fabric.strain_threshold;
    if (!finite(in)) {
      fit.garments.push_back(std::move(g));
      continue;
    }
    g.strain = triangle_strain(model, in.x, in.warp);
    g.strain_percent = strain_percent_of_limit(model, g.strain, g.strain_limit);
    for (float s : g.strain_percent) g.peak_strain_percent = std::max(g.peak_strain_percent, s);
    g.contacts = contact_forces(model, in.x, in.seam_pairs, body_collider, gravity,
                                model.fabric.collision_thickness + kContactMargin);
    add_pressure(fit.pressure, body.mesh, g.contacts);
    fit.garments.push_back(std::move(g));
  }
  finish_pressure(fit.pressure, body.mesh);
  for (float p : fit.pressure.pressure) fit.peak_pressure_pa = std::max(fit.peak_pressure_pa, p);

  const body::Slicer slicer(body.mesh);
  const std::array<Line, 5> lines = girth_lines(body, slicer);

  for (size_t k = 0; k < garments.size(); ++k) {
    const FitGarment& in = garments[k];
    GarmentFit& g = fit.garments[k];
    if (!finite(in)) continue;
    const ClothModel& model = *in.model;
    const size_t tris = model.triangles.size();
    const auto on_arm = [&](const Tri& t) { return !in.on_arm.empty() && (in.on_arm[t[0]] || in.on_arm[t[1]] || in.on_arm[t[2]]); };
    const auto centroid = [&](const Tri& t) { return Vec3f((in.x[t[0]] + in.x[t[1]] + in.x[t[2]]) / 3.0f); };
    // Peak strain (% of limit) over the triangles selected whose centroid passes `where`: the 95th
    // percentile, since the very highest are single triangles at an outline or an open seam.
    float bias = 0;  // the last zone's peak bias stretch
    std::vector<float> values, biases;
    const auto zone_strain = [&](const std::vector<uint8_t>& selected, auto&& where, size_t* count, size_t* at_limit) {
      values.clear();
      biases.clear();
      for (size_t t = 0; t < tris; ++t) {
        if (!selected[t] || !g.strain.measured[t] || !where(centroid(model.triangles[t]))) continue;
        biases.push_back(g.strain.bias[t]);
        const float s = 100.0f * std::max(0.0f, g.strain.along_grain(t)) / g.strain_limit;
        values.push_back(s);
        if (count) ++*count;
        if (at_limit && s >= th.zone_limit_percent) ++*at_limit;
      }
      bias = percentile(biases, 0.95);
      return percentile(values, 0.95);
    };

    // Neck and shoulders: zones, tight when the body holds much of the cloth there at the limit.
    {
      std::vector<uint8_t> torso(tris);
      for (size_t t = 0; t < tris; ++t) torso[t] = !on_arm(model.triangles[t]);
      const float neck_half = 0.25f * (lm.left_shoulder.x() - lm.right_shoulder.x());
      struct Zone {
        const char* region;
        std::function<bool(const Vec3f&)> garment_where, body_where;
      };
      const float neck_bottom = lm.neck_base.y() - 0.04f;
      const auto near_shoulder = [&](const Vec3f& p) {
        return (p - lm.left_shoulder).norm() < 0.08f || (p - lm.right_shoulder).norm() < 0.08f;
      };
      const std::array<Zone, 2> zones{{
          {"neck", [&](const Vec3f& p) { return p.y() > neck_bottom && std::abs(p.x()) < neck_half; },
           [&](const Vec3f& p) { return p.y() > neck_bottom && p.y() < lm.neck.y() + 0.03f && std::abs(p.x()) < neck_half; }},
          {"shoulders", near_shoulder, near_shoulder},
      }};
      for (const Zone& z : zones) {
        size_t count = 0, at_limit = 0;
        std::vector<uint8_t> all(tris, 1);
        const std::vector<uint8_t>& selected = std::string_view(z.region) == "neck" ? torso : all;
        const float peak = zone_strain(selected, z.garment_where, &count, &at_limit);
        if (count < 4) continue;  // the garment does not reach this zone
        RegionFit r;
        r.region = z.region;
        r.peak_strain_percent = peak;
        r.peak_bias_strain = bias;
        for (size_t v = 0; v < body.mesh.positions.size(); ++v)
          if (z.body_where(body.mesh.positions[v])) r.peak_pressure_pa = std::max(r.peak_pressure_pa, fit.pressure.pressure[v]);
        const float fraction = static_cast<float>(at_limit) / static_cast<float>(count);
        r.verdict = fraction >= th.zone_tight_fraction ? FitVerdict::tight : FitVerdict::good;
        r.reason = fmt::format("{}{}: {:.0f} % of the cloth there is stretched to {:.0f} % of its limit or more (peak {:.0f} %)",
                               r.region, r.verdict == FitVerdict::tight ? " is tight" : "", 100 * fraction,
                               th.zone_limit_percent, peak);
        g.regions.push_back(std::move(r));
      }
    }

    // Girth lines.
    for (const Line& base : lines) {
      std::optional<GirthCut> cut = cut_at_line(slicer, in, base, th, g.strain_limit, true);
      if (!cut) continue;
      RegionFit& r = cut->region;
      const Line& line = cut->line;
      r.peak_strain_percent = zone_strain(cut->selected, [&](const Vec3f& p) {
        return std::abs((p - line.centre).dot(line.normal)) < kBand && (p - line.centre).norm() < line.reach;
      }, nullptr, nullptr);
      r.peak_bias_strain = bias;
      r.peak_pressure_pa = peak_pressure(body, fit.pressure, line.centre, line.normal, line.reach, line.part);
      g.regions.push_back(std::move(r));
    }

    add_lengths(body, in, g.regions);
  }
  return fit;
}

std::vector<RegionFit> pattern_measurements(const Body& body, const FitGarment& placed, const FitThresholds& thresholds) {
  std::vector<RegionFit> out;
  const body::Slicer slicer(body.mesh);
  for (const Line& line : girth_lines(body, slicer))
    if (auto cut = cut_at_line(slicer, placed, line, thresholds, placed.model->fabric.strain_threshold, false))
      out.push_back(std::move(cut->region));
  add_lengths(body, placed, out);
  return out;
}

std::string fit_json(const FitAnalysis& fit) {
  nlohmann::ordered_json out;
  nlohmann::ordered_json garments = nlohmann::ordered_json::array();
  for (const GarmentFit& g : fit.garments) {
    nlohmann::ordered_json regions = nlohmann::ordered_json::array();
    for (const RegionFit& r : g.regions) {
      nlohmann::ordered_json j{{"region", r.region}, {"verdict", std::string(to_string(r.verdict))}};
      if (r.girth) {
        j["ease_cm"] = 100.0 * r.ease_m;
        j["body_girth_m"] = r.body_m;
        j["garment_girth_m"] = r.garment_m;
        j["draped_girth_m"] = r.draped_m;
        j["hoop_strain"] = r.hoop_strain;
        j["open_seam_m"] = r.open_seam_m;
      } else if (r.body_m > 0 || r.garment_m > 0) {
        j["garment_length_m"] = r.garment_m;
        if (r.region != "garment_length") {
          j["body_length_m"] = r.body_m;
          j["ease_cm"] = 100.0 * r.ease_m;
        }
      }
      j["peak_strain_percent_of_limit"] = r.peak_strain_percent;
      j["peak_bias_strain"] = r.peak_bias_strain;
      j["peak_pressure_pa"] = r.peak_pressure_pa;
      j["reason"] = r.reason;
      regions.push_back(std::move(j));
    }
    garments.push_back({{"name", g.name},
                        {"size", g.size},
                        {"strain_limit", g.strain_limit},
                        {"peak_strain_percent_of_limit", g.peak_strain_percent},
                        {"particles_in_contact", g.contacts.in_contact},
                        {"contact_force_n", {g.contacts.total.x(), g.contacts.total.y(), g.contacts.total.z()}},
                        {"weight_n", g.contacts.weight},
                        {"unbalanced_force_off_body_n", g.contacts.unbalanced},
                        {"regions", regions}});
  }
  out["garments"] = garments;
  out["peak_pressure_pa"] = fit.peak_pressure_pa;
  out["pressure_force_on_body_n"] = {fit.pressure.total.x(), fit.pressure.total.y(), fit.pressure.total.z()};
  return out.dump();
}

std::string fit_table(const FitAnalysis& fit) {
  std::string s;
  for (const GarmentFit& g : fit.garments) {
    s += fmt::format("fit of {} {} (strain limit {:.0f} %):\n", g.name, g.size, 100 * g.strain_limit);
    s += fmt::format("  {:<15} {:<7} {:>9} {:>12} {:>14}\n", "region", "verdict", "ease", "peak strain", "peak pressure");
    for (const RegionFit& r : g.regions) {
      // Girths and sleeve / leg lengths: ease; the garment's length: itself; zones: nothing.
      const std::string ease = r.girth || r.region == "sleeve_length" || r.region == "leg_length"
                                   ? fmt::format("{:+.1f} cm", 100 * r.ease_m)
                               : r.region == "garment_length" ? fmt::format("{:.0f} cm", 100 * r.garment_m)
                                                              : std::string("-");
      s += fmt::format("  {:<15} {:<7} {:>9} {:>10.0f} % {:>9.0f} N/m2\n", r.region, to_string(r.verdict), ease,
                       r.peak_strain_percent, r.peak_pressure_pa);
    }
  }
  return s;
}

}  // namespace drape
