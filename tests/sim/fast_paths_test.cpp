// The step's fast paths against the plain computations they replace: the square-root-free early
// out of the velocity-modification kernel, and the strain passes that revisit only the springs
// whose ends changed.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "drape/cloth.hpp"
#include "sim/kernels.hpp"
#include "sim/stages.hpp"

namespace drape::sim {
namespace {

Vec3f random_unit(std::mt19937& rng) {
  std::normal_distribution<float> n(0.0f, 1.0f);
  const Vec3f u(n(rng), n(rng), n(rng));
  return u.normalized();
}

// velocity_limit_idle may only say "idle" where the full test of limit_spring_velocity finds no
// excess; and it must say so for most short, slow springs, or it saves nothing.
TEST(FastPaths, VelocityLimitIdleOnlyWhereTheExactTestFindsNoExcess) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> stretch(0.9f, 1.08f), speed(0.0f, 0.05f), rest_of(0.002f, 0.05f);
  const float dt = 5e-4f;
  int idle = 0, short_and_slow = 0;
  for (int i = 0; i < 200000; ++i) {
    const float rest = rest_of(rng), max_length = 1.05f * rest;
    const Vec3f d = stretch(rng) * rest * random_unit(rng);
    const Vec3f va = speed(rng) * random_unit(rng), vb = va + speed(rng) * random_unit(rng);
    // The exact test, as limit_spring_velocity makes it.
    const float len = d.norm();
    const Vec3f u = d / len;
    const float excess = (vb.dot(u) - va.dot(u)) - std::max(0.0f, (max_length - len) / dt);
    const bool is_idle = velocity_limit_idle(d, vb - va, max_length, dt);
    if (is_idle) {
      ++idle;
      ASSERT_LE(excess, 0.0f) << "spring " << i;
    }
    if (len < 0.99f * max_length && (vb - va).norm() * dt < 0.4f * (max_length - len)) ++short_and_slow;
  }
  EXPECT_GT(short_and_slow, 1000);
  EXPECT_GE(idle, short_and_slow);  // every clearly idle spring is found
}

struct Scene {
  ClothModel model;
  ClothState state;
  StepScratch scratch;
  StepSettings settings;
};

// A 24 x 24 grid stretched by up to 10 % and shaken: springs over, at and under the limit.
Scene shaken_grid() {
  Fabric fabric;
  GridClothOptions o;
  o.nx = o.ny = 24;
  Scene s{grid_cloth(fabric, o), {}, {}, {}};
  s.state = initial_state(s.model);
  s.scratch.resize(s.model, 1);
  s.settings = default_step_settings(s.model);
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  for (size_t i = 0; i < s.model.particle_count(); ++i) {
    s.state.x[i] *= 1.0f + 0.05f * (1.0f + u(rng));
    s.state.x[i] += 0.002f * Vec3f(u(rng), u(rng), u(rng));
    s.state.v[i] = 0.3f * Vec3f(u(rng), u(rng), u(rng));
  }
  return s;
}

// Strain passes that skip springs whose ends did not change against plain Gauss-Seidel passes over
// every spring, colour by colour, as many passes as the fast version ran: the same velocities, bit
// for bit (a skipped spring would have computed what it computed last time: nothing).
TEST(FastPaths, StrainPassesThatSkipUnchangedSpringsMatchFullPasses) {
  Scene s = shaken_grid();
  s.settings.strain_passes = 6;
  const float dt = s.model.stable_time_step();
  const ClothModel& m = s.model;
  ClothState full = s.state;
  const StepContext c{s.model, s.state, s.scratch, s.settings, dt};
  const StrainLimitResult r = limit_strain_velocity(c, false);
  ASSERT_GT(r.passes, 1u);  // later passes ran, so skipping was exercised
  const float stretch = 1.0f + s.settings.strain_threshold;
  float largest_change = 0;
  for (uint32_t pass = 0; pass < r.passes; ++pass)
    for (size_t k = 0; k < m.limit_a.size(); ++k) {
      const uint32_t a = m.limit_a[k], b = m.limit_b[k];
      const Vec3f va0 = full.v[a];
      limit_spring_velocity(full.x[a], full.x[b], full.v[a], full.v[b], m.inverse_mass[a], m.inverse_mass[b],
                            stretch * m.limit_rest[k], dt, 1e-4f * m.limit_rest[k]);
      largest_change = std::max(largest_change, (full.v[a] - va0).norm());
    }
  ASSERT_GT(largest_change, 0.01f);  // the passes did real work
  for (size_t i = 0; i < m.particle_count(); ++i) ASSERT_EQ(s.state.v[i], full.v[i]) << "particle " << i;
}

}  // namespace
}  // namespace drape::sim
