// Skin showing through the cloth (drape/fit.hpp, measure_skin_through): one ray per body vertex into
// the body against the garment's triangles, through an Embree BVH of the cloth (the collision
// layer's TriangleBvh, built over the garment's final state).
#include <algorithm>

#include "collision/body_surface.hpp"
#include "collision/triangle_bvh.hpp"
#include "drape/fit.hpp"

namespace drape {

SkinThroughStats measure_skin_through(const Mesh& body, std::span<const Vec3f> cloth, std::span<const Tri> triangles,
                                      float reach, float tolerance) {
  SkinThroughStats stats;
  if (triangles.empty() || body.positions.empty()) return stats;
  const collision::BodySurface surface(cloth, triangles);
  const collision::TriangleBvh bvh(surface, /*refit=*/false);
  const std::vector<Vec3f> computed =
      body.normals.size() == body.positions.size() ? std::vector<Vec3f>{} : vertex_normals(body.positions, body.triangles);
  const std::vector<Vec3f>& normals = computed.empty() ? body.normals : computed;
  size_t count = 0;
  float deepest = 0;
  const auto n = static_cast<std::ptrdiff_t>(body.positions.size());
#pragma omp parallel for schedule(static) reduction(+ : count) reduction(max : deepest)
  for (std::ptrdiff_t v = 0; v < n; ++v) {
    const Vec3f& normal = normals[static_cast<size_t>(v)];
    if (!(normal.squaredNorm() > 0.5f)) continue;  // a degenerate vertex has no inward direction
    float depth = 0;
    if (!bvh.first_hit(body.positions[static_cast<size_t>(v)], -normal, reach, depth) || depth <= tolerance) continue;
    ++count;
    deepest = std::max(deepest, depth);
  }
  stats.body_vertices = count;
  stats.max_depth_m = deepest;
  return stats;
}

}  // namespace drape
