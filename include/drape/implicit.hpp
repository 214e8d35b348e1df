#pragma once
// The implicit solver: each step minimises the incremental potential of the particle system
//
//   E(x) = sum_i m_i / (2 h^2) |x_i - y_i|^2          inertia (y = x_n + h v_n; at rest: y = x_n)
//        + sum_springs k / 2 (|x_b - x_a| - l0)^2       stretch, shear, bending, elastic bands
//        + sum_structural k_lim / 2 (l - (1 + s) l0)^2_+ the strain limit, a stiff barrier at the
//                                                       fabric's threshold s
//        + sum_seams  seam(|x_b - x_a|)                 zero-length seams (force-capped while sewing)
//        + sum_i c(t - d_i(x_i))                        contact: a penalty inside the thickness t,
//                                                       stiffening with depth, 100x past the skin
//        + sum_(i,T) k_c,i / 2 (t - g_iT(x))^2_+          self-contact: particle i and a triangle T
//                                                       of the same cloth at gap g (optional)
//        + sum_i mu lambda_i f(|T_i (x_i - x_n,i)|)     Coulomb friction, lagged (IPC's smoothing)
//        - sum_i m_i g . x_i                            gravity
//
// by Newton's method (Baraff & Witkin 1998 without their one-iteration shortcut): the springs'
// exact Hessian, or where that is indefinite each spring's made positive semi-definite by dropping
// its compressive transverse term, the sparse
// system solved directly (Cholesky with a fill-reducing ordering analysed once per model: the
// pattern never changes), a backtracking line search on E, and a cap on how far one iteration
// moves a particle so contacts found at the start of an iteration stay valid for it. Contacts are
// found anew every iteration, as tangent planes of the nearest collider surface.
//
// Two modes: dynamic (implicit Euler; stable at steps of 1/30 s and longer) and quasi-static
// (every step starts at rest and the inertia term becomes a Levenberg-Marquardt damping around
// each Newton iterate, weakened while full Newton steps succeed: the steps walk down E to the
// state of rest, which is what dressing wants; a step's end is where contacts and friction's
// normal forces are found anew). See docs/cloth.md.
#include <cstdint>
#include <memory>
#include <span>

#include "drape/cloth.hpp"

