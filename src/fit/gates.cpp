// The quality gates of a dressing (docs/dressing.md): each compares one measurement with a limit.
#include <fmt/format.h>

#include "drape/fit.hpp"

namespace drape {

std::vector<GateResult> evaluate_gates(const FitQuality& q, float strain_threshold, const QualityGates& g) {
  std::vector<GateResult> out;
  const auto gate = [&](std::string name, bool passed, double value, double limit, std::string detail) {
    out.push_back({std::move(name), passed, value, limit, std::move(detail)});
  };
  gate("finite", q.finite, q.finite ? 0 : 1, 0,
       q.finite ? "every position finite" : "the simulation produced NaN or exploded");
  gate("seams_closed", q.finite && q.max_seam_gap_m <= g.max_seam_gap_m, q.max_seam_gap_m, g.max_seam_gap_m,
       fmt::format("largest seam gap {:.2f} mm (limit {:.1f} mm)", 1e3 * q.max_seam_gap_m, 1e3 * g.max_seam_gap_m));
  gate("penetration", q.finite && q.penetration_fraction <= g.max_penetration_fraction, q.penetration_fraction,
       g.max_penetration_fraction,
       fmt::format("{} vertices inside the body ({:.2f} %, limit {:.2f} %)", q.penetrating_vertices,
                   100 * q.penetration_fraction, 100 * g.max_penetration_fraction));
  const double strain_limit = static_cast<double>(strain_threshold) + g.strain_margin;
  gate("strain", q.finite && q.max_strain <= strain_limit, q.max_strain, strain_limit,
       fmt::format("max structural strain {:.2f} % (limit {:.2f} %)", 100 * q.max_strain, 100 * strain_limit));
  gate("settled", q.settled, q.settled ? 1 : 0, 1, q.settled ? "came to rest" : "still moving when the run stopped");
  gate("above_floor", q.finite && q.lowest_y >= g.floor_y, q.lowest_y, g.floor_y,
       fmt::format("lowest garment vertex at y = {:.3f} m", q.lowest_y));
  gate("stayed_on", q.finite && q.drop_m <= g.max_drop_m, q.drop_m, g.max_drop_m,
       fmt::format("garment centre fell {:.3f} m from where it was placed (limit {:.2f} m)", q.drop_m, g.max_drop_m));
  return out;
}

bool all_passed(const std::vector<GateResult>& gates) {
  for (const GateResult& g : gates)
    if (!g.passed) return false;
  return true;
}

}  // namespace drape
