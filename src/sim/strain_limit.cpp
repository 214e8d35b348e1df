// Strain limiting against the super-elasticity of mass-spring cloth.
//   Velocity modification (Vassilev & Spanlang sec. 3.3): after the velocity update, springs that
//   are, or would become, longer than (1 + threshold) rest lose the stretching part of their ends'
//   relative velocity. Position modification (Provot 1995, the paper's sec. 3.2 baseline): after the
//   position update, over-long springs have their ends moved together.
// Joined pairs (StepSettings::joined_pairs, sewn seams) are held together in the same passes, after
// the springs, in their given order on one thread (they may share particles at seam corners).
// Both run Gauss-Seidel passes over the model's spring colours: the springs of one colour share no
// particle, so a colour runs in parallel without races, and colours run in a fixed order, so the
// result is the same on any number of threads. With velocity-response contacts, every velocity pass
// is followed by the contact response (velocities only): a spring that pulls a particle into a body
// and a body that pushes it out, answered alternately, converge to a velocity that does neither;
// answering contacts only once, after the limit, lets each step's normal push stretch the springs
// that leave the body at an angle (a table's edge) a little more. Passes stop early when a pass corrects nothing
// beyond the tolerance (a strain change of 1e-4 of the rest length); the counts go to the profile.
// Rings converge slowly under Gauss-Seidel (see the converge passes below): the position passes can
// continue over only the springs still near the limit until none is over it
// (StepSettings::converge_passes).
#include <algorithm>
#include <bit>
#include <cmath>
#include <limits>
#include <utility>

#include "sim/kernels.hpp"
#include "sim/parallel.hpp"
#include "sim/stages.hpp"

