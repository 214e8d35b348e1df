// Per-cell candidate lists for exact closest-point queries; see candidate_grid.hpp.
#include "collision/candidate_grid.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "collision/triangle_bvh.hpp"

namespace drape::collision {

CandidateGrid::CandidateGrid(const TriangleBvh& bvh, float cell, float band)
    : surface_(bvh.surface()), cell_(cell), band_(band), half_diagonal_(0.5f * std::sqrt(3.0f) * cell) {
  if (!(cell > 0) || !(band > 0)) throw std::invalid_argument("candidate grid: cell and band must be positive");
  const auto positions = surface_.positions();
  Bounds box;
  for (const Vec3f& p : positions) box.extend(p);
  const float margin = band_ + cell_;
  origin_ = box.min - Vec3f::Constant(margin);
  for (int a = 0; a < 3; ++a)
    dims_[a] = static_cast<uint32_t>(std::ceil((box.max[a] - box.min[a] + 2 * margin) / cell_)) + 1;
  const size_t nx = dims_[0], ny = dims_[1], nz = dims_[2];
  const size_t cells = nx * ny * nz;

  // Cells that may lie within the band: those meeting a triangle's box grown by band + half diagonal.
  std::vector<uint8_t> near(cells, 0);
  for (uint32_t t = 0; t < surface_.triangle_count(); ++t) {
    Bounds tb;
    for (uint32_t v : surface_.triangle(t)) tb.extend(positions[v]);
    size_t lo[3], hi[3];
    for (int a = 0; a < 3; ++a) {
      const float grow = band_ + half_diagonal_;
      lo[a] = static_cast<size_t>(std::max(0.0f, std::floor((tb.min[a] - grow - origin_[a]) / cell_)));
      hi[a] = std::min(static_cast<size_t>(dims_[a] - 1),
                       static_cast<size_t>(std::max(0.0f, std::floor((tb.max[a] + grow - origin_[a]) / cell_))));
    }
    for (size_t z = lo[2]; z <= hi[2]; ++z)
      for (size_t y = lo[1]; y <= hi[1]; ++y) std::fill_n(&near[(z * ny + y) * nx + lo[0]], hi[0] - lo[0] + 1, 1);
  }
  std::vector<uint32_t> marked;
  for (size_t c = 0; c < cells; ++c)
    if (near[c]) marked.push_back(static_cast<uint32_t>(c));

  // Lists of the marked cells, in fixed chunks (the result does not depend on the thread count),
  // then concatenated in cell order.
  constexpr size_t kChunk = 512;
  const size_t chunks = (marked.size() + kChunk - 1) / kChunk;
  std::vector<std::vector<Candidate>> chunk_candidates(chunks);
  std::vector<uint32_t> count(cells, 0);
#pragma omp parallel for schedule(dynamic, 1)
  for (std::ptrdiff_t k = 0; k < static_cast<std::ptrdiff_t>(chunks); ++k) {
    std::vector<uint32_t> within;
    std::vector<Candidate>& out = chunk_candidates[static_cast<size_t>(k)];
    const size_t begin = static_cast<size_t>(k) * kChunk, end = std::min(marked.size(), begin + kChunk);
    for (size_t m = begin; m < end; ++m) {
      const size_t c = marked[m];
      const Vec3f centre = origin_ + cell_ * Vec3f(static_cast<float>(c % nx) + 0.5f, static_cast<float>((c / nx) % ny) + 0.5f,
                                                   static_cast<float>(c / (nx * ny)) + 0.5f);
      SurfaceHit nearest;
      if (!bvh.closest(centre, band_, nearest)) continue;
      bvh.within(centre, nearest.distance + 2 * half_diagonal_, within);
      const size_t first = out.size();
      for (uint32_t t : within) out.push_back({t, surface_.closest_on(t, centre).distance});
      std::sort(out.begin() + static_cast<std::ptrdiff_t>(first), out.end(), [](const Candidate& a, const Candidate& b) {
        return a.centre_distance < b.centre_distance || (a.centre_distance == b.centre_distance && a.triangle < b.triangle);
      });
      if (out.size() - first > kMaxList) {
        out[first + kMaxList].triangle = kTruncated;  // keeps the first left out's distance
        out.resize(first + kMaxList + 1);
      }
      count[c] = static_cast<uint32_t>(out.size() - first);
    }
  }
  first_.assign(cells + 1, 0);
  for (size_t c = 0; c < cells; ++c) first_[c + 1] = first_[c] + count[c];
  candidates_.reserve(first_[cells]);
  for (const auto& chunk : chunk_candidates) candidates_.insert(candidates_.end(), chunk.begin(), chunk.end());
}

CandidateGrid::Answer CandidateGrid::closest(const Vec3f& p, float radius, SurfaceHit& hit) const {
  const Vec3f g = (p - origin_) * (1.0f / cell_);
  const bool in_grid = g.x() >= 0.0f && g.y() >= 0.0f && g.z() >= 0.0f && g.x() < static_cast<float>(dims_[0]) &&
                       g.y() < static_cast<float>(dims_[1]) && g.z() < static_cast<float>(dims_[2]);
  // Outside the grid: farther than the band from the body.
  if (!in_grid) return radius <= band_ ? Answer::kNone : Answer::kUnknown;
  const auto x = static_cast<uint32_t>(g.x()), y = static_cast<uint32_t>(g.y()), z = static_cast<uint32_t>(g.z());
  const size_t c = (static_cast<size_t>(z) * dims_[1] + y) * dims_[0] + x;
  const uint32_t begin = first_[c], end = first_[c + 1];
  // No list: the cell centre is beyond the band, so p is beyond band - half diagonal.
  if (begin == end) return radius <= band_ - half_diagonal_ ? Answer::kNone : Answer::kUnknown;

  const Vec3f centre = origin_ + cell_ * Vec3f(static_cast<float>(x) + 0.5f, static_cast<float>(y) + 0.5f, static_cast<float>(z) + 0.5f);
  const float offset = (p - centre).norm();
  float best = radius;
  bool found = false;
  for (uint32_t k = begin; k < end; ++k) {
    const Candidate& candidate = candidates_[k];
    if (candidate.centre_distance - offset >= best) break;  // d(p, T) >= d(c, T) - |p - c|: no nearer one follows
    if (candidate.triangle == kTruncated) return found ? Answer::kTruncatedFound : Answer::kTruncatedNone;
    const SurfaceHit h = surface_.closest_on(candidate.triangle, p);
    if (h.distance < best) {
      best = h.distance;
      hit = h;
      found = true;
    }
  }
  return found ? Answer::kFound : Answer::kNone;
}

double CandidateGrid::mean_list_length() const {
  size_t lists = 0;
  for (size_t c = 0; c + 1 < first_.size(); ++c) lists += first_[c + 1] > first_[c];  // truncation entries included
  return lists ? static_cast<double>(candidates_.size()) / static_cast<double>(lists) : 0.0;
}

}  // namespace drape::collision
