// Fit measurements on a final cloth state: seam gaps, structural strain, penetration of the body
// (generalized winding number, collision/inside_test), the lowest vertex.
#include <algorithm>
#include <cmath>
#include <limits>

#include "drape/fit.hpp"

namespace drape {

SeamGapStats seam_gap_stats(std::span<const Vec3f> x, std::span<const std::array<uint32_t, 2>> pairs) {
  SeamGapStats s;
  s.pairs = pairs.size();
  double sum = 0;
  for (const auto& [a, b] : pairs) {
    const float gap = (x[a] - x[b]).norm();
    s.max = std::max(s.max, gap);
    sum += gap;
  }
  s.mean = pairs.empty() ? 0.0f : static_cast<float>(sum / static_cast<double>(pairs.size()));
  return s;
}

GarmentMeasure measure_garment(const ClothModel& model, std::span<const Vec3f> x, const InsideTest& body) {
  GarmentMeasure m;
  m.strain = strain_stats(model, x, SpringKind::Structural);
  // Every structural spring's stretch, so the p99 over several garments is the true p99.
  const SpringRange r = model.range(SpringKind::Structural);
  m.structural_strain.reserve(r.size());
  for (uint32_t s = r.begin; s < r.end; ++s) {
    const float rest = model.rest_length[s];
    m.structural_strain.push_back(((x[model.spring_b[s]] - x[model.spring_a[s]]).norm() - rest) / rest);
  }
  m.lowest_y = std::numeric_limits<float>::infinity();
  for (const Vec3f& p : x) {
    if (!p.allFinite()) m.finite = false;
    m.lowest_y = std::min(m.lowest_y, p.y());
  }
  if (m.finite) m.penetration = measure_penetration(body, x, kPenetrationTolerance);
  return m;
}

}  // namespace drape
