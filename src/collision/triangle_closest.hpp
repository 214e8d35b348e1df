#pragma once
// Closest point on a triangle (Ericson, Real-Time Collision Detection, sec. 5.1.5), extended to
// report the barycentric weights and which feature (vertex, edge, interior) holds the point: the
// feature picks the pseudo-normal that gives the sign of the distance (Baerentzen & Aanaes 2005).
#include <cstdint>

#include "drape/mesh.hpp"

namespace drape::collision {

enum class TriangleFeature : uint8_t { kVertex0, kVertex1, kVertex2, kEdge01, kEdge12, kEdge20, kFace };

struct TrianglePoint {
  Vec3f point;
  float b1, b2;  // weights of corners 1 and 2; corner 0 has 1 - b1 - b2
  TriangleFeature feature;
};

[[gnu::always_inline]] inline TrianglePoint closest_on_triangle(const Vec3f& p, const Vec3f& a, const Vec3f& b, const Vec3f& c) {
  const Vec3f ab = b - a, ac = c - a, ap = p - a;
  const float d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0.0f && d2 <= 0.0f) return {a, 0.0f, 0.0f, TriangleFeature::kVertex0};
  const Vec3f bp = p - b;
  const float d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0.0f && d4 <= d3) return {b, 1.0f, 0.0f, TriangleFeature::kVertex1};
  const float vc = d1 * d4 - d3 * d2;
  if (vc <= 0.0f && d1 >= 0.0f && d3 <= 0.0f) {
    const float v = d1 / (d1 - d3);
    return {a + v * ab, v, 0.0f, TriangleFeature::kEdge01};
  }
  const Vec3f cp = p - c;
  const float d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0.0f && d5 <= d6) return {c, 0.0f, 1.0f, TriangleFeature::kVertex2};
  const float vb = d5 * d2 - d1 * d6;
  if (vb <= 0.0f && d2 >= 0.0f && d6 <= 0.0f) {
    const float w = d2 / (d2 - d6);
    return {a + w * ac, 0.0f, w, TriangleFeature::kEdge20};
  }
  const float va = d3 * d6 - d5 * d4;
  if (va <= 0.0f && (d4 - d3) >= 0.0f && (d5 - d6) >= 0.0f) {
    const float w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
    return {b + w * (c - b), 1.0f - w, w, TriangleFeature::kEdge12};
  }
  const float sum = va + vb + vc;
  if (!(sum > 0.0f)) return {a, 0.0f, 0.0f, TriangleFeature::kVertex0};  // degenerate (zero-area) triangle
  const float v = vb / sum, w = vc / sum;
  return {a + ab * v + ac * w, v, w, TriangleFeature::kFace};
}

}  // namespace drape::collision
