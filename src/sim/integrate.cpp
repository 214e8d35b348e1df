// Position update of eq. 3 and the health check that makes a failed simulation say so.
#include <cmath>
#include <limits>

#include "sim/parallel.hpp"
#include "sim/stages.hpp"

namespace drape::sim {

// With velocity-response contacts, each particle's contact is kept as its tangent plane before the
// particle moves (d(x) = n . x + plane), so the position passes after it can keep the particle out of
// the body (keep_out_of_contact) without asking the colliders again.
void integrate_positions(const StepContext& c) {
  Vec3f* x = c.state.x.data();
  const Vec3f* v = c.state.v.data();
  const ContactSample* contact = c.scratch.contact.data();
  float* plane = c.scratch.contact_plane.data();
  Vec3f* start = c.scratch.step_start.data();
  const bool planes = c.settings.collision_response == CollisionResponse::Velocity;
  const float dt = c.dt;
  parallel_blocks(c.model.particle_count(), [&](size_t, size_t begin, size_t end) {
    for (size_t i = begin; i < end; ++i) {
      plane[i] = planes ? contact[i].distance - contact[i].normal.dot(x[i]) : std::numeric_limits<float>::infinity();
      start[i] = x[i];
      x[i] += dt * v[i];
    }
  });
}

// Non-finite positions or velocities, or a particle faster than settings.max_speed (an explicit
// integrator that exploded), end the simulation: the status is sticky and reported, never reset.
// Kinetic energy is summed per fixed block and the blocks in order: thread-count independent.
StepStatus check_health(const StepContext& c) {
  const ClothModel& m = c.model;
  const Vec3f* x = c.state.x.data();
  const Vec3f* v = c.state.v.data();
  const float* mass = m.mass.data();
  double* block_energy = c.scratch.block_energy.data();
  float* block_speed = c.scratch.block_speed.data();
  uint32_t* block_bad = c.scratch.block_count.data();
  parallel_blocks(m.particle_count(), [&](size_t b, size_t begin, size_t end) {
    double energy = 0;
    float speed2 = 0;
    uint32_t bad = 0;
    for (size_t i = begin; i < end; ++i) {
      const float s2 = v[i].squaredNorm();
      bad += (std::isfinite(s2) && std::isfinite(x[i].squaredNorm())) ? 0u : 1u;
      speed2 = std::max(speed2, s2);
      energy += 0.5 * mass[i] * s2;
    }
    block_energy[b] = energy;
    block_speed[b] = speed2;
    block_bad[b] = bad;
  });
  double energy = 0;
  float speed2 = 0;
  uint32_t bad = 0;
  for (size_t b = 0; b < block_count(m.particle_count()); ++b) {
    energy += block_energy[b];
    speed2 = std::max(speed2, block_speed[b]);
    bad += block_bad[b];
  }
  c.state.kinetic_energy = energy;
  c.state.max_speed = std::sqrt(speed2);
  if (bad > 0) return StepStatus::NonFinite;
  if (c.state.max_speed > c.settings.max_speed) return StepStatus::Exploded;
  return StepStatus::Ok;
}

}  // namespace drape::sim
