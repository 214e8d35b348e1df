// Object-space body collider; see bvh_collider.hpp.
#include "collision/bvh_collider.hpp"

#include <algorithm>
#include <chrono>
#include <limits>

namespace drape::collision {

void sample_from_hit(const BodySurface& surface, const SurfaceHit* hit, const Vec3f& p, ContactSample& out) {
  if (!hit) {
    out.distance = std::numeric_limits<float>::infinity();
    out.normal = Vec3f::Zero();
    out.velocity = Vec3f::Zero();
    return;
  }
  const float sign = surface.sign(*hit, p);
  out.distance = sign * hit->distance;
  out.normal = surface.smooth_normal(*hit);
  // Away from the surface, the way out is along p - nearest point; the interpolated normal can point
  // elsewhere at a crease (the top of a narrow gap), which would push the cloth into the other wall.
  if (hit->distance > 1e-3f) {
    const Vec3f out_direction = sign * (p - hit->where.point) / hit->distance;
    if (out_direction.dot(out.normal) < 0.7f) out.normal = out_direction;
  }
  out.velocity = surface.moving() ? surface.velocity(*hit) : Vec3f::Zero();
}

bool exact_sample(const TriangleBvh& bvh, const Vec3f& p, float radius, ContactSample& out) {
  SurfaceHit hit;
  const bool found = bvh.closest(p, radius, hit);
  sample_from_hit(bvh.surface(), found ? &hit : nullptr, p, out);
  return found;
}

BvhCollider::BvhCollider(const Mesh& body, bool candidate_grid) : surface_(body.positions, body.triangles) {
  const auto start = std::chrono::steady_clock::now();
  bvh_ = std::make_unique<TriangleBvh>(surface_, /*refit=*/true);
  if (candidate_grid) bvh_->build_candidate_grid();
  stats_.build_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  // Embree reports no size: about 64 B per triangle.
  stats_.memory_bytes = surface_.triangle_count() * 64 + (candidate_grid ? bvh_->candidate_grid()->memory_bytes() : 0);
}

void BvhCollider::set_surface(std::span<const Vec3f> positions, double t) {
  const auto start = std::chrono::steady_clock::now();
  surface_.set_positions(positions, t);
  bvh_->update();
  stats_.memory_bytes = surface_.triangle_count() * 64;
  stats_.build_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

void BvhCollider::query(std::span<const Vec3f> points, float radius, std::span<ContactSample> out) const {
  // In chunks: the nearest points of the whole chunk (batched: TriangleBvh::closest_batch), then
  // the surface data of all their triangles prefetched in two rounds, then the samples.
  constexpr size_t kChunk = 64;
  SurfaceHit hits[kChunk];
  uint8_t found[kChunk];
  for (size_t start = 0; start < points.size(); start += kChunk) {
    const size_t n = std::min(kChunk, points.size() - start);
    bvh_->closest_batch(points.subspan(start, n), radius, std::span(hits, n), std::span(found, n));
    for (int step = 0; step < 2; ++step)
      for (size_t j = 0; j < n; ++j)
        if (found[j]) surface_.prefetch(hits[j], step);
    for (size_t j = 0; j < n; ++j) sample_from_hit(surface_, found[j] ? &hits[j] : nullptr, points[start + j], out[start + j]);
  }
}

}  // namespace drape::collision
