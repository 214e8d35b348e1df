// Self-contact pairs of a cloth (src/sim/self_contact.hpp, docs/cloth.md "Self-contact").
#include "sim/self_contact.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <functional>
#include <limits>
#include <stdexcept>
#include <utility>

#include <Eigen/Geometry>

#include "collision/triangle_closest.hpp"
#include "sim/parallel.hpp"

namespace drape::sim {
namespace {

inline uint32_t hash_cell(int32_t x, int32_t y, int32_t z, uint32_t mask) {
  return ((static_cast<uint32_t>(x) * 73856093u) ^ (static_cast<uint32_t>(y) * 19349663u) ^
          (static_cast<uint32_t>(z) * 83492791u)) & mask;
}

inline int32_t cell_coordinate(double v, double inv_cell) {
  return static_cast<int32_t>(std::floor(std::clamp(v * inv_cell, -1e9, 1e9)));
}

}  // namespace

double SelfContactFinder::default_exclusion(const ClothModel& model) {
  const SpringRange structural = model.range(SpringKind::Structural);
  double sum = 0;
  for (uint32_t k = structural.begin; k < structural.end; ++k) sum += model.rest_length[k];
  const double mean = structural.size() > 0 ? sum / structural.size() : 0.0;
  return std::max(2.0 * mean, 0.002);
}

SelfContactFinder::SelfContactFinder(const ClothModel& model, double exclusion) : model_(model) {
  const size_t n = model.particle_count();
  const size_t triangles = model.triangles.size();
  // The sewn cloth as a graph: structural and shear springs at their rest length, seams at theirs
  // (zero where sewn edge to edge).
  std::vector<uint32_t> link_begin(n + 1, 0), link;
  std::vector<double> link_length;
  const SpringRange flexion = model.range(SpringKind::Flexion);
  const auto linked = [&](size_t k) { return k < flexion.begin || k >= flexion.end; };
  for (size_t k = 0; k < model.spring_count(); ++k)
    if (linked(k)) {
      ++link_begin[model.spring_a[k] + 1];
      ++link_begin[model.spring_b[k] + 1];
    }
  for (size_t i = 0; i < n; ++i) link_begin[i + 1] += link_begin[i];
  link.resize(link_begin[n]);
  link_length.resize(link_begin[n]);
  {
    std::vector<uint32_t> fill(link_begin.begin(), link_begin.end() - 1);
    for (size_t k = 0; k < model.spring_count(); ++k) {
      if (!linked(k)) continue;
      const uint32_t a = model.spring_a[k], b = model.spring_b[k];
      link_length[fill[a]] = link_length[fill[b]] = model.rest_length[k];
      link[fill[a]++] = b;
      link[fill[b]++] = a;
    }
  }
  // Triangles around each particle (CSR).
  std::vector<uint32_t> around_begin(n + 1, 0), around;
  for (const Tri& t : model.triangles)
    for (uint32_t v : t) ++around_begin[v + 1];
  for (size_t i = 0; i < n; ++i) around_begin[i + 1] += around_begin[i];
  around.resize(around_begin[n]);
  {
    std::vector<uint32_t> fill(around_begin.begin(), around_begin.end() - 1);
    for (size_t t = 0; t < triangles; ++t)
      for (uint32_t v : model.triangles[t]) around[fill[v]++] = static_cast<uint32_t>(t);
  }
  // Per particle: the triangles with a corner within `exclusion` of it along the sewn cloth
  // (Dijkstra over the graph above, stopped at `exclusion`).
  std::vector<double> distance(n, std::numeric_limits<double>::infinity());
  std::vector<uint32_t> reached, list;
  using Entry = std::pair<double, uint32_t>;
  std::vector<Entry> heap;
  excluded_begin_.assign(n + 1, 0);
  excluded_.clear();
  for (size_t i = 0; i < n; ++i) {
    list.clear();
    reached.clear();
    heap.clear();
    distance[i] = 0;
    reached.push_back(static_cast<uint32_t>(i));
    heap.emplace_back(0.0, static_cast<uint32_t>(i));
    while (!heap.empty()) {
      std::pop_heap(heap.begin(), heap.end(), std::greater<>());
      const auto [d, v] = heap.back();
      heap.pop_back();
      if (d > distance[v]) continue;
      for (uint32_t a = around_begin[v]; a < around_begin[v + 1]; ++a) list.push_back(around[a]);
      for (uint32_t q = link_begin[v]; q < link_begin[v + 1]; ++q) {
        const uint32_t u = link[q];
        const double du = d + link_length[q];
        if (du >= exclusion || du >= distance[u]) continue;
        if (!std::isfinite(distance[u])) reached.push_back(u);
        distance[u] = du;
        heap.emplace_back(du, u);
        std::push_heap(heap.begin(), heap.end(), std::greater<>());
      }
    }
    for (uint32_t v : reached) distance[v] = std::numeric_limits<double>::infinity();
    std::sort(list.begin(), list.end());
    list.erase(std::unique(list.begin(), list.end()), list.end());
    excluded_.insert(excluded_.end(), list.begin(), list.end());
    excluded_begin_[i + 1] = static_cast<uint32_t>(excluded_.size());
  }
  for (const Tri& t : model.triangles)
    for (size_t j = 0; j < 3; ++j) edges_.push_back({std::min(t[j], t[(j + 1) % 3]), std::max(t[j], t[(j + 1) % 3])});
  std::sort(edges_.begin(), edges_.end());
  edges_.erase(std::unique(edges_.begin(), edges_.end()), edges_.end());
  edge_crossings_.assign(edges_.size(), 0);
  edge_first_.assign(edges_.size(), UINT32_MAX);
  const uint32_t buckets = std::bit_ceil(static_cast<uint32_t>(std::max<size_t>(64, 2 * triangles)));
  bucket_begin_.assign(static_cast<size_t>(buckets) + 1, 0);
  bucket_fill_.assign(buckets, 0);
  cell_box_.resize(triangles);
  centre_.resize(triangles);
  bound_.resize(triangles);
  slot_.resize(kPerParticle * n);
  slot_count_.assign(n, 0);
}

void SelfContactFinder::build_grid(std::span<const Vec3d> x, double radius) {
  const ClothModel& m = model_;
  const size_t triangles = m.triangles.size();
  inv_cell_ = 1.0 / radius;
  const uint32_t buckets = static_cast<uint32_t>(bucket_fill_.size()), mask = buckets - 1;
  // Each triangle's box of cells (its corners' box grown by the radius) and bounding sphere.
  std::fill(bucket_begin_.begin(), bucket_begin_.end(), 0u);
  for (size_t t = 0; t < triangles; ++t) {
    const Tri& tri = m.triangles[t];
    Vec3d lo = x[tri[0]], hi = x[tri[0]];
    for (int j = 1; j < 3; ++j) {
      lo = lo.cwiseMin(x[tri[static_cast<size_t>(j)]]);
      hi = hi.cwiseMax(x[tri[static_cast<size_t>(j)]]);
    }
    centre_[t] = 0.5 * (lo + hi);
    bound_[t] = 0.5 * (hi - lo).norm();
    auto& box = cell_box_[t];
    for (int a = 0; a < 3; ++a) {
      box[static_cast<size_t>(a)] = cell_coordinate(lo[a] - radius, inv_cell_);
      box[static_cast<size_t>(a) + 3] = cell_coordinate(hi[a] + radius, inv_cell_);
    }
    for (int32_t cz = box[2]; cz <= box[5]; ++cz)
      for (int32_t cy = box[1]; cy <= box[4]; ++cy)
        for (int32_t cx = box[0]; cx <= box[3]; ++cx) ++bucket_begin_[hash_cell(cx, cy, cz, mask) + 1];
  }
  for (uint32_t b = 0; b < buckets; ++b) bucket_begin_[b + 1] += bucket_begin_[b];
  bucket_triangle_.resize(bucket_begin_[buckets]);
  std::copy(bucket_begin_.begin(), bucket_begin_.end() - 1, bucket_fill_.begin());
  for (size_t t = 0; t < triangles; ++t) {
    const auto& box = cell_box_[t];
    for (int32_t cz = box[2]; cz <= box[5]; ++cz)
      for (int32_t cy = box[1]; cy <= box[4]; ++cy)
        for (int32_t cx = box[0]; cx <= box[3]; ++cx)
          bucket_triangle_[bucket_fill_[hash_cell(cx, cy, cz, mask)]++] = static_cast<uint32_t>(t);
  }
}

uint32_t SelfContactFinder::bucket_of(const Vec3d& p) const {
  const uint32_t mask = static_cast<uint32_t>(bucket_fill_.size()) - 1;
  return hash_cell(cell_coordinate(p.x(), inv_cell_), cell_coordinate(p.y(), inv_cell_), cell_coordinate(p.z(), inv_cell_), mask);
}

bool SelfContactFinder::excluded(uint32_t particle, uint32_t triangle) const {
  return std::binary_search(excluded_.data() + excluded_begin_[particle], excluded_.data() + excluded_begin_[particle + 1], triangle);
}

bool SelfContactFinder::listed(uint32_t triangle, const Vec3d& p) const {
  // A bucket holds every triangle one of whose cells hashes to it: only those whose box of cells
  // holds p's cell are near p, and each of them is listed there once for that cell.
  const auto& box = cell_box_[triangle];
  for (int a = 0; a < 3; ++a) {
    const int32_t c = cell_coordinate(p[a], inv_cell_);
    if (c < box[static_cast<size_t>(a)] || c > box[static_cast<size_t>(a) + 3]) return false;
  }
  return true;
}

double SelfContactFinder::longest_edge(std::span<const Vec3d> x) const {
  double longest = 0;
  for (const auto& [a, b] : edges_) longest = std::max(longest, (x[b] - x[a]).squaredNorm());
  return std::sqrt(longest);
}

void SelfContactFinder::find(std::span<const Vec3d> x, std::span<const Vec3d> x_start, std::span<const uint8_t> free,
                             double radius, std::vector<SelfPair>& pairs, std::vector<uint8_t>& tangled, bool mark_tangled) {
  const ClothModel& m = model_;
  const size_t n = m.particle_count(), triangles = m.triangles.size();
  pairs.clear();
  if (triangles == 0 || n == 0) return;
  if (mark_tangled) {
    // One grid for both: an edge that crosses a triangle has its midpoint within half its length of it.
    build_grid(x, std::max(radius, 0.5 * longest_edge(x)));
    crossings_on_grid(x, &tangled);
  } else {
    build_grid(x, radius);
  }
  const bool any_tangled = tangled.size() == n;
  // Each particle against the triangles listed in its cell's bucket: the nearest kPerParticle
  // within the radius.
  parallel_blocks(n, [&](size_t, size_t begin, size_t end) {
    for (size_t i = begin; i < end; ++i) {
      slot_count_[i] = 0;
      if (!free[i] || (any_tangled && tangled[i])) continue;
      const Vec3d& p = x[i];
      const uint32_t b = bucket_of(p);
      SelfPair* slots = slot_.data() + kPerParticle * i;
      std::array<double, kPerParticle> dist{};
      size_t count = 0;
      for (uint32_t q = bucket_begin_[b]; q < bucket_begin_[b + 1]; ++q) {
        const uint32_t t = bucket_triangle_[q];
        if ((p - centre_[t]).squaredNorm() > (radius + bound_[t]) * (radius + bound_[t])) continue;
        if (!listed(t, p) || excluded(static_cast<uint32_t>(i), t)) continue;
        const Tri& tri = m.triangles[t];
        if (any_tangled && (tangled[tri[0]] || tangled[tri[1]] || tangled[tri[2]])) continue;
        const auto hit = collision::closest_on_triangle(p.cast<float>(), x[tri[0]].cast<float>(), x[tri[1]].cast<float>(),
                                                        x[tri[2]].cast<float>());
        const std::array<double, 3> w{1.0 - static_cast<double>(hit.b1) - static_cast<double>(hit.b2),
                                      static_cast<double>(hit.b1), static_cast<double>(hit.b2)};
        const Vec3d c = w[0] * x[tri[0]] + w[1] * x[tri[1]] + w[2] * x[tri[2]];
        const double d = (p - c).norm();
        if (d >= radius) continue;
        if (count == kPerParticle && !(d < dist[count - 1])) continue;
        Vec3d normal = (x[tri[1]] - x[tri[0]]).cross(x[tri[2]] - x[tri[0]]);
        const double area2 = normal.norm();
        if (!(area2 > 1e-14)) continue;
        normal /= area2;
        if (hit.feature != collision::TriangleFeature::kFace && d > 1e-9) normal = (p - c) / d;
        // The side at the step's start.
        const Vec3d c0 = w[0] * x_start[tri[0]] + w[1] * x_start[tri[1]] + w[2] * x_start[tri[2]];
        if (normal.dot(x_start[i] - c0) < 0) normal = -normal;
        // Insert in order of distance (ties: the triangle listed first stays first).
        size_t at = std::min(count, kPerParticle - 1);
        if (count < kPerParticle) ++count;
        while (at > 0 && dist[at - 1] > d) {
          dist[at] = dist[at - 1];
          slots[at] = slots[at - 1];
          --at;
        }
        dist[at] = d;
        slots[at] = SelfPair{static_cast<uint32_t>(i), t, w, normal};
      }
      slot_count_[i] = static_cast<uint8_t>(count);
    }
  });
  for (size_t i = 0; i < n; ++i)
    pairs.insert(pairs.end(), slot_.begin() + static_cast<std::ptrdiff_t>(kPerParticle * i),
                 slot_.begin() + static_cast<std::ptrdiff_t>(kPerParticle * i + slot_count_[i]));
}

size_t SelfContactFinder::crossings(std::span<const Vec3d> x, std::vector<uint8_t>* tangled) {
  if (model_.triangles.empty()) {
    if (tangled) tangled->assign(model_.particle_count(), 0);
    return 0;
  }
  // An edge that crosses a triangle has its midpoint within half its length of it.
  build_grid(x, std::max(0.5 * longest_edge(x), 1e-6));
  return crossings_on_grid(x, tangled);
}

size_t SelfContactFinder::crossings_on_grid(std::span<const Vec3d> x, std::vector<uint8_t>* tangled) {
  const ClothModel& m = model_;
  // Per edge in parallel: how many triangles it crosses and the first; gathered in edge order.
  parallel_blocks(edges_.size(), [&](size_t, size_t begin, size_t end) {
    for (size_t e = begin; e < end; ++e) {
      const auto [a, b] = edges_[e];
      const Vec3d& p = x[a];
      const Vec3d d = x[b] - p;
      const Vec3d mid = p + 0.5 * d;
      const double half = 0.5 * d.norm();
      const uint32_t bucket = bucket_of(mid);
      uint32_t count = 0, first = UINT32_MAX;
      for (uint32_t q = bucket_begin_[bucket]; q < bucket_begin_[bucket + 1]; ++q) {
        const uint32_t t = bucket_triangle_[q];
        if ((mid - centre_[t]).squaredNorm() > (half + bound_[t]) * (half + bound_[t])) continue;
        if (!listed(t, mid) || excluded(a, t) || excluded(b, t)) continue;
        // Moeller-Trumbore: the segment p + s d, s in [0, 1], through the triangle.
        const Tri& tri = m.triangles[t];
        const Vec3d e1 = x[tri[1]] - x[tri[0]], e2 = x[tri[2]] - x[tri[0]];
        const Vec3d h = d.cross(e2);
        const double det = e1.dot(h);
        if (std::abs(det) < 1e-18) continue;
        const Vec3d o = p - x[tri[0]];
        const double u = o.dot(h) / det;
        if (u < 0 || u > 1) continue;
        const Vec3d qv = o.cross(e1);
        const double v = d.dot(qv) / det;
        if (v < 0 || u + v > 1) continue;
        const double s = e2.dot(qv) / det;
        if (s < 0 || s > 1) continue;
        if (count++ == 0) first = t;
      }
      edge_crossings_[e] = count;
      edge_first_[e] = first;
    }
  });
  if (tangled) tangled->assign(m.particle_count(), 0);
  size_t total = 0;
  for (size_t e = 0; e < edges_.size(); ++e) {
    total += edge_crossings_[e];
    if (!tangled || edge_crossings_[e] == 0) continue;
    const Tri& tri = m.triangles[edge_first_[e]];
    for (uint32_t v : {edges_[e][0], edges_[e][1], tri[0], tri[1], tri[2]}) (*tangled)[v] = 1;
  }
  // And every particle sharing an edge with one of those: next to a crossing the cloth lies on both
  // sides of itself, and the sides taken there hold it as it is as surely as in it.
  if (tangled && total > 0) {
    for (const auto& [a, b] : edges_)
      if ((*tangled)[a] == 1 || (*tangled)[b] == 1) {
        if ((*tangled)[a] == 0) (*tangled)[a] = 2;
        if ((*tangled)[b] == 0) (*tangled)[b] = 2;
      }
  }
  return total;
}

}  // namespace drape::sim

namespace drape {

size_t self_intersections(const ClothModel& model, std::span<const Vec3f> x) {
  if (x.size() != model.particle_count()) throw std::invalid_argument("self_intersections: positions not made for this model");
  std::vector<Vec3d> at(x.size());
  for (size_t i = 0; i < x.size(); ++i) at[i] = x[i].cast<double>();
  sim::SelfContactFinder finder(model, sim::SelfContactFinder::default_exclusion(model));
  return finder.crossings(at);
}

}  // namespace drape
