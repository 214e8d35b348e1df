#pragma once
// The primitives of the generated body's implicit surface: lofts (a cross-section curve swept along
// a straight axis, its size varying smoothly between control rings) and ellipsoids, joined with a
// smooth minimum. Cordier et al. build the reference body from metaballs around the skeleton; a
// loft is the same idea with a continuous, measurable cross-section, so a girth can be set exactly.
#include <vector>

#include "drape/mesh.hpp"

namespace drape::body {

// One control ring of a loft: at distance `t` along the axis, a superellipse with half-width `a`
// along the lateral axis u, `front` / `back` half-depths along v (v > 0 / v < 0), its centre shifted
// by `shift` along v.
struct Ring {
  float t;
  float a;
  float front;
  float back;
  float shift = 0.0f;
};

struct Loft {
  Vec3f origin;      // t = 0
  Vec3f axis;        // unit, t grows along it
  Vec3f lateral;     // unit u, perpendicular to axis
  Vec3f forward;     // unit v = axis x lateral... (kept as given; perpendicular to both)
  float exponent = 2.0f;  // superellipse exponent of the cross-section (2 = ellipse)
  std::vector<Ring> rings;  // increasing t; ring parameters interpolated by monotone cubics
  float blend = 0.02f;      // smooth-min radius when joined to what came before

  // Approximate signed distance (< 0 inside).
  float distance(const Vec3f& p) const;
  Bounds bounds() const;
  // Ring parameters at t (clamped to the first/last ring).
  Ring ring_at(float t) const;
};

struct Ellipsoid {
  Vec3f centre;
  Eigen::Matrix3f axes;  // columns: unit axes
  Vec3f radii;
  float blend = 0.02f;
  float floor_y = -1e9f;  // cut flat below this height (a foot's sole)

  float distance(const Vec3f& p) const;
  Bounds bounds() const;
};

// A box with rounded edges (a mitten hand): every edge has radius `rounding`, so no part of the
// surface is thinner than the polygonisation grid can follow.
struct RoundBox {
  Vec3f centre;
  Eigen::Matrix3f axes;  // columns: unit axes
  Vec3f half;            // half extents including the rounding
  float rounding;
  float blend = 0.02f;

  float distance(const Vec3f& p) const;
  Bounds bounds() const;
};

// Polynomial smooth minimum (Quilez): equals min(a, b) when |a - b| >= k.
inline float smooth_min(float a, float b, float k) {
  const float h = std::max(k - std::abs(a - b), 0.0f) / k;
  return std::min(a, b) - h * h * k * 0.25f;
}

// Perimeter of a ring's cross-section (sampled).
float ring_perimeter(const Ring& ring, float exponent);

}  // namespace drape::body
