// The size for a body (docs/garment-format.md, "Size chart"): a garment file may list, per size, the
// body measurements the size is drafted for; the size whose entry is nearest to the body's own
// measurements (drape/body.hpp, measured on every body) is made when none is asked for.
#include <fmt/format.h>

#include <cmath>
#include <limits>

#include "drape/dress.hpp"

namespace drape {
namespace {

// The body's value of a measurement key, or 0 where the body layer has none.
float body_measurement(const Measurements& body, std::string_view key) {
  for (const MeasurementInfo& m : measurement_table())
    if (m.key == key) return body.*m.field;
  return 0.0f;
}

}  // namespace

SizeChoice choose_size(const GarmentSpec& spec, const Measurements& body) {
  const std::string& base = spec.sizes.at(spec.base_size);
  // Score every size with a chart entry: RMS of (body - chart) / chart over the measurements both have.
  size_t best = spec.sizes.size();
  double best_rms = std::numeric_limits<double>::infinity();
  std::string others;
  for (size_t k = 0; k < spec.size_chart.size() && k < spec.sizes.size(); ++k) {
    double sum = 0;
    size_t n = 0;
    for (const auto& [key, chart] : spec.size_chart[k]) {
      const double b = body_measurement(body, key);
      if (b <= 0) continue;
      sum += (b - chart) * (b - chart) / (chart * chart);
      ++n;
    }
    if (n == 0) continue;
    const double rms = std::sqrt(sum / static_cast<double>(n));
    others += fmt::format("{}{} {:.1f} %", others.empty() ? "" : ", ", spec.sizes[k], 100 * rms);
    if (rms < best_rms) {
      best_rms = rms;
      best = k;
    }
  }
  if (best == spec.sizes.size())
    return {base, spec.size_chart.empty() ? "the base size (the garment has no size chart)"
                                          : "the base size (the body has none of the size chart's measurements)"};

  // Name the body's measurements against the chosen entry.
  std::string fit;
  for (const auto& [key, chart] : spec.size_chart[best]) {
    const double b = body_measurement(body, key);
    if (b > 0) fit += fmt::format("{}{} {:.3f} m (chart {:.3f})", fit.empty() ? "" : ", ", key, b, chart);
  }
  return {spec.sizes[best], fmt::format("nearest in the size chart: body {}; RMS difference per size: {}", fit, others)};
}

}  // namespace drape