namespace drape {

enum class Solver : uint8_t { Explicit, Implicit };
std::string_view to_string(Solver solver);

struct ImplicitSettings {
  double time_step = 1.0 / 30.0;        // s
  bool quasi_static = false;            // every step starts at rest (draping to equilibrium)
  bool moving_colliders = false;        // colliders move or deform: every contact found anew each step
  Vec3f gravity{0.0f, -9.81f, 0.0f};    // m/s^2
  float friction = 0.3f;                // Coulomb coefficient against colliders
  // Friction's static range (m): tangential slip from where friction holds a particle is resisted
  // like a spring up to this, by the whole Coulomb force beyond it.
  double friction_slip = 1e-4;
  float strain_threshold = 0.05f;       // structural stretch at which the limit's barrier starts
  float seam_stiffness = 2000.0f;       // N/m per sewn pair (a closed seam's zero-length spring)
  float seam_force = 0.0f;              // N, the most one pair pulls with (sewing); 0: no cap
  float max_move = 0.01f;               // m, the most one Newton iteration moves a particle
  // The contact penalty 100x stiffer past the skin (a particle inside the collider), where cloth
  // resting outside never feels it: a waistband at its strain limit stays out of the body. Off for
  // the sewing scene's capped cylinder, whose panels its seams pull over the rim's sharp edge: there
  // the plane of one face stands for the surface, and the stiffer penalty held the cloth against the
  // edge (n = 24: 18-63 particles in the cylinder instead of 7, seams 5-51 mm open, 6-15 % strain
  // with it 3-100x stiffer).
  bool stiff_past_skin = true;
  int max_newton_iterations = 12;       // per step
  // Newton stops once no particle's net force (inertia included) is over this fraction of its
  // weight (or an iteration moved no particle more than 1e-8 m).
  double force_tolerance = 0.002;
  // The Newton direction: conjugate gradients preconditioned by the step's last factorisation, to
  // this relative residual in at most `direction_iterations`, else a new factorisation. Tight (the
  // default, dressing): once they missed in a step, the step factorises every iteration (where the
  // matrix changed enough for one miss the next mostly misses too). Loose, at least
  // kLooseDirection (animation asks for 0.5): cheaper, less exact directions that Newton's further
  // iterations correct, the preconditioner tried again after each factorisation.
  double direction_tolerance = 1e-3;
  int direction_iterations = 16;
  static constexpr double kLooseDirection = 0.1;
  // The springs' exact Hessian blocks (a factorisation that fails, where the cloth buckles, falls
  // back to the projected ones for the rest of the step), else each made positive semi-definite.
  bool exact_hessian = true;
  // Vertex block descent (Chen et al. 2024) inside a dynamic step's Newton iterations: before each
  // iteration (and after the last, unless it converged), this many Gauss-Seidel sweeps over colours
  // of particles that share no spring or stencil, each particle moved by the Newton step of its own
  // 3x3 block of E with every other particle held, shortened by a backtracking line search on its
  // own terms. Newton's direct solve carries what is global (stretch across the cloth, a garment
  // carried by the body); the sweeps what is local and stiff and not in the last factorisation's
  // matrix (a spring crossing the strain barrier's start, a contact met or left), which Newton's
  // iterations otherwise go back and forth over. 0: none. Quasi-static steps do not sweep (no gain
  // in dressing: docs/cloth.md).
  int block_sweeps = 0;
  // 0: a fresh factorisation whenever the conjugate gradients miss (above). k > 0: a fresh one at
  // the step's first Newton iteration and every k iterations after; in between, the conjugate
  // gradients' direction on it as far as they got (the block sweeps correct what they miss).
  // sweep_dynamic_steps() asks for 4.
  int factorisation_interval = 0;
  // Self-contact: every free particle is kept the fabric's contact thickness from the triangles of
  // the same cloth that are not its own neighbourhood on the pattern (a skirt's folds, a collar
  // turned down, the two layers of a sleeve), with the body contact's penalty, acting on the
  // particle and the triangle's corners alike (equal and opposite). docs/cloth.md, "Self-contact".
  bool self_collision = false;
};
// Settings from the model's fabric (friction, threshold).
ImplicitSettings default_implicit_settings(const ClothModel& model);
// Dynamic steps as `drape animate` and `drape scene` take them: 4 block sweeps between the Newton
// iterations, a fresh factorisation every 4 of them, loose directions (0.5 of the residual in at
// most 3 conjugate-gradient iterations) between. Against tight directions and a factorisation
// whenever they miss: the motions of docs/animation.md 1.4-2.0x the frames per wall second with
// 2.2-2.8x fewer factorisations; with one factorisation a step the shirt over the skirt at 4 cm cells
// ended a frame with 1.3 % of its vertices inside the body (the gate 1 %). At most 6 Newton
// iterations a step, ending once no particle is off balance by more than its weight (dressing
// asks for 0.2 % of it): at most g h^2 = 1.2 mm off at 1/30 s where nothing stiffer than inertia
// holds it, far less in the cloth. The sphere scene at n = 64 then takes 4.3 s for its 2 s against
// 8.5 s solved to 0.2 %, with the same strain and nothing inside (docs/benchmarks.md).
void sweep_dynamic_steps(ImplicitSettings& s);

// What one step did.
struct ImplicitStepStats {
  int newton_iterations = 0;
  float max_move = 0;      // m, the largest displacement of a particle over the step
  float residual = 0;      // largest |net force| / (m g) at the end of the step (inertia excluded)
  uint32_t contacts = 0;   // particles within the contact thickness at the end
  uint32_t self_contacts = 0;  // particle-triangle pairs of the cloth closer than the thickness at the end
  bool converged = false;  // Newton's last iteration moved no particle more than the tolerance
};

// Wall-clock seconds per stage of the implicit step, summed over steps.
struct ImplicitProfile {
  double contacts = 0, assemble = 0, factorize = 0, solve = 0, line_search = 0;
  double self_contacts = 0;  // finding the self-contact pairs
  double sweeps = 0;         // block descent (ImplicitSettings::block_sweeps)
  uint64_t steps = 0, newton_iterations = 0, factorizations = 0, line_search_halvings = 0;
  uint64_t triangular_solves = 0;  // with a factorisation: one per conjugate-gradient iteration and one to start them
  uint64_t block_sweeps = 0;
  // Analyses of the sparse pattern: the first, and each time self-contact needed blocks the pattern
  // lacked (below 4000 particles; from there such pairs are left out of the factorised matrix).
  uint64_t analyses = 0;
  // Self-contact pairs whose blocks the pattern lacks, summed over the assembled matrices (from 4000
  // particles: in the conjugate gradients' products, not the factorised matrix).
  uint64_t self_pairs_outside_pattern = 0;
  double total_seconds() const { return contacts + self_contacts + sweeps + assemble + factorize + solve + line_search; }
};

// The solver for one model: its sparse pattern and ordering are analysed once, at construction;
// step() allocates nothing. The model is read, never changed; everything carried from step to step
// is in the ClothState.
class ImplicitSolver {
 public:
  explicit ImplicitSolver(const ClothModel& model, size_t max_colliders = 4);
  ~ImplicitSolver();
  ImplicitSolver(ImplicitSolver&&) noexcept;
  ImplicitSolver& operator=(ImplicitSolver&&) noexcept;

  // One step of h = settings.time_step. Colliders are brought to the new time first. Returns the
  // state's status (sticky, as for the explicit step).
  StepStatus step(ClothState& state, std::span<Collider* const> colliders, const ImplicitSettings& settings,
                  ImplicitStepStats* stats = nullptr, ImplicitProfile* profile = nullptr);

  // The largest |net force| / (m g) over the free particles at `x` (inertia excluded, friction
  // taking up to mu times the normal force of the tangential force), with contacts found now.
  float residual(std::span<const Vec3f> x, std::span<Collider* const> colliders, const ImplicitSettings& settings);

  // The colliders' force on each particle where the last step ended (N): the contact penalty along
  // its contact plane's normal and friction across it, as the step applied them; zero out of
  // contact. `point`: the nearest point of the collider's surface (on the contact plane). A body
  // that gives way takes the reaction, equal and opposite (drape/soft_body.hpp).
  void contact_forces(std::span<Vec3f> force, std::span<Vec3f> point) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace drape
