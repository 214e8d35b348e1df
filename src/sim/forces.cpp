// Forces and the velocity update of eq. 3. Spring forces are computed once per spring (eq. 2 plus
// damping), then each particle gathers its springs' forces in the model's fixed incidence order:
// no atomics, no scatter races, and the same sums on any number of threads.
#include <cmath>

#include "sim/kernels.hpp"
#include "sim/parallel.hpp"
#include "sim/stages.hpp"

namespace drape::sim {

void compute_spring_forces(const StepContext& c) {
  const ClothModel& m = c.model;
  const Vec3f* x = c.state.x.data();
  const Vec3f* v = c.state.v.data();
  const uint32_t* sa = m.spring_a.data();
  const uint32_t* sb = m.spring_b.data();
  const float* rest = m.rest_length.data();
  const float* k = m.stiffness.data();
  const float* damping = m.damping.data();
  Vec3f* out = c.scratch.spring_force.data();
  parallel_blocks(m.spring_count(), [&](size_t, size_t begin, size_t end) {
    for (size_t s = begin; s < end; ++s) {
      const uint32_t a = sa[s], b = sb[s];
      out[s] = spring_force(x[a], x[b], v[a], v[b], rest[s], k[s], damping[s]);
    }
  });
}

// Sum of forces on each particle -> acceleration -> v(t + dt) = v(t) + dt a (eq. 3).
// External forces: gravity, viscous damping -gamma m v (sec. 2.2; m the inertial mass, so the damping
// rate gamma is the same for every particle), quadratic air drag.
void integrate_velocities(const StepContext& c) {
  const ClothModel& m = c.model;
  const Vec3f* force = c.scratch.spring_force.data();
  Vec3f* v = c.state.v.data();
  const uint32_t* begin_of = m.incident_begin.data();
  const uint32_t* spring = m.incident_spring.data();
  const float* sign = m.incident_sign.data();
  const float* inv_mass = m.inverse_mass.data();
  const float* area = m.drag_area.data();
  const float* inertia = m.inertia_scale.empty() ? nullptr : m.inertia_scale.data();
  const Vec3f g = c.settings.gravity;
  const float dt = c.dt, drag = m.fabric.air_drag;
  const float gamma = c.settings.air_damping >= 0 ? c.settings.air_damping : m.fabric.air_damping;
  parallel_blocks(m.particle_count(), [&](size_t, size_t begin, size_t end) {
    for (size_t i = begin; i < end; ++i) {
      Vec3f f = Vec3f::Zero();
      for (uint32_t e = begin_of[i]; e < begin_of[i + 1]; ++e) f += sign[e] * force[spring[e]];
      const Vec3f vi = v[i];
      f -= (drag * area[i] * vi.norm()) * vi;
      const float live = inv_mass[i] > 0 ? 1.0f : 0.0f;
      // Weight m g on an inertial mass s m (scale_inertia()): g / s.
      const Vec3f gi = inertia ? Vec3f(g / inertia[i]) : g;
      const Vec3f a = inv_mass[i] * f + live * (gi - gamma * vi);
      v[i] = vi + dt * a;
    }
  });
}

}  // namespace drape::sim
