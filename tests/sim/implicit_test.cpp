// The implicit solver (drape/implicit.hpp): Newton converges, the state of rest it finds is an
// equilibrium (the residual), contact keeps the cloth outside, large steps stay stable, and the
// result does not depend on the number of threads.
#include <gtest/gtest.h>
#include <omp.h>

#include <cmath>
#include <cstdio>
#include <tuple>
#include <thread>
#include <vector>

#include "drape/analytic_colliders.hpp"
#include "drape/fit_map.hpp"
#include "drape/implicit.hpp"
#include "drape/shapes.hpp"

namespace drape {
namespace {

ClothModel hanging_cloth(uint32_t n, bool pin) {
  GridClothOptions o;
  o.nx = o.ny = n;
  o.width = o.height = 0.6f;
  // Vertical: weft along x, warp down from y = 1.
  o.origin = Vec3f(-0.3f, 1.0f, 0.0f);
  o.u_axis = Vec3f(1, 0, 0);
  o.v_axis = Vec3f(0, -1, 0);
  ClothSpec spec = grid_cloth_spec(fabric_or_throw("cotton"), o);
  if (pin) {
    spec.pinned.assign(spec.positions.size(), 0);
    spec.pinned[0] = spec.pinned[n - 1] = 1;
  }
  return compile(std::move(spec));
}

// A flat cloth above a sphere, falling onto it.
ClothModel cloth_over_sphere(uint32_t n) {
  GridClothOptions o;
  o.nx = o.ny = n;
  o.width = o.height = 1.0f;
  o.origin = Vec3f(-0.5f, 0.55f, -0.5f);
  return grid_cloth(fabric_or_throw("cotton"), o);
}

// Two flat sheets of cotton, one `gap` above the other, in one model (no spring joins them), over a
// sphere of radius 0.5 at the origin.
ClothModel two_sheets(uint32_t n, float gap) {
  GridClothOptions o;
  o.nx = o.ny = n;
  o.width = o.height = 0.8f;
  o.origin = Vec3f(-0.4f, 0.52f, -0.4f);
  ClothSpec spec = grid_cloth_spec(fabric_or_throw("cotton"), o);
  o.origin.y() += gap;
  const ClothSpec top = grid_cloth_spec(fabric_or_throw("cotton"), o);
  const auto offset = static_cast<uint32_t>(spec.positions.size());
  spec.positions.insert(spec.positions.end(), top.positions.begin(), top.positions.end());
  spec.mass.insert(spec.mass.end(), top.mass.begin(), top.mass.end());
  spec.drag_area.insert(spec.drag_area.end(), top.drag_area.begin(), top.drag_area.end());
  spec.flat_positions.insert(spec.flat_positions.end(), top.flat_positions.begin(), top.flat_positions.end());
  for (Tri t : top.triangles) spec.triangles.push_back({t[0] + offset, t[1] + offset, t[2] + offset});
  for (ClothSpec::Spring sp : top.springs) {
    sp.a += offset;
    sp.b += offset;
    spec.springs.push_back(sp);
  }
  for (ClothSpec::Bend b : top.bends) spec.bends.push_back({b.a + offset, b.m + offset, b.b + offset, b.stiffness});
  spec.grid_nx = spec.grid_ny = 0;
  return compile(std::move(spec));
}

// A horizontal strip of `cells` x (rows - 1) cells of side h at y = 1, clamped along one end: its
// first two columns (x = -h and 0) are pinned, so the slope there is zero; the rest is free.
struct Strip {
  ClothModel model;
  ClothState state;
  uint32_t nx = 0, ny = 5;
};
Strip clamped_strip(const Fabric& fabric, uint32_t cells, float h, uint32_t rows = 5) {
  GridClothOptions o;
  o.nx = cells + 2;
  o.ny = rows;
  o.width = h * static_cast<float>(o.nx - 1);
  o.height = h * static_cast<float>(o.ny - 1);
  o.origin = Vec3f(-h, 1.0f, 0.0f);
  ClothSpec spec = grid_cloth_spec(fabric, o);
  spec.pinned.assign(spec.positions.size(), 0);
  for (uint32_t iy = 0; iy < o.ny; ++iy) spec.pinned[iy * o.nx] = spec.pinned[iy * o.nx + 1] = 1;
  Strip strip{compile(std::move(spec)), {}, o.nx, o.ny};
  strip.state = initial_state(strip.model);
  return strip;
}

// Quasi-static steps of 0.05 s, force tolerance `tolerance`.
ImplicitSettings quasi_static_settings(const ClothModel& m, double tolerance = ImplicitSettings{}.force_tolerance) {
  ImplicitSettings settings = default_implicit_settings(m);
  settings.quasi_static = true;
  settings.time_step = 0.05;
  settings.force_tolerance = tolerance;
  return settings;
}

// Quasi-static steps (at most 100) until one converged with the largest net force at most `residual`
// of a particle's weight; `stats` is the last step's. Returns the steps before that one.
int come_to_rest(ImplicitSolver& solver, ClothState& state, const ImplicitSettings& settings, float residual,
                 ImplicitStepStats& stats) {
  int steps = 0;
  for (; steps < 100; ++steps) {
    EXPECT_EQ(solver.step(state, {}, settings, &stats), StepStatus::Ok);
    if (state.status != StepStatus::Ok || (stats.converged && stats.residual <= residual)) break;
  }
  return steps;
}

float hang(Strip& strip, float residual) {
  ImplicitSolver solver(strip.model);
  ImplicitStepStats stats;
  come_to_rest(solver, strip.state, quasi_static_settings(strip.model), residual, stats);
  return stats.residual;
}

// The strip bending under its own weight (bending stencils, ClothModel::bend_stencil). Small
// deflections: Euler-Bernoulli's cantilever under a uniform load q per area, tip deflection
// q L^4 / (8 B) for the bending rigidity B.
TEST(ImplicitSolver, CantileverStripBendsAsEulerBernoulliPredicts) {
  const Fabric fabric = fabric_or_throw("cotton");
  const float length = 0.03f, h = 0.0015f;
  Strip strip = clamped_strip(fabric, static_cast<uint32_t>(std::lround(length / h)), h);
  ASSERT_FALSE(strip.model.bend_stencil.empty());
  ASSERT_LE(hang(strip, 0.001f), 0.001f);
  double tip = 0;
  for (uint32_t iy = 0; iy < strip.ny; ++iy) tip += 1.0 - strip.state.x[iy * strip.nx + strip.nx - 1].y();
  tip /= strip.ny;
  const double q = 9.81 * fabric.areal_density, expected = q * std::pow(length, 4) / (8.0 * fabric.bending_rigidity);
  ASSERT_LT(expected, 0.1 * length) << "the strip must stay in the small-deflection range";
  EXPECT_NEAR(tip, expected, 0.15 * expected);
}

// From 4000 particles the factorised matrix leaves out the couplings between a stencil's ends (two
// cells apart), and the Newton directions are conjugate gradients on the whole Hessian
// preconditioned by it. On a strip of 1.5 mm cells, where bending holds the cloth up, that
// preconditioner is poor: after three misses the solver factorises the whole Hessian again. A strip
// 20 cells long and 184 wide (4070 particles) converges in 5 Newton iterations (4 with the whole
// Hessian factorised from the start; without the return to it, 15 over three steps).
TEST(ImplicitSolver, DirectionsSolveTheWholeHessianWhereBendingHoldsTheCloth) {
  const Fabric fabric = fabric_or_throw("cotton");
  Strip strip = clamped_strip(fabric, 20, 0.0015f, 185);
  ASSERT_GE(strip.model.particle_count(), 4000u);
  ImplicitSolver solver(strip.model);
  ImplicitSettings settings = default_implicit_settings(strip.model);
  settings.quasi_static = true;
  settings.time_step = 0.05;
  ImplicitStepStats stats;
  ImplicitProfile profile;
  for (int steps = 0; steps < 100; ++steps) {
    ASSERT_EQ(solver.step(strip.state, {}, settings, &stats, &profile), StepStatus::Ok);
    if (stats.converged && stats.residual <= 0.001f) break;
  }
  EXPECT_LE(stats.residual, 0.001f);
  EXPECT_LE(profile.newton_iterations, 6u);
  EXPECT_GT(profile.triangular_solves, profile.factorizations) << "conjugate gradients after each factorisation";
}

// The flexion springs the stencils stand in for do not bend the cloth a second time: a strip with
// no bending rigidity does not hold itself up (the paper's flexion springs alone would hold a few
// millimetres of it at most).
TEST(ImplicitSolver, WithoutBendingRigidityTheStripHangsDown) {
  Fabric fabric = fabric_or_throw("cotton");
  fabric.bending_rigidity = 0;
  Strip strip = clamped_strip(fabric, 20, 0.0015f);
  hang(strip, 0.01f);
  EXPECT_LT(strip.state.x[strip.nx - 1].y(), 1.0f - 0.02f);
}

TEST(ImplicitSolver, HangingClothReachesEquilibriumQuasiStatically) {
  const ClothModel m = hanging_cloth(16, true);
  ClothState s = initial_state(m);
  ImplicitSolver solver(m);
  ImplicitStepStats stats;
  const int steps = come_to_rest(solver, s, quasi_static_settings(m), 0.01f, stats);
  ASSERT_EQ(s.status, StepStatus::Ok);
  EXPECT_LE(stats.residual, 0.01f);
  EXPECT_LT(steps, 60);
  // The strain limit holds inside the solve: a cloth hanging from two corners stretches there.
  EXPECT_LT(strain_stats(m, s.x).max, m.fabric.strain_threshold + 0.01f);
  EXPECT_LT(s.x[m.particle_count() / 2].y(), 1.0f - 0.25f);
}

// A state at rest goes into the next step as the solver left it: the positions it stores are
// floats, and the springs pulled into the strain barrier near the pins (1000x the spring) would
// turn their rounding (~3e-8 m) into forces of several times a particle's weight. The state carries
// what the rounding left out (ClothState::x_rounding), so the next step, quasi-static or dynamic,
// starts at rest: no Newton iteration.
TEST(ImplicitSolver, AStateAtRestStartsTheNextStepAtRest) {
  const ClothModel m = hanging_cloth(16, true);
  ClothState s = initial_state(m);
  ImplicitSolver solver(m);
  const ImplicitSettings settings = quasi_static_settings(m, 1e-3);
  ImplicitStepStats stats;
  come_to_rest(solver, s, settings, 1e-3f, stats);
  ASSERT_EQ(s.status, StepStatus::Ok);
  ASSERT_LE(stats.residual, 1e-3f);
  ASSERT_GT(strain_stats(m, s.x).max, m.fabric.strain_threshold);  // the barrier holds it
  // The rounding is there to carry (a compiler that folded the float round trip away left it 0).
  ASSERT_EQ(s.x_rounding.size(), s.x.size());
  size_t rounded = 0;
  for (const Vec3f& r : s.x_rounding) rounded += r.squaredNorm() > 0 ? 1u : 0u;
  EXPECT_GT(rounded, s.x.size() / 2);

  ClothState again = s;
  ASSERT_EQ(solver.step(again, {}, settings, &stats), StepStatus::Ok);
  EXPECT_EQ(stats.newton_iterations, 0);
  EXPECT_LE(stats.residual, 1e-3f);
  ImplicitSettings dynamic = settings;
  dynamic.quasi_static = false;
  dynamic.time_step = 1.0 / 30;
  ASSERT_EQ(solver.step(s, {}, dynamic, &stats), StepStatus::Ok);
  EXPECT_EQ(stats.newton_iterations, 0);
  EXPECT_LE(stats.residual, 1e-3f);
}

TEST(ImplicitSolver, ClothOnASphereRestsOutsideIt) {
  const ClothModel m = cloth_over_sphere(24);
  ClothState s = initial_state(m);
  SphereCollider sphere(Vec3f(0, 0, 0), 0.5f);
  Collider* colliders[] = {&sphere};
  ImplicitSolver solver(m, 1);
  ImplicitSettings settings = default_implicit_settings(m);
  settings.quasi_static = true;
  settings.time_step = 0.05;
  ImplicitStepStats stats;
  ImplicitProfile profile;
  int steps = 0;
  for (; steps < 200; ++steps) {
    ASSERT_EQ(solver.step(s, colliders, settings, &stats, &profile), StepStatus::Ok);
    if (stats.converged && stats.residual <= 0.01f) break;
  }
  EXPECT_LE(stats.residual, 0.01f);
  float closest = 1e9f;
  for (const Vec3f& p : s.x) closest = std::min(closest, sphere.signed_distance(p, nullptr));
  EXPECT_GT(closest, 0.0f);
  EXPECT_GT(stats.contacts, 10u);
}

// Cloth dropped on a unit-diameter sphere and draped by quasi-static steps to rest.
struct ClothAtRestOnASphere {
  ClothModel model = cloth_over_sphere(24);
  ClothState state = initial_state(model);
  SphereCollider sphere{Vec3f(0, 0, 0), 0.5f};
  ImplicitSolver solver{model, 1};
  ImplicitSettings settings = [this] {
    ImplicitSettings s = default_implicit_settings(model);
    s.quasi_static = true;
    s.time_step = 0.05;
    return s;
  }();
  // Steps until a step converged with every particle off balance by at most 1 % of its weight.
  bool settle(ImplicitStepStats& stats) {
    Collider* colliders[] = {&sphere};
    for (int steps = 0; steps < 200; ++steps) {
      if (solver.step(state, colliders, settings, &stats) != StepStatus::Ok) return false;
      if (stats.converged && stats.residual <= 0.01f) return true;
    }
    return false;
  }
};

// Static friction is carried from one step to the next (ClothState::friction_slip): cloth at rest
// on a sphere, held on its slopes by friction, is still at rest at the next step's start, so that
// step neither moves it nor needs more than a Newton iteration. (Measured from each step's start,
// friction let go of what it held and the cloth slid until it held again.)
TEST(ImplicitSolver, StaticFrictionHoldsFromOneStepToTheNext) {
  ClothAtRestOnASphere rest;
  ClothState& s = rest.state;
  Collider* colliders[] = {&rest.sphere};
  ImplicitSolver& solver = rest.solver;
  const ImplicitSettings& settings = rest.settings;
  ASSERT_GT(settings.friction, 0.0f);
  ImplicitStepStats stats;
  ASSERT_TRUE(rest.settle(stats));
  ASSERT_EQ(s.friction_slip.size(), s.x.size());
  size_t held = 0;
  for (const Vec3f& u : s.friction_slip) held += u.norm() > 1e-7f ? 1 : 0;
  EXPECT_GT(held, 10u) << "friction holds the cloth on the sphere's slopes";
  ASSERT_EQ(solver.step(s, colliders, settings, &stats), StepStatus::Ok);
  EXPECT_LE(stats.newton_iterations, 1);
  // At rest to within 10 um: the last iteration's roundings (float positions, 40 ulp of 0.3 m)
  // move it by 1.2 um in the sanitizer build's code (-O1), under 1 um in the release build's.
  EXPECT_LT(stats.max_move, 1e-5f);
  EXPECT_LE(stats.residual, 0.01f);
}

// A square of cotton lying on a plane through the origin with the given normal, at rest against it
// (its thickness from the plane), moving with the plane's velocity; dynamic steps of a walking
// body's (1/90 s), contacts found anew every step as in motion.
struct ClothOnAMovingPlane {
  ClothModel model;
  ClothState state;
  PlaneCollider plane;
  ImplicitSolver solver;
  ImplicitSettings settings;
  ClothOnAMovingPlane(const Vec3f& normal, const Vec3f& plane_velocity, const Vec3f& cloth_velocity)
      : model([&] {
          GridClothOptions o;
          o.nx = o.ny = 11;
          o.width = o.height = 0.2f;
          // Two edges of the square in the plane, the cloth resting its thickness above it.
          const Vec3f u = normal.unitOrthogonal(), v = normal.cross(u);
          o.u_axis = u;
          o.v_axis = v;
          const Fabric cotton = fabric_or_throw("cotton");
          o.origin = -0.1f * (u + v) + cotton.collision_thickness * normal;
          return grid_cloth(cotton, o);
        }()),
        state(initial_state(model)),
        plane(Vec3f::Zero(), normal),
        solver(model, 1),
        settings([&] {
          ImplicitSettings s = default_implicit_settings(model);
          s.time_step = 1.0 / 90.0;
          s.moving_colliders = true;
          return s;
        }()) {
    plane.set_velocity(plane_velocity);
    for (Vec3f& v : state.v) v = cloth_velocity;
  }
  // Steps for `seconds`; false when a step fails.
  bool run(double seconds) {
    Collider* colliders[] = {&plane};
    const int steps = static_cast<int>(std::lround(seconds / settings.time_step));
    for (int k = 0; k < steps; ++k)
      if (solver.step(state, colliders, settings) != StepStatus::Ok) return false;
    return true;
  }
  Vec3f mean(const std::vector<Vec3f>& values) const {
    Vec3f sum = Vec3f::Zero();
    for (const Vec3f& v : values) sum += v;
    return sum / static_cast<float>(values.size());
  }
};

// Friction carries cloth along with a surface that moves under it (a body in motion): cotton at
// rest on a floor that starts sliding at 0.3 m/s is dragged up to the floor's speed by kinetic
// friction (mu g = 2.9 m/s^2: within 0.1 s) and then carried with it, neither stretched nor pushed
// into it.
TEST(ImplicitSolver, FrictionCarriesClothAlongWithASurfaceThatMoves) {
  ClothOnAMovingPlane c(Vec3f(0, 1, 0), Vec3f(0.3f, 0, 0), Vec3f::Zero());
  ASSERT_GT(c.settings.friction, 0.0f);
  ASSERT_TRUE(c.run(0.5));
  const Vec3f v = c.mean(c.state.v);
  EXPECT_NEAR(v.x(), 0.3f, 0.015f);
  EXPECT_NEAR(v.y(), 0.0f, 0.01f);
  EXPECT_NEAR(v.z(), 0.0f, 0.01f);
  // Where the floor carried it: 0.15 m less what it slid while it was being dragged up to speed
  // (0.3^2 / (2 mu g) = 1.5 cm).
  EXPECT_NEAR(c.mean(c.state.x).x(), 0.15f - 0.015f, 0.005f);
  float closest = 1e9f;
  for (const Vec3f& p : c.state.x) closest = std::min(closest, c.plane.signed_distance(p, nullptr));
  EXPECT_GT(closest, 0.0f);
  EXPECT_LT(strain_stats(c.model, c.state.x).max, 0.005f);
}

// Dynamic steps with friction converge: cotton on a floor that starts sliding at 0.3 m/s (dragged
// up to its speed, then carried), each step solved to 0.2 % of a particle's weight with directions
// solved tightly. Each step starts where the floor carries the cloth (the floor's motion over the
// last step), so that with friction's static range of 1 mm (what `drape animate` asks for) or 0.1 mm
// (dressing's), every step converges within 12 Newton iterations, in at most one on average.
// (Started where the cloth was: 81 and 115 iterations over the 45 steps, Newton's iterates
// passing from static to sliding friction and back.)
TEST(ImplicitSolver, DynamicStepsWithFrictionConverge) {
  const auto newton_iterations = [](double slip, int& unconverged) {
    ClothOnAMovingPlane c(Vec3f(0, 1, 0), Vec3f(0.3f, 0, 0), Vec3f::Zero());
    c.settings.friction_slip = slip;
    c.settings.max_newton_iterations = 12;
    Collider* colliders[] = {&c.plane};
    int total = 0;
    unconverged = 0;
    for (int k = 0; k < 45; ++k) {
      ImplicitStepStats stats;
      EXPECT_EQ(c.solver.step(c.state, colliders, c.settings, &stats), StepStatus::Ok);
      total += stats.newton_iterations;
      unconverged += stats.converged ? 0 : 1;
    }
    return total;
  };
  int unconverged = 0, unconverged_short = 0;
  const int iterations = newton_iterations(1e-3, unconverged);
  const int iterations_short = newton_iterations(1e-4, unconverged_short);
  std::printf("Newton iterations over 45 steps: %d with a 1 mm static range (%d steps unconverged), %d with 0.1 mm (%d)\n",
              iterations, unconverged, iterations_short, unconverged_short);
  EXPECT_EQ(unconverged, 0);
  EXPECT_EQ(unconverged_short, 0);
  EXPECT_LE(iterations, 45);
  EXPECT_LE(iterations_short, 45);
}

// Friction is bounded by the normal force where the surface was at a step's start. A slope of 30
// degrees (steeper than cotton's friction holds: tan 30 = 0.58 > 0.3) rises along its normal at
// 1.35 m/s, a walking body's 1.5 cm a step, carrying the cloth lying on it at that speed. Nothing
// presses harder than the cloth's weight, so it slides down the slope as on one that stands still:
// g (sin 30 - mu cos 30) = 2.4 m/s^2 along it. (Bounded by the depth found against where the surface
// would be at the step's end, 1.5 cm into it, friction took the normal force as a thousand times
// the weight and held the cloth where it was.)
TEST(ImplicitSolver, FrictionOnASurfaceMovingTowardsTheClothIsBoundedByItsWeight) {
  const float angle = static_cast<float>(M_PI) / 6.0f;
  const Vec3f normal(-std::sin(angle), std::cos(angle), 0.0f);  // the slope descends towards -x
  const Vec3f velocity = 1.35f * normal;
  ClothOnAMovingPlane c(normal, velocity, velocity);
  // As in a walk's steps, Newton stops at its cap of 12 iterations before the step converges, and
  // what friction took at the step's start is what it holds with (a dynamic step does not take the
  // normal forces again).
  c.settings.max_newton_iterations = 12;
  c.settings.force_tolerance = 0.0;
  const float mu = c.settings.friction;
  ASSERT_LT(mu, std::tan(angle));
  const Vec3f start = c.mean(c.state.x);
  const double seconds = 0.3;
  ASSERT_TRUE(c.run(seconds));
  // How far it slid down the slope, the plane's motion taken off.
  const Vec3f down_slope(-std::cos(angle), -std::sin(angle), 0.0f);
  const Vec3f moved = c.mean(c.state.x) - start - velocity * static_cast<float>(seconds);
  const float along = moved.dot(down_slope);
  const float expected = 0.5f * 9.81f * (std::sin(angle) - mu * std::cos(angle)) * static_cast<float>(seconds * seconds);
  EXPECT_GT(along, 0.7f * expected);
  EXPECT_LT(along, 1.3f * expected);
  EXPECT_NEAR(moved.dot(normal), 0.0f, 0.002f) << "the cloth rides on the slope, neither into it nor off it";
}

// The colliders' forces on the cloth (ImplicitSolver::contact_forces), what a body that gives way
// takes the reaction of: cloth at rest on a sphere is held up by them, so they carry its weight,
// act at the sphere's surface, and handed to the sphere's vertices (add_pressure) they are equal
// and opposite (Newton's third law).
TEST(ImplicitSolver, ContactForcesOfClothAtRestCarryItsWeightAndTheSphereTakesTheirReaction) {
  ClothAtRestOnASphere rest;
  const ClothModel& m = rest.model;
  ImplicitSolver& solver = rest.solver;
  ImplicitStepStats stats;
  ASSERT_TRUE(rest.settle(stats));
  ContactForces contacts;
  contacts.force.resize(m.particle_count());
  contacts.point.resize(m.particle_count());
  solver.contact_forces(contacts.force, contacts.point);
  Vec3d total = Vec3d::Zero();
  double weight = 0;
  size_t touching = 0;
  for (size_t i = 0; i < m.particle_count(); ++i) {
    weight += static_cast<double>(m.mass[i]) * 9.81;
    total += contacts.force[i].cast<double>();
    if (contacts.force[i].squaredNorm() == 0.0f) continue;
    ++touching;
    EXPECT_NEAR(contacts.point[i].norm(), 0.5f, 1e-4f) << i;
  }
  EXPECT_GT(touching, 20u);
  // At rest each particle is off balance by at most 1 % of its weight.
  EXPECT_NEAR(total.y(), weight, 0.01 * weight);
  EXPECT_LT(std::hypot(total.x(), total.z()), 0.01 * weight);
  const Mesh ball = uv_sphere(0.5f, Vec3f::Zero(), 48, 24);
  PressureMap map = empty_pressure_map(ball);
  add_pressure(map, ball, contacts);
  EXPECT_LT((map.total.cast<double>() + total).norm(), 1e-4 * weight);
  EXPECT_LT(map.total.y(), 0.0f) << "the cloth presses down on the sphere";
}

// Implicit Euler at 1/30 s, thirty times the explicit bound, on a cloth swinging from two corners:
// stable, and its energy never grows (implicit Euler only dissipates).
TEST(ImplicitSolver, DynamicStepsOfAThirtiethOfASecondAreStable) {
  const ClothModel m = hanging_cloth(20, true);
  ASSERT_LT(m.stable_time_step(), 1.0f / 30.0f / 10.0f);
  ClothState s = initial_state(m);
  // Swung sideways: every free particle starts at 1 m/s along x.
  for (size_t i = 0; i < m.particle_count(); ++i)
    if (m.inverse_mass[i] > 0) s.v[i] = Vec3f(1.0f, 0.0f, 0.0f);
  const ClothState start = s;
  // Newton alone, and with block sweeps between its iterations and one factorisation a step.
  for (const bool sweeps : {false, true}) {
    s = start;
    ImplicitSolver solver(m);
    ImplicitSettings settings = default_implicit_settings(m);
    settings.time_step = 1.0 / 30.0;
    if (sweeps) {
      settings.block_sweeps = 4;
      settings.factorisation_interval = 60;
    }
    double previous = cloth_energy(m, s, settings.gravity).total();
    for (int k = 0; k < 60; ++k) {
      ASSERT_EQ(solver.step(s, {}, settings), StepStatus::Ok) << k;
      const double e = cloth_energy(m, s, settings.gravity).total();
      EXPECT_LE(e, previous + 1e-6) << k << (sweeps ? " with sweeps" : "");
      previous = e;
    }
    EXPECT_LT(s.max_speed, 1.0f);
    EXPECT_LT(strain_stats(m, s.x).max, m.fabric.strain_threshold + 0.01f);
  }
}

// Block sweeps between Newton's iterations (ImplicitSettings::block_sweeps, what `drape animate`
// steps with) find the same minimum of the step's incremental potential: cloth falling onto a
// sphere in dynamic steps of 1/90 s, from each of the states Newton's steps pass through as it lands,
// one step with sweeps (a fresh factorisation every 8 Newton iterations, the other directions from
// the conjugate gradients on it) ends within 0.05 mm of Newton's tightly solved step on average,
// outside the sphere, with a third of the factorisations or fewer.
TEST(ImplicitSolver, BlockSweepsWithFewFactorisationsEndAStepWhereNewtonDoes) {
  const ClothModel m = cloth_over_sphere(30);
  SphereCollider sphere(Vec3f(0, 0, 0), 0.5f);
  Collider* colliders[] = {&sphere};
  ImplicitSettings newton = default_implicit_settings(m);
  newton.time_step = 1.0 / 90.0;
  newton.max_newton_iterations = 60;
  newton.force_tolerance = 1e-3;
  ImplicitSettings swept = newton;
  swept.block_sweeps = 4;
  swept.factorisation_interval = 8;
  swept.direction_tolerance = 0.5;
  swept.direction_iterations = 3;
  ImplicitSolver solver(m, 1);
  ClothState s = initial_state(m);
  ImplicitProfile newton_profile, swept_profile;
  uint64_t newton_compared = 0;  // Newton's factorisations in the steps compared
  double worst_mean = 0;
  size_t far = 0, particles = 0;
  float closest = 1e9f;
  int compared = 0;
  for (int k = 0; k < 30; ++k) {
    const ClothState before = s;
    ImplicitStepStats stats;
    const uint64_t factorizations = newton_profile.factorizations;
    ASSERT_EQ(solver.step(s, colliders, newton, &stats, &newton_profile), StepStatus::Ok);
    if (k < 18 || !stats.converged) continue;  // from where the cloth reaches the sphere
    newton_compared += newton_profile.factorizations - factorizations;
    ClothState t = before;
    ImplicitSolver other(m, 1);
    ImplicitStepStats other_stats;
    ImplicitProfile profile;
    ASSERT_EQ(other.step(t, colliders, swept, &other_stats, &profile), StepStatus::Ok);
    EXPECT_TRUE(other_stats.converged) << k;
    swept_profile.factorizations += profile.factorizations;
    swept_profile.newton_iterations += profile.newton_iterations;
    swept_profile.block_sweeps += profile.block_sweeps;
    ++compared;
    double sum = 0;
    for (size_t i = 0; i < s.x.size(); ++i) {
      const float d = (s.x[i] - t.x[i]).norm();
      sum += static_cast<double>(d);
      far += d > 1e-4f ? 1 : 0;
      closest = std::min(closest, sphere.signed_distance(t.x[i], nullptr));
    }
    particles += s.x.size();
    worst_mean = std::max(worst_mean, sum / static_cast<double>(s.x.size()));
  }
  std::printf("%d steps compared; Newton over all 30 steps %llu iterations and %llu factorisations (%llu in those compared); with sweeps %llu iterations, "
              "%llu factorisations and %llu sweeps; %.4f mm apart on average at most, %zu of %zu particles more "
              "than 0.1 mm\n",
              compared, static_cast<unsigned long long>(newton_profile.newton_iterations),
              static_cast<unsigned long long>(newton_profile.factorizations),
              static_cast<unsigned long long>(newton_compared),
              static_cast<unsigned long long>(swept_profile.newton_iterations),
              static_cast<unsigned long long>(swept_profile.factorizations),
              static_cast<unsigned long long>(swept_profile.block_sweeps), 1e3 * worst_mean, far, particles);
  EXPECT_GE(compared, 8);
  // Where the cloth lands on the sphere in folds it has more than one state of rest nearby: a
  // particle of a fold may take another (one of 900 went 3.4 mm another way in one step).
  EXPECT_LT(worst_mean, 5e-5);
  EXPECT_LT(far, particles / 500);
  EXPECT_GT(closest, 0.0f);
  EXPECT_GT(swept_profile.block_sweeps, 0u);
  EXPECT_LT(3 * swept_profile.factorizations, newton_compared);
}

// The same steps on one thread and on two give the same state, bit for bit (8464 particles: loops
// of fewer than 8 blocks of 1024 run on one thread).
TEST(ImplicitSolver, ResultsDoNotDependOnTheThreadCount) {
  const ClothModel m = cloth_over_sphere(92);
  SphereCollider sphere(Vec3f(0, 0, 0), 0.5f);
  Collider* colliders[] = {&sphere};
  ImplicitSettings settings = default_implicit_settings(m);
  settings.quasi_static = true;
  settings.time_step = 0.05;
  const auto run = [&](int threads) {
    const int previous = omp_get_max_threads();
    omp_set_num_threads(threads);
    ClothState s = initial_state(m);
    ImplicitSolver solver(m, 1);
    solver.step(s, colliders, settings);
    omp_set_num_threads(previous);
    return state_hash(s);
  };
  EXPECT_EQ(run(1), run(2));
}

// Self-contact (ImplicitSettings::self_collision): two sheets, the upper one 2 cm above the lower,
// draped onto a sphere by quasi-static steps to rest. With it, the upper sheet comes to rest on the
// lower one, the self-contact distance (a quarter of the fabric's contact thickness) away, and no edge passes
// through a triangle; without it the upper one falls through the lower one onto the sphere.
TEST(ImplicitSolver, SelfContactKeepsASheetDrapedOnAnotherOnTopOfIt) {
  constexpr uint32_t kSide = 17;
  const ClothModel m = two_sheets(kSide, 0.02f);
  const size_t half = m.particle_count() / 2;
  SphereCollider sphere(Vec3f(0, 0, 0), 0.5f);
  Collider* colliders[] = {&sphere};
  const float distance = 0.25f * m.fabric.collision_thickness;
  const auto drape = [&](bool self_collision) {
    ImplicitSolver solver(m, 1);
    ImplicitSettings settings = default_implicit_settings(m);
    settings.self_collision = self_collision;
    settings.quasi_static = true;
    settings.time_step = 0.05;
    settings.max_newton_iterations = 40;
    ClothState s = initial_state(m);
    ImplicitStepStats stats;
    for (int k = 0; k < 200; ++k) {
      EXPECT_EQ(solver.step(s, colliders, settings, &stats), StepStatus::Ok);
      if (stats.converged && stats.residual <= 0.01f) break;
    }
    EXPECT_LE(stats.residual, 0.01f) << (self_collision ? "with" : "without") << " self-contact";
    // Over the sphere's top (the middle 5 x 5 particles), how much farther from its centre the upper
    // sheet lies than the lower one.
    float least = 1e9f;
    for (uint32_t iy = kSide / 2 - 2; iy <= kSide / 2 + 2; ++iy)
      for (uint32_t ix = kSide / 2 - 2; ix <= kSide / 2 + 2; ++ix) {
        const size_t i = iy * kSide + ix;
        least = std::min(least, s.x[half + i].norm() - s.x[i].norm());
      }
    return std::tuple{least, self_intersections(m, s.x), stats.self_contacts};
  };
  const auto [apart, crossings, touching] = drape(true);
  EXPECT_GT(apart, 0.8f * distance);
  EXPECT_LT(apart, 2.0f * distance);
  EXPECT_EQ(crossings, 0u);
  EXPECT_GT(touching, 0u);
  const auto [apart_without, crossings_without, touching_without] = drape(false);
  EXPECT_LT(apart_without, 0.2f * distance);
  EXPECT_EQ(touching_without, 0u);
}

// With self-contact on, the result is the same on one thread or two (the pairs are found per particle
// in parallel and gathered in particle order; their terms summed in pair order), also with block
// sweeps, where particles of a colour move side by side and those a self-contact pair joins to one
// of their colour one after another.
TEST(ImplicitSolver, SelfContactDoesNotDependOnTheThreadCount) {
  const ClothModel m = two_sheets(66, 0.006f);  // 8712 particles: the parallel loops run on both threads
  SphereCollider sphere(Vec3f(0, 0, 0), 0.5f);
  Collider* colliders[] = {&sphere};
  ImplicitSettings settings = default_implicit_settings(m);
  settings.self_collision = true;
  settings.block_sweeps = 4;
  settings.factorisation_interval = 8;
  const auto run = [&](int threads) {
    const int previous = omp_get_max_threads();
    omp_set_num_threads(threads);
    ClothState s = initial_state(m);
    ImplicitSolver solver(m, 1);
    ImplicitStepStats stats;
    ImplicitProfile profile;
    for (int k = 0; k < 3; ++k) solver.step(s, colliders, settings, &stats, &profile);
    omp_set_num_threads(previous);
    EXPECT_GT(stats.self_contacts, 0u);
    EXPECT_GT(profile.block_sweeps, 0u);
    return state_hash(s);
  };
  EXPECT_EQ(run(1), run(2));
}

// self_intersections() counts edges through triangles: none in a sheet folded over with a gap, or
// in two sheets apart; the two sheets crossing at right angles cross along a line of triangles.
TEST(SelfIntersections, CountsEdgesThroughTrianglesOfTheSameCloth) {
  const ClothModel apart = two_sheets(9, 0.01f);
  EXPECT_EQ(self_intersections(apart, apart.rest_position), 0u);
  // The upper sheet turned upright through the lower one's middle.
  std::vector<Vec3f> x = apart.rest_position;
  const size_t half = x.size() / 2;
  for (size_t i = half; i < x.size(); ++i) x[i] = Vec3f(x[i].x(), 0.5f + x[i].z(), 0.013f);
  EXPECT_GE(self_intersections(apart, x), 8u);
  // One sheet folded over itself along its middle, 1 cm apart.
  const ClothModel sheet = cloth_over_sphere(21);
  std::vector<Vec3f> folded = sheet.rest_position;
  for (Vec3f& p : folded)
    if (p.x() > 0.0f) p = Vec3f(-p.x(), p.y() + 0.01f, p.z());
  EXPECT_EQ(self_intersections(sheet, folded), 0u);
  // ... and one half pushed through the other.
  for (Vec3f& p : folded)
    if (p.y() > 0.555f && p.x() < -0.2f) p.y() -= 0.02f;
  EXPECT_GT(self_intersections(sheet, folded), 0u);
}

// Two solvers stepping at the same time on their own threads, as dressings side by side do (`drape
// fit`, the web service's workers), give what each gives alone: the sparse factorisation's BLAS
// calls run on both threads at once where the BLAS locks its buffers (OpenBLAS's pthread build,
// the reference BLAS), and are serialised where it does not (a serial OpenBLAS, which answers
// wrongly from two threads at once).
TEST(ImplicitSolver, TwoSolversOnTwoThreadsGiveWhatEachGivesAlone) {
  const ClothModel m = hanging_cloth(40, true);
  ImplicitSettings settings = default_implicit_settings(m);
  settings.quasi_static = true;
  settings.time_step = 0.05;
  const auto run = [&] {
    ClothState s = initial_state(m);
    ImplicitSolver solver(m);
    for (int k = 0; k < 4; ++k) solver.step(s, {}, settings);
    return s.x;
  };
  const std::vector<Vec3f> alone = run();
  std::vector<Vec3f> a, b;
  std::thread first([&] { a = run(); }), second([&] { b = run(); });
  first.join();
  second.join();
  ASSERT_EQ(a.size(), alone.size());
  ASSERT_EQ(b.size(), alone.size());
  for (size_t i = 0; i < alone.size(); ++i) {
    ASSERT_TRUE(std::isfinite(a[i].squaredNorm()) && std::isfinite(b[i].squaredNorm())) << i;
    ASSERT_EQ(a[i], alone[i]) << i;
    ASSERT_EQ(b[i], alone[i]) << i;
  }
}

}  // namespace
}  // namespace drape
