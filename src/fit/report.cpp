// report.json (DESIGN.md): `quality` with exactly its nine keys, `simulation`, `gates`, then the
// caller's extra objects. Non-finite numbers become null (JSON has no NaN).
#include <cmath>
#include <nlohmann/json.hpp>

#include "drape/fit.hpp"
#include "fit/quality_json.hpp"

namespace drape {
namespace {

nlohmann::json number(double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr); }

}  // namespace

nlohmann::ordered_json quality_json(const FitQuality& q) {
  return {{"max_strain", number(q.max_strain)},
          {"p99_strain", number(q.p99_strain)},
          {"penetrating_vertices", q.penetrating_vertices},
          {"penetration_fraction", number(q.penetration_fraction)},
          {"max_penetration_m", number(q.max_penetration_m)},
          {"max_seam_gap_m", number(q.max_seam_gap_m)},
          {"mean_seam_gap_m", number(q.mean_seam_gap_m)},
          {"settled", q.settled},
          {"residual", number(q.residual)}};
}

std::string report_json(const FitQuality& q, const SimulationSummary& s, const std::vector<GateResult>& gates,
                        const std::string& extra_json_object) {
  nlohmann::ordered_json report;
  report["quality"] = quality_json(q);
  report["simulation"] = {{"iterations", s.iterations},
                          {"time_step_s", number(s.time_step_s)},
                          {"wall_seconds", number(s.wall_seconds)},
                          {"seconds_per_iteration", number(s.seconds_per_iteration)}};
  nlohmann::ordered_json failed = nlohmann::ordered_json::array();
  nlohmann::ordered_json list = nlohmann::ordered_json::array();
  for (const GateResult& g : gates) {
    list.push_back({{"name", g.name}, {"passed", g.passed}, {"value", number(g.value)}, {"limit", number(g.limit)},
                    {"detail", g.detail}});
    if (!g.passed) failed.push_back(g.name);
  }
  report["gates"] = {{"passed", failed.empty()}, {"failed", failed}, {"checks", list}};
  const nlohmann::ordered_json extra = nlohmann::ordered_json::parse(extra_json_object);
  for (auto it = extra.begin(); it != extra.end(); ++it)
    if (!report.contains(it.key())) report[it.key()] = it.value();
  return report.dump(2) + "\n";
}

}  // namespace drape
