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

// The nearest surface over all colliders for each point of one chunk. `other` holds the second
// and later colliders' answers (the chunk's size).
void nearest_in_chunk(std::span<Collider* const> colliders, std::span<const Vec3f> x, float radius,
                      std::span<ContactSample> nearest, std::span<ContactSample> other) {
  if (colliders.empty()) {
    for (ContactSample& s : nearest) s = {std::numeric_limits<float>::infinity(), Vec3f::UnitY(), Vec3f::Zero()};
    return;
  }
  colliders[0]->query(x, radius, nearest);
  for (size_t k = 1; k < colliders.size(); ++k) {
    colliders[k]->query(x, radius, other);
    for (size_t i = 0; i < x.size(); ++i)
      if (other[i].distance < nearest[i].distance) nearest[i] = other[i];
  }
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
  const std::span<const Vec3f> x(c.state.x);
  const std::span<ContactSample> nearest(c.scratch.contact), other(c.scratch.contact_tmp);
  parallel_blocks(x.size(), [&](size_t, size_t begin, size_t end) {
    const size_t count = end - begin;
    nearest_in_chunk(colliders, x.subspan(begin, count), radius, nearest.subspan(begin, count),
                     colliders.size() > 1 ? other.subspan(begin, count) : other);
  });
}

// Faces over curved parts (StepSettings::face_clearance). The response keeps each particle
// `collision_thickness` off the body, but the faces between particles are flat: over a convex part
// (a shoulder under a 2.6 cm grid) they come nearer the skin than their vertices by the rise of the
// surface under each edge, and pass through it where that exceeds the thickness. The rise is
// measured: the collider is asked for the distance of the edge's midpoint, and the rise is the mean
// of its ends' distances less the midpoint's (rise_exceeds rules out, without a query, the edges
// over flat or gently curved skin, most of them; structural and shear springs, so a grid cell's
// diagonals cover its centre). Each particle in contact is kept further off by what its edges need
// for their midpoints to stay face_clearance off, by lowering its contact's distance: every
// response after this (velocity, position passes, forces) then keeps it that much further out,
// with nothing else to change. The lift follows a rise at once but falls by at most kFaceLiftFall:
// lifts measured afresh each step flickered as the particles moved (the default shirt never
// settled). Edges are picked and measured per fixed block, and their lifts scattered on one thread
// in spring order, so the result is the same on any number of threads.
void lift_over_curvature(const StepContext& c, std::span<Collider* const> colliders) {
  const ClothModel& m = c.model;
  const SpringRange edges{m.range(SpringKind::Structural).begin, m.range(SpringKind::Shear).end};
  if (!(c.settings.face_clearance >= 0) || edges.size() == 0 || colliders.empty()) return;
  const float thickness = m.fabric.collision_thickness;
  // A rise up to `allowed` leaves the faces face_clearance off; contacts farther than `reach`
  // cannot be lifted into the thickness layer. A clearance beyond the thickness (allowed < 0) lifts
  // every particle in contact by the difference, and each convex edge by its rise on top.
  const float allowed = thickness - c.settings.face_clearance, reach = thickness + kMaxFaceLift;
  const float base = std::max(-allowed, 0.0f), filter = std::max(allowed, 0.0f);
  ContactSample* contact = c.scratch.contact.data();
  StepScratch::FaceLift& f = c.scratch.face_lift;
  const Vec3f* x = c.state.x.data();
  const uint32_t* sa = m.spring_a.data();
  const uint32_t* sb = m.spring_b.data();
  // Per block of edges: the edges whose rise may exceed `allowed`, in spring order, with their
  // midpoints, at the start of the block's range; then their midpoints' contacts.
  const std::span<ContactSample> measured(f.contact), other(f.contact_tmp);
  parallel_blocks(edges.size(), [&](size_t block, size_t begin, size_t end) {
    size_t count = 0;
    for (size_t k = begin; k < end; ++k) {
      const uint32_t s = edges.begin + static_cast<uint32_t>(k);
      const ContactSample& ca = contact[sa[s]];
      const ContactSample& cb = contact[sb[s]];
      if (!(ca.distance < reach && cb.distance < reach) ||
          !rise_exceeds(x[sa[s]], ca.distance, ca.normal, x[sb[s]], cb.distance, cb.normal, filter))
        continue;
      f.edge[begin + count] = s;
      f.midpoint[begin + count] = 0.5f * (x[sa[s]] + x[sb[s]]);
      ++count;
    }
    f.block_measured[block] = static_cast<uint32_t>(count);
    nearest_in_chunk(colliders, std::span<const Vec3f>(f.midpoint).subspan(begin, count), reach,
                     measured.subspan(begin, count), colliders.size() > 1 ? other.subspan(begin, count) : other);
  });
  // What each particle's edges need, on one thread in spring order.
  float* need = f.need.data();
  std::fill(f.need.begin(), f.need.end(), base);
  for (size_t block = 0; block < block_count(edges.size()); ++block)
    for (size_t q = block * kBlock; q < block * kBlock + f.block_measured[block]; ++q) {
      if (!(measured[q].distance < reach)) continue;
      const uint32_t a = sa[f.edge[q]], b = sb[f.edge[q]];
      const float lift = 0.5f * (contact[a].distance + contact[b].distance) - measured[q].distance - allowed;
      need[a] = std::max(need[a], lift);
      need[b] = std::max(need[b], lift);
    }
  float* lift = f.lift.data();
  const float fall = kFaceLiftFall * c.dt;
  parallel_blocks(m.particle_count(), [&](size_t, size_t begin, size_t end) {
    for (size_t i = begin; i < end; ++i) {
      lift[i] = contact[i].distance < reach ? std::max(std::min(need[i], kMaxFaceLift), lift[i] - fall) : 0.0f;
      if (lift[i] > 0) contact[i].distance -= lift[i];
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
