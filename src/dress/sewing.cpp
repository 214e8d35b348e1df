// Stage 5: sewing and draping (paper sec. 6.2): "elastic forces are applied along the seaming
// lines. After a certain number of iterations the patterns are seamed ... Then several more
// iterations are performed applying gravity in order to drape the cloth."
//
// Sewing: gravity off, body collision on, the zero-length seam springs pull every pair together.
// After each step the seams get the paper's velocity modification (sec. 3.3) with a rest length of
// 0: a pair may close but never open, and never close faster than its gap in one step, so pairs do
// not overshoot through each other (the cloth core limits only springs with a positive rest length,
// so this kernel lives here). Sewing ends when every pair is closer than seam_closed_m.
// Draping: gravity on; the seam springs stay (they are never welded, so the seam gap in the
// report is a real distance). Settled: every vertex slower than settle_speed for settle_window_s
// of simulated time in a row.
#include <algorithm>
#include <chrono>

#include "drape/dress.hpp"

namespace drape {
namespace {

// Velocity modification of one zero-length seam spring: no opening, no overshoot.
inline void limit_seam_velocity(const Vec3f& xa, const Vec3f& xb, Vec3f& va, Vec3f& vb, float wa, float wb, float dt) {
  const Vec3f d = xb - xa;
  const float gap = d.norm();
  if (gap <= 1e-7f || wa + wb <= 0) return;
  const Vec3f u = d / gap;
  const float rate = (vb - va).dot(u);  // > 0 opening
  const float lowest = -gap / dt;       // closing the whole gap in one step
  const float target = std::clamp(rate, lowest, 0.0f);
  if (target == rate) return;
  // Mass-weighted change of the relative velocity along the pair.
  const float change = (target - rate) / (wa + wb);
  va -= (change * wa) * u;
  vb += (change * wb) * u;
}

void limit_seams(const ClothModel& model, ClothState& state, std::span<const std::array<uint32_t, 2>> pairs, float dt) {
  for (const auto& [a, b] : pairs)
    limit_seam_velocity(state.x[a], state.x[b], state.v[a], state.v[b], model.inverse_mass[a], model.inverse_mass[b], dt);
}

Vec3f centre_of_mass(const ClothModel& m, const std::vector<Vec3f>& x) {
  Vec3f c = Vec3f::Zero();
  double total = 0;
  for (size_t i = 0; i < x.size(); ++i) {
    c += m.mass[i] * x[i];
    total += m.mass[i];
  }
  return total > 0 ? Vec3f(c / static_cast<float>(total)) : c;
}

}  // namespace

void sew_and_drape(DressedGarment& g, std::span<Collider* const> colliders, const DressOptions& o,
                   const DressProgressCallback& progress, size_t index, size_t count) {
  StepSettings settings = default_step_settings(g.model);
  const float dt = g.model.stable_time_step();
  settings.time_step = dt;
  g.time_step = dt;
  StepScratch scratch(g.model, std::max<size_t>(colliders.size(), 1));
  const uint64_t cap = o.max_iterations ? o.max_iterations : std::numeric_limits<uint64_t>::max();
  const auto seam_gap = [&] { return seam_gap_stats(g.state.x, g.seam_pairs).max; };
  const auto report = [&](const char* phase, double limit) {
    if (progress && g.state.iterations % 50 == 0)
      progress({index, count, phase, g.state.iterations, g.state.time, limit});
  };
  g.initial_max_gap = seam_gap();
  if (!o.simulate) return;

  // Sewing: no gravity until every pair is closed.
  auto start = std::chrono::steady_clock::now();
  settings.gravity = Vec3f::Zero();
  g.seams_closed = g.seam_pairs.empty();
  while (!g.seams_closed && g.state.time < o.max_sewing_seconds && g.state.iterations < cap) {
    g.status = step(g.model, g.state, colliders, settings, scratch, &g.profile);
    if (g.status != StepStatus::Ok) break;
    limit_seams(g.model, g.state, g.seam_pairs, dt);
    g.seams_closed = seam_gap() <= o.seam_closed_m;
    report("sewing", o.max_sewing_seconds);
  }
  g.sewing_iterations = g.state.iterations;
  g.sewing_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();

  // Draping: gravity until every vertex has been slow for the settle window.
  start = std::chrono::steady_clock::now();
  settings.gravity = Vec3f(0.0f, -9.81f, 0.0f);
  const Vec3f before = centre_of_mass(g.model, g.state.x);
  const double drape_start = g.state.time;
  double calm_since = -1;
  g.settled = false;
  while (g.status == StepStatus::Ok && g.state.time - drape_start < o.max_drape_seconds && g.state.iterations < cap) {
    g.status = step(g.model, g.state, colliders, settings, scratch, &g.profile);
    if (g.status != StepStatus::Ok) break;
    limit_seams(g.model, g.state, g.seam_pairs, dt);
    if (g.state.max_speed < o.settle_speed) {
      if (calm_since < 0) calm_since = g.state.time;
      if (g.state.time - calm_since >= o.settle_window_s) {
        g.settled = true;
        break;
      }
    } else {
      calm_since = -1;
    }
    report("draping", o.max_drape_seconds);
  }
  g.drape_iterations = g.state.iterations - g.sewing_iterations;
  g.drape_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  g.drop_m = std::max(0.0f, before.y() - centre_of_mass(g.model, g.state.x).y());
}

}  // namespace drape
