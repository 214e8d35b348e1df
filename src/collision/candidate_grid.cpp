// Per-cell candidate lists for exact closest-point queries; see candidate_grid.hpp.
#include "collision/candidate_grid.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "collision/triangle_bvh.hpp"

namespace drape::collision {

CandidateGrid::CandidateGrid(const TriangleBvh& bvh, float cell, float band, const CellFilter& wanted)
    : surface_(bvh.surface()), cell_(cell), band_(band), half_diagonal_(0.5f * std::sqrt(3.0f) * cell) {
  if (!(cell > 0) || !(band > 0)) throw std::invalid_argument("candidate grid: cell and band must be positive");
  if (surface_.triangle_count() >= kTruncated) throw std::invalid_argument("candidate grid: more than 16.7 million triangles");
  // Listed centre distances are at most band + 2 half diagonals (see below); 16 bits span that.
  distance_unit_ = (band_ + 2 * half_diagonal_) / 65000.0f;
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
  // Triangle records in Morton order of their centroids (10 bits per axis over the body's box).
  const Vec3f extent = (box.max - box.min).cwiseMax(Vec3f::Constant(1e-6f));
  auto spread = [](uint64_t v) {  // bits b -> 3b
    v &= 0x3ff;
    v = (v | (v << 16)) & 0x30000ff;
    v = (v | (v << 8)) & 0x300f00f;
    v = (v | (v << 4)) & 0x30c30c3;
    return (v | (v << 2)) & 0x9249249;
  };
  std::vector<std::pair<uint64_t, uint32_t>> order(surface_.triangle_count());
  for (uint32_t t = 0; t < surface_.triangle_count(); ++t) {
    const Tri& tri = surface_.triangle(t);
    const Vec3f unit = ((positions[tri[0]] + positions[tri[1]] + positions[tri[2]]) / 3.0f - box.min).cwiseQuotient(extent);
    uint64_t code = 0;
    for (int a = 0; a < 3; ++a) code |= spread(static_cast<uint64_t>(std::clamp(unit[a], 0.0f, 1.0f) * 1023.0f)) << a;
    order[t] = {code, t};
  }
  std::sort(order.begin(), order.end());
  records_.resize(order.size());
  record_of_.resize(order.size());
  for (uint32_t k = 0; k < order.size(); ++k) {
    const uint32_t t = order[k].second;
    const Tri& tri = surface_.triangle(t);
    records_[k] = {positions[tri[0]], positions[tri[1]], positions[tri[2]], t};
    record_of_[t] = k;
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
    std::vector<SurfaceHit> within;
    struct Pending {
      uint32_t record;
      float distance;
      Vec3f away;
    };
    std::vector<Pending> list;
    std::vector<Candidate>& out = chunk_candidates[static_cast<size_t>(k)];
    const size_t begin = static_cast<size_t>(k) * kChunk, end = std::min(marked.size(), begin + kChunk);
    for (size_t m = begin; m < end; ++m) {
      const size_t c = marked[m];
      const Vec3f centre = origin_ + cell_ * Vec3f(static_cast<float>(c % nx) + 0.5f, static_cast<float>((c / nx) % ny) + 0.5f,
                                                   static_cast<float>(c / (nx * ny)) + 0.5f);
      if (wanted && !wanted(Bounds{centre - Vec3f::Constant(0.5f * cell_), centre + Vec3f::Constant(0.5f * cell_)})) {
        // Not asked here: "the list goes on beyond this entry" from the start, so the tree answers.
        out.push_back({static_cast<uint16_t>(kTruncated & 0xffff), static_cast<uint8_t>(kTruncated >> 16), {0, 0, 0}, 0});
        count[c] = 1;
        continue;
      }
      SurfaceHit nearest;
      if (!bvh.closest(centre, band_, nearest)) continue;
      // U: no point of the cell is farther than U from the body (the farthest corner from the
      // centre's nearest triangle; distance to a triangle is convex, so a corner is the farthest).
      float reach = 0;
      for (int corner = 0; corner < 8; ++corner) {
        const Vec3f offset((corner & 1 ? 0.5f : -0.5f) * cell_, (corner & 2 ? 0.5f : -0.5f) * cell_, (corner & 4 ? 0.5f : -0.5f) * cell_);
        reach = std::max(reach, surface_.closest_on(nearest.triangle, centre + offset).distance);
      }
      // Triangle T with centre distance d and direction u (Candidate::away) is at least
      // d + (p - centre) . u >= d - h(u) from any point p of the cell, h(u) = cell/2 (|ux| + |uy| + |uz|):
      // it can be nearest somewhere in the cell only if d - h(u) <= U; those all lie within U + r.
      bvh.within(centre, reach + half_diagonal_, within);
      list.clear();
      for (const SurfaceHit& h : within) {
        const uint32_t t = h.triangle;
        const Vec3f away = h.distance > 0.0f ? Vec3f((centre - h.where.point) / h.distance) : Vec3f::Zero();
        if (h.distance - 0.5f * cell_ * away.lpNorm<1>() > reach + 1e-5f) continue;  // 10 um for rounding
        list.push_back({record_of_[t], h.distance, away});
      }
      std::sort(list.begin(), list.end(), [](const Pending& a, const Pending& b) {
        return a.distance < b.distance || (a.distance == b.distance && a.record < b.record);
      });
      if (list.size() > kMaxList) {
        list[kMaxList].record = kTruncated;  // keeps the first left out's distance
        list.resize(kMaxList + 1);
      }
      const size_t first = out.size();
      for (const Pending& entry : list) {
        const Vec3f scaled = 127.0f * entry.away;
        const float units = std::floor(entry.distance / distance_unit_);
        out.push_back({static_cast<uint16_t>(entry.record & 0xffff), static_cast<uint8_t>(entry.record >> 16),
                       {static_cast<int8_t>(std::lround(scaled.x())), static_cast<int8_t>(std::lround(scaled.y())),
                        static_cast<int8_t>(std::lround(scaled.z()))},
                       static_cast<uint16_t>(std::min(units, 65535.0f))});
      }
      count[c] = static_cast<uint32_t>(out.size() - first);
    }
  }
  first_.assign(cells + 1, 0);
  for (size_t c = 0; c < cells; ++c) first_[c + 1] = first_[c] + count[c];
  candidates_.reserve(first_[cells]);
  for (const auto& chunk : chunk_candidates) candidates_.insert(candidates_.end(), chunk.begin(), chunk.end());
}

size_t CandidateGrid::cell_of(const Vec3f& p) const {
  const Vec3f g = (p - origin_) * (1.0f / cell_);
  const bool in_grid = g.x() >= 0.0f && g.y() >= 0.0f && g.z() >= 0.0f && g.x() < static_cast<float>(dims_[0]) &&
                       g.y() < static_cast<float>(dims_[1]) && g.z() < static_cast<float>(dims_[2]);
  if (!in_grid) return npos;
  const auto x = static_cast<uint32_t>(g.x()), y = static_cast<uint32_t>(g.y()), z = static_cast<uint32_t>(g.z());
  return (static_cast<size_t>(z) * dims_[1] + y) * dims_[0] + x;
}

void CandidateGrid::prefetch_list(size_t cell) const {
  if (cell == npos) return;
  const uint32_t begin = first_[cell], end = first_[cell + 1];
  if (begin == end) return;
  // The first 16 entries (a scan reads about 9): up to three cache lines.
  __builtin_prefetch(&candidates_[begin]);
  __builtin_prefetch(&candidates_[std::min(end, begin + 8) - 1]);
  __builtin_prefetch(&candidates_[std::min(end, begin + 16) - 1]);
}

void CandidateGrid::prefetch_triangles(size_t cell) const {
  if (cell == npos) return;
  const uint32_t begin = first_[cell], end = std::min(first_[cell + 1], first_[cell] + 6);
  for (uint32_t k = begin; k < end && candidates_[k].record() != kTruncated; ++k) __builtin_prefetch(&records_[candidates_[k].record()]);
}

CandidateGrid::Answer CandidateGrid::closest_in(size_t c, const Vec3f& p, float radius, SurfaceHit& hit) const {
  // Outside the grid: farther than the band from the body.
  if (c == npos) return radius <= band_ ? Answer::kNone : Answer::kUnknown;
  const uint32_t begin = first_[c], end = first_[c + 1];
  // No list: the cell centre is beyond the band, so p is beyond band - half diagonal.
  if (begin == end) return radius <= band_ - half_diagonal_ ? Answer::kNone : Answer::kUnknown;

  const size_t nx = dims_[0], ny = dims_[1];
  const auto x = static_cast<float>(c % nx), y = static_cast<float>((c / nx) % ny), z = static_cast<float>(c / (nx * ny));
  const Vec3f centre = origin_ + cell_ * Vec3f(x + 0.5f, y + 0.5f, z + 0.5f);
  const Vec3f from_centre = p - centre;
  const float offset = from_centre.norm();
  const Vec3f scaled = from_centre * (1.0f / 127.0f);
  const float slack = offset * kAwayError + 1e-6f;  // rounding of `away`, and 1 um for the float sums
  float best = radius, best_squared = radius * radius;
  bool found = false;
  for (uint32_t k = begin; k < end; ++k) {
    const Candidate& candidate = candidates_[k];
    const float centre_distance = static_cast<float>(candidate.distance) * distance_unit_;
    // d(p, T) >= d(c, T) - |p - c|: no nearer one follows (1 um for rounding).
    if (centre_distance - offset - 1e-6f >= best) break;
    const uint32_t record = candidate.record();
    if (record == kTruncated) return found ? Answer::kTruncatedFound : Answer::kTruncatedNone;
    // The plane bound (see Candidate::away).
    const float along = scaled.x() * candidate.away[0] + scaled.y() * candidate.away[1] + scaled.z() * candidate.away[2];
    if (centre_distance + along - slack >= best) continue;
    const Record& r = records_[record];
    const TrianglePoint where = closest_on_triangle(p, r.a, r.b, r.c);
    const float distance_squared = (where.point - p).squaredNorm();
    if (distance_squared < best_squared) {  // (the square root only for a nearer one)
      const float distance = std::sqrt(distance_squared);
      best = distance;
      best_squared = distance_squared;
      hit.triangle = r.triangle;
      hit.where = where;
      hit.distance = distance;
      found = true;
    }
  }
  return found ? Answer::kFound : Answer::kNone;
}

size_t CandidateGrid::listed_cells() const {
  size_t lists = 0;
  for (size_t c = 0; c + 1 < first_.size(); ++c)  // a cell left out holds only a truncation entry
    lists += first_[c + 1] > first_[c] && candidates_[first_[c]].record() != kTruncated;
  return lists;
}

double CandidateGrid::mean_list_length() const {
  size_t lists = 0;
  for (size_t c = 0; c + 1 < first_.size(); ++c) lists += first_[c + 1] > first_[c];  // truncation entries included
  return lists ? static_cast<double>(candidates_.size()) / static_cast<double>(lists) : 0.0;
}

}  // namespace drape::collision
