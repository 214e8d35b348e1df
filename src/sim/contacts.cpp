// Contacts between cloth particles and colliders. Detection asks each collider once per step for
// the nearest surface of every particle (in fixed chunks, concurrently, as drape::Collider allows)
// and keeps the nearest over all colliders. The response is eq. 5 on velocities (static and slowly
// moving bodies) or sec. 5's force for animated bodies; both are per-particle kernels (kernels.hpp).
#include <algorithm>
#include <limits>

#include "sim/kernels.hpp"
#include "sim/parallel.hpp"
#include "sim/stages.hpp"

namespace drape::sim {
namespace {
// The most a particle is lifted off the body for its faces (StepSettings::face_clearance), m.
constexpr float kMaxFaceLift = 0.006f;
constexpr float kFaceLiftFall = 0.01f;  // m/s

// The nearest surface over all colliders for each point, in fixed chunks, concurrently (as
// drape::Collider allows). `other` holds the second and later colliders' answers (points' size).
void nearest_contacts(std::span<Collider* const> colliders, std::span<const Vec3f> x, float radius,
                      std::span<ContactSample> nearest, std::span<ContactSample> other) {
  parallel_blocks(x.size(), [&](size_t, size_t begin, size_t end) {
    const size_t count = end - begin;
    if (colliders.empty()) {
      for (size_t i = begin; i < end; ++i)
        nearest[i] = {std::numeric_limits<float>::infinity(), Vec3f::UnitY(), Vec3f::Zero()};
      return;
    }
    colliders[0]->query(x.subspan(begin, count), radius, nearest.subspan(begin, count));
    for (size_t k = 1; k < colliders.size(); ++k) {
      colliders[k]->query(x.subspan(begin, count), radius, other.subspan(begin, count));
      for (size_t i = begin; i < end; ++i)
        if (other[i].distance < nearest[i].distance) nearest[i] = other[i];
    }
  });
}

}  // namespace

void update_colliders(std::span<Collider* const> colliders, double time) {
  for (Collider* collider : colliders) collider->update(time);
}

void detect_contacts(const StepContext& c, std::span<Collider* const> colliders) {
  // Search radius: the thickness plus twice the distance the fastest particle covers in a step;
  // with face_clearance, particles up to kMaxFaceLift further out may still be lifted into the layer.
  const float radius = c.model.fabric.collision_thickness + (c.settings.face_clearance >= 0 ? kMaxFaceLift : 0.0f) +
                       2.0f * c.dt * std::max(c.state.max_speed, 1.0f);
  nearest_contacts(colliders, c.state.x, radius, c.scratch.contact, c.scratch.contact_tmp);
}

// Faces over curved parts (StepSettings::face_clearance). The response keeps each particle
// `collision_thickness` off the body, but the faces between particles are flat: over a convex part
// (a shoulder under a 2.6 cm grid) they come nearer the skin than their vertices by the rise of the
// surface under each edge, and pass through it where that exceeds the thickness. The rise is
// measured: the collider is asked for the distance of the edge's midpoint, and the rise is the mean
// of its ends' distances less the midpoint's (rise_bound rules out the edges over flat or gently
// curved skin without a query; structural and shear springs, so a grid cell's diagonals cover its
// centre). Each particle in contact is kept further off by what its edges need for their
// midpoints to stay face_clearance off, by lowering its contact's distance: every response after
// this (velocity, position passes, forces) then keeps it that much further out, with nothing else
// to change. Per edge in parallel, then gathered per particle in the model's incidence order (no
// races, the same on any number of threads).
void lift_over_curvature(const StepContext& c, std::span<Collider* const> colliders) {
  const ClothModel& m = c.model;
  const SpringRange edges{m.range(SpringKind::Structural).begin, m.range(SpringKind::Shear).end};
  if (!(c.settings.face_clearance >= 0) || edges.size() == 0 || colliders.empty()) return;
  const float thickness = m.fabric.collision_thickness;
  // A rise up to `allowed` leaves the faces face_clearance off; contacts farther than `reach`
  // cannot be lifted into the thickness layer.
  const float allowed = std::max(thickness - c.settings.face_clearance, 0.0f), reach = thickness + kMaxFaceLift;
  ContactSample* contact = c.scratch.contact.data();
  StepScratch::FaceLift& f = c.scratch.face_lift;
  const Vec3f* x = c.state.x.data();
  const uint32_t* sa = m.spring_a.data();
  const uint32_t* sb = m.spring_b.data();
  // Edges whose rise may exceed `allowed`, in spring order, with their midpoints.
  size_t count = 0;
  for (uint32_t k = 0; k < edges.size(); ++k) {
    f.lift[k] = 0.0f;
    const uint32_t a = sa[edges.begin + k], b = sb[edges.begin + k];
    const ContactSample& ca = contact[a];
    const ContactSample& cb = contact[b];
    if (!(ca.distance < reach && cb.distance < reach) ||
        !(rise_bound(x[a], ca.distance, ca.normal, x[b], cb.distance, cb.normal) > allowed))
      continue;
    f.edge[count] = k;
    f.midpoint[count] = 0.5f * (x[a] + x[b]);
    ++count;
  }
  const std::span<const Vec3f> midpoints(f.midpoint.data(), count);
  nearest_contacts(colliders, midpoints, reach, std::span(f.contact.data(), count), std::span(f.contact_tmp));
  parallel_blocks(count, [&](size_t, size_t begin, size_t end) {
    for (size_t q = begin; q < end; ++q) {
      if (!(f.contact[q].distance < reach)) continue;
      const uint32_t k = f.edge[q];
      const float ends = 0.5f * (contact[sa[edges.begin + k]].distance + contact[sb[edges.begin + k]].distance);
      f.lift[k] = ends - f.contact[q].distance - allowed;
    }
  });
  const uint32_t* begin_of = m.incident_begin.data();
  const uint32_t* spring = m.incident_spring.data();
  const float fall = kFaceLiftFall * c.dt;
  parallel_blocks(m.particle_count(), [&](size_t, size_t begin, size_t end) {
    for (size_t i = begin; i < end; ++i) {
      if (!(contact[i].distance < reach)) {
        f.particle_lift[i] = 0.0f;
        continue;
      }
      float most = 0;
      for (uint32_t e = begin_of[i]; e < begin_of[i + 1]; ++e)
        if (spring[e] >= edges.begin && spring[e] < edges.end) most = std::max(most, f.lift[spring[e] - edges.begin]);
      f.particle_lift[i] = std::max(std::min(most, kMaxFaceLift), f.particle_lift[i] - fall);
      contact[i].distance -= f.particle_lift[i];
    }
  });
}

uint64_t respond_to_contacts(const StepContext& c, uint32_t* changed, uint32_t mark) {
  const ClothModel& m = c.model;
  Vec3f* x = c.state.x.data();
  Vec3f* v = c.state.v.data();
  ContactSample* contact = c.scratch.contact.data();
  const float* w = m.inverse_mass.data();
  const Fabric& f = m.fabric;
  const float dt = c.dt, friction = c.settings.friction >= 0 ? c.settings.friction : f.friction;
  uint64_t contacts = 0;
  const std::ptrdiff_t blocks = static_cast<std::ptrdiff_t>(block_count(m.particle_count()));
#pragma omp parallel for schedule(static) reduction(+ : contacts) if (blocks >= kMinParallelBlocks)
  for (std::ptrdiff_t b = 0; b < blocks; ++b) {
    const size_t begin = static_cast<size_t>(b) * kBlock, end = std::min(m.particle_count(), begin + kBlock);
    for (size_t i = begin; i < end; ++i) {
      ContactSample& s = contact[i];
      if (w[i] == 0 || !(s.distance < std::numeric_limits<float>::infinity())) continue;
      const Vec3f x0 = x[i], v0 = v[i];
      if (respond_contact_velocity(x[i], v[i], s.distance, s.normal, s.velocity, f.collision_thickness, friction,
                                   f.restitution, dt)) {
        ++contacts;
        if (changed && (x[i] != x0 || v[i] != v0)) changed[i] = mark;
      }
      // A particle put back on the thickness layer is now at the thickness (a second call is velocity-only).
      s.distance = std::max(s.distance, f.collision_thickness);
    }
  }
  return contacts;
}

uint64_t apply_contact_forces(const StepContext& c) {
  const ClothModel& m = c.model;
  Vec3f* v = c.state.v.data();
  const ContactSample* contact = c.scratch.contact.data();
  const float* w = m.inverse_mass.data();
  const Fabric& f = m.fabric;
  const float dt = c.dt;
  uint64_t contacts = 0;
  const std::ptrdiff_t blocks = static_cast<std::ptrdiff_t>(block_count(m.particle_count()));
#pragma omp parallel for schedule(static) reduction(+ : contacts) if (blocks >= kMinParallelBlocks)
  for (std::ptrdiff_t b = 0; b < blocks; ++b) {
    const size_t begin = static_cast<size_t>(b) * kBlock, end = std::min(m.particle_count(), begin + kBlock);
    for (size_t i = begin; i < end; ++i) {
      const ContactSample& s = contact[i];
      if (w[i] == 0 || !(s.distance < std::numeric_limits<float>::infinity())) continue;
      contacts += respond_contact_force(v[i], s.distance, s.normal, s.velocity, f.collision_thickness, f.friction, dt)
                      ? 1u
                      : 0u;
    }
  }
  return contacts;
}

}  // namespace drape::sim