namespace drape::sim {
namespace {

constexpr float kRelativeTolerance = 1e-4f;
constexpr float kJoinedTolerance = 1e-5f;  // m: a joined pair this close counts as held

// What one spring's kernel did: nothing, a change within the tolerance, or a correction beyond it
// (counted; a pass with none ends the passes).
enum class Change : uint8_t { None, Small, Corrected };

// Passes after the first visit only the springs with an end that changed since their last visit:
// every particle carries the pass that last changed it (changed_in_pass, 1 + pass index), written
// wherever a spring, a joined pair or the after-pass step (contacts) changed it at all. A spring
// whose ends did not change since its last visit, which changed nothing (a change marks its own
// ends), would compute the same nothing again: skipping it gives the same result bit for bit
// (tests/sim/fast_paths_test.cpp). Marking only the changes beyond the tolerance would skip more,
// but a change within it can be 5 mm/s, and leaving its neighbours alone kept the skirt from settling.
// Only the velocity passes skip: in the position passes, springs held at the limit move by rounding
// on nearly every visit, so the marks skipped little and cost more than they saved (measured on
// the shirt, bench_cloth BM_ShirtDrapeStep).
template <bool kSkipUnchanged, class Kernel, class Hold, class AfterPass>
StrainLimitResult run_passes(const StepContext& c, int max_passes, Kernel&& kernel, Hold&& hold, AfterPass&& after_pass) {
  const ClothModel& m = c.model;
  StrainLimitResult result;
  const size_t colours = m.limit_colour_begin.empty() ? 0 : m.limit_colour_begin.size() - 1;
  uint32_t* changed = c.scratch.changed_in_pass.data();
  const uint32_t* limit_a = m.limit_a.data();
  const uint32_t* limit_b = m.limit_b.data();
  if (kSkipUnchanged) std::fill(c.scratch.changed_in_pass.begin(), c.scratch.changed_in_pass.end(), 0u);
  for (int pass = 0; pass < max_passes; ++pass) {
    // A spring is visited if an end changed in the previous pass (mark == pass) or in this one.
    const uint32_t since = static_cast<uint32_t>(pass), mark = since + 1;
    uint64_t corrections = 0;
    for (size_t colour = 0; colour < colours; ++colour) {
      const size_t first = m.limit_colour_begin[colour], count = m.limit_colour_begin[colour + 1] - first;
      const std::ptrdiff_t blocks = static_cast<std::ptrdiff_t>(block_count(count));
#pragma omp parallel for schedule(static) reduction(+ : corrections) if (blocks >= kMinParallelBlocks)
      for (std::ptrdiff_t b = 0; b < blocks; ++b) {
        const size_t begin = first + static_cast<size_t>(b) * kBlock;
        const size_t end = std::min(first + count, begin + kBlock);
        for (size_t s = begin; s < end; ++s) {
          const uint32_t a = limit_a[s], e = limit_b[s];
          if (kSkipUnchanged && pass > 0 && changed[a] < since && changed[e] < since) continue;
          const Change change = kernel(s);
          if (change == Change::None) continue;
          if (kSkipUnchanged) changed[a] = changed[e] = mark;
          corrections += change == Change::Corrected ? 1u : 0u;
        }
      }
    }
    for (const auto& [a, b] : c.settings.joined_pairs)
      if (hold(a, b)) {
        if (kSkipUnchanged) changed[a] = changed[b] = mark;
        ++corrections;
      }
    if (corrections > 0) after_pass(changed, mark);  // nothing changed: nothing to answer
    ++result.passes;
    result.corrections += corrections;
    result.at_pass_limit = corrections > 0;
    if (corrections == 0) break;
  }
  return result;
}

}  // namespace

StrainLimitResult limit_strain_velocity(const StepContext& c, bool answer_contacts) {
  const ClothModel& m = c.model;
  const Vec3f* x = c.state.x.data();
  Vec3f* v = c.state.v.data();
  const float* w = m.inverse_mass.data();
  const float stretch = 1.0f + c.settings.strain_threshold, dt = c.dt;
  return run_passes<true>(c, c.settings.strain_passes, [&](size_t s) {
    const uint32_t a = m.limit_a[s], b = m.limit_b[s];
    const float rest = m.limit_rest[s];
    const Vec3f va = v[a], vb = v[b];
    if (limit_spring_velocity(x[a], x[b], v[a], v[b], w[a], w[b], stretch * rest, dt, kRelativeTolerance * rest))
      return Change::Corrected;
    return v[a] != va || v[b] != vb ? Change::Small : Change::None;
  }, [&](uint32_t a, uint32_t b) {
    return hold_pair_velocity(x[a], x[b], v[a], v[b], w[a], w[b], dt, kJoinedTolerance);
  }, [&](uint32_t* changed, uint32_t mark) {
    if (answer_contacts) respond_to_contacts(c, changed, mark);
  });
}

namespace {

// Done when no spring is over the limit by more than 0.1 % strain (the regular passes' 0.01 %
// kept the trousers' hips, where contacts push back, at the pass cap: 16 % more time).
constexpr float kConvergeTolerance = 1e-3f;

// The contacts of this step as seen by the position passes: each particle's tangent plane
// (StepScratch::contact_plane, written by integrate_positions). A correction that pulls a particle
// into the body is undone along the normal at once, in the same Gauss-Seidel pass: the contact is
// one more constraint, solved last. Without it a ring held at the strain limit round a body it
// barely fits (a skirt's waist on the hips) is pulled into the body by the position passes, pushed
// out by the next step's response, and pulled in again: the converge passes turned that into
// velocities of 1-2 m/s at the band and the skirt never settled.
struct ContactPlanes {
  const ContactSample* contact = nullptr;  // nullptr: no contacts (relaxation outside a step)
  const float* plane = nullptr;
  const float* inverse_mass = nullptr;
  const Vec3f* start = nullptr;  // position before the step's position update
  float thickness = 0, friction = 0;
  void keep_out(Vec3f* x, uint32_t i) const {
    if (contact && inverse_mass[i] > 0)
      keep_out_of_contact(x[i], contact[i].normal, plane[i], thickness, start[i], friction);
  }
};
ContactPlanes contact_planes(const StepContext& c) {
  if (c.settings.collision_response != CollisionResponse::Velocity || c.scratch.contact_plane.empty()) return {};
  return {c.scratch.contact.data(), c.scratch.contact_plane.data(), c.model.inverse_mass.data(),
          c.scratch.step_start.data(), c.model.fabric.collision_thickness,
          c.settings.friction >= 0 ? c.settings.friction : c.model.fabric.friction};
}

// Position modification (Provot) of strain-limited spring s, for run_passes and the converge passes:
// a correction beyond `tolerance` (a fraction of the rest length) counts. Its ends are kept out of
// the body after a correction that counts, or after any visit with `keep_out_always` (the converge
// passes, whose sub-tolerance corrections add up over their many passes).
auto position_limit(const StepContext& c, float tolerance, ContactPlanes contacts, bool keep_out_always = false) {
  return [&m = c.model, x = c.state.x.data(), stretch = 1.0f + c.settings.strain_threshold, tolerance, contacts,
          keep_out_always](size_t s) {
    const uint32_t a = m.limit_a[s], b = m.limit_b[s];
    const float rest = m.limit_rest[s];
    const bool corrected =
        limit_spring_position(x[a], x[b], m.inverse_mass[a], m.inverse_mass[b], stretch * rest, tolerance * rest);
    if (corrected || keep_out_always) {
      contacts.keep_out(x, a);
      contacts.keep_out(x, b);
    }
    return corrected ? Change::Corrected : Change::None;
  };
}

// A joined pair brought to its mass-weighted mean position, for run_passes.
auto position_hold(const StepContext& c) {
  return [x = c.state.x.data(), w = c.model.inverse_mass.data()](uint32_t a, uint32_t b) {
    return hold_pair_position(x[a], x[b], w[a], w[b], kJoinedTolerance);
  };
}

// The springs at the limit projected back to it together (fast projection, Goldenthal et al. 2007:
// Newton iterations on the constraints C_k(x) = 0, each step dx = -W J^T lambda with
// (J W J^T) lambda = C). Gauss-Seidel converges over a ring of n springs at ~(pi/n)^2 per pass, so a
// waistband held at the limit over the hips kept the converge passes at their cap of 128 on every
// draping step (the trousers: 2.0 of 2.6 s) and still left it 0.25 % over; the system J W J^T of a
// ring is its graph Laplacian, which conjugate gradients solve in ~n products over only the few
// hundred springs concerned.
// - The constraints: every spring over the limit, C = |x_b - x_a| - L; every spring within
//   kProjectNear of it, C = 0 (kept at its length: pulling one spring back stretches its
//   neighbours, which then need an iteration of their own).
// - The particles of a joined pair (a sewn seam) are one node of the system, of their summed mass,
//   and move together. Holding the pairs apart from the solve, at the seams the band crosses, undid
//   it (the iterations stalled at 0.5-0.7 % over); pairs as constraint rows made the system
//   singular where seams close loops of springs, and the solve diverged.
// - Matrix-free and Jacobi-preconditioned, on one thread in a fixed order (the same result on any
//   thread count). Written here because the set and its matrix change every iteration and the solve
//   is a few dozen lines; Eigen's sparse solvers would rebuild a matrix each time.
// - After each iteration the particles moved are kept out of the body (with friction), as in the
//   Gauss-Seidel passes. The iterations end once no spring is over its limit by more than
//   `tolerance` of its rest length.
// Returns the iterations run.
int project_to_limit(const StepContext& c, const ContactPlanes& contacts, float tolerance, int iterations) {
  constexpr int kCgIterations = 64;
  constexpr double kCgRelativeResidual = 0.1;  // of the right-hand side: the next iteration corrects the rest
  constexpr float kProjectNear = 0.002f;        // strain below the limit that joins the set, held at its length
  constexpr float kMaxMove = 0.002f;  // m: no particle moves further in one iteration (a safeguard)
  const ClothModel& m = c.model;
  StepScratch::Projection& p = c.scratch.projection;
  Vec3f* x = c.state.x.data();
  const size_t particles = m.particle_count();
  const float stretch = 1.0f + c.settings.strain_threshold;
  // Nodes: each particle its own, the particles of joined pairs merged (union-find, the smaller
  // index represents). w is the node's inverse mass: 1 / (sum of its particles' masses), 0 if one is pinned.
  uint32_t* node = p.node.data();
  float* w = p.node_inverse_mass.data();
  for (size_t i = 0; i < particles; ++i) node[i] = static_cast<uint32_t>(i);
  const auto find = [&](uint32_t i) {
    while (node[i] != i) i = node[i] = node[node[i]];
    return i;
  };
  for (const auto& [a, b] : c.settings.joined_pairs) {
    const uint32_t ra = find(a), rb = find(b);
    if (ra != rb) node[std::max(ra, rb)] = std::min(ra, rb);
  }
  for (size_t i = 0; i < particles; ++i) {
    node[i] = find(static_cast<uint32_t>(i));
    w[i] = 0;  // mass summed into the node first
  }
  for (size_t i = 0; i < particles; ++i) {
    const float wi = m.inverse_mass[i];
    if (w[node[i]] >= 0) w[node[i]] = wi > 0 ? w[node[i]] + 1.0f / wi : -1.0f;  // -1: pinned
  }
  for (size_t i = 0; i < particles; ++i)
    if (node[i] == i) w[i] = w[i] > 0 ? 1.0f / w[i] : 0.0f;
  uint8_t* merged = p.merged.data();  // the node has more than one particle
  std::fill(merged, merged + particles, uint8_t{0});
  for (size_t i = 0; i < particles; ++i)
    if (node[i] != i) merged[node[i]] = 1;
  Vec3f* g = p.gathered.data();
  // y = (J W J^T) v: gather J^T v per node, then each row's gradient . W (J^T v).
  const auto gather = [&](size_t n, const float* v) {
    for (size_t k = 0; k < n; ++k) g[p.a[k]] = g[p.b[k]] = Vec3f::Zero();
    for (size_t k = 0; k < n; ++k) {
      const Vec3f d = p.direction[k] * v[k];
      g[p.a[k]] -= d;
      g[p.b[k]] += d;
    }
  };
  const auto multiply = [&](size_t n, const float* v, float* y) {
    gather(n, v);
    for (size_t k = 0; k < n; ++k) y[k] = p.direction[k].dot(w[p.b[k]] * g[p.b[k]] - w[p.a[k]] * g[p.a[k]]);
  };
  const auto dot = [](size_t n, const float* u, const float* v) {
    double sum = 0;
    for (size_t k = 0; k < n; ++k) sum += double(u[k]) * double(v[k]);
    return sum;
  };
  int run = 0;
  double previous_residual = std::numeric_limits<double>::infinity();
  Vec3f* saved = p.saved.data();
  for (; run < iterations; ++run) {
    size_t n = 0, seam_rows = 0;
    bool over_tolerance = false;
    double residual = 0;  // sum of the squared strains over the limit
    for (size_t s = 0; s < m.limit_a.size(); ++s) {
      const uint32_t a = node[m.limit_a[s]], b = node[m.limit_b[s]];
      const float limit = stretch * m.limit_rest[s], near = limit - kProjectNear * m.limit_rest[s];
      const Vec3f d = x[b] - x[a];
      const float len2 = d.squaredNorm();
      if (a == b || !(len2 > near * near) || w[a] + w[b] <= 0) continue;
      const float len = std::sqrt(len2);
      if (len > limit) residual += double((len - limit) / m.limit_rest[s]) * double((len - limit) / m.limit_rest[s]);
      // Springs along a seam on both of its panels join the same two nodes: one row for them (the
      // first in spring order), or the system is singular there.
      if (merged[a] && merged[b]) {
        bool duplicate = false;
        for (size_t k = 0; k < seam_rows && !duplicate; ++k) {
          const size_t r = p.seam_row[k];
          duplicate = (p.a[r] == a && p.b[r] == b) || (p.a[r] == b && p.b[r] == a);
        }
        if (duplicate) continue;
        p.seam_row[seam_rows++] = static_cast<uint32_t>(n);
      }
      p.a[n] = a;
      p.b[n] = b;
      p.direction[n] = d / len;
      p.rhs[n] = std::max(len - limit, 0.0f);
      over_tolerance = over_tolerance || len - limit > tolerance * m.limit_rest[s];
      ++n;
    }
    if (!over_tolerance) break;
    // An iteration that did not lower the residual is undone, and the projection ends there: the
    // Gauss-Seidel passes go on from the best state it reached (without this the skirt at 4x Table
    // 2's resolution, whose loose solves overshot, did not settle with the projection on).
    if (residual >= previous_residual) {
      std::copy(saved, saved + particles, x);
      break;
    }
    previous_residual = residual;
    std::copy(x, x + particles, saved);
    // Preconditioned conjugate gradients on (J W J^T) lambda = C, from lambda = 0.
    float* lambda = p.lambda.data();
    float* r = p.residual.data();
    float* q = p.search.data();
    float* aq = p.product.data();
    float* diagonal = p.diagonal.data();
    double rz = 0;
    for (size_t k = 0; k < n; ++k) {
      diagonal[k] = w[p.a[k]] + w[p.b[k]];
      lambda[k] = 0;
      r[k] = p.rhs[k];
      q[k] = r[k] / diagonal[k];
      rz += double(r[k]) * q[k];
    }
    const double stop = kCgRelativeResidual * kCgRelativeResidual * dot(n, r, r);
    for (int it = 0; it < kCgIterations && rz > 0; ++it) {
      multiply(n, q, aq);
      const double qaq = dot(n, q, aq);
      if (!(qaq > 0)) break;
      const float alpha = static_cast<float>(rz / qaq);
      for (size_t k = 0; k < n; ++k) {
        lambda[k] += alpha * q[k];
        r[k] -= alpha * aq[k];
      }
      if (dot(n, r, r) <= stop) break;
      double rz_next = 0;
      for (size_t k = 0; k < n; ++k) rz_next += double(r[k]) * double(r[k]) / diagonal[k];
      const float beta = static_cast<float>(rz_next / rz);
      rz = rz_next;
      for (size_t k = 0; k < n; ++k) q[k] = r[k] / diagonal[k] + beta * q[k];
    }
    // dx = -W J^T lambda, the same for every particle of a node.
    gather(n, lambda);
    float largest = 0;  // squared
    for (size_t k = 0; k < n; ++k)
      largest = std::max({largest, (w[p.a[k]] * g[p.a[k]]).squaredNorm(), (w[p.b[k]] * g[p.b[k]]).squaredNorm()});
    const float scale = largest > kMaxMove * kMaxMove ? kMaxMove / std::sqrt(largest) : 1.0f;
    for (size_t i = 0; i < particles; ++i) {
      const uint32_t k = node[i];
      if (w[k] > 0 && g[k] != Vec3f::Zero()) {
        x[i] -= scale * w[k] * g[k];
        contacts.keep_out(x, static_cast<uint32_t>(i));
      }
    }
    for (size_t k = 0; k < n; ++k) g[p.a[k]] = g[p.b[k]] = Vec3f::Zero();
  }
  return run;
}

}  // namespace

StrainLimitResult limit_strain_position(const StepContext& c, int max_passes, int converge_passes) {
  const ClothModel& m = c.model;
  Vec3f* x = c.state.x.data();
  const float stretch = 1.0f + c.settings.strain_threshold;
  const auto hold = position_hold(c);
  const ContactPlanes contacts = contact_planes(c);
  StrainLimitResult result = run_passes<false>(c, max_passes, position_limit(c, kRelativeTolerance, contacts), hold,
                                               [](uint32_t*, uint32_t) {});
  if (!result.at_pass_limit || converge_passes <= 0) return result;

  // Converge passes: Gauss-Seidel over only the springs within kNearLimit of the limit, on one
  // thread in a fixed order (the same result on any number of threads). The set is gathered again
  // every kRegather passes, since pulling one spring back stretches its neighbours. A ring needs tens
  // of passes (its widening mode converges at ~(pi/n)^2 per pass), but it is a few hundred springs
  // of thousands, so this costs a fraction of as many full passes.
  // - The passes sweep the set forwards and backwards in turn (symmetric Gauss-Seidel). Sweeping one
  //   way only, every pass pulls a ring's particles a little along the ring in the sweep's
  //   direction; where contacts keep the ring from shrinking (a waist it barely fits) the passes
  //   never end and the skirt turned about the body a few mm per window, never settling.
  // - What the passes moved, d = x - x_start, is taken out of the velocities once, at the end: a
  //   particle moving against d (the way that over-stretched the ring) loses that motion, up to
  //   |d| / dt. Otherwise it keeps the velocity that over-stretched the ring, which velocity
  //   modification takes out of a ring only slowly, and moves straight back out next step; the band
  //   trembles and the garment does not settle. Only taken out, never added (position-based
  //   dynamics would add d / dt): where contacts keep a ring from shrinking the passes move the
  //   particles every step, and adding that motion kept the garment moving; taking it out is the
  //   paper's velocity modification (sec. 3.3) applied to what the passes had to correct, and
  //   answers a push out of the body inelastically.
  constexpr float kNearLimit = 0.002f;  // strain below the threshold that still joins the set
  constexpr int kRegather = 8;
  constexpr int kProjectAfter = 16;
  uint32_t* active = c.scratch.active_spring.data();
  const uint32_t* incident_begin = c.scratch.limit_incident_begin.data();
  const uint32_t* incident = c.scratch.limit_incident.data();
  uint64_t* near_bits = c.scratch.near_limit_bits.data();
  const size_t near_words = c.scratch.near_limit_bits.size();
  const auto near_limit = [&](size_t s) {
    const float near = (stretch - kNearLimit) * m.limit_rest[s];
    return (x[m.limit_b[s]] - x[m.limit_a[s]]).squaredNorm() > near * near;
  };
  Vec3f* x_start = c.scratch.converge_start.data();
  std::copy(x, x + m.particle_count(), x_start);
  size_t count = 0;
  const auto limit = position_limit(c, kConvergeTolerance, contacts, /*keep_out_always=*/true);
  const auto correct = [&](uint32_t s) { return limit(s) == Change::Corrected ? 1u : 0u; };
  const float pair_tolerance = std::max(c.settings.converge_pair_tolerance, kJoinedTolerance);
  for (int pass = 0; pass < converge_passes; ++pass) {
    // What Gauss-Seidel has not finished in kProjectAfter passes (a ring held at the limit) is
    // projected as a whole, then the passes go on from there. Projecting before any pass (or after
    // 4 or 8) left the dress at Table 2's resolution unsettled after 5 s; see docs/cloth.md for what
    // it does at 4x.
    const bool project = pass == kProjectAfter && c.settings.projection_iterations > 0;
    if (project)
      result.passes += static_cast<uint32_t>(project_to_limit(c, contacts, kConvergeTolerance, c.settings.projection_iterations));
    if (pass == 0 || project) {
      count = 0;
      for (size_t s = 0; s < m.limit_a.size(); ++s)
        if (near_limit(s)) active[count++] = static_cast<uint32_t>(s);
    } else if (pass % kRegather == 0) {
      // Since the last gathering only the ends of the springs gathered then and the joined pairs'
      // particles have moved, so only the springs touching them can have come near the limit or
      // left it; every other spring keeps its length and its verdict. The set is the one a scan of
      // every spring would give, in the same (spring index) order: marked in a bitmap, read back in
      // order. At 16x Table 2's shirt a full scan was a tenth of the draping step.
      const auto mark_near = [&](uint32_t i) {
        for (uint32_t e = incident_begin[i]; e < incident_begin[i + 1]; ++e) {
          const uint32_t s = incident[e];
          if (near_limit(s)) near_bits[s >> 6] |= uint64_t{1} << (s & 63);
        }
      };
      for (size_t k = 0; k < count; ++k) {
        mark_near(m.limit_a[active[k]]);
        mark_near(m.limit_b[active[k]]);
      }
      for (const auto& [a, b] : c.settings.joined_pairs) {
        mark_near(a);
        mark_near(b);
      }
      count = 0;
      for (size_t w = 0; w < near_words; ++w)
        for (uint64_t bits = std::exchange(near_bits[w], 0); bits != 0; bits &= bits - 1)
          active[count++] = static_cast<uint32_t>(64 * w + static_cast<size_t>(std::countr_zero(bits)));
    }
    uint64_t corrections = 0;
    if (pass % 2 == 0) {
      for (size_t k = 0; k < count; ++k) corrections += correct(active[k]);
    } else {
      for (size_t k = count; k-- > 0;) corrections += correct(active[k]);
    }
    for (const auto& [a, b] : c.settings.joined_pairs) {
      const bool counts = (x[a] - x[b]).squaredNorm() > pair_tolerance * pair_tolerance;
      if (!hold(a, b)) continue;
      corrections += counts ? 1u : 0u;
      contacts.keep_out(x, a);
      contacts.keep_out(x, b);
    }
    ++result.passes;
    result.corrections += corrections;
    result.at_pass_limit = corrections > 0;
    if (corrections == 0) break;
  }
  Vec3f* v = c.state.v.data();
  const float inv_dt = 1.0f / c.dt;
  parallel_blocks(m.particle_count(), [&](size_t, size_t begin, size_t end) {
    for (size_t i = begin; i < end; ++i) {
      if (x[i] == x_start[i]) continue;
      const Vec3f d = x[i] - x_start[i];
      const float along = v[i].dot(d), d2 = d.squaredNorm();  // < 0: moving against the correction
      if (along < 0) v[i] += std::min(inv_dt, -along / d2) * d;
    }
  });
  return result;
}

}  // namespace drape::sim

namespace drape {

int relax_to_strain_limit(const ClothModel& model, ClothState& state, const StepSettings& settings, int max_passes) {
  StepScratch unused;  // the position passes keep no per-step scratch (run_passes<false>)
  const sim::StepContext c{model, state, unused, settings, settings.time_step};
  return sim::run_passes<false>(c, max_passes, sim::position_limit(c, sim::kConvergeTolerance, {}), sim::position_hold(c),
                                [](uint32_t*, uint32_t) {})
      .passes;
}

}  // namespace drape
