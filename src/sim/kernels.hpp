#pragma once
// Pure kernels of the cloth step: one spring, one over-stretched spring, one colliding particle.
// Plain values in, plain values out, so each is unit-tested alone and easy to move to SIMD or a GPU.
#include <algorithm>
#include <cmath>

#include "drape/mesh.hpp"

namespace drape::sim {

// Eq. 2 plus damping along the spring: the force on end a (end b gets its negative).
// A zero-length spring with rest length 0 (a closed seam) gives zero force, not NaN.
inline Vec3f spring_force(const Vec3f& xa, const Vec3f& xb, const Vec3f& va, const Vec3f& vb, float rest,
                          float stiffness, float damping) {
  const Vec3f d = xb - xa;
  const float len2 = d.squaredNorm();
  const float inv_len = len2 > 1e-24f ? 1.0f / std::sqrt(len2) : 0.0f;
  const Vec3f u = d * inv_len;
  const float len = len2 * inv_len;
  return (stiffness * (len - rest) + damping * (vb - va).dot(u)) * u;
}

// Velocity modification (sec. 3.3) of one spring, as the paper does it: a spring longer than
// max_length that is still stretching loses the stretching components of its end velocities, i.e.
// the part of each end's velocity along the spring that points away from the other end (v1t, v2t
// of fig. 1) is set to zero; motion towards the other end is kept. A spring still shorter than
// max_length that would pass it within dt loses just enough of those components to end the step
// at max_length. The components are judged in the world frame, not relative to each other: that
// is what lets one pass hold a long hanging chain (every spring stops its own lower end), and it
// also means the modification dissipates energy, which draping wants. Returns true if it
// changed a velocity by more than `tolerance` / dt along the spring.
// Most springs are well short of the limit and slow: velocity_limit_idle() rules those out without
// a square root or a division, with a margin over rounding, so the result is the same bit for bit.
inline bool velocity_limit_idle(const Vec3f& d, const Vec3f& dv, float max_length, float dt) {
  // len < max and |dv| dt < max - len: the spring cannot reach max_length within dt, excess <= 0.
  // max - len = (max^2 - len^2) / (max + len) >= (max^2 - len^2) / (2 max), so it is enough that
  // 4 |dv|^2 dt^2 max^2 < (max^2 - len^2)^2; len^2 < 0.999 max^2 and the 1 % factor keep the float
  // evaluation of both sides far from the rounding that could decide the exact test differently.
  const float max2 = max_length * max_length, len2 = d.squaredNorm();
  if (!(len2 < 0.999f * max2)) return false;
  const float gap2 = max2 - len2;
  return 4.04f * dv.squaredNorm() * (dt * dt) * max2 < gap2 * gap2;
}

inline bool limit_spring_velocity(const Vec3f& xa, const Vec3f& xb, Vec3f& va, Vec3f& vb, float wa, float wb,
                                  float max_length, float dt, float tolerance) {
  const Vec3f d = xb - xa;
  if (velocity_limit_idle(d, vb - va, max_length, dt)) return false;
  const float len = d.norm();
  if (len <= 0) return false;
  const Vec3f u = d / len;
  const float ua = va.dot(u), ub = vb.dot(u);
  const float rate = ub - ua;
  const float allowed = std::max(0.0f, (max_length - len) / dt);
  const float excess = rate - allowed;
  if (excess <= 0) return false;
  // Stretching components: a moving away from b (ua < 0), b moving away from a (ub > 0).
  // Pinned ends (inverse mass 0) are kinematic and keep their velocity.
  const float sa = wa > 0 ? std::min(ua, 0.0f) : 0.0f, sb = wb > 0 ? std::max(ub, 0.0f) : 0.0f;
  const float stretching = sb - sa;
  if (stretching <= 0) return false;
  const float fraction = len >= max_length ? 1.0f : std::min(1.0f, excess / stretching);
  va -= (fraction * sa) * u;
  vb -= (fraction * sb) * u;
  return fraction * stretching * dt > tolerance;
}

// Position modification (Provot 1995, sec. 3.2) of one spring: ends moved towards each other,
// mass-weighted, until the spring is max_length long. Returns true if it corrected.
inline bool limit_spring_position(Vec3f& xa, Vec3f& xb, float wa, float wb, float max_length, float tolerance) {
  const float w = wa + wb;
  if (w <= 0) return false;
  const Vec3f d = xb - xa;
  const float len = d.norm();
  const float excess = len - max_length;
  if (excess <= 0) return false;
  const Vec3f correction = d * (excess / (len * w));
  xa += wa * correction;
  xb -= wb * correction;
  return excess > tolerance;
}

// A particle pulled into a body by a position correction goes back out along its contact's normal,
// to the thickness layer. The contact is the tangent plane of this step's nearest surface,
// d(x) = normal . x + plane (plane = +inf: no surface near). Coulomb friction at the position level
// (as position-based dynamics does it): the push out, p, takes up to friction x p off the particle's
// sliding along the surface since the start of the step (x - start, tangential part). Without it a
// band held on the hips by the position passes pressed on the body with no friction to show for it,
// and how much of its grip was velocity response (with friction) or position pass (without)
// depended on the time step. Returns true if it moved the particle.
inline bool keep_out_of_contact(Vec3f& x, const Vec3f& normal, float plane, float thickness, const Vec3f& start,
                                float friction) {
  const float d = normal.dot(x) + plane;
  if (!(d < thickness)) return false;
  const float push = thickness - d;
  x += push * normal;
  if (friction > 0) {
    const Vec3f moved = x - start;
    const Vec3f slide = moved - normal.dot(moved) * normal;
    const float length = slide.norm();
    if (length > 0) x -= std::min(1.0f, friction * push / length) * slide;
  }
  return true;
}

// Whether a body surface may rise more than `allowed` above the straight cloth edge between two
// particles in contact with it: the body points under them are p = x - distance * normal, and a
// surface whose normal turns by theta between them rises at most (|p_b - p_a| / 2) tan(theta / 2)
// above the chord's midpoint (a ridge halfway; a circular arc rises (|p_b - p_a| / 2) tan(theta / 4)).
// A concave surface (normals turning towards each other) stays under the chord. Squared, without
// a root or a division: it runs on every edge in contact, to rule out the few that need a collider
// query at their midpoint.
inline bool rise_exceeds(const Vec3f& xa, float da, const Vec3f& na, const Vec3f& xb, float db, const Vec3f& nb,
                         float allowed) {
  const Vec3f chord = (xb - db * nb) - (xa - da * na);
  if ((nb - na).dot(chord) <= 0) return false;  // concave or flat
  const float c = std::clamp(na.dot(nb), -1.0f, 1.0f);
  // (|chord| / 2)^2 tan^2(theta / 2) > allowed^2, with tan^2(theta / 2) = (1 - c) / (1 + c).
  return 0.25f * chord.squaredNorm() * (1.0f - c) > allowed * allowed * (1.0f + c);
}

// A joined pair (a sewn seam): both ends get their mass-weighted mean velocity plus the share of
// -gap/dt that closes the gap at the end of the step (velocity pass), or both move to their
// mass-weighted mean position (position pass). Momentum is kept. Returns true if it changed
// something by more than `tolerance` (m, over the step).
inline bool hold_pair_velocity(const Vec3f& xa, const Vec3f& xb, Vec3f& va, Vec3f& vb, float wa, float wb, float dt,
                               float tolerance) {
  const float w = wa + wb;
  if (w <= 0) return false;
  const Vec3f closing = (xa + dt * va) - (xb + dt * vb);  // gap at the end of the step
  if (closing.norm() <= tolerance) return false;
  const Vec3f change = closing / (dt * w);
  va -= wa * change;
  vb += wb * change;
  return true;
}
inline bool hold_pair_position(Vec3f& xa, Vec3f& xb, float wa, float wb, float tolerance) {
  const float w = wa + wb;
  if (w <= 0) return false;
  const Vec3f d = xa - xb;
  if (d.norm() <= tolerance) return false;
  xa -= (wa / w) * d;
  xb += (wb / w) * d;
  return true;
}

// Collision response by velocity (eq. 5, v = C_fric v_t - C_refl v_n) for one particle whose
// nearest surface is `distance` away along `normal`, moving with `surface_velocity`. Contact when
// the particle would end the step closer than `thickness`. A particle already inside the thickness
// layer is first put back on it (position). The normal velocity relative to the surface is
// reflected with C_refl = restitution; C_fric follows Coulomb's law from the normal velocity change,
// C_fric = max(0, 1 - mu |dv_n| / |v_t|), so friction does not depend on the time step.
// Returns true on contact.
inline bool respond_contact_velocity(Vec3f& x, Vec3f& v, float distance, const Vec3f& normal,
                                     const Vec3f& surface_velocity, float thickness, float friction,
                                     float restitution, float dt) {
  const float vn = v.dot(normal);
  if (distance + dt * vn >= thickness) return false;
  if (distance < thickness) {
    x += (thickness - distance) * normal;
    distance = thickness;
  }
  const float sn = surface_velocity.dot(normal);
  const float vn_rel = vn - sn;
  const float target_rel = vn_rel < 0 ? -restitution * vn_rel : vn_rel;
  const float vn_new = std::max(sn + target_rel, (thickness - distance) / dt);
  const float dvn = vn_new - vn;
  const Vec3f vt_rel = (v - surface_velocity) - vn_rel * normal;
  const float vt_len = vt_rel.norm();
  const float c_fric = vt_len > 0 ? std::max(0.0f, 1.0f - friction * std::abs(dvn) / vt_len) : 0.0f;
  v = (surface_velocity - sn * normal) + c_fric * vt_rel + vn_new * normal;
  return true;
}

// Collision response by force (sec. 5, for animated bodies): inside the thickness layer, a force
// along the normal proportional to the depth plus critical damping of the normal velocity relative
// to the surface, applied over dt as a velocity change; Coulomb friction from the same impulse.
// The spring rate is m (0.5/dt)^2, well inside the explicit stability limit. Returns true on contact.
inline bool respond_contact_force(Vec3f& v, float distance, const Vec3f& normal, const Vec3f& surface_velocity,
                                  float thickness, float friction, float dt) {
  const float depth = thickness - distance;
  if (depth <= 0) return false;
  const float omega = 0.5f / dt;
  const Vec3f v_rel = v - surface_velocity;
  const float vn_rel = v_rel.dot(normal);
  const float dvn = dt * (omega * omega * depth - 2.0f * omega * vn_rel);
  if (dvn <= 0) return true;
  const Vec3f vt_rel = v_rel - vn_rel * normal;
  const float vt_len = vt_rel.norm();
  const float c_fric = vt_len > 0 ? std::max(0.0f, 1.0f - friction * dvn / vt_len) : 0.0f;
  v = surface_velocity + c_fric * vt_rel + (vn_rel + dvn) * normal;
  return true;
}

}  // namespace drape::sim
