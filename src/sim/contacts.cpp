// Contacts between cloth particles and colliders. Detection asks each collider once per step for
// the nearest surface of every particle (in fixed chunks, concurrently, as drape::Collider allows)
// and keeps the nearest over all colliders. The response is eq. 5 on velocities (static and slowly
// moving bodies) or sec. 5's force for animated bodies; both are per-particle kernels (kernels.hpp).
#include <limits>

#include "sim/kernels.hpp"
#include "sim/parallel.hpp"
#include "sim/stages.hpp"

namespace drape::sim {

void update_colliders(std::span<Collider* const> colliders, double time) {
  for (Collider* collider : colliders) collider->update(time);
}

void detect_contacts(const StepContext& c, std::span<Collider* const> colliders) {
  const size_t n = c.model.particle_count();
  std::span<const Vec3f> x(c.state.x);
  std::span<ContactSample> nearest(c.scratch.contact);
  std::span<ContactSample> other(c.scratch.contact_tmp);
  // Search radius: the thickness plus twice the distance the fastest particle covers in a step.
  const float radius = c.model.fabric.collision_thickness + 2.0f * c.dt * std::max(c.state.max_speed, 1.0f);
  parallel_blocks(n, [&](size_t, size_t begin, size_t end) {
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
