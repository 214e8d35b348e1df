#pragma once
// The collider interface the simulation step talks to. Analytic obstacles (plane, sphere, box,
// capsule), the body (image-space maps, BVH, distance field) and, later, a dressed body's clothing
// all sit behind it. A collider may move or deform over time (animation, soft tissue): the step
// calls update() with the new time before querying, and each sample carries the surface velocity
// so the response can carry cloth along (Vassilev & Spanlang sec. 5).
#include <span>
#include <string_view>

#include "drape/mesh.hpp"

namespace drape {

// What a collider knows about the surface nearest to one query point.
struct ContactSample {
  float distance;  // signed distance to the surface, > 0 outside; +inf when nothing lies within the query radius
  Vec3f normal;    // outward unit normal of the surface at the nearest point
  Vec3f velocity;  // velocity of the surface at the nearest point (m/s)
};

class Collider {
 public:
  virtual ~Collider() = default;
  virtual std::string_view name() const = 0;

  // Brings the collider to simulated time t (seconds). Static colliders ignore it.
  virtual void update(double /*t*/) {}

  // For each point, the nearest surface within `radius` (metres). Thread-safe: the step calls it
  // concurrently on disjoint chunks of points. Must not allocate.
  virtual void query(std::span<const Vec3f> points, float radius, std::span<ContactSample> out) const = 0;
};

}  // namespace drape
