// Bucket grid over a closed outline's segments: nearest distance and crossing queries in O(1)
// cells per query, used by the grid mesher to keep lattice points and springs inside the outline.
#include <algorithm>
#include <cmath>

#include "pattern/meshing.hpp"

namespace drape::pattern {
namespace {

double cross(const Vec2d& a, const Vec2d& b) { return a.x() * b.y() - a.y() * b.x(); }

double point_segment_distance(const Vec2d& p, const Vec2d& a, const Vec2d& b) {
  const Vec2d d = b - a;
  const double dd = d.squaredNorm();
  const double t = dd > 0 ? std::clamp((p - a).dot(d) / dd, 0.0, 1.0) : 0.0;
  return (a + t * d - p).norm();
}

}  // namespace

SegmentGrid::SegmentGrid(const std::vector<Vec2d>& loop, double cell) : loop_(loop), cell_(cell) {
  Eigen::AlignedBox2d box;
  for (const Vec2d& p : loop_) box.extend(p);
  origin_ = box.min();
  nx_ = std::max(1, static_cast<int>(std::ceil(box.sizes().x() / cell_)) + 1);
  ny_ = std::max(1, static_cast<int>(std::ceil(box.sizes().y() / cell_)) + 1);
  cells_.resize(static_cast<size_t>(nx_) * static_cast<size_t>(ny_));
  for (size_t i = 0; i < loop_.size(); ++i) {
    const Vec2d& a = loop_[i];
    const Vec2d& b = loop_[(i + 1) % loop_.size()];
    visit(a.cwiseMin(b), a.cwiseMax(b), [&](size_t c) { cells_[c].push_back(static_cast<uint32_t>(i)); });
  }
}

template <class F>
void SegmentGrid::visit(const Vec2d& lo, const Vec2d& hi, F&& f) const {
  const auto clamp_x = [&](double x) { return std::clamp(static_cast<int>(std::floor((x - origin_.x()) / cell_)), 0, nx_ - 1); };
  const auto clamp_y = [&](double y) { return std::clamp(static_cast<int>(std::floor((y - origin_.y()) / cell_)), 0, ny_ - 1); };
  for (int y = clamp_y(lo.y()); y <= clamp_y(hi.y()); ++y)
    for (int x = clamp_x(lo.x()); x <= clamp_x(hi.x()); ++x)
      f(static_cast<size_t>(y) * static_cast<size_t>(nx_) + static_cast<size_t>(x));
}

double SegmentGrid::distance(const Vec2d& p, double max_distance) const {
  double best = max_distance;
  const Vec2d r = Vec2d::Constant(max_distance);
  visit(p - r, p + r, [&](size_t cell) {
    for (uint32_t i : cells_[cell]) best = std::min(best, point_segment_distance(p, loop_[i], loop_[(i + 1) % loop_.size()]));
  });
  return best;
}

bool SegmentGrid::crosses(const Vec2d& a, const Vec2d& b) const {
  bool hit = false;
  visit(a.cwiseMin(b), a.cwiseMax(b), [&](size_t cell) {
    for (uint32_t i : cells_[cell]) {
      const Vec2d& p = loop_[i];
      const Vec2d& q = loop_[(i + 1) % loop_.size()];
      const double d1 = cross(b - a, p - a), d2 = cross(b - a, q - a);
      const double d3 = cross(q - p, a - p), d4 = cross(q - p, b - p);
      if (((d1 > 0) != (d2 > 0)) && ((d3 > 0) != (d4 > 0)) && d1 != 0 && d2 != 0 && d3 != 0 && d4 != 0) hit = true;
    }
  });
  return hit;
}

}  // namespace drape::pattern
