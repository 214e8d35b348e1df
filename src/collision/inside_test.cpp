// The independent inside test behind report.json's penetration keys: generalized winding number for
// inside/outside (robust to small holes), exact BVH distance for the depth. It never looks at a
// collider's own picture of the body (maps, field), so it can judge all of them.
#include <algorithm>
#include <limits>

#include "collision/body_surface.hpp"
#include "collision/triangle_bvh.hpp"
#include "collision/winding_number.hpp"
#include "drape/collision.hpp"

namespace drape {

struct InsideTest::Impl {
  explicit Impl(const Mesh& body)
      : surface(body.positions, body.triangles), bvh(surface, false), winding(body.positions, body.triangles) {}
  collision::BodySurface surface;
  collision::TriangleBvh bvh;
  collision::WindingNumberTree winding;
};

InsideTest::InsideTest(const Mesh& body) : impl_(std::make_unique<Impl>(body)) {}
InsideTest::~InsideTest() = default;
InsideTest::InsideTest(InsideTest&&) noexcept = default;
InsideTest& InsideTest::operator=(InsideTest&&) noexcept = default;

double InsideTest::winding_number(const Vec3f& p) const { return impl_->winding.winding_number(p); }

float InsideTest::unsigned_distance(const Vec3f& p) const {
  collision::SurfaceHit hit;
  if (!impl_->bvh.closest(p, std::numeric_limits<float>::infinity(), hit)) return std::numeric_limits<float>::infinity();
  return hit.distance;
}

PenetrationStats measure_penetration(const InsideTest& body, std::span<const Vec3f> points, float tolerance) {
  PenetrationStats stats;
  const auto n = static_cast<int64_t>(points.size());
  size_t count = 0;
  float deepest = 0;
#pragma omp parallel for reduction(+ : count) reduction(max : deepest) schedule(dynamic, 256)
  for (int64_t i = 0; i < n; ++i) {
    const Vec3f& p = points[static_cast<size_t>(i)];
    if (!body.inside(p)) continue;
    const float depth = body.unsigned_distance(p);
    if (depth <= tolerance) continue;
    ++count;
    deepest = std::max(deepest, depth);
  }
  stats.penetrating = count;
  stats.fraction = points.empty() ? 0.0 : static_cast<double>(count) / static_cast<double>(points.size());
  stats.max_depth_m = deepest;
  return stats;
}

PenetrationStats measure_penetration(const Mesh& body, std::span<const Vec3f> points, float tolerance) {
  return measure_penetration(InsideTest(body), points, tolerance);
}

}  // namespace drape
