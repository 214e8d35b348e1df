// The step's fast paths against the plain computations they replace: the square-root-free early
// out of the velocity-modification kernel, and the strain passes that revisit only the springs
// whose ends changed.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
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

// The converge passes' count of held pairs (StepSettings::converge_pair_tolerance). A joined pair
// whose particles rest on contact planes that disagree by 0.03 mm (as where a seam crosses a
// waistband on the hips and each particle of a pair has its own plane), each tied by a spring at
// the limit to a pinned particle: every converge pass holds the pair together and keeps each
// particle out of its plane, which opens the pair again. Beside it a free chain 1 % over the limit
// keeps the regular passes busy, so the converge passes run. Counted as a correction, the pair kept
// them at their cap (as it did on every draping step of the trousers); with a tolerance of 0.05 mm
// they end once the chain is done (8 converge passes), leaving the pair and the chain as they
// would be at the cap.
TEST(FastPaths, ConvergePassesEndWhileAHeldPairOnTwoContactPlanesReopensByHundredthsOfAMillimetre) {
  constexpr float rest = 0.02f, threshold = 0.05f, reopen = 3e-5f;  // m: what the planes leave between the pair
  constexpr float limit = (1.0f + threshold) * rest;
  ClothSpec spec;
  spec.fabric = fabric_or_throw("cotton");
  const auto add = [&](Vec3f x, bool pinned) {
    spec.positions.push_back(x);
    spec.mass.push_back(0.001f);
    spec.drag_area.push_back(0.0f);
    spec.pinned.push_back(pinned ? 1 : 0);
    return static_cast<uint32_t>(spec.positions.size() - 1);
  };
  const auto link = [&](uint32_t i, uint32_t j) { spec.springs.push_back({i, j, rest, 10.0f, SpringKind::Structural}); };
  // The pair at x = -/+ reopen / 2, tied to anchors 0.05 % inside the limit.
  const float tie = (1.0f + threshold - 0.0005f) * rest;
  const uint32_t left = add({-0.5f * reopen - tie, 1, 0}, true), a = add({-0.5f * reopen, 1, 0}, false);
  const uint32_t b = add({0.5f * reopen, 1, 0}, false), right = add({0.5f * reopen + tie, 1, 0}, true);
  link(left, a);
  link(b, right);
  // The free chain, 4 springs 1 % over the limit, 10 cm below.
  uint32_t previous = add({0, 0.9f, 0}, false);
  for (int i = 1; i <= 4; ++i) {
    const uint32_t next = add({1.01f * limit * static_cast<float>(i), 0.9f, 0}, false);
    link(previous, next);
    previous = next;
  }
  const ClothModel model = compile(std::move(spec));
  const std::array<std::array<uint32_t, 2>, 1> pair{{{a, b}}};
  struct Outcome {
    StrainLimitResult result;
    float gap, strain;
  };
  const auto run = [&](float pair_tolerance) {
    ClothState state = initial_state(model);
    StepScratch scratch(model, 1);
    StepSettings settings = default_step_settings(model);
    settings.strain_threshold = threshold;
    settings.friction = 0.0f;
    settings.joined_pairs = pair;
    settings.converge_pair_tolerance = pair_tolerance;
    // The pair's planes (d = n.x + plane >= thickness): a kept at x <= -reopen / 2, b at x >= reopen / 2.
    const float thickness = model.fabric.collision_thickness;
    scratch.step_start = state.x;
    scratch.contact[a].normal = Vec3f(-1, 0, 0);
    scratch.contact_plane[a] = thickness - 0.5f * reopen;
    scratch.contact[b].normal = Vec3f(1, 0, 0);
    scratch.contact_plane[b] = thickness - 0.5f * reopen;
    const StepContext c{model, state, scratch, settings, 1e-3f};
    const StrainLimitResult r = limit_strain_position(c, 4, 128);
    return Outcome{r, (state.x[a] - state.x[b]).norm(), strain_stats(model, state.x).max};
  };
  const Outcome counted = run(0.0f), tolerated = run(5e-5f);
  EXPECT_TRUE(counted.result.at_pass_limit);  // the pair kept the passes going to their cap
  EXPECT_EQ(counted.result.passes, 4u + 128u);
  EXPECT_FALSE(tolerated.result.at_pass_limit);  // they ended on their own
  EXPECT_LT(tolerated.result.passes, 4u + 16u) << tolerated.result.passes;  // 12 when written
  for (const Outcome& o : {counted, tolerated}) {
    EXPECT_NEAR(o.gap, reopen, 2e-6f);        // held as close as the planes allow
    EXPECT_LT(o.strain, threshold + 1e-3f);   // the chain pulled back to the limit
  }
}

}  // namespace
}  // namespace drape::sim
