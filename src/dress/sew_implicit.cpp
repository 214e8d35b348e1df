// Stage 5 with the implicit solver (drape/implicit.hpp, docs/dressing.md): the same two phases as
// the paper's sec. 6.2, each a walk to a state of rest by quasi-static steps.
//
// Sewing: no gravity, frictionless contact, every seam pair pulled together by a force of at most
// kSewingForce (a constant pull from afar, a stiff zero-length spring once close), until every pair
// is within seam_closed_m or sewing is at rest (a step's Newton iterations converged, to a particle's weight: without
// friction, the steps walk down one energy, so a step that ends at its minimum ends them all; what
// the body holds open then, draping's stiff seams close). Draping: gravity and the fabric's friction on, the seams stiff
// zero-length springs, until the largest net force on a particle is at most kResidual of its
// weight. Settled: then a continued dynamic simulation of settle_window_s (implicit Euler at
// 1/30 s, from rest) moves no particle more than settle_distance_m; where it does, draping goes
// on from where it went (at most kSettleRounds tests).
#include <algorithm>
#include <chrono>
#include <cmath>

#include "drape/dress.hpp"
#include "drape/implicit.hpp"

namespace drape {
namespace {

constexpr double kQuasiStaticStep = 0.05;  // s, the proximal term's time scale
constexpr double kDynamicStep = 1.0 / 30.0;
constexpr float kSewingForce = 0.05f;      // N, the most one seam pair pulls with while sewing
constexpr float kResidual = 0.01f;         // equilibrium: |net force| <= 1 % of a particle's weight
// Sewing's steps end once no particle is off balance by more than its weight (draping's, a
// hundredth of it). Without gravity and friction, sewing's end is only where draping starts, whose
// gravity, friction and stiff seams move the cloth far more than that; and where the body holds a
// seam open, the projected Hessian's steps near that rest crawl, the force left falling by a few
// per cent an iteration: the default jeans on the female body spent 14 steps, 168 Newton
// iterations, taking it from 7.6 weights to 0.02 with the widest gap unchanged to 0.1 mm.
constexpr double kSewingTolerance = 1.0;
constexpr int kMaxSewingSteps = 30;  // most garments close in 2-6; what the body holds open, draping's stiff seams close
constexpr int kMaxDrapeSteps = 200;
// Newton iterations per quasi-static draping step: with the exact Hessian they mostly converge, and
// a step's end re-anchors friction, which sets the cloth off balance again. 12, 24, 40 and 80 on
// the shirt, skirt, trousers, male shirt and dress: 1237 (with the projected Hessian), 891, 863 and
// 1048 Newton iterations in all (docs/cloth.md).
constexpr int kDrapeNewtonIterations = 40;
// Settled tests, each after draping to equilibrium again. Newton's method also stops at a balance
// that is not a minimum (a fold about to turn over), which the continued simulation leaves: the
// trousers XL on mean_all from one of the robustness starts (1.081x) came back to such balances
// three times (moved 1.3, 6.3 and 2.8 mm) and rested after the fourth.
constexpr int kSettleRounds = 6;

float centre_height(const ClothModel& m, const std::vector<Vec3f>& x) {
  double c = 0, total = 0;
  for (size_t i = 0; i < x.size(); ++i) {
    c += static_cast<double>(m.mass[i]) * x[i].y();
    total += m.mass[i];
  }
  return total > 0 ? static_cast<float>(c / total) : 0.0f;
}

float widest_gap(const ClothState& s, std::span<const std::array<uint32_t, 2>> pairs) {
  float widest = 0;
  for (const auto& [a, b] : pairs) widest = std::max(widest, (s.x[a] - s.x[b]).norm());
  return widest;
}

}  // namespace

void sew_and_drape_implicit(DressedGarment& g, std::span<Collider* const> colliders, const DressOptions& o,
                            const DressProgressCallback& progress, size_t index, size_t count) {
  g.placed_centre_y = g.sewn_centre_y = g.final_centre_y = centre_height(g.model, g.state.x);
  g.time_step = static_cast<float>(kQuasiStaticStep);
  if (!o.simulate) return;
  ImplicitSolver solver(g.model, std::max<size_t>(colliders.size(), 1));
  ImplicitSettings s = default_implicit_settings(g.model);
  s.time_step = kQuasiStaticStep;
  s.quasi_static = true;
  const uint64_t cap = o.max_iterations ? o.max_iterations : std::numeric_limits<uint64_t>::max();
  ImplicitStepStats stats;
  const auto report = [&](const char* phase, double limit) {
    if (progress) progress({index, count, phase, g.state.iterations, g.state.time, limit});
  };

  // Sewing.
  auto start = std::chrono::steady_clock::now();
  s.gravity = Vec3f::Zero();
  s.friction = 0.0f;
  s.seam_force = kSewingForce;
  // Sewing pulls panels from afar and folds them in compression, where the exact Hessian is mostly
  // indefinite: the trousers took 424 Newton iterations with it against 287 without.
  s.exact_hessian = false;
  // Sewing runs without self-contact: panels placed round the body overlap where they wrap (the
  // skirt's front and back at its side seams), and their edges pass each other to meet; with it,
  // the skirt, shirt, trousers and dress each ran to the cap of their Newton iterations, not settled.
  // What sewing leaves passing through itself is left out of self-contact while draping
  // (docs/cloth.md, "Self-contact").
  s.self_collision = false;
  s.force_tolerance = kSewingTolerance;
  g.seams_closed = widest_gap(g.state, g.seam_pairs) <= o.seam_closed_m;
  for (int k = 0; k < kMaxSewingSteps && !g.seams_closed && g.state.iterations < cap; ++k) {
    g.status = solver.step(g.state, colliders, s, &stats, &g.implicit_profile);
    if (g.status != StepStatus::Ok) break;
    g.seams_closed = widest_gap(g.state, g.seam_pairs) <= o.seam_closed_m;
    report("sewing", kMaxSewingSteps * kQuasiStaticStep);
    if (stats.converged) break;
  }
  g.sewing_iterations = g.state.iterations;
  g.sewing_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  g.sewn_max_strain = strain_stats(g.model, g.state.x).max;
  g.sewn_centre_y = centre_height(g.model, g.state.x);

  // Draping.
  start = std::chrono::steady_clock::now();
  s.gravity = Vec3f(0.0f, -9.81f, 0.0f);
  s.friction = g.model.fabric.friction;
  s.seam_force = 0.0f;
  s.exact_hessian = true;
  s.force_tolerance = ImplicitSettings{}.force_tolerance;
  s.self_collision = o.self_collision;
  s.max_newton_iterations = kDrapeNewtonIterations;
  g.residual = std::numeric_limits<float>::infinity();
  const uint64_t drape_start = g.state.iterations;
  ImplicitSettings dynamic = s;
  dynamic.quasi_static = false;
  dynamic.time_step = kDynamicStep;
  dynamic.max_newton_iterations = ImplicitSettings{}.max_newton_iterations;
  const int settle_steps = std::max(1, static_cast<int>(std::lround(o.settle_window_s / kDynamicStep)));
  g.settled = false;
  int drape_steps = 0;
  for (int round = 0; round < kSettleRounds && g.status == StepStatus::Ok && !g.settled; ++round) {
    for (; drape_steps < kMaxDrapeSteps && g.status == StepStatus::Ok && g.state.iterations < cap; ++drape_steps) {
      g.status = solver.step(g.state, colliders, s, &stats, &g.implicit_profile);
      g.residual = stats.residual;
      report("draping", kMaxDrapeSteps * kQuasiStaticStep);
      if (g.status != StepStatus::Ok || stats.residual <= kResidual) break;
    }
    if (g.status != StepStatus::Ok || g.residual > kResidual) break;
    // Settled: a continued dynamic simulation from rest hardly moves it. Where it does (the
    // garment rested on an unstable balance, such as a fold about to turn over), draping goes on
    // from where the continuation took it.
    ClothState trial = g.state;
    StepStatus status = StepStatus::Ok;
    for (int k = 0; k < settle_steps && status == StepStatus::Ok; ++k)
      status = solver.step(trial, colliders, dynamic, nullptr, &g.implicit_profile);
    float moved = 0;
    for (size_t i = 0; i < trial.x.size(); ++i) moved = std::max(moved, (trial.x[i] - g.state.x[i]).norm());
    g.settled = status == StepStatus::Ok && moved <= o.settle_distance_m;
    if (!g.settled && status == StepStatus::Ok) {
      g.state.x = trial.x;
      g.state.x_rounding = trial.x_rounding;
      g.residual = solver.residual(g.state.x, colliders, s);
    }
  }
  g.seams_closed = widest_gap(g.state, g.seam_pairs) <= o.seam_closed_m;
  g.drape_iterations = g.state.iterations - drape_start;
  g.drape_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  g.final_centre_y = centre_height(g.model, g.state.x);
}

}  // namespace drape
