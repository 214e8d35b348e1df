// Stage 5: sewing and draping (paper sec. 6.2): "elastic forces are applied along the seaming
// lines. After a certain number of iterations the patterns are seamed ... Then several more
// iterations are performed applying gravity in order to drape the cloth."
//
// Sewing: gravity off, body collision on with frictionless contact (the panels slide into place as
// a garment does when put on), the zero-length seam springs pull every pair together. After each
// step the seams get the paper's velocity modification (sec. 3.3) with a rest length of 0: a pair
// may close but never open, and never close faster than its gap in one step. A pair that comes
// within seam_closed_m is joined ("seamed"): from then on the step holds its two particles together
// (StepSettings::joined_pairs, solved in the same Gauss-Seidel passes as the strain limit). The
// particles stay distinct, so the seam gap in the report is the real distance between them.
// Sewing ends when every pair is joined.
// Draping: gravity on, the fabric's friction, viscous damping raised for quasi-static draping.
// Settled: over a window of settle_window_s of simulated time no vertex moved more than
// settle_distance_m (its net displacement: the shape has stopped changing; a vertex pinched between
// arm and torso may still tremble by a fraction of a millimetre from step to step, which this
// ignores and a speed threshold would not).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>

#include "drape/dress.hpp"

namespace drape {
namespace {

constexpr int kConvergePasses = 128;  // StepSettings::converge_passes while draping
constexpr float kConvergePairTolerance = 5e-5f;  // m, StepSettings::converge_pair_tolerance once seamed
constexpr float kRelaxAbove = 0.01f;  // strain over the limit after sewing that is relaxed before draping
constexpr int kRelaxPasses = 1000;    // at most, Gauss-Seidel position passes (a pass is ~20 us per 1000 springs)

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

// Joined pairs (sec. 6.2, "the patterns are seamed"): a pair whose seam forces brought it within
// `closed` is joined, and from then on the step holds its two particles together (StepSettings::
// joined_pairs: one velocity, one position, solved with the strain limit). Newly closed pairs are
// added to `held` in pair order; returns whether every pair is joined.
bool join_closed_pairs(const ClothState& state, std::span<const std::array<uint32_t, 2>> pairs,
                       std::vector<uint8_t>& joined, std::vector<std::array<uint32_t, 2>>& held, float closed) {
  bool all = true, changed = false;
  for (size_t i = 0; i < pairs.size(); ++i) {
    if (!joined[i] && (state.x[pairs[i][0]] - state.x[pairs[i][1]]).norm() <= closed) joined[i] = changed = true;
    all = all && joined[i];
  }
  if (changed) {
    held.clear();
    for (size_t i = 0; i < pairs.size(); ++i)
      if (joined[i]) held.push_back(pairs[i]);
  }
  return all;
}

// The widest gap of the pairs not yet joined (0 when every pair is).
float widest_open_pair(const ClothState& state, std::span<const std::array<uint32_t, 2>> pairs,
                       const std::vector<uint8_t>& joined) {
  float widest2 = 0;
  for (size_t i = 0; i < pairs.size(); ++i)
    if (!joined[i]) widest2 = std::max(widest2, (state.x[pairs[i][0]] - state.x[pairs[i][1]]).squaredNorm());
  return std::sqrt(widest2);
}

}  // namespace

void sew_and_drape(DressedGarment& g, std::span<Collider* const> colliders, const DressOptions& o,
                   const DressProgressCallback& progress, size_t index, size_t count) {
  StepSettings settings = default_step_settings(g.model);
  settings.strain_passes = o.strain_passes;
  settings.position_passes = o.position_passes;
  const auto stable_step = [&] { return o.directional_time_step ? g.model.directional_stable_time_step() : g.model.stable_time_step(); };
  float dt = stable_step();
  settings.time_step = dt;
  g.time_step = dt;
  StepScratch scratch(g.model, std::max<size_t>(colliders.size(), 1));
  const uint64_t cap = o.max_iterations ? o.max_iterations : std::numeric_limits<uint64_t>::max();
  const auto report = [&](const char* phase, double limit) {
    if (progress && g.state.iterations % 50 == 0)
      progress({index, count, phase, g.state.iterations, g.state.time, limit});
  };
  g.placed_centre_y = g.final_centre_y = centre_of_mass(g.model, g.state.x).y();
  if (!o.simulate) return;

  // Sewing: no gravity until every pair is closed.
  auto start = std::chrono::steady_clock::now();
  settings.gravity = Vec3f::Zero();
  settings.friction = 0.0f;
  std::vector<uint8_t> joined(g.seam_pairs.size(), 0);
  std::vector<std::array<uint32_t, 2>> held;
  held.reserve(g.seam_pairs.size());
  g.seams_closed = join_closed_pairs(g.state, g.seam_pairs, joined, held, o.seam_closed_m);
  settings.joined_pairs = held;
  // Stall windows: the pairs joined and the widest open pair at the start of the current one.
  double stall_began = g.state.time;
  size_t stall_joined = held.size();
  float stall_gap = widest_open_pair(g.state, g.seam_pairs, joined);
  g.sewing_stalled = false;
  while (!g.seams_closed && g.state.time < o.max_sewing_seconds && g.state.iterations < cap) {
    g.status = step(g.model, g.state, colliders, settings, scratch, &g.profile);
    if (g.status != StepStatus::Ok) break;
    limit_seams(g.model, g.state, g.seam_pairs, dt);
    g.seams_closed = join_closed_pairs(g.state, g.seam_pairs, joined, held, o.seam_closed_m);
    settings.joined_pairs = held;
    report("sewing", o.max_sewing_seconds);
    if (o.sewing_stall_s > 0 && !g.seams_closed && g.state.time - stall_began >= o.sewing_stall_s) {
      const float gap = widest_open_pair(g.state, g.seam_pairs, joined);
      if (held.size() == stall_joined && gap > o.sewing_stall_gap_m && stall_gap - gap < o.sewing_stall_m) {
        g.sewing_stalled = true;
        break;
      }
      stall_began = g.state.time;
      stall_joined = held.size();
      stall_gap = gap;
    }
  }
  // The last stitches (DressOptions::pull_closed_m): pairs still open by a few millimetres are
  // pulled closed and joined, momentum kept; the relaxation below and the draping's strain passes
  // take up the jump.
  g.pulled_closed = 0;
  if (o.pull_closed_m > 0 && !g.seams_closed && g.status == StepStatus::Ok) {
    for (size_t i = 0; i < g.seam_pairs.size(); ++i) {
      const auto [a, b] = g.seam_pairs[i];
      if (joined[i] || (g.state.x[a] - g.state.x[b]).norm() > o.pull_closed_m) continue;
      const float wa = g.model.mass[a], wb = g.model.mass[b];
      const Vec3f x = (wa * g.state.x[a] + wb * g.state.x[b]) / (wa + wb);
      const Vec3f v = (wa * g.state.v[a] + wb * g.state.v[b]) / (wa + wb);
      g.state.x[a] = g.state.x[b] = x;
      g.state.v[a] = g.state.v[b] = v;
      ++g.pulled_closed;
    }
    g.seams_closed = join_closed_pairs(g.state, g.seam_pairs, joined, held, o.seam_closed_m);
    settings.joined_pairs = held;
  }
  g.sewing_iterations = g.state.iterations;
  g.sewing_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();

  // The seam forces may pull the cloth past the strain limit while sewing (they must be able to, for
  // a moment). Draping's converge passes carry their corrections into the velocities, and a
  // correction of d in one step is a speed of d / dt: the shirt sewn 7.5 % over the limit at --edge
  // 0.013 (dt 0.29 ms) got over 50 m/s in its first draping step and was reported exploded. So a
  // garment sewn more than kRelaxAbove over the limit is relaxed to it once, positions only.
  g.sewn_max_strain = strain_stats(g.model, g.state.x).max;
  if (g.sewn_max_strain - settings.strain_threshold > kRelaxAbove) {
    g.relax_passes = relax_to_strain_limit(g.model, g.state, settings, kRelaxPasses);
  }

  // Draping looks for the state of rest, which does not depend on the inertia: light particles at the
  // outline get more (DressOptions::mass_scaling), for a longer step. Not while sewing: the seams run
  // along the outline, and heavier seam particles closed too slowly (in a trial build that scaled
  // them, the 2021 pants and trousers XL on the default male body kept a seam 15-20 mm open after 1.5 s).
  g.mass_scaled = scale_inertia(g.model, o.mass_scaling);
  dt = stable_step();
  settings.time_step = dt;
  g.time_step = dt;

  // Draping: gravity until every vertex has been slow for the settle window.
  start = std::chrono::steady_clock::now();
  settings.gravity = Vec3f(0.0f, -9.81f, 0.0f);
  settings.friction = -1.0f;
  settings.air_damping = o.drape_damping;
  // What waits until the garment is seamed, because a pair still closing must be able to pull the
  // cloth: the faces over curved parts (DressOptions::face_clearance: lifting the cloth off the body
  // pushed the seams apart), and the converge passes' looser count of held pairs
  // (StepSettings::converge_pair_tolerance: with it the pair closed no more). Jeans S on the
  // average female MakeHuman body, sewn with its inseams 13-15 mm open at the crotch, kept them
  // open with either from the start of draping.
  const auto once_seamed = [&](bool seamed) {
    settings.face_clearance = seamed ? o.face_clearance : -1.0f;
    settings.converge_pair_tolerance = seamed ? kConvergePairTolerance : 0.0f;
  };
  once_seamed(g.seams_closed);
  // A waistband hangs on the hips by its hoop tension, which the strain limit must hold, and a ring
  // of springs converges slowly under Gauss-Seidel: continue the position passes over the springs
  // still near the limit until none is over it (skirt: 7.5 % -> 5.1 % max strain at a 5 % threshold).
  // Not while sewing: there the seams must be able to pull the cloth past the limit for a moment.
  settings.converge_passes = kConvergePasses;
  settings.projection_iterations = o.projection_iterations;
  g.sewn_centre_y = centre_of_mass(g.model, g.state.x).y();
  const double drape_start = g.state.time;
  // Settle windows: positions at the start of the current window (allocated once).
  std::vector<Vec3f> window_start = g.state.x;
  double window_began = g.state.time;
  g.settled = false;
  while (g.status == StepStatus::Ok && g.state.time - drape_start < o.max_drape_seconds && g.state.iterations < cap) {
    g.status = step(g.model, g.state, colliders, settings, scratch, &g.profile);
    if (g.status != StepStatus::Ok) break;
    limit_seams(g.model, g.state, g.seam_pairs, dt);
    once_seamed(join_closed_pairs(g.state, g.seam_pairs, joined, held, o.seam_closed_m));
    settings.joined_pairs = held;
    if (g.state.time - window_began >= o.settle_window_s) {
      float moved2 = 0;
      for (size_t i = 0; i < window_start.size(); ++i) moved2 = std::max(moved2, (g.state.x[i] - window_start[i]).squaredNorm());
      if (std::sqrt(moved2) < o.settle_distance_m) {
        g.settled = true;
        break;
      }
      window_start = g.state.x;  // same size: no allocation
      window_began = g.state.time;
    }
    report("draping", o.max_drape_seconds);
  }
  g.drape_iterations = g.state.iterations - g.sewing_iterations;
  g.drape_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  g.final_centre_y = centre_of_mass(g.model, g.state.x).y();
  // Equilibrium measured as the implicit solver measures it (seams as stiff zero-length springs).
  g.residual = ImplicitSolver(g.model, std::max<size_t>(colliders.size(), 1))
                   .residual(g.state.x, colliders, default_implicit_settings(g.model));
}

std::vector<float> DressedGarment::seam_gaps() const {
  std::vector<float> gaps(seam_names.size(), 0.0f);
  for (size_t i = 0; i < seam_pairs.size() && i < seam_of_pair.size(); ++i) {
    const auto [a, b] = seam_pairs[i];
    gaps.at(seam_of_pair[i]) = std::max(gaps.at(seam_of_pair[i]), (state.x[a] - state.x[b]).norm());
  }
  return gaps;
}

size_t DressedGarment::widest_seam() const {
  const std::vector<float> gaps = seam_gaps();
  return static_cast<size_t>(std::max_element(gaps.begin(), gaps.end()) - gaps.begin());
}

}  // namespace drape
