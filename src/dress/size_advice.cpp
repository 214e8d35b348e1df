// Size advice (drape/size_advice.hpp, docs/fit.md): every size dressed, judged and compared.
//
// Sizes are dressed two at a time (an OpenMP loop over sizes, one size per thread; the dressing's
// own parallel loops then run on one thread each). A dressing's result does not depend on the
// number of threads it runs on, so neither does the advice.
#include <fmt/format.h>
#include <omp.h>

#include <algorithm>
#include <cmath>
#include <exception>
#include <numeric>

#include <nlohmann/json.hpp>

#include "drape/collision.hpp"
#include "drape/size_advice.hpp"
#include "dress/stages.hpp"

namespace drape {
namespace {

const GateResult* find_gate(const std::vector<GateResult>& gates, std::string_view name) {
  for (const GateResult& g : gates)
    if (g.name == name) return &g;
  return nullptr;
}

bool gate_passed(const std::vector<GateResult>& gates, std::string_view name) {
  const GateResult* g = find_gate(gates, name);
  return g != nullptr && g->passed;
}

// RMS of (body - chart) / chart over the chart entry's measurements the body has (choose_size's score).
double chart_distance(const SizeMeasurements& entry, const Measurements& body) {
  double sum = 0;
  size_t n = 0;
  for (const auto& [key, chart] : entry) {
    for (const MeasurementInfo& m : measurement_table()) {
      if (m.key != key) continue;
      const double b = body.*m.field;
      if (b <= 0) continue;
      sum += (b - chart) * (b - chart) / (chart * chart);
      ++n;
    }
  }
  return n == 0 ? -1.0 : std::sqrt(sum / static_cast<double>(n));
}

// What the fit per region found wrong: tight or loose girth lines (`girths`), tight zones, lengths
// that are too long (`others`).
void fit_problems(const SizeTrial& t, std::vector<std::string>* girths, std::vector<std::string>* others) {
  for (const GarmentFit& g : t.fit.garments)
    for (const RegionFit& r : g.regions) {
      if (r.verdict == FitVerdict::tight && r.girth && girths) {
        girths->push_back(r.open_seam_m > 0
                              ? fmt::format("tight at the {} (a seam {:.0f} mm open there)", r.region, 1e3f * r.open_seam_m)
                              : fmt::format("tight at the {} (ease {:+.1f} cm, stretched {:.1f} %, limit {:.0f} %)", r.region,
                                            100 * r.ease_m, 100 * r.hoop_strain, 100 * g.strain_limit));
      } else if (r.verdict == FitVerdict::loose && girths) {
        girths->push_back(fmt::format("loose at the {} (ease {:+.1f} cm)", r.region, 100 * r.ease_m));
      } else if (r.verdict == FitVerdict::tight && !r.girth && others) {
        others->push_back(fmt::format("tight at the {} ({:.0f} % of the limit)", r.region, r.peak_strain_percent));
      } else if (r.verdict == FitVerdict::long_ && others) {
        others->push_back(r.reason);
      }
    }
  if (others)
    for (const GateResult& g : t.result.gates)
      if (!g.passed && g.name != "seams_closed" && g.name != "stayed_on" && g.name != "finite")
        others->push_back(g.name == "settled" ? std::string("still moving when the run stopped") : g.detail);
}

std::string join(const std::vector<std::string>& parts) {
  std::string s;
  for (const std::string& p : parts) s += (s.empty() ? "" : "; ") + p;
  return s;
}

// One line: why this size does or does not fit.
std::string size_verdict(const SizeTrial& t) {
  if (!gate_passed(t.result.gates, "finite")) return "the simulation failed (non-finite positions)";
  std::vector<std::string> girths, others;
  if (!t.closes) {
    std::string s = "does not close";
    for (const DressedGarment& g : t.result.garments) {
      const size_t seam = g.widest_seam();
      if (seam < g.seam_names.size()) {
        s = fmt::format("does not close: seam '{}' stays {:.0f} mm open", g.seam_names[seam], 1e3f * g.seam_gaps()[seam]);
        break;
      }
    }
    fit_problems(t, &girths, nullptr);
    girths.erase(std::remove_if(girths.begin(), girths.end(), [](const std::string& p) { return p.rfind("tight", 0) != 0; }),
                 girths.end());
    return girths.empty() ? s : s + "; " + join(girths);
  }
  if (!t.stays_on) return fmt::format("slides off: it fell {:.2f} m", static_cast<double>(t.result.quality.drop_m));
  fit_problems(t, &girths, &others);
  girths.insert(girths.end(), others.begin(), others.end());
  return girths.empty() ? std::string("fits") : join(girths);
}

// "hips ease +1.3 cm, thighs ease +16.6 cm (loose)", then what else was found (a tight zone, a
// failed gate).
std::string ease_summary(const SizeTrial& t) {
  std::string s;
  for (const GarmentFit& g : t.fit.garments)
    for (const RegionFit& r : g.regions)
      if (r.girth)
        s += fmt::format("{}{} ease {:+.1f} cm{}", s.empty() ? "" : ", ", r.region, 100 * r.ease_m,
                         r.verdict == FitVerdict::good ? std::string() : fmt::format(" ({})", to_string(r.verdict)));
  if (s.empty()) s = "no girth line covered";
  std::vector<std::string> others;
  fit_problems(t, nullptr, &others);
  return others.empty() ? s : s + "; " + join(others);
}

// The body's distances for measuring a dressed garment: a few thousand queries per size, cheaper
// straight from the tree than through the candidate grid a simulation builds.
std::unique_ptr<BodyCollider> exact_collider(const Body& body) {
  BodyColliderOptions exact;
  exact.candidate_grid = false;
  return make_body_collider(body.mesh, CollisionMethod::bvh, exact);
}

}  // namespace

FitGarment fit_garment(const DressedGarment& dressed, const Garment& garment) {
  FitGarment f;
  f.name = dressed.name;
  f.size = dressed.size;
  f.model = &dressed.model;
  f.x = dressed.state.x;
  f.seam_pairs = dressed.seam_pairs;
  const size_t n = dressed.model.particle_count();
  f.warp.assign(n, Vec2f::UnitY());
  f.on_arm.assign(n, 0);
  f.on_leg.assign(n, 0);
  for (size_t p = 0; p + 1 < dressed.panel_first_vertex.size() && p < garment.panels.size(); ++p) {
    const Panel& panel = garment.panels[p];
    const Vec2f grain = panel.grain.cast<float>().normalized();
    const bool arm = panel.placement && (panel.placement->body_part == BodyRegion::left_arm ||
                                         panel.placement->body_part == BodyRegion::right_arm);
    const uint8_t leg = !panel.placement                                        ? 0
                        : panel.placement->body_part == BodyRegion::left_leg  ? 1
                        : panel.placement->body_part == BodyRegion::right_leg ? 2
                                                                              : 0;
    for (uint32_t i = dressed.panel_first_vertex[p]; i < dressed.panel_first_vertex[p + 1] && i < n; ++i) {
      f.warp[i] = grain;
      f.on_arm[i] = arm ? 1 : 0;
      f.on_leg[i] = leg;
    }
  }
  return f;
}

FitAnalysis analyse_dress_fit(const Body& body, const DressResult& result, std::span<const Garment> garments) {
  std::vector<FitGarment> in;
  for (size_t i = 0; i < result.garments.size() && i < garments.size(); ++i)
    in.push_back(fit_garment(result.garments[i], garments[i]));
  const auto collider = exact_collider(body);
  return analyse_fit(body, in, *collider);
}

std::string report_with_fit(const std::string& report_json, const FitAnalysis& fit) {
  nlohmann::ordered_json report = nlohmann::ordered_json::parse(report_json);
  report["fit"] = nlohmann::ordered_json::parse(fit_json(fit));
  return report.dump(2) + "\n";
}

SizeAdvice advise_size(const Body& body, const GarmentSpec& spec, const DressOptions& options,
                       const std::function<void(size_t, size_t)>& progress) {
  SizeAdvice advice;
  advice.garment = spec.name;
  // Every size resolved (and validated) before anything is simulated, in the file's order (a
  // pattern grades its sizes from the smallest).
  for (const std::string& size : spec.sizes) {
    SizeTrial t;
    t.size = size;
    t.garment = garment_in_size(spec, size);
    const auto k = advice.sizes.size();
    if (k < spec.size_chart.size() && !spec.size_chart[k].empty()) t.chart_distance = chart_distance(spec.size_chart[k], body.measurements);
    advice.sizes.push_back(std::move(t));
  }
  // Before draping: each size's pattern placed round the body and measured at the body's girth
  // lines and at its own.
  {
    BodyColliderOptions few_queries;  // placement only: straight from the tree
    few_queries.candidate_grid = false;
    const auto placement_collider = make_body_collider(body.mesh, options.collision, few_queries);
    for (SizeTrial& t : advice.sizes) {
      const DressedGarment placed =
          dressing::prepare_garment(body, t.garment, *placement_collider, options, dressing::PlacementUse::measuring);
      t.pattern = pattern_measurements(body, fit_garment(placed, t.garment));
      t.pattern_girths = pattern_girths(body, placed, t.garment, spec);
    }
  }
  bool has_chart = std::any_of(advice.sizes.begin(), advice.sizes.end(), [](const SizeTrial& t) { return t.chart_distance >= 0; });
  GarmentSpec charted;
  if (!has_chart) {
    // No chart in the file: the one its pattern makes.
    std::vector<PatternSize> measured;
    for (const SizeTrial& t : advice.sizes) measured.push_back({t.size, t.pattern_girths});
    charted = spec;
    charted.size_chart = chart_from_pattern(measured);
    for (size_t k = 0; k < advice.sizes.size(); ++k)
      if (!charted.size_chart[k].empty()) advice.sizes[k].chart_distance = chart_distance(charted.size_chart[k], body.measurements);
    has_chart = advice.chart_from_pattern =
        std::any_of(advice.sizes.begin(), advice.sizes.end(), [](const SizeTrial& t) { return t.chart_distance >= 0; });
  }
  if (has_chart) advice.chart_size = choose_size(advice.chart_from_pattern ? charted : spec, body.measurements).size;

  const auto collider = exact_collider(body);
  const auto count = static_cast<int>(advice.sizes.size());
  std::vector<std::exception_ptr> errors(advice.sizes.size());
  size_t done = 0;
  const int threads = std::min(2, omp_get_max_threads());
#pragma omp parallel for schedule(dynamic, 1) num_threads(threads)
  for (int k = 0; k < count; ++k) {
    SizeTrial& t = advice.sizes[static_cast<size_t>(k)];
    try {
      t.result = dress(body, {GarmentRequest{spec, t.size}}, options);
      t.fit = analyse_fit(body, std::vector<FitGarment>{fit_garment(t.result.garments.at(0), t.garment)}, *collider);
    } catch (...) {
      errors[static_cast<size_t>(k)] = std::current_exception();
    }
#pragma omp critical(drape_size_advice_progress)
    {
      ++done;
      if (progress) progress(done, advice.sizes.size());
    }
  }
  for (const std::exception_ptr& e : errors)
    if (e) std::rethrow_exception(e);

  for (SizeTrial& t : advice.sizes) {
    t.closes = gate_passed(t.result.gates, "finite") && gate_passed(t.result.gates, "seams_closed");
    t.stays_on = gate_passed(t.result.gates, "stayed_on");
    t.verdict = size_verdict(t);
  }

  // The rule (docs/fit.md): closes and stays on; every gate passed first; the chart's size, else
  // the smallest not tight anywhere.
  std::vector<size_t> candidates;
  for (size_t k = 0; k < advice.sizes.size(); ++k)
    if (advice.sizes[k].closes && advice.sizes[k].stays_on) candidates.push_back(k);
  std::vector<size_t> passing;
  for (size_t k : candidates)
    if (advice.sizes[k].result.passed()) passing.push_back(k);
  const std::vector<size_t>& group = passing.empty() ? candidates : passing;
  const std::string group_words = passing.empty() ? "closes and stays on (no size passed every check)"
                                                  : "passes every check";
  advice.recommended = advice.sizes.size();
  if (!group.empty()) {
    const auto tight = [&](size_t k) {
      for (const GarmentFit& g : advice.sizes[k].fit.garments)
        for (const RegionFit& r : g.regions)
          if (r.verdict == FitVerdict::tight) return true;
      return false;
    };
    if (has_chart) {
      size_t best = group.front();
      for (size_t k : group)
        if (advice.sizes[k].chart_distance >= 0 &&
            (advice.sizes[best].chart_distance < 0 || advice.sizes[k].chart_distance < advice.sizes[best].chart_distance))
          best = k;
      advice.recommended = best;
      const char* chart = advice.chart_from_pattern ? "the size chart made from the pattern" : "the size chart";
      advice.rule = advice.sizes[best].size == advice.chart_size
                        ? fmt::format("{}'s size for the body; it {}", chart, group_words)
                        : fmt::format("{} gives {}, which does not qualify; {} is the nearest in the chart that {}", chart,
                                      advice.chart_size, advice.sizes[best].size, group_words);
    } else {
      const auto loose_fit = std::find_if(group.begin(), group.end(), [&](size_t k) { return !tight(k); });
      advice.recommended = loose_fit != group.end() ? *loose_fit : group.back();
      advice.rule = loose_fit != group.end()
                        ? fmt::format("no size chart: the smallest size that {} and is not tight anywhere", group_words)
                        : fmt::format("no size chart: every size that {} is tight somewhere; the largest", group_words);
    }
  } else {
    advice.rule = "no size closes and stays on the body";
  }

  if (advice.has_recommendation()) {
    const SizeTrial& r = advice.sizes[advice.recommended];
    advice.reasons.push_back(fmt::format("{}: recommended ({}): {}", r.size, advice.rule, ease_summary(r)));
  } else {
    advice.reasons.push_back("no size is recommended: none closes and stays on the body");
  }
  for (size_t k = 0; k < advice.sizes.size(); ++k) {
    const SizeTrial& t = advice.sizes[k];
    if (k == advice.recommended) continue;
    advice.reasons.push_back(t.closes && t.stays_on ? fmt::format("{}: {}", t.size, ease_summary(t))
                                                    : fmt::format("{}: {}", t.size, t.verdict));
  }
  return advice;
}

std::string size_advice_json(const Body& body, const SizeAdvice& advice) {
  nlohmann::ordered_json extra;
  extra["garment"] = advice.garment;
  extra["recommended_size"] = advice.has_recommendation() ? nlohmann::ordered_json(advice.sizes[advice.recommended].size)
                                                          : nlohmann::ordered_json(nullptr);
  extra["chart_size"] = advice.chart_size.empty() ? nlohmann::ordered_json(nullptr) : nlohmann::ordered_json(advice.chart_size);
  extra["chart_source"] = advice.chart_size.empty() ? nlohmann::ordered_json(nullptr)
                          : nlohmann::ordered_json(advice.chart_from_pattern ? "pattern" : "garment");
  extra["rule"] = advice.rule;
  extra["reasons"] = advice.reasons;
  nlohmann::ordered_json sizes = nlohmann::ordered_json::array();
  for (size_t k = 0; k < advice.sizes.size(); ++k) {
    const SizeTrial& t = advice.sizes[k];
    nlohmann::ordered_json gates = nlohmann::ordered_json::array();
    nlohmann::ordered_json failed = nlohmann::ordered_json::array();
    for (const GateResult& g : t.result.gates) {
      gates.push_back({{"name", g.name}, {"passed", g.passed}, {"value", std::isfinite(g.value) ? nlohmann::ordered_json(g.value) : nlohmann::ordered_json(nullptr)},
                       {"limit", g.limit}, {"detail", g.detail}});
      if (!g.passed) failed.push_back(g.name);
    }
    nlohmann::ordered_json fit = nlohmann::ordered_json::parse(fit_json(t.fit));
    nlohmann::ordered_json regions = fit["garments"].empty() ? nlohmann::ordered_json::array() : fit["garments"][0]["regions"];
    nlohmann::ordered_json pattern = nlohmann::ordered_json::array();
    for (const RegionFit& r : t.pattern) {
      if (r.girth)
        pattern.push_back({{"region", r.region}, {"verdict", std::string(to_string(r.verdict))}, {"ease_cm", 100.0 * r.ease_m},
                           {"garment_girth_m", r.garment_m}, {"body_girth_m", r.body_m}});
      else
        pattern.push_back({{"region", r.region}, {"verdict", std::string(to_string(r.verdict))},
                           {"garment_length_m", r.garment_m}, {"body_length_m", r.body_m}, {"reason", r.reason}});
    }
    nlohmann::ordered_json girths = nlohmann::ordered_json::array();
    for (const PatternGirth& g : t.pattern_girths)
      girths.push_back({{"key", g.key}, {"line", g.line}, {"garment_girth_m", g.girth_m}, {"intended_ease_m", g.ease_m},
                        {"body_m", g.body_m()}});
    sizes.push_back({{"size", t.size},
                     {"recommended", k == advice.recommended},
                     {"verdict", t.verdict},
                     {"closes", t.closes},
                     {"stays_on", t.stays_on},
                     {"chart_distance", t.chart_distance >= 0 ? nlohmann::ordered_json(t.chart_distance) : nlohmann::ordered_json(nullptr)},
                     {"regions", regions},
                     {"pattern", pattern},
                     {"pattern_girths", girths},
                     {"fit", fit},
                     {"gates", {{"passed", failed.empty()}, {"failed", failed}, {"checks", gates}}},
                     {"max_strain", t.result.quality.max_strain},
                     {"iterations", t.result.simulation.iterations},
                     {"wall_seconds", t.result.simulation.wall_seconds}});
  }
  extra["sizes"] = sizes;
  if (advice.has_recommendation()) extra["fit"] = nlohmann::ordered_json::parse(fit_json(advice.sizes[advice.recommended].fit));
  const Measurements& m = body.measurements;
  extra["body"] = {{"vertices", body.mesh.vertex_count()}, {"height_m", m.height}, {"bust_m", m.bust}, {"waist_m", m.waist},
                   {"hips_m", m.hips}, {"thigh_m", m.thigh}, {"upper_arm_m", m.upper_arm}, {"arm_length_m", m.arm_length},
                   {"inseam_m", m.inseam}};
  // DESIGN.md's quality, simulation and gates: of the recommended size (the smallest when none).
  const SizeTrial& shown = advice.sizes.at(advice.has_recommendation() ? advice.recommended : 0);
  return report_json(shown.result.quality, shown.result.simulation, shown.result.gates, extra.dump());
}

}  // namespace drape
