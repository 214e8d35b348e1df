// Sparse narrow-band signed distance field; see sdf_collider.hpp.
#include "collision/sdf_collider.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "collision/bvh_collider.hpp"

namespace drape::collision {

// Every brick cell overlapping the box [lo, hi], clipped to the grid, visited by cell index.
template <class Visit>
void SdfCollider::for_each_brick(const Vec3f& lo, const Vec3f& hi, Visit&& visit) const {
  const float brick_size = voxel_ * kBrick;
  int first[3], last[3];
  for (int a = 0; a < 3; ++a) {
    first[a] = std::max(0, static_cast<int>(std::floor((lo[a] - origin_[a]) / brick_size)));
    last[a] = std::min(dims_[a] - 1, static_cast<int>(std::floor((hi[a] - origin_[a]) / brick_size)));
  }
  const auto nx = static_cast<size_t>(dims_[0]), ny = static_cast<size_t>(dims_[1]);
  for (int z = first[2]; z <= last[2]; ++z)
    for (int y = first[1]; y <= last[1]; ++y)
      for (int x = first[0]; x <= last[0]; ++x)
        visit((static_cast<size_t>(z) * ny + static_cast<size_t>(y)) * nx + static_cast<size_t>(x));
}

size_t SdfCollider::memory_bytes() const {
  return brick_of_.size() * sizeof(int32_t) + distance_.size() * sizeof(float) + nearest_triangle_.size() * sizeof(uint32_t);
}

SdfCollider::SdfCollider(const Mesh& body, float voxel_size, float band)
    : surface_(body.positions, body.triangles), voxel_(voxel_size), band_(band) {
  if (!(voxel_size > 0) || !(band > 0)) throw std::invalid_argument("sdf collider: voxel size and band must be positive");
  bvh_ = std::make_unique<TriangleBvh>(surface_, /*refit=*/true);
  build_field();
}

void SdfCollider::set_surface(std::span<const Vec3f> positions, double t) {
  surface_.set_positions(positions, t);
  bvh_->update();
  update_field();
}

// Incremental update for a moving body: only bricks near vertices that moved more than an eighth of
// a voxel since they were last sampled are sampled again. A kept brick's samples are then off by at
// most a quarter voxel (a distance changes no more than the surface near it moves, and a vertex's
// drift from the pose its bricks were sampled at stays below two eighths). The region a moved vertex
// can affect: a stored sample lies within band + brick diagonal + a triangle's size of the skin, and
// its old or new nearest triangle within a triangle's size of the vertex, so bricks within that
// much of the vertex's old or new position. Falls back to a full rebuild when most of the body moved or when
// the moved surface needs a brick that stores no samples yet.
void SdfCollider::update_field() {
  const auto start = std::chrono::steady_clock::now();
  const auto positions = surface_.positions();
  const float tolerance = 0.125f * voxel_;
  std::vector<uint32_t> moved;
  for (uint32_t v = 0; v < positions.size(); ++v)
    if ((positions[v] - sampled_positions_[v]).squaredNorm() > tolerance * tolerance) moved.push_back(v);
  stats_.rebuilt_fraction = 0;
  if (moved.empty()) {
    stats_.build_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return;
  }
  if (2 * moved.size() > positions.size()) return build_field();

  const float brick_size = voxel_ * kBrick;
  const float reach = band_ + std::sqrt(3.0f) * brick_size + 2 * longest_edge_ + tolerance;
  std::vector<uint8_t> dirty(brick_of_.size(), 0);
  const auto mark = [&](const Vec3f& p, float grow) {
    for_each_brick(p - Vec3f::Constant(grow), p + Vec3f::Constant(grow), [&](size_t c) { dirty[c] = 1; });
  };
  for (uint32_t v : moved) {
    // The moved surface must stay inside the grid and its band inside stored bricks.
    for (int a = 0; a < 3; ++a)
      if (positions[v][a] - band_ < origin_[a] || positions[v][a] + band_ > origin_[a] + static_cast<float>(dims_[a]) * brick_size)
        return build_field();
    mark(sampled_positions_[v], reach);
    mark(positions[v], reach);
  }
  // A moved triangle's box grown by the band must lie in stored bricks, as the full build makes it
  // (stored bricks the surface has left keep their samples: still exact, only unneeded).
  std::vector<uint8_t> vertex_moved(positions.size(), 0);
  for (uint32_t v : moved) vertex_moved[v] = 1;
  for (const Tri& tri : surface_.triangles()) {
    if (!vertex_moved[tri[0]] && !vertex_moved[tri[1]] && !vertex_moved[tri[2]]) continue;
    Bounds tb;
    for (uint32_t v : tri) tb.extend(positions[v]);
    for_each_brick(tb.min - Vec3f::Constant(band_), tb.max + Vec3f::Constant(band_), [&](size_t c) {
      if (brick_of_[c] < 0) brick_of_[c] = kNewlyStored;
    });
  }
  // Bricks the moved surface now needs get sample blocks (in cell order) and are sampled below.
  for (size_t c = 0; c < brick_of_.size(); ++c)
    if (brick_of_[c] == kNewlyStored) {
      brick_of_[c] = static_cast<int32_t>(stored_bricks_++);
      dirty[c] = 1;
    }
  distance_.resize(stored_bricks_ * kSamples);
  nearest_triangle_.resize(stored_bricks_ * kSamples);
  std::vector<size_t> stored, flagged;
  for (size_t c = 0; c < dirty.size(); ++c)
    if (dirty[c]) (brick_of_[c] >= 0 ? stored : flagged).push_back(c);
  sample_bricks(stored);
  judge_far_bricks(flagged);
  for (uint32_t v : moved) sampled_positions_[v] = positions[v];
  stats_.rebuilt_fraction = stored_bricks_ ? static_cast<double>(stored.size()) / static_cast<double>(stored_bricks_) : 0.0;
  stats_.memory_bytes = memory_bytes();
  stats_.build_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

void SdfCollider::build_field() {
  const auto start = std::chrono::steady_clock::now();
  const float brick_size = voxel_ * kBrick;
  const Bounds box = bounds(std::vector<Vec3f>(surface_.positions().begin(), surface_.positions().end()));
  origin_ = box.min - Vec3f::Constant(band_ + voxel_);
  for (int a = 0; a < 3; ++a)
    dims_[a] = static_cast<int>(std::ceil((box.max[a] - box.min[a] + 2 * (band_ + voxel_)) / brick_size)) + 1;
  const size_t brick_cells = static_cast<size_t>(dims_[0]) * static_cast<size_t>(dims_[1]) * static_cast<size_t>(dims_[2]);

  // Bricks within the band of some triangle (its box grown by the band) store samples.
  brick_of_.assign(brick_cells, kFarOutside);
  for (const Tri& tri : surface_.triangles()) {
    Bounds tb;
    for (uint32_t v : tri) tb.extend(surface_.position(v));
    for_each_brick(tb.min - Vec3f::Constant(band_), tb.max + Vec3f::Constant(band_), [&](size_t c) { brick_of_[c] = 0; });
  }
  std::vector<size_t> stored_cells;
  for (size_t c = 0; c < brick_cells; ++c)
    if (brick_of_[c] == 0) {
      brick_of_[c] = static_cast<int32_t>(stored_cells.size());
      stored_cells.push_back(c);
    }

  // Exact signed samples of the stored bricks; the others judged far inside or far outside.
  distance_.resize(stored_cells.size() * kSamples);
  nearest_triangle_.resize(stored_cells.size() * kSamples);
  stored_bricks_ = stored_cells.size();
  sample_bricks(stored_cells);
  std::vector<size_t> flagged;
  for (size_t c = 0; c < brick_cells; ++c)
    if (brick_of_[c] < 0) flagged.push_back(c);
  judge_far_bricks(flagged);
  sampled_positions_.assign(surface_.positions().begin(), surface_.positions().end());
  longest_edge_ = 0;
  for (const Tri& tri : surface_.triangles())
    for (int k = 0; k < 3; ++k)
      longest_edge_ = std::max(longest_edge_, (surface_.position(tri[k]) - surface_.position(tri[(k + 1) % 3])).norm());
  stats_.rebuilt_fraction = 1;
  stats_.build_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  stats_.memory_bytes = memory_bytes();
}

// Exact signed samples of stored bricks (given by brick cell), in parallel: each brick independent.
void SdfCollider::sample_bricks(const std::vector<size_t>& cells) {
  const float brick_size = voxel_ * kBrick;
  const auto count = static_cast<int64_t>(cells.size());
  const float infinity = std::numeric_limits<float>::infinity();
#pragma omp parallel for schedule(dynamic, 4)
  for (int64_t i = 0; i < count; ++i) {
    const size_t c = cells[static_cast<size_t>(i)];
    const auto b = static_cast<size_t>(brick_of_[c]);
    const int bx = static_cast<int>(c % static_cast<size_t>(dims_[0]));
    const int by = static_cast<int>((c / static_cast<size_t>(dims_[0])) % static_cast<size_t>(dims_[1]));
    const int bz = static_cast<int>(c / (static_cast<size_t>(dims_[0]) * static_cast<size_t>(dims_[1])));
    const Vec3f corner = origin_ + brick_size * Vec3f(static_cast<float>(bx), static_cast<float>(by), static_cast<float>(bz));
    float* dist = &distance_[b * kSamples];
    uint32_t* tri = &nearest_triangle_[b * kSamples];
    for (int k = 0; k < kSamples; ++k) {
      const int x = k % kSide, y = (k / kSide) % kSide, z = k / (kSide * kSide);
      const Vec3f p = corner + voxel_ * Vec3f(static_cast<float>(x), static_cast<float>(y), static_cast<float>(z));
      // The previous sample along an axis bounds the distance (1-Lipschitz): a small query sphere
      // prunes most of the tree.
      const int previous = x > 0 ? k - 1 : y > 0 ? k - kSide : z > 0 ? k - kSide * kSide : -1;
      const float bound = previous >= 0 ? std::abs(dist[previous]) + 1.001f * voxel_ + 1e-6f : infinity;
      SurfaceHit hit;
      if (!bvh_->closest(p, bound, hit)) bvh_->closest(p, infinity, hit);
      dist[k] = surface_.sign(hit, p) * hit.distance;
      tri[k] = hit.triangle;
    }
  }
}

// Bricks without samples: far inside when their centre is inside the body, else far outside.
void SdfCollider::judge_far_bricks(const std::vector<size_t>& cells) {
  const float brick_size = voxel_ * kBrick;
  const float infinity = std::numeric_limits<float>::infinity();
  Bounds box;
  for (const Vec3f& p : surface_.positions()) box.extend(p);
  const auto count = static_cast<int64_t>(cells.size());
#pragma omp parallel for schedule(dynamic, 64)
  for (int64_t i = 0; i < count; ++i) {
    const size_t uc = cells[static_cast<size_t>(i)];
    brick_of_[uc] = kFarOutside;
    const Vec3f centre = origin_ + brick_size * Vec3f(static_cast<float>(uc % static_cast<size_t>(dims_[0])) + 0.5f,
                                                      static_cast<float>((uc / static_cast<size_t>(dims_[0])) % static_cast<size_t>(dims_[1])) + 0.5f,
                                                      static_cast<float>(uc / (static_cast<size_t>(dims_[0]) * static_cast<size_t>(dims_[1]))) + 0.5f);
    if (((centre - box.min).array() < 0).any() || ((centre - box.max).array() > 0).any()) continue;
    SurfaceHit hit;
    bvh_->closest(centre, infinity, hit);
    if (surface_.sign(hit, centre) < 0) brick_of_[uc] = kFarInside;
  }
}

ContactSample SdfCollider::sample(const Vec3f& p, float radius) const {
  const float infinity = std::numeric_limits<float>::infinity();
  ContactSample out{infinity, Vec3f::Zero(), Vec3f::Zero()};
  const Vec3f g = (p - origin_) / voxel_;  // continuous voxel coordinates
  int brick[3];
  for (int a = 0; a < 3; ++a) {
    const float fb = std::floor(g[a] / kBrick);
    if (!(fb >= 0.0f && fb < static_cast<float>(dims_[a]))) {  // outside the grid: beyond the band, outside
      if (radius > band_) exact_sample(*bvh_, p, radius, out);
      return out;
    }
    brick[a] = static_cast<int>(fb);
  }
  const int32_t b = brick_of_[(static_cast<size_t>(brick[2]) * static_cast<size_t>(dims_[1]) + static_cast<size_t>(brick[1])) *
                                  static_cast<size_t>(dims_[0]) +
                              static_cast<size_t>(brick[0])];
  if (b == kFarOutside && radius <= band_) return out;
  if (b < 0) {  // beyond the band (deep inside, or a query radius wider than the band): ask the BVH
    exact_sample(*bvh_, p, radius, out);
    return out;
  }
  // Trilinear interpolation in the brick's cell and its analytic gradient.
  int cell[3];
  float f[3];
  for (int a = 0; a < 3; ++a) {
    const float local = g[a] - static_cast<float>(brick[a] * kBrick);
    cell[a] = std::clamp(static_cast<int>(local), 0, kBrick - 1);
    f[a] = local - static_cast<float>(cell[a]);
  }
  const float* d = &distance_[static_cast<size_t>(b) * kSamples];
  const int base = (cell[2] * kSide + cell[1]) * kSide + cell[0];
  const float c000 = d[base], c100 = d[base + 1], c010 = d[base + kSide], c110 = d[base + kSide + 1];
  const float c001 = d[base + kSide * kSide], c101 = d[base + kSide * kSide + 1];
  const float c011 = d[base + kSide * kSide + kSide], c111 = d[base + kSide * kSide + kSide + 1];
  const float x0 = c000 + f[0] * (c100 - c000), x1 = c010 + f[0] * (c110 - c010);
  const float x2 = c001 + f[0] * (c101 - c001), x3 = c011 + f[0] * (c111 - c011);
  const float y0 = x0 + f[1] * (x1 - x0), y1 = x2 + f[1] * (x3 - x2);
  const float distance = y0 + f[2] * (y1 - y0);
  if (!(distance <= radius)) return out;

  const float gx0 = (c100 - c000) + f[1] * ((c110 - c010) - (c100 - c000));
  const float gx1 = (c101 - c001) + f[1] * ((c111 - c011) - (c101 - c001));
  const Vec3f gradient(gx0 + f[2] * (gx1 - gx0), x1 - x0 + f[2] * ((x3 - x2) - (x1 - x0)), y1 - y0);
  const float length = gradient.norm();
  out.distance = distance;
  out.normal = length > 0 ? Vec3f(gradient / length) : Vec3f::UnitY();
  // Surface velocity: at the nearest point of the triangle nearest to the closest corner sample.
  const int corner = base + (f[0] > 0.5f ? 1 : 0) + (f[1] > 0.5f ? kSide : 0) + (f[2] > 0.5f ? kSide * kSide : 0);
  out.velocity = surface_.velocity(surface_.closest_on(nearest_triangle_[static_cast<size_t>(b) * kSamples + static_cast<size_t>(corner)], p));
  return out;
}

void SdfCollider::query(std::span<const Vec3f> points, float radius, std::span<ContactSample> out) const {
  for (size_t i = 0; i < points.size(); ++i) out[i] = sample(points[i], radius);
}

}  // namespace drape::collision
