#include "body/loft.hpp"

#include <algorithm>
#include <cmath>

namespace drape::body {

namespace {

// Monotone cubic (Fritsch-Carlson) slope at knot i, so that interpolated ring sizes never overshoot
// their control values: a waist ring stays the narrowest, a hip ring the fullest.
float pchip_slope(const std::vector<Ring>& r, size_t i, float Ring::*f) {
  auto secant = [&](size_t a) { return (r[a + 1].*f - r[a].*f) / (r[a + 1].t - r[a].t); };
  if (r.size() < 2) return 0.0f;
  if (i == 0) return secant(0);
  if (i + 1 == r.size()) return secant(i - 1);
  const float d0 = secant(i - 1), d1 = secant(i);
  if (d0 * d1 <= 0) return 0.0f;
  const float w0 = 2 * (r[i + 1].t - r[i].t) + (r[i].t - r[i - 1].t);
  const float w1 = (r[i + 1].t - r[i].t) + 2 * (r[i].t - r[i - 1].t);
  return (w0 + w1) / (w0 / d0 + w1 / d1);
}

float superellipse_radius(float cu, float cv, float a, float d, float n) {
  if (n == 2.0f) return 1.0f / std::sqrt((cu / a) * (cu / a) + (cv / d) * (cv / d));
  return std::pow(std::pow(std::abs(cu / a), n) + std::pow(std::abs(cv / d), n), -1.0f / n);
}

}  // namespace

Ring Loft::ring_at(float t) const {
  if (t <= rings.front().t) return rings.front();
  if (t >= rings.back().t) return rings.back();
  size_t i = 0;
  while (rings[i + 1].t < t) ++i;
  const Ring& r0 = rings[i];
  const Ring& r1 = rings[i + 1];
  const float h = r1.t - r0.t;
  const float s = (t - r0.t) / h;
  const float h00 = (1 + 2 * s) * (1 - s) * (1 - s), h10 = s * (1 - s) * (1 - s);
  const float h01 = s * s * (3 - 2 * s), h11 = s * s * (s - 1);
  Ring out{t, 0, 0, 0, 0};
  for (float Ring::*f : {&Ring::a, &Ring::front, &Ring::back, &Ring::shift})
    out.*f = h00 * (r0.*f) + h10 * h * pchip_slope(rings, i, f) + h01 * (r1.*f) + h11 * h * pchip_slope(rings, i + 1, f);
  return out;
}

float Loft::distance(const Vec3f& p) const {
  const Vec3f q = p - origin;
  const float t = q.dot(axis);
  const Ring r = ring_at(t);
  const float u = q.dot(lateral);
  const float v = q.dot(forward) - r.shift;
  const float rho = std::sqrt(u * u + v * v);
  float radial;
  if (rho < 1e-6f) {
    radial = -std::min(r.a, std::min(r.front, r.back));
  } else {
    radial = rho - superellipse_radius(u / rho, v / rho, r.a, v >= 0 ? r.front : r.back, exponent);
  }
  // Flat caps beyond the first and last ring.
  const float beyond = std::max(rings.front().t - t, t - rings.back().t);
  if (beyond <= 0) return radial;
  return radial <= 0 ? beyond : std::sqrt(radial * radial + beyond * beyond);
}

Bounds Loft::bounds() const {
  Bounds b;
  for (const Ring& r : rings) {
    const float reach = std::max({r.a, r.front + std::abs(r.shift), r.back + std::abs(r.shift)});
    const Vec3f c = origin + r.t * axis;
    b.extend(c - Vec3f::Constant(reach));
    b.extend(c + Vec3f::Constant(reach));
  }
  return b;
}

float Ellipsoid::distance(const Vec3f& p) const {
  // Distance scaled by the smallest radius: exact on the surface's normal direction for spheres, a
  // smooth approximation otherwise.
  const Vec3f local = axes.transpose() * (p - centre);
  const float k = local.cwiseQuotient(radii).norm();
  const float d = (k - 1.0f) * radii.minCoeff();
  return std::max(d, floor_y - p.y());
}

Bounds Ellipsoid::bounds() const {
  const float reach = radii.maxCoeff();
  Bounds b;
  b.extend(centre - Vec3f::Constant(reach));
  b.extend(centre + Vec3f::Constant(reach));
  return b;
}

float RoundBox::distance(const Vec3f& p) const {
  const Vec3f local = axes.transpose() * (p - centre);
  const Vec3f q = local.cwiseAbs() - (half - Vec3f::Constant(rounding));
  return q.cwiseMax(0.0f).norm() + std::min(q.maxCoeff(), 0.0f) - rounding;
}

Bounds RoundBox::bounds() const {
  const float reach = half.norm();
  Bounds b;
  b.extend(centre - Vec3f::Constant(reach));
  b.extend(centre + Vec3f::Constant(reach));
  return b;
}

float ring_perimeter(const Ring& ring, float exponent) {
  constexpr int kSamples = 256;
  double perimeter = 0;
  Vec2f previous = Vec2f::Zero();
  for (int i = 0; i <= kSamples; ++i) {
    const float angle = 2.0f * static_cast<float>(M_PI) * static_cast<float>(i) / kSamples;
    const float cu = std::cos(angle), cv = std::sin(angle);
    const float r = superellipse_radius(cu, cv, ring.a, cv >= 0 ? ring.front : ring.back, exponent);
    const Vec2f q(r * cu, r * cv);
    if (i > 0) perimeter += (q - previous).norm();
    previous = q;
  }
  return static_cast<float>(perimeter);
}

}  // namespace drape::body
