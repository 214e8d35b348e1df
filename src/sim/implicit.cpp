// The implicit solver (include/drape/implicit.hpp, docs/cloth.md): Newton's method on the
// incremental potential, its directions conjugate gradients preconditioned by a sparse Cholesky
// factorisation of the Hessian less the bending stencils' far couplings, over a pattern analysed
// once.
//
// Assembly is deterministic on any number of threads: every spring's gradient and Hessian block
// are computed in parallel into per-spring slots, then gathered per particle (diagonal blocks and
// gradient, over the model's fixed incidence order) and per off-diagonal block (over a fixed list of
// the springs that share it). Energies are summed per fixed block of items, the blocks in order.
#include "drape/implicit.hpp"

// GCC 12 sees a null dereference in Eigen's sparse views when it inlines them into the CHOLMOD
// wrapper (an empty matrix's index pointers, never read): a false positive inside the library.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wnull-dereference"
#include <Eigen/CholmodSupport>
#include <dlfcn.h>
#include <omp.h>
#include <Eigen/Sparse>
#pragma GCC diagnostic pop
#include <algorithm>
#include <array>
#include <cstdint>
#include <chrono>
#include <cmath>
#include <limits>
#include <mutex>
#include <stdexcept>
#include <utility>

#include "sim/parallel.hpp"
#include "sim/self_contact.hpp"
#include "sim/supernodal.hpp"

namespace drape {
namespace {

using Mat3d = Eigen::Matrix3d;
using SparseMatrix = Eigen::SparseMatrix<double, Eigen::ColMajor, int>;

// The strain limit's barrier is this many times stiffer than the spring it limits: a structural
// spring pulled by ten times the force that stretches it to the threshold s goes past it by 0.009 s
// (0.045 % at s = 5 %), within the gates' 1 % tolerance, also where a waistband carries a garment
// or the body presses a size too small outwards. At 300x, garments pressed out by the body rested
// 1.0-1.3 % over the threshold (the trousers L and M on the default male body 6.04 and 6.60 %, one
// robustness start of the skirt L on him 6.25 %, of the trousers XL 6.08 %). Newton iterations at
// 1000x: README's five garments 982 against 997, five more 1216 against 1170 (docs/cloth.md).
constexpr double kLimitStiffness = 1000.0;
// Contact penalty per square metre of cloth a particle represents (N/m per m^2): a pressure of
// 100 Pa per millimetre inside the thickness layer. Hanging cloth presses with its weight, ~1.5 Pa;
// a garment at its strain limit round a 5 cm limb with ~200 Pa: both stay within the layer.
constexpr double kContactStiffnessPerArea = 1e5;
// The contact penalty stiffens with depth, k (1 + d / kContactStiffening): gentle where cloth
// rests on the body (depths well under a millimetre), and 6x stiffer 5 mm into the layer, where a
// garment pulled tight round the body would otherwise reach the skin.
constexpr double kContactStiffening = 1e-3;  // m
// Past the skin (depth d over the thickness t: the particle inside the body) the penalty is this
// many times stiffer again, k kDeepContact (d - t) on top. A waistband at its strain limit round a
// body a little too large for it pressed with ~2.6 kPa at its edge and went 2.3 mm into the skin
// (the jeans M on the average man, 0.57 % of its vertices); with it, none is inside. Cloth that
// stays outside the body never feels it (docs/cloth.md).
constexpr double kDeepContact = 100.0;
constexpr double kNoSkin = std::numeric_limits<double>::infinity();  // self-contact: no skin behind the layer
// Its energy, force and stiffness at depth d (0 outside the layer), with the skin t deep.
inline double contact_energy(double k, double d, double t) {
  if (d <= 0) return 0.0;
  const double past = std::max(d - t, 0.0);
  return k * (d * d * (0.5 + d / (6.0 * kContactStiffening)) + 0.5 * kDeepContact * past * past);
}
inline double contact_force(double k, double d, double t) {
  return d > 0 ? k * (d * (1.0 + 0.5 * d / kContactStiffening) + kDeepContact * std::max(d - t, 0.0)) : 0.0;
}
inline double contact_stiffness(double k, double d, double t) {
  return d > 0 ? k * (1.0 + d / kContactStiffening + (d > t ? kDeepContact : 0.0)) : 0.0;
}
// Friction's smoothing (IPC, ImplicitSettings::friction_slip): tangential slip below it is resisted
// like a stiff spring (static friction), above it by the full Coulomb force. The slip is measured
// from where friction holds the particle, which is carried from step to step
// (ClothState::friction_slip): a step's end that friction holds stays held at the next step's
// start. Measured from each step's start instead, every step began with the static friction of the
// last one let go, off balance by up to mu N (at rest on the body: 20x a particle's weight), and
// spent iterations finding it again.
// A contact plane is found anew once its particle moved this far from where it was found.
constexpr double kReplane = 1e-3;  // m
// A contact plane found anew whose normal is more than 90 degrees from the last one's is another
// wall of a crease; the last is kept beside it while the particle is within kCreaseReach past the
// thickness of it. From 60 degrees, the default trousers on the female body took 431 Newton
// iterations instead of 254 (planes of one wall's curve kept as a crease's).
constexpr double kCreaseCosine = 0.0;
constexpr double kTurnedCosine = 0.9994;  // a plane found anew turned by more than 2 degrees
constexpr double kMaxReplane = 8e-3;     // m
constexpr double kCreaseReach = 2e-3;  // m
// A block sweep moves a particle this little without checking that its energy fell.
constexpr double kSweepSettled = 1e-6;  // m
// Self-contact keeps this fraction of the fabric's contact thickness (1 mm of the default 4 mm)
// between a particle and the cloth's other triangles. Where cloth lies in two layers on the body,
// or is caught between an arm and the side, the layers' distance presses the inner one towards the
// skin: with the whole thickness the trousers M on the default male body pressed 0.83 % of its
// vertices into him (0.41 % without self-contact; the gate 0.5 %), with half of it the shirt on the
// CMU run 1.29 % at its last frame (the walk's gate 1 %); with a quarter, 0.41 % and 0.72 %.
constexpr double kSelfThickness = 0.25;
// Self-contact pairs are found anew once a particle moved this far from where they were found.
constexpr double kSelfRefind = 5e-3;  // m
// Newton also stops when an iteration moved no particle more than this (ImplicitSettings has the
// force tolerance).
constexpr double kStagnation = 1e-8;  // m
// Friction's normal forces are lagged (taken where the step starts); once a quasi-static step's
// Newton has converged with them, they are taken again where the contacts are now and Newton goes
// on, at most this many times a step. Without it a quasi-static step ends where static friction,
// bounded by the normal forces of the step's start, balances a contact that has since pressed
// harder or eased: the state of rest for the start's forces, not the end's, and the next step
// starts off balance again by the difference (the default shirt's last dozen steps ended 0.04-0.3
// of a particle's weight off). A dynamic step keeps the start's forces, as IPC's lagged friction
// does: taken again in a step of a walk, they move the minimum Newton is converging to while the
// body drags the cloth, and steps solved to their tolerance took 1.6x the Newton iterations
// (docs/animation.md).
constexpr int kMaxRelags = 4;
constexpr int kMaxHalvings = 12;
constexpr double kMaxDampingStep = 10.0;  // s: the weakest quasi-static damping, m / h_d^2
constexpr double kArmijo = 1e-4;
// CHOLMOD's relaxed supernodal amalgamation: the most columns of a merged supernode, always, with
// at most 80 % of its entries zero, and with at most 10 % (zrelax's defaults).
constexpr size_t kRelaxAlways = 32, kRelaxMostlyZeros = 96, kRelaxFewZeros = 192;

// CHOLMOD's supernodal factorisation and solves call the BLAS, and a BLAS built without locks
// (Debian's libopenblas0-serial) returns wrong numbers when two threads call it at once, as two
// dressings on their own threads do (`drape fit` dressing sizes side by side, the web service's
// workers). OpenBLAS's pthread and OpenMP builds (libopenblas0-pthread, which `make deps` installs
// and the system picks first) lock their buffers; told to use one thread (the dressings already
// share the cores), they take calls from several threads at once, and so does the reference BLAS,
// which keeps nothing between calls. Only a serial OpenBLAS is called under one lock for every
// solver in the process. Asked once, through the symbols OpenBLAS exports, whatever BLAS the
// system links in.
bool blas_takes_concurrent_calls() {
  static const bool concurrent = [] {
    const auto parallel = reinterpret_cast<int (*)()>(dlsym(RTLD_DEFAULT, "openblas_get_parallel"));
    if (!parallel) return true;
    if (parallel() == 0) return false;
    if (const auto set = reinterpret_cast<void (*)(int)>(dlsym(RTLD_DEFAULT, "openblas_set_num_threads"))) set(1);
    return true;
  }();
  return concurrent;
}
std::mutex& blas_lock() {
  static std::mutex lock;
  return lock;
}

// Debian's CHOLMOD is built with OpenMP regions of a fixed four threads (CHOLMOD_OMP_NUM_THREADS)
// inside the supernodal factorisation, one per large supernode: on two cores, their threads'
// wake-ups and sleeps cost more than the factorisation's arithmetic (the shirt's 4188 unknowns: 38
// ms a factorisation, a third of it in the kernel's futex calls). No setting of CHOLMOD's reaches
// them, so while any solver is in CHOLMOD no OpenMP region may be active (OpenMP's active levels
// are the process's, set to 0 by the first call in and restored by the last one out): the
// process's other loops run on one thread meanwhile, which changes none of their results.
// Every call into CHOLMOD holds one of these: the BLAS lock where the BLAS needs it, then OpenMP
// made serial.
class CholmodCall {
 public:
  CholmodCall() {
    if (!blas_takes_concurrent_calls()) hold_ = std::unique_lock(blas_lock());
    const std::lock_guard lock(levels_mutex_);
    if (inside_++ == 0) {
      saved_levels_ = omp_get_max_active_levels();
      omp_set_max_active_levels(0);
    }
  }
  ~CholmodCall() {
    const std::lock_guard lock(levels_mutex_);
    if (--inside_ == 0) omp_set_max_active_levels(saved_levels_);
  }
  CholmodCall(const CholmodCall&) = delete;
  CholmodCall& operator=(const CholmodCall&) = delete;

 private:
  static inline std::mutex levels_mutex_;
  static inline int inside_ = 0, saved_levels_ = 0;  // calls in CHOLMOD now; the levels before the first
  std::unique_lock<std::mutex> hold_;
};

// CHOLMOD's symbolic analysis (its ordering, supernodes and their rows), then the numeric
// factorisation and the triangular solves on both cores (sim::SupernodalFactorisation: the
// subtrees below the top separators side by side, the same result to the bit on any number of
// threads; the solves on the factor rounded to single precision). CHOLMOD factorises and solves
// where the analysis is not one that allows it (CHOLMOD's solve into storage kept from call to call:
// Eigen's solve() has CHOLMOD allocate the result and its workspace at every call).
class Cholesky : public Eigen::CholmodSupernodalLLT<SparseMatrix, Eigen::Lower> {
 public:
  Cholesky() = default;
  Cholesky(const Cholesky&) = delete;
  Cholesky& operator=(const Cholesky&) = delete;
  ~Cholesky() {
    cholmod_free_dense(&x_, &cholmod());
    cholmod_free_dense(&y_, &cholmod());
    cholmod_free_dense(&e_, &cholmod());
  }

  // After analyzePattern: the factor's values allocated, and the factorisation on both cores
  // prepared where the analysis allows.
  void prepare_factorisation(const SparseMatrix& a) {
    parallel_.clear();
    cholmod_factor* f = m_cholmodFactor;
    if (!f || !f->is_super) return;
    if (!cholmod_change_factor(CHOLMOD_REAL, true, true, true, true, f, &cholmod()) || f->xtype != CHOLMOD_REAL ||
        !f->x || !f->is_ll)
      return;
    parallel_.analyse(*f, a.outerIndexPtr(), a.innerIndexPtr());
  }
  // factorize(a), on up to `threads` threads.
  void factorise(const SparseMatrix& a, int threads) {
    if (!parallel_.ready()) {
      const CholmodCall call;
      factorize(a);
      return;
    }
    std::unique_lock<std::mutex> hold;
    if (!blas_takes_concurrent_calls()) {
      hold = std::unique_lock(blas_lock());
      threads = 1;
    }
    m_info = parallel_.factorise(*m_cholmodFactor, a.valuePtr(), threads) ? Eigen::Success : Eigen::NumericalIssue;
    m_factorizationIsOk = true;
  }
  // out = A^-1 rhs with the last factorisation (out sized like rhs), on up to `threads` threads.
  void solve_into(const Eigen::VectorXd& rhs, Eigen::VectorXd& out, int threads) {
    if (parallel_.ready()) {
      parallel_.solve(rhs.data(), out.data(), threads);
      return;
    }
    const CholmodCall call;
    cholmod_dense b = Eigen::viewAsCholmod(const_cast<Eigen::VectorXd&>(rhs));  // read only
    if (!cholmod_solve2(CHOLMOD_A, m_cholmodFactor, &b, nullptr, &x_, nullptr, &y_, &e_, &cholmod()))
      throw std::runtime_error("implicit solver: CHOLMOD could not solve with its factorisation");
    out = Eigen::Map<const Eigen::VectorXd>(static_cast<const double*>(x_->x), rhs.size());
  }

 private:
  cholmod_dense *x_ = nullptr, *y_ = nullptr, *e_ = nullptr;  // CHOLMOD's result and workspace
  sim::SupernodalFactorisation parallel_;
};

double now() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

// Adds `seconds since the last mark` to a profile field.
class Timer {
 public:
  explicit Timer(bool on) : on_(on), last_(on ? now() : 0) {}
  void mark(double& into) {
    if (!on_) return;
    const double t = now();
    into += t - last_;
    last_ = t;
  }

 private:
  bool on_;
  double last_;
};

// The spring of (a, b): energy, force on b (a gets its negative) and its Hessian block.
struct SpringTerm {
  double energy = 0;
  Vec3d gradient_b = Vec3d::Zero();  // dE/dx_b; dE/dx_a = -dE/dx_b
  Mat3d hessian = Mat3d::Zero();     // d2E/dx_b2 = d2E/dx_a2 = -d2E/dx_a dx_b
};

// k/2 (l - rest)^2. Its Hessian block is k (u u^T + (1 - rest/l)(I - u u^T)): `exact`, or with the
// transverse term of a compressed spring (negative) dropped, positive semi-definite.
inline void add_spring(SpringTerm& t, const Vec3d& d, double l, double rest, double k, bool exact) {
  if (k <= 0) return;
  if (l < 1e-12) {
    t.hessian.diagonal().array() += k;
    t.energy += 0.5 * k * rest * rest;
    return;
  }
  const Vec3d u = d / l;
  t.energy += 0.5 * k * (l - rest) * (l - rest);
  t.gradient_b += k * (l - rest) * u;
  const double transverse = exact ? 1.0 - rest / l : std::max(0.0, 1.0 - rest / l);
  t.hessian += k * (transverse * Mat3d::Identity() + (1.0 - transverse) * u * u.transpose());
}

// Zero-length seam: k/2 l^2 up to the length where it pulls with `cap`, then a constant pull of
// `cap` (its Hessian: the zero-length spring that pulls with `cap` at this length).
inline bool seam_capped(double l, double k, double cap) { return cap > 0 && k * l > cap; }
inline double seam_energy(double l, double k, double cap) {
  return seam_capped(l, k, cap) ? cap * (l - 0.5 * (cap / k)) : 0.5 * k * l * l;
}
inline void add_seam(SpringTerm& t, const Vec3d& d, double l, double k, double cap) {
  t.energy += seam_energy(l, k, cap);
  if (seam_capped(l, k, cap)) {
    t.gradient_b += (cap / l) * d;
    t.hessian.diagonal().array() += cap / l;
    return;
  }
  t.gradient_b += k * d;
  t.hessian.diagonal().array() += k;
}

// A symmetric 3x3 block by its six entries (a block sweep's per particle).
struct SymmetricBlock {
  double xx = 0, xy = 0, xz = 0, yy = 0, yz = 0, zz = 0;
  void add_diagonal(double c) {
    xx += c;
    yy += c;
    zz += c;
  }
  void add_outer(double c, const Vec3d& v) {  // c v v^T
    const double cx = c * v.x(), cy = c * v.y();
    xx += cx * v.x();
    xy += cx * v.y();
    xz += cx * v.z();
    yy += cy * v.y();
    yz += cy * v.z();
    zz += c * v.z() * v.z();
  }
  // The block's inverse times r by its adjugate (positive definite: the determinant is positive).
  Vec3d solve(const Vec3d& r) const {
    const double a00 = yy * zz - yz * yz, a01 = xz * yz - xy * zz, a02 = xy * yz - xz * yy;
    const double a11 = xx * zz - xz * xz, a12 = xy * xz - xx * yz, a22 = xx * yy - xy * xy;
    const double det = xx * a00 + xy * a01 + xz * a02;
    return Vec3d(a00 * r.x() + a01 * r.y() + a02 * r.z(), a01 * r.x() + a11 * r.y() + a12 * r.z(),
                 a02 * r.x() + a12 * r.y() + a22 * r.z()) /
           det;
  }
};

}  // namespace

std::string_view to_string(Solver solver) { return solver == Solver::Explicit ? "explicit" : "implicit"; }

void sweep_dynamic_steps(ImplicitSettings& s) {
  s.force_tolerance = 1.0;
  s.max_newton_iterations = 6;
  s.block_sweeps = 4;
  s.factorisation_interval = 4;
  s.direction_tolerance = 0.5;
  s.direction_iterations = 3;
}

ImplicitSettings default_implicit_settings(const ClothModel& model) {
  ImplicitSettings s;
  s.friction = model.fabric.friction;
  s.strain_threshold = model.fabric.strain_threshold;
  return s;
}

struct ImplicitSolver::Impl {
  const ClothModel& model;
  size_t n = 0;
  std::vector<uint8_t> free;          // per particle: 1 unless pinned
  std::vector<double> contact_k;      // per particle: contact penalty stiffness (N/m)

  // Sparse pattern: block offsets into the matrix's values. Block b's column k (0..2) starts at
  // values[block_offset[3 b + k]] (its three rows follow). Blocks 0..n-1 are the diagonal.
  SparseMatrix matrix;
  std::vector<int> block_offset;
  // Off-diagonal blocks and the springs that share each (CSR, in spring order), and each block's
  // two particles.
  std::vector<uint32_t> offdiag_begin, offdiag_spring, offdiag_block, offdiag_block_t;
  std::vector<std::array<uint32_t, 2>> offdiag_pair;
  // Bending stencils (ClothModel::bend_stencil): their Hessian is constant, summed once per particle
  // (bend_diag) and per off-diagonal block (bend_offdiag); flexion springs a stencil stands in for
  // are left out (spring_skipped).
  std::vector<double> bend_diag, bend_offdiag;
  std::vector<uint8_t> spring_skipped;
  // The stencils' end pairs that no spring or contact joins (two apart along the cloth's grid) are
  // left out of the factorised matrix: their blocks double the fill of its factor (the shirt's 71
  // million flops a factorisation against 36 without them). Each such pair's term b I (b = k w_a w_c,
  // summed over the stencils that share it) is replaced there by |b| I on both particles' diagonal
  // blocks, which keeps the factorised matrix P at least as stiff as the Hessian A in every
  // direction (P - A = |b| (e_a - sign(b) e_c)(e_a - sign(b) e_c)^T per pair, positive
  // semi-definite). Newton directions are then conjugate gradients on A preconditioned by P: where
  // the bending is soft beside inertia and stretch (garments), they converge in a few iterations
  // (the 20k-vertex shirt: 260 ms a factorisation against 434 ms, docs/cloth.md). Where bending
  // holds the cloth (a strip of millimetre cells), P is a poor stand-in for A (a second-order
  // operator for a fourth-order one) and they do not: once the conjugate gradients after a fresh
  // factorisation have missed kFreshMisses times and in more than a quarter of the attempts, the
  // pattern takes the stencils' ends in again (whole_stencils) for the rest of the solver's life.
  // Below kReducedFrom particles it takes them in from the start: there a factorisation costs more
  // in CHOLMOD's overheads than in arithmetic (the default shirt's 1396 particles: half the flops,
  // 18 % less time), and the conjugate gradients' solves and other Newton paths took more than that
  // (the four default garments 12.7 s of simulation against 10.8 s, the trousers 433 Newton
  // iterations against 306).
  static constexpr uint32_t kFreshMisses = 3;
  static constexpr size_t kReducedFrom = 4000;
  static constexpr size_t kNestedDissectionFrom = 8000;
  bool whole_stencils = false;
  uint32_t fresh_attempts = 0, fresh_misses = 0;
  std::vector<std::array<uint32_t, 2>> far_pair;
  std::vector<double> far_coefficient;  // b per far pair
  std::vector<double> far_diag;         // per particle: sum of |b| over its far pairs
  // out = A v: the factorised matrix's product less P - A over the far pairs.
  void hessian_product(const Eigen::VectorXd& v, Eigen::VectorXd& out) const {
    out.noalias() = matrix * v;
    for (size_t q = 0; q < far_pair.size(); ++q) {
      const auto [a, c] = far_pair[q];
      const double b = far_coefficient[q], m = std::abs(b);
      const auto ia = static_cast<Eigen::Index>(3 * a), ic = static_cast<Eigen::Index>(3 * c);
      out.segment<3>(ia) += b * v.segment<3>(ic) - m * v.segment<3>(ia);
      out.segment<3>(ic) += b * v.segment<3>(ia) - m * v.segment<3>(ic);
    }
    // Self-contact pairs whose blocks the pattern lacks: the matrix holds 4 diag(a^2) (x) K n n^T
    // for each (add_self_hessian); A holds a a^T (x) K n n^T.
    for (const LoosePair& lp : loose_pairs) {
      const sim::SelfPair& pr = self_pairs[lp.pair];
      const Tri& tri = model.triangles[pr.triangle];
      const std::array<uint32_t, 4> node{pr.particle, tri[0], tri[1], tri[2]};
      const std::array<double, 4> a{1.0, -pr.weight[0], -pr.weight[1], -pr.weight[2]};
      double along = 0;
      for (size_t j = 0; j < 4; ++j)
        if (free[node[j]]) along += a[j] * pr.normal.dot(v.segment<3>(static_cast<Eigen::Index>(3 * node[j])));
      for (size_t j = 0; j < 4; ++j) {
        if (!free[node[j]]) continue;
        const auto i = static_cast<Eigen::Index>(3 * node[j]);
        const double own = pr.normal.dot(v.segment<3>(i));
        out.segment<3>(i) += (lp.k * a[j] * (along - 4.0 * a[j] * own)) * pr.normal;
      }
    }
  }
  std::vector<Vec3d> bend_gradient;  // per particle, at the iterate
  // sum k/2 |d|^2 over the stencils at `at`, and (with `gradient`) each particle's gradient.
  double bend_terms(const std::vector<Vec3d>& at, bool gradient);
  Cholesky cholesky;

  // Per step and iteration (allocated once).
  std::vector<Vec3d> x, x0, y, trial;     // positions now, at the step start, inertial target, trial
  std::vector<Vec3d> detected_at;         // positions where the contacts were found
  // How far each particle in contact moves before its plane is found anew: kReplane, doubled (up
  // to kMaxReplane) each time a plane found anew turned (kTurnedCosine). Found anew at every
  // millimetre, a particle's plane could go round in a cycle with Newton's iterations, each plane
  // sending it back to where the last was found, for ever: the skirt M at an 8 mm contact
  // thickness (between two walls of the body) and the trousers L on the default female body
  // repeated the same 4-5 iterations until their steps ran out.
  std::vector<double> replane_reach;
  std::vector<Vec3f> xf;                  // float positions for the colliders
  std::vector<ContactSample> sample, sample_tmp;
  std::vector<Vec3d> plane_normal;        // per particle: contact plane d(x) = n.x + c
  std::vector<double> plane_offset;
  std::vector<uint8_t> in_range;          // a surface within the query radius
  // A second plane where the nearest surface moved to another wall of a crease (the crotch between
  // the thighs): the wall it left, kept while the particle is within its reach, so that the particle
  // rests against both (one plane at a time, Newton's iterates went from one wall to the other).
  std::vector<Vec3d> crease_normal;
  std::vector<double> crease_offset;
  std::vector<uint8_t> in_crease;
  std::vector<double> friction_force;     // per particle: lagged normal force x mu (N)
  std::vector<Vec3d> surface_velocity;  // per particle: its surface's displacement over the step
  double planes_h = 0;                  // the step surface_velocity was found for (s)
  std::vector<Vec3d> held_slip;           // per particle: the slip friction held at the step's start
  std::vector<SpringTerm> spring_term;
  Eigen::VectorXd gradient, direction;
  std::vector<double> block_sum;
  double force_ratio = 0;  // after assemble(): the largest |gradient_i| / (m_i g)
  size_t max_colliders = 0;
  bool analysed = false;  // the pattern, ordering and symbolic factorisation: at the first step
  bool factored = false;
  bool planes_valid = false;  // contact planes found at least once  // the factorisation holds a matrix of this step
  Eigen::VectorXd residual_vec, search, product, preconditioned;  // conjugate gradients
  // Conjugate gradients from zero into `direction`: they reach the tolerance, run out of
  // iterations, or meet a direction of non-positive curvature (the iterate before it is kept).
  enum class Solve : uint8_t { Reached, Missed, Indefinite };
  Solve preconditioned_solve(double tolerance, int iterations);
  uint64_t triangular_solves = 0;  // since construction
  uint64_t analyses = 0;           // of the pattern, since construction
  // out = A^-1 rhs with the current factorisation (Cholesky::solve_into).
  void solve(const Eigen::VectorXd& rhs, Eigen::VectorXd& out) {
    cholesky.solve_into(rhs, out, omp_get_max_threads());
    ++triangular_solves;
  }

  Impl(const ClothModel& m, size_t colliders);
  void analyse_pattern();
  // Contact planes refreshed where needed (see detect_contacts), and friction's normal forces.
  void detect_contacts(std::span<Collider* const> colliders, const ImplicitSettings& s, double h, bool refresh_all);
  void lag_friction(const ImplicitSettings& s, bool at_step_start = false);
  // The largest |mu N - lagged mu N| / (m g) over the particles, N the normal force at x.
  double friction_lag_error(const ImplicitSettings& s) const;
  bool exact = false;  // this iteration's springs: exact Hessian blocks (else projected)
  // Where the contact penalty stiffens kDeepContact-fold: the skin, or nowhere
  // (ImplicitSettings::stiff_past_skin).
  double skin = kNoSkin;
  void set_skin(const ImplicitSettings& s) {
    skin = s.stiff_past_skin ? static_cast<double>(model.fabric.collision_thickness) : kNoSkin;
  }
  // How far `p` is inside particle i's contact layer (thickness - distance to its plane).
  double depth(size_t i, const Vec3d& p) const {
    return model.fabric.collision_thickness - (plane_normal[i].dot(p) + plane_offset[i]);
  }
  double crease_depth(size_t i, const Vec3d& p) const {
    return model.fabric.collision_thickness - (crease_normal[i].dot(p) + crease_offset[i]);
  }
  // Friction's force on particle i is -friction_scale(i, |u|) u for its slip u: a stiff spring
  // below friction_slip (static friction), the full Coulomb force above it.
  double friction_slip = 1e-4;  // m, the step's ImplicitSettings::friction_slip
  double friction_scale(size_t i, double slip) const {
    return slip < friction_slip ? friction_force[i] / friction_slip : friction_force[i] / slip;
  }
  // Its energy: friction_scale's force integrated along the slip.
  double friction_energy(size_t i, double slip) const {
    return friction_force[i] * (slip < friction_slip ? 0.5 * slip * slip / friction_slip : slip - 0.5 * friction_slip);
  }
  // Particle i's tangential slip at `p` from where friction holds it.
  Vec3d tangential_slip(size_t i, const Vec3d& p) const {
    Vec3d u = p - x0[i] - surface_velocity[i] + held_slip[i];
    u -= plane_normal[i].dot(u) * plane_normal[i];
    return u;
  }
  std::vector<uint32_t> refresh;  // particles whose contacts are being refreshed

  // Self-contact (ImplicitSettings::self_collision): the pairs found at self_found_at, kept while
  // no particle moved kSelfRefind from there, their gradient per
  // particle at the iterate.
  std::unique_ptr<sim::SelfContactFinder> self_finder;
  std::vector<sim::SelfPair> self_pairs;
  std::vector<Vec3d> self_found_at, self_gradient;
  // Particles where the cloth passes through itself at the step's start (an edge through a
  // triangle: its ends and the triangle's corners): they take part in no pair (see
  // find_self_contacts).
  std::vector<uint8_t> tangled;
  static constexpr uint32_t kNoBlock = UINT32_MAX;
  // Particle pairs self-contacts coupled (sorted; those a spring or stencil joins too are one block):
  // the pattern holds their blocks (add_self_blocks()).
  std::vector<std::array<uint32_t, 2>> contact_blocks;
  std::vector<std::array<uint32_t, 2>> needed_blocks;  // scratch
  // Where the pattern leaves out the stencils' far ends (Newton's directions are conjugate
  // gradients on A preconditioned by the factorised P), a self-contact pair whose blocks the
  // pattern lacks is not analysed into it: P holds its majorant on the diagonal blocks and the
  // gradients' products the pair itself (hessian_product). A new analysis, each time self-contact
  // met blocks the pattern lacked, was one thread's work (the 20k-vertex shirt analysed 28 times,
  // 4.4 s in all), and the blocks it added made the factor larger (docs/cloth.md).
  struct LoosePair {
    uint32_t pair = 0;  // into self_pairs
    double k = 0;       // the penalty's stiffness at the pair's depth
  };
  std::vector<LoosePair> loose_pairs;  // assembled with the matrix
  bool reduced() const { return !far_pair.empty(); }
  static constexpr size_t kKeptContactBlocks = 256;
  // The off-diagonal block of (a, b), or kNoBlock.
  uint32_t block_of(uint32_t a, uint32_t b) const {
    const std::array<uint32_t, 2> pair{std::min(a, b), std::max(a, b)};
    const auto found = std::lower_bound(offdiag_pair.begin(), offdiag_pair.end(), pair);
    return found != offdiag_pair.end() && *found == pair ? static_cast<uint32_t>(found - offdiag_pair.begin()) : kNoBlock;
  }
  // Adds the blocks that the pairs near contact (within twice the thickness) need to the pattern
  // where it lacks one; true when the pattern changed (analysed again: the factorisation is gone).
  bool add_self_blocks();
  bool self_valid = false;  // self_pairs were found in this step
  void find_self_contacts(const ImplicitSettings& s);
  // sum of the self-contact energies at `at`; with `gradient`, each particle's into self_gradient.
  double self_terms(const std::vector<Vec3d>& at, bool gradient);
  // Their Hessian, majorised (below), added to the matrix.
  void add_self_hessian(double* values);
  // The distance self-contact keeps between a particle and a triangle of the same cloth.
  double self_thickness() const { return kSelfThickness * static_cast<double>(model.fabric.collision_thickness); }
  // How far a pair's particle is inside the thickness from its triangle at `at`.
  double self_depth(const sim::SelfPair& pr, const std::vector<Vec3d>& at) const {
    const Tri& tri = model.triangles[pr.triangle];
    const Vec3d c = pr.weight[0] * at[tri[0]] + pr.weight[1] * at[tri[1]] + pr.weight[2] * at[tri[2]];
    return self_thickness() - pr.normal.dot(at[pr.particle] - c);
  }
  double energy(const std::vector<Vec3d>& at, const ImplicitSettings& s, double h);
  void spring_terms(const std::vector<Vec3d>& at, const ImplicitSettings& s);  // into spring_term
  void assemble(const ImplicitSettings& s, double h);
  float residual(const ImplicitSettings& s);

  // Block sweeps (ImplicitSettings::block_sweeps): the particles in colours that share no spring or
  // stencil (CSR, index order within each), each particle's colour, and the stencils each particle
  // is in (3 q + its slot j).
  std::vector<uint32_t> colour_begin, colour_particle, particle_colour;
  std::vector<uint32_t> stencil_begin, stencil_slot;
  void colour_particles();
  // The self-contact pairs each particle is in (CSR: 4 pair + its role, 0 the particle, 1-3 the
  // triangle's corners), and the particles that share a pair with one of their own colour: those
  // move one after another, after the rest of their colour (deferred).
  std::vector<uint32_t> self_begin, self_entry;
  std::vector<uint8_t> deferred;
  void index_self_pairs();
  // Cloths of fewer particles sweep on one thread: a sweep has a barrier per colour, and where the
  // two cores are shared (two processes, or tests side by side) a barrier can wait a scheduler time
  // slice. Parallel from 512 particles, the walking shirt's frames per wall second were 1.16x on an
  // idle machine, but the run's test (the shirt at 4 cm cells, 700 particles) took 6.5x as long
  // beside another. From 2048: the walking dress of 4,198 particles sweeps in 3.1 s against 5.6 s
  // on one thread (2.91 frames per wall second against 2.60, the same bits).
  static constexpr size_t kParallelSweeps = 2048;
  // Particle i's move: the Newton step of its own block of E with every other particle held.
  Vec3d block_step(size_t i, const ImplicitSettings& s, double inv_h2) const;
  // The terms of E that involve particle i, with i at p and every other particle at x: their energy,
  // and with `grad`, their gradient and (positive semi-definite) Hessian.
  double block_terms(size_t i, const Vec3d& p, const ImplicitSettings& s, double inv_h2, Vec3d* grad,
                     SymmetricBlock* block) const;
  // `sweeps` sweeps of block descent from x (contacts as found for x at the first).
  void block_descent(std::span<Collider* const> colliders, const ImplicitSettings& s, double h, int sweeps);
};

ImplicitSolver::Impl::Impl(const ClothModel& m, size_t colliders) : model(m), n(m.particle_count()) {
  free.resize(n);
  contact_k.resize(n);
  const double density = std::max(1e-6, static_cast<double>(m.fabric.areal_density));
  for (size_t i = 0; i < n; ++i) {
    free[i] = m.inverse_mass[i] > 0 ? 1 : 0;
    const double area = m.drag_area.size() == n && m.drag_area[i] > 0 ? m.drag_area[i] : m.mass[i] / density;
    contact_k[i] = kContactStiffnessPerArea * area;
  }
  x.resize(n);
  x0.resize(n);
  y.resize(n);
  trial.resize(n);
  detected_at.resize(n);
  replane_reach.assign(n, kReplane);
  refresh.resize(n);
  xf.resize(n);
  sample.resize(n);
  sample_tmp.resize(colliders > 1 ? n : 0);  // indexed by position in `refresh`, like sample
  plane_normal.assign(n, Vec3d::UnitY());
  plane_offset.assign(n, 0.0);
  in_range.assign(n, 0);
  crease_normal.assign(n, Vec3d::UnitY());
  crease_offset.assign(n, 0.0);
  in_crease.assign(n, 0);
  friction_force.assign(n, 0.0);
  surface_velocity.assign(n, Vec3d::Zero());
  held_slip.assign(n, Vec3d::Zero());
  spring_term.resize(m.spring_count());
  bend_diag.assign(n, 0.0);
  bend_gradient.assign(n, Vec3d::Zero());
  spring_skipped.assign(m.spring_count(), 0);
  if (!m.bend_stencil.empty()) {
    // The flexion springs between the ends of a stencil.
    std::vector<std::array<uint32_t, 2>> ends;
    for (const auto& st : m.bend_stencil) ends.push_back({std::min(st[0], st[2]), std::max(st[0], st[2])});
    std::sort(ends.begin(), ends.end());
    const SpringRange flex = m.range(SpringKind::Flexion);
    for (uint32_t k = flex.begin; k < flex.end; ++k) {
      const std::array<uint32_t, 2> e{std::min(m.spring_a[k], m.spring_b[k]), std::max(m.spring_a[k], m.spring_b[k])};
      spring_skipped[k] = std::binary_search(ends.begin(), ends.end(), e) ? 1 : 0;
    }
    for (size_t q = 0; q < m.bend_stencil.size(); ++q)
      for (int j = 0; j < 3; ++j) {
        const double w = m.bend_weight[q][static_cast<size_t>(j)];
        bend_diag[m.bend_stencil[q][static_cast<size_t>(j)]] += static_cast<double>(m.bend_stiffness[q]) * w * w;
      }
  }
  for (Eigen::VectorXd* v : {&gradient, &direction, &residual_vec, &search, &product, &preconditioned})
    v->setZero(static_cast<Eigen::Index>(3 * n));
  block_sum.assign(std::max(sim::block_count(n), sim::block_count(m.spring_count())), 0.0);
  max_colliders = colliders;
  whole_stencils = n < kReducedFrom;
}

void ImplicitSolver::Impl::analyse_pattern() {
  ++analyses;
  const size_t springs = model.spring_count();
  // Off-diagonal blocks: one per distinct (a, b) pair with a < b, in first-spring order.
  // Neighbours in a bending stencil that no spring joins get a block too (kNoSpring).
  constexpr uint32_t kNoSpring = UINT32_MAX;
  // Flexion springs a stencil stands in for have no terms and no block; a stencil's ends get one
  // only where something else joins them (see far_pair), or once whole_stencils.
  std::vector<std::array<uint32_t, 3>> keyed;  // min, max, spring
  keyed.reserve(springs + 3 * model.bend_stencil.size() + contact_blocks.size());
  for (size_t s = 0; s < springs; ++s) {
    if (spring_skipped[s]) continue;
    const uint32_t a = model.spring_a[s], b = model.spring_b[s];
    keyed.push_back({std::min(a, b), std::max(a, b), static_cast<uint32_t>(s)});
  }
  for (const auto& st : model.bend_stencil)
    for (const auto& [j, l] : {std::pair{0, 1}, std::pair{1, 2}, std::pair{0, 2}})
      if (whole_stencils || l - j == 1)
        keyed.push_back({std::min(st[static_cast<size_t>(j)], st[static_cast<size_t>(l)]),
                       std::max(st[static_cast<size_t>(j)], st[static_cast<size_t>(l)]), kNoSpring});
  for (const auto& [a, b] : contact_blocks) keyed.push_back({a, b, kNoSpring});
  std::sort(keyed.begin(), keyed.end());
  std::vector<std::array<uint32_t, 2>> blocks;  // (row particle, column particle): diagonal first
  blocks.reserve(n + 2 * springs);
  for (size_t i = 0; i < n; ++i) blocks.push_back({static_cast<uint32_t>(i), static_cast<uint32_t>(i)});
  offdiag_begin.clear();
  offdiag_spring.clear();
  offdiag_block.clear();
  offdiag_block_t.clear();
  offdiag_pair.clear();
  for (size_t k = 0; k < keyed.size(); ++k) {
    const auto [lo, hi, s] = keyed[k];
    if (lo == hi) continue;  // a spring from a particle to itself has no force
    if (k == 0 || keyed[k - 1][0] != lo || keyed[k - 1][1] != hi) {
      offdiag_begin.push_back(static_cast<uint32_t>(offdiag_spring.size()));
      offdiag_block.push_back(static_cast<uint32_t>(blocks.size()));
      blocks.push_back({lo, hi});
      offdiag_block_t.push_back(static_cast<uint32_t>(blocks.size()));
      blocks.push_back({hi, lo});
      offdiag_pair.push_back({lo, hi});
    }
    if (s != kNoSpring) offdiag_spring.push_back(s);
  }
  offdiag_begin.push_back(static_cast<uint32_t>(offdiag_spring.size()));
  // The stencils' constant off-diagonal terms, per block, or per far pair where there is none.
  bend_offdiag.assign(offdiag_pair.size(), 0.0);
  std::vector<std::pair<std::array<uint32_t, 2>, double>> far;
  for (size_t q = 0; q < model.bend_stencil.size(); ++q)
    for (const auto& [j, l] : {std::pair{0, 1}, std::pair{1, 2}, std::pair{0, 2}}) {
      const uint32_t a = model.bend_stencil[q][static_cast<size_t>(j)], b = model.bend_stencil[q][static_cast<size_t>(l)];
      const double term = static_cast<double>(model.bend_stiffness[q]) * model.bend_weight[q][static_cast<size_t>(j)] *
                          model.bend_weight[q][static_cast<size_t>(l)];
      if (a == b) continue;
      const uint32_t block = block_of(a, b);
      if (block != kNoBlock) bend_offdiag[block] += term;
      else if (free[a] && free[b]) far.push_back({{std::min(a, b), std::max(a, b)}, term});
    }
  // Summed per pair, in pair order.
  std::sort(far.begin(), far.end(), [](const auto& u, const auto& v) { return u.first < v.first; });
  far_pair.clear();
  far_coefficient.clear();
  far_diag.assign(n, 0.0);
  for (size_t k = 0; k < far.size(); ++k) {
    if (k == 0 || far[k].first != far[k - 1].first) {
      far_pair.push_back(far[k].first);
      far_coefficient.push_back(0.0);
    }
    far_coefficient.back() += far[k].second;
  }
  for (size_t q = 0; q < far_pair.size(); ++q)
    for (const uint32_t i : far_pair[q]) far_diag[i] += std::abs(far_coefficient[q]);

  std::vector<Eigen::Triplet<double, int>> triplets;
  triplets.reserve(9 * blocks.size());
  for (const auto& [r, c] : blocks)
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) triplets.emplace_back(static_cast<int>(3 * r) + i, static_cast<int>(3 * c) + j, 1.0);
  matrix.resize(static_cast<int>(3 * n), static_cast<int>(3 * n));
  matrix.setFromTriplets(triplets.begin(), triplets.end());
  matrix.makeCompressed();
  block_offset.assign(3 * blocks.size(), 0);
  const int* outer = matrix.outerIndexPtr();
  const int* inner = matrix.innerIndexPtr();
  for (size_t b = 0; b < blocks.size(); ++b) {
    const auto [r, c] = blocks[b];
    for (int k = 0; k < 3; ++k) {
      const int col = static_cast<int>(3 * c) + k;
      const int* found = std::lower_bound(inner + outer[col], inner + outer[col + 1], static_cast<int>(3 * r));
      block_offset[3 * b + static_cast<size_t>(k)] = static_cast<int>(found - inner);
    }
  }
  {
    const CholmodCall call;
    // A factorisation that finds the matrix indefinite is expected (the exact Hessian where the
    // cloth buckles; the step falls back to the projected one): CHOLMOD is not to print it.
    cholesky.cholmod().print = 0;
    // Supernodes merged more freely than CHOLMOD's defaults (nrelax 4, 16, 48 columns): a cloth's
    // 3x3 blocks leave many supernodes of a few columns, each its own BLAS calls, and merged into
    // larger ones (always up to 32 columns; up to 96 with at most 80 % explicit zeros, 192 with 10 %)
    // they factorise in 25-30 % less time for a little more fill (docs/cloth.md).
    cholmod_common& c = cholesky.cholmod();
    c.nrelax[0] = kRelaxAlways;
    c.nrelax[1] = kRelaxMostlyZeros;
    c.nrelax[2] = kRelaxFewZeros;
    // Large reduced patterns are ordered by CHOLMOD's nested dissection (METIS's separators, its
    // own refinement) rather than its default choice of AMD or METIS, whose factor of the 20k-vertex
    // shirt took 3.36 billion flops against 1.70 (docs/cloth.md). It costs more to analyse, which
    // a reduced pattern does once. Below kNestedDissectionFrom its factorisations were 4-26 % faster
    // but the four garments tried (4.1k-5.1k particles) took 3-38 % more Newton iterations.
    if (reduced() && n >= kNestedDissectionFrom) {
      c.nmethods = 1;
      c.method[0].ordering = CHOLMOD_NESDIS;
    } else {
      c.nmethods = 0;  // CHOLMOD's default strategy
    }
    cholesky.analyzePattern(matrix);
    cholesky.prepare_factorisation(matrix);
  }
}

void ImplicitSolver::Impl::detect_contacts(std::span<Collider* const> colliders, const ImplicitSettings& s, double h,
                                           bool refresh_all) {
  const float thickness = model.fabric.collision_thickness;
  const float radius = thickness + 2.0f * s.max_move;
  // The particles to ask about, in index order.
  size_t count = 0;
  for (size_t i = 0; i < n; ++i) {
    if (!free[i]) continue;
    const double reach = in_range[i] ? replane_reach[i] : static_cast<double>(s.max_move);
    if (refresh_all || (x[i] - detected_at[i]).squaredNorm() > reach * reach) {
      refresh[count] = static_cast<uint32_t>(i);
      xf[count] = x[i].cast<float>();
      detected_at[i] = x[i];
      ++count;
    }
  }
  sim::parallel_blocks(count, [&](size_t, size_t begin, size_t end) {
    const size_t chunk = end - begin;
    const std::span<const Vec3f> points(xf.data() + begin, chunk);
    const std::span<ContactSample> nearest(sample.data() + begin, chunk);
    if (colliders.empty()) {
      for (ContactSample& c : nearest) c.distance = std::numeric_limits<float>::infinity();
    } else {
      colliders[0]->query(points, radius, nearest);
      for (size_t k = 1; k < colliders.size(); ++k) {
        const std::span<ContactSample> other(sample_tmp.data() + begin, chunk);
        colliders[k]->query(points, radius, other);
        for (size_t q = 0; q < chunk; ++q)
          if (other[q].distance < nearest[q].distance) nearest[q] = other[q];
      }
    }
    for (size_t q = begin; q < end; ++q) {
      const size_t i = refresh[q];
      const ContactSample& c = sample[q];
      const bool was = in_range[i] != 0;
      in_range[i] = c.distance < radius ? 1 : 0;
      if (!in_range[i]) {
        in_crease[i] = 0;
        continue;
      }
      const Vec3d normal = c.normal.cast<double>().normalized();
      // Planes found anew for all (a step's start with colliders that move) start without one.
      if (refresh_all) {
        in_crease[i] = 0;
      } else if (was && normal.dot(plane_normal[i]) < kCreaseCosine && depth(i, x[i]) > -kCreaseReach) {
        crease_normal[i] = plane_normal[i];
        crease_offset[i] = plane_offset[i];
        in_crease[i] = 1;
      } else if (in_crease[i] && crease_depth(i, x[i]) <= -kCreaseReach) {
        in_crease[i] = 0;
      }
      if (refresh_all) replane_reach[i] = kReplane;
      else if (was && normal.dot(plane_normal[i]) < kTurnedCosine) replane_reach[i] = std::min(kMaxReplane, 2.0 * replane_reach[i]);
      plane_normal[i] = normal;
      plane_offset[i] = static_cast<double>(c.distance) - plane_normal[i].dot(x[i]);
      surface_velocity[i] = c.velocity.cast<double>() * h;  // the surface's displacement over the step
    }
  });
  planes_h = h;
}

void ImplicitSolver::Impl::lag_friction(const ImplicitSettings& s, bool at_step_start) {
  const double mu = std::max(0.0f, s.friction);
  for (size_t i = 0; i < n; ++i) {
    // At a step's start the planes are the colliders' at the step's end: a surface that moves
    // towards the cloth is found up to its whole displacement over the step deeper than it was.
    // The normal force friction is bounded by is the one at the start, where the surface was: from
    // the depth there, the displacement along the normal taken off (a walking body's 1.5 cm a step
    // would otherwise give friction a thousand times the particle's weight, and hold the cloth to
    // where the body dragged it).
    double d = depth(i, at_step_start ? x0[i] : x[i]);
    if (at_step_start) d -= plane_normal[i].dot(surface_velocity[i]);
    friction_force[i] = in_range[i] ? mu * contact_force(contact_k[i], d, skin) : 0.0;
  }
}

double ImplicitSolver::Impl::friction_lag_error(const ImplicitSettings& s) const {
  const double mu = std::max(0.0f, s.friction);
  const double gscale = s.gravity.norm() > 0 ? static_cast<double>(s.gravity.norm()) : 9.81;
  double worst = 0;
  for (size_t i = 0; i < n; ++i) {
    if (!free[i]) continue;
    const double now = in_range[i] ? mu * contact_force(contact_k[i], depth(i, x[i]), skin) : 0.0;
    worst = std::max(worst, std::abs(now - friction_force[i]) / (static_cast<double>(model.mass[i]) * gscale));
  }
  return worst;
}

double ImplicitSolver::Impl::energy(const std::vector<Vec3d>& at, const ImplicitSettings& s, double h) {
  const ClothModel& m = model;
  const double inv_h2 = 1.0 / (h * h);
  const Vec3d g = s.gravity.cast<double>();
  // Particles: inertia, gravity, contact, friction.
  double total = 0;
  const size_t pblocks = sim::block_count(n);
  sim::parallel_blocks(n, [&](size_t b, size_t begin, size_t end) {
    double e = 0;
    for (size_t i = begin; i < end; ++i) {
      if (!free[i]) continue;
      e += 0.5 * m.inertial_mass(i) * inv_h2 * (at[i] - y[i]).squaredNorm() - m.mass[i] * g.dot(at[i]);
      if (!in_range[i]) continue;
      const double pen = depth(i, at[i]);
      if (pen > 0) e += contact_energy(contact_k[i], pen, skin);
      if (in_crease[i]) e += contact_energy(contact_k[i], crease_depth(i, at[i]), skin);
      if (friction_force[i] > 0) {
        e += friction_energy(i, tangential_slip(i, at[i]).norm());
      }
    }
    block_sum[b] = e;
  });
  for (size_t b = 0; b < pblocks; ++b) total += block_sum[b];
  // Springs: their terms at `at` (the gradients and blocks are not needed here, but one kernel
  // keeps the energy and the forces the same function).
  spring_terms(at, s);
  const size_t springs = m.spring_count();
  sim::parallel_blocks(springs, [&](size_t b, size_t begin, size_t end) {
    double e = 0;
    for (size_t k = begin; k < end; ++k) e += spring_term[k].energy;
    block_sum[b] = e;
  });
  for (size_t b = 0; b < sim::block_count(springs); ++b) total += block_sum[b];
  if (self_valid) total += self_terms(at, false);
  return total + bend_terms(at, false);
}

void ImplicitSolver::Impl::find_self_contacts(const ImplicitSettings& s) {
  if (!self_finder) {
    self_finder = std::make_unique<sim::SelfContactFinder>(model, sim::SelfContactFinder::default_exclusion(model));
    self_found_at.resize(n);
    self_gradient.assign(n, Vec3d::Zero());
  }
  // Pairs within the thickness plus what the particle and the triangle can move relative to each
  // other before they are found again: one iteration's max_move each, after up to 2 kSelfRefind
  // since they were found (see step()).
  const double radius = self_thickness() + 2.0 * (static_cast<double>(s.max_move) + kSelfRefind);
  // Which side of a triangle a particle belongs on is taken from the step's start; where the cloth
  // passes through itself there (sewing ran without self-contact, and panels wrapped round the body
  // overlap), that side is the wrong one, and the penalty would hold the cloth through itself
  // against its springs: the jeans XL on GarmentCode's mean body then did not settle in 8360 Newton
  // iterations (residual 137 weights). Those particles and their neighbours are left out of
  // self-contact until the springs have pulled them free (SelfContactFinder::crossings).
  self_finder->find(x, x0, free, radius, self_pairs, tangled, !self_valid);
  std::copy(x.begin(), x.end(), self_found_at.begin());
  self_valid = true;
}

double ImplicitSolver::Impl::self_terms(const std::vector<Vec3d>& at, bool with_gradient) {
  if (with_gradient) std::fill(self_gradient.begin(), self_gradient.end(), Vec3d::Zero());
  double total = 0;
  // In pair order on one thread (a few hundred pairs where a garment folds): the same sums on any
  // number of threads.
  for (const sim::SelfPair& pr : self_pairs) {
    const double d = self_depth(pr, at);
    if (d <= 0) continue;
    const double k = contact_k[pr.particle];
    total += contact_energy(k, d, kNoSkin);
    if (!with_gradient) continue;
    const Vec3d f = contact_force(k, d, kNoSkin) * pr.normal;  // on the particle; its reaction on the triangle
    self_gradient[pr.particle] -= f;
    const Tri& tri = model.triangles[pr.triangle];
    for (size_t j = 0; j < 3; ++j) self_gradient[tri[j]] += pr.weight[j] * f;
  }
  return total;
}

bool ImplicitSolver::Impl::add_self_blocks() {
  if (reduced()) return false;  // the pairs the pattern lacks are loose_pairs
  needed_blocks.clear();
  bool missing = false;
  const double near = -self_thickness();
  for (const sim::SelfPair& pr : self_pairs) {
    if (self_depth(pr, x) <= near) continue;
    const Tri& tri = model.triangles[pr.triangle];
    for (size_t j = 0; j < 3; ++j)
      for (const auto& [a, b] : {std::pair{pr.particle, tri[j]}, std::pair{tri[j], tri[(j + 1) % 3]}}) {
        needed_blocks.push_back({std::min(a, b), std::max(a, b)});
        missing = missing || block_of(a, b) == kNoBlock;
      }
  }
  if (!missing) return false;
  // The pattern holds what the pairs near contact need now, and what it held before while that is
  // not much more than they need: pairs that come and go keep their blocks (the walking shirt
  // analysed its pattern 91 times in 85 frames so, 222 times when it held only what was needed
  // now), and a long animation's pattern does not grow with every place a sleeve ever brushed.
  std::sort(needed_blocks.begin(), needed_blocks.end());
  needed_blocks.erase(std::unique(needed_blocks.begin(), needed_blocks.end()), needed_blocks.end());
  if (contact_blocks.size() <= 4 * needed_blocks.size() + kKeptContactBlocks) {
    contact_blocks.insert(contact_blocks.end(), needed_blocks.begin(), needed_blocks.end());
    std::sort(contact_blocks.begin(), contact_blocks.end());
    contact_blocks.erase(std::unique(contact_blocks.begin(), contact_blocks.end()), contact_blocks.end());
  } else {
    contact_blocks = needed_blocks;
  }
  analyse_pattern();
  factored = false;
  return true;
}

void ImplicitSolver::Impl::add_self_hessian(double* values) {
  // A pair's Hessian is K a a^T (x) n n^T for a = (1, -w0, -w1, -w2) over (particle, corners):
  // positive semi-definite, and without stiffness where the particle and the triangle move
  // together (a fold sliding along itself). add_self_blocks() put its blocks in the pattern; a
  // pair without them (one that became active after it, or any in the reduced pattern, whose
  // products take the pair itself: loose_pairs) gets a matrix at least as stiff in every direction
  // from its diagonal blocks: a a^T <= 4 diag(a^2).
  const auto add_block = [&](uint32_t block, const Mat3d& a) {
    for (int k = 0; k < 3; ++k) {
      double* col = values + block_offset[3 * block + static_cast<size_t>(k)];
      for (int r = 0; r < 3; ++r) col[r] += a(r, k);
    }
  };
  for (const sim::SelfPair& pr : self_pairs) {
    const double d = self_depth(pr, x);
    if (d <= 0) continue;
    const Tri& tri = model.triangles[pr.triangle];
    const std::array<uint32_t, 4> node{pr.particle, tri[0], tri[1], tri[2]};
    const std::array<double, 4> a{1.0, -pr.weight[0], -pr.weight[1], -pr.weight[2]};
    const Mat3d nn = contact_stiffness(contact_k[pr.particle], d, kNoSkin) * pr.normal * pr.normal.transpose();
    bool coupled = true;
    std::array<uint32_t, 6> block{};
    size_t e = 0;
    for (size_t j = 0; j < 4; ++j)
      for (size_t l = j + 1; l < 4; ++l, ++e) {
        block[e] = block_of(node[j], node[l]);
        coupled = coupled && block[e] != kNoBlock;
      }
    for (size_t j = 0; j < 4; ++j)
      if (free[node[j]]) add_block(node[j], ((coupled ? 1.0 : 4.0) * a[j] * a[j]) * nn);
    if (!coupled) {
      if (reduced())
        loose_pairs.push_back({static_cast<uint32_t>(&pr - self_pairs.data()), contact_stiffness(contact_k[pr.particle], d, kNoSkin)});
      continue;
    }
    e = 0;
    for (size_t j = 0; j < 4; ++j)
      for (size_t l = j + 1; l < 4; ++l, ++e) {
        if (!free[node[j]] || !free[node[l]]) continue;
        const Mat3d b = (a[j] * a[l]) * nn;
        add_block(offdiag_block[block[e]], b);
        add_block(offdiag_block_t[block[e]], b);
      }
  }
}

double ImplicitSolver::Impl::bend_terms(const std::vector<Vec3d>& at, bool with_gradient) {
  const ClothModel& m = model;
  if (with_gradient) std::fill(bend_gradient.begin(), bend_gradient.end(), Vec3d::Zero());
  double total = 0;
  for (size_t q = 0; q < m.bend_stencil.size(); ++q) {
    const auto& st = m.bend_stencil[q];
    const auto& w = m.bend_weight[q];
    const double k = m.bend_stiffness[q];
    const Vec3d d = static_cast<double>(w[0]) * at[st[0]] + static_cast<double>(w[1]) * at[st[1]] +
                    static_cast<double>(w[2]) * at[st[2]];
    total += 0.5 * k * d.squaredNorm();
    if (with_gradient)
      for (size_t j = 0; j < 3; ++j) bend_gradient[st[j]] += (k * static_cast<double>(w[j])) * d;
  }
  return total;
}

void ImplicitSolver::Impl::spring_terms(const std::vector<Vec3d>& at, const ImplicitSettings& s) {
  const ClothModel& m = model;
  const SpringRange structural = m.range(SpringKind::Structural), seams = m.range(SpringKind::Seam);
  const double limit = 1.0 + s.strain_threshold;
  sim::parallel_blocks(m.spring_count(), [&](size_t, size_t begin, size_t end) {
    for (size_t k = begin; k < end; ++k) {
      SpringTerm& t = spring_term[k];
      t = SpringTerm{};
      if (spring_skipped[k]) continue;
      const Vec3d d = at[m.spring_b[k]] - at[m.spring_a[k]];
      const double l = d.norm();
      if (k >= seams.begin && k < seams.end) {
        add_seam(t, d, l, s.seam_stiffness, s.seam_force);
        continue;
      }
      const double rest = m.rest_length[k], stiff = m.stiffness[k];
      add_spring(t, d, l, rest, stiff, exact);
      if (k >= structural.begin && k < structural.end && l > limit * rest)
        add_spring(t, d, l, limit * rest, kLimitStiffness * stiff, exact);
    }
  });
}

void ImplicitSolver::Impl::assemble(const ImplicitSettings& s, double h) {
  const ClothModel& m = model;
  const double inv_h2 = 1.0 / (h * h);
  const Vec3d g = s.gravity.cast<double>();
  double* values = matrix.valuePtr();
  const auto set_block = [&](uint32_t block, const Mat3d& a) {
    for (int k = 0; k < 3; ++k) {
      double* col = values + block_offset[3 * block + static_cast<size_t>(k)];
      for (int r = 0; r < 3; ++r) col[r] = a(r, k);
    }
  };
  spring_terms(x, s);
  bend_terms(x, true);
  if (self_valid) self_terms(x, true);
  // Per particle: diagonal block and gradient (springs in the model's incidence order).
  const double gscale = s.gravity.norm() > 0 ? static_cast<double>(s.gravity.norm()) : 9.81;
  sim::parallel_blocks(n, [&](size_t b, size_t begin, size_t end) {
    double ratio = 0;
    for (size_t i = begin; i < end; ++i) {
      Vec3d grad = Vec3d::Zero();
      Mat3d diag = Mat3d::Zero();
      if (free[i]) {
        const double mi = m.inertial_mass(i) * inv_h2;
        grad += mi * (x[i] - y[i]) - static_cast<double>(m.mass[i]) * g + bend_gradient[i];
        if (self_valid) grad += self_gradient[i];
        diag.diagonal().array() += mi + bend_diag[i] + far_diag[i];
        for (uint32_t q = m.incident_begin[i]; q < m.incident_begin[i + 1]; ++q) {
          const SpringTerm& t = spring_term[m.incident_spring[q]];
          grad -= static_cast<double>(m.incident_sign[q]) * t.gradient_b;  // sign +1: i is the a end
          diag += t.hessian;
        }
        if (in_range[i]) {
          const Vec3d& nrm = plane_normal[i];
          const double pen = depth(i, x[i]);
          if (pen > 0) {
            grad -= contact_force(contact_k[i], pen, skin) * nrm;
            diag += contact_stiffness(contact_k[i], pen, skin) * nrm * nrm.transpose();
          }
          const double crease = in_crease[i] ? crease_depth(i, x[i]) : 0.0;
          if (crease > 0) {
            const Vec3d& cn = crease_normal[i];
            grad -= contact_force(contact_k[i], crease, skin) * cn;
            diag += contact_stiffness(contact_k[i], crease, skin) * cn * cn.transpose();
          }
          if (friction_force[i] > 0) {
            const Mat3d tangent = Mat3d::Identity() - nrm * nrm.transpose();
            const Vec3d u = tangent * (x[i] - x0[i] - surface_velocity[i] + held_slip[i]);
            const double slip = u.norm();
            const double scale = friction_scale(i, slip);
            grad += scale * u;
            // Sliding: the Coulomb force has no stiffness along the slip, only across it (its
            // direction turns with the slip), so Newton lets the particle slide as far as the
            // other forces take it instead of treating friction as a spring.
            if (slip >= friction_slip) diag += scale * (tangent - (u / slip) * (u / slip).transpose());
            else diag += scale * tangent;
          }
        }
      } else {
        diag = Mat3d::Identity();
      }
      gradient.segment<3>(static_cast<Eigen::Index>(3 * i)) = grad;
      set_block(static_cast<uint32_t>(i), diag);
      ratio = std::max(ratio, grad.norm() / (static_cast<double>(m.mass[i]) * gscale));
    }
    block_sum[b] = ratio;
  });
  force_ratio = 0;
  for (size_t b = 0; b < sim::block_count(n); ++b) force_ratio = std::max(force_ratio, block_sum[b]);
  // Off-diagonal blocks: -sum of the springs sharing them, zero where an end is pinned.
  sim::parallel_blocks(offdiag_block.size(), [&](size_t, size_t begin, size_t end) {
    for (size_t q = begin; q < end; ++q) {
      Mat3d sum = Mat3d::Zero();
      for (uint32_t j = offdiag_begin[q]; j < offdiag_begin[q + 1]; ++j) sum -= spring_term[offdiag_spring[j]].hessian;
      sum.diagonal().array() += bend_offdiag[q];
      const auto [a, b] = offdiag_pair[q];
      if (!free[a] || !free[b]) sum.setZero();
      set_block(offdiag_block[q], sum);
      set_block(offdiag_block_t[q], sum.transpose());
    }
  });
  loose_pairs.clear();
  if (self_valid) add_self_hessian(values);
}

ImplicitSolver::Impl::Solve ImplicitSolver::Impl::preconditioned_solve(double tolerance, int iterations) {
  Eigen::VectorXd& d = direction;
  Eigen::VectorXd& r = residual_vec;
  d.setZero();
  r = -gradient;
  const double target = tolerance * r.norm();
  solve(r, preconditioned);
  search = preconditioned;
  double rz = r.dot(preconditioned);
  for (int k = 0; k < iterations; ++k) {
    hessian_product(search, product);
    const double curvature = search.dot(product);
    if (!(curvature > 0)) return Solve::Indefinite;
    const double step = rz / curvature;
    d += step * search;
    r -= step * product;
    if (r.norm() <= target) return Solve::Reached;
    solve(r, preconditioned);
    const double rz_next = r.dot(preconditioned);
    search = preconditioned + (rz_next / rz) * search;
    rz = rz_next;
  }
  return Solve::Missed;
}

void ImplicitSolver::Impl::colour_particles() {
  const ClothModel& m = model;
  // Neighbours: the ends of every spring the solver keeps, and the particles of every stencil.
  std::vector<std::array<uint32_t, 2>> pairs;
  for (size_t k = 0; k < m.spring_count(); ++k)
    if (!spring_skipped[k]) pairs.push_back({m.spring_a[k], m.spring_b[k]});
  for (const auto& st : m.bend_stencil)
    for (const auto& [j, l] : {std::pair{0, 1}, std::pair{1, 2}, std::pair{0, 2}})
      pairs.push_back({st[static_cast<size_t>(j)], st[static_cast<size_t>(l)]});
  std::vector<uint32_t> begin(n + 1, 0), adjacent(2 * pairs.size());
  for (const auto& [a, b] : pairs) {
    ++begin[a + 1];
    ++begin[b + 1];
  }
  for (size_t i = 0; i < n; ++i) begin[i + 1] += begin[i];
  std::vector<uint32_t> fill(begin.begin(), begin.end() - 1);
  for (const auto& [a, b] : pairs) {
    adjacent[fill[a]++] = b;
    adjacent[fill[b]++] = a;
  }
  // Greedy colouring in index order: the smallest colour no neighbour has yet.
  constexpr uint32_t kNone = UINT32_MAX;
  std::vector<uint32_t>& colour = particle_colour;
  colour.assign(n, kNone);
  std::vector<uint32_t> taken;
  uint32_t colours = 0;
  for (size_t i = 0; i < n; ++i) {
    taken.assign(colours + 1, 0);
    for (uint32_t q = begin[i]; q < begin[i + 1]; ++q)
      if (colour[adjacent[q]] != kNone) taken[colour[adjacent[q]]] = 1;
    uint32_t c = 0;
    while (taken[c]) ++c;
    colour[i] = c;
    colours = std::max(colours, c + 1);
  }
  colour_begin.assign(colours + 1, 0);
  for (size_t i = 0; i < n; ++i) ++colour_begin[colour[i] + 1];
  for (uint32_t c = 0; c < colours; ++c) colour_begin[c + 1] += colour_begin[c];
  colour_particle.resize(n);
  std::vector<uint32_t> next(colour_begin.begin(), colour_begin.end() - 1);
  for (size_t i = 0; i < n; ++i) colour_particle[next[colour[i]]++] = static_cast<uint32_t>(i);
  // Each particle's stencils.
  stencil_begin.assign(n + 1, 0);
  for (const auto& st : m.bend_stencil)
    for (uint32_t p : st) ++stencil_begin[p + 1];
  for (size_t i = 0; i < n; ++i) stencil_begin[i + 1] += stencil_begin[i];
  stencil_slot.resize(3 * m.bend_stencil.size());
  std::vector<uint32_t> at(stencil_begin.begin(), stencil_begin.end() - 1);
  for (size_t q = 0; q < m.bend_stencil.size(); ++q)
    for (uint32_t j = 0; j < 3; ++j) stencil_slot[at[m.bend_stencil[q][j]]++] = static_cast<uint32_t>(3 * q + j);
}

double ImplicitSolver::Impl::block_terms(size_t i, const Vec3d& p, const ImplicitSettings& s, double inv_h2, Vec3d* grad,
                                         SymmetricBlock* block) const {
  // Written out in scalars: one block is small, and a sweep builds one per particle (Eigen's
  // fixed-size 3x3 expressions here took twice the time).
  const ClothModel& m = model;
  const SpringRange structural = m.range(SpringKind::Structural), seams = m.range(SpringKind::Seam);
  const double limit = 1.0 + s.strain_threshold;
  const double mi = m.inertial_mass(i) * inv_h2;
  const Vec3d g = s.gravity.cast<double>();
  double e = 0.5 * mi * (p - y[i]).squaredNorm() - static_cast<double>(m.mass[i]) * g.dot(p);
  Vec3d gr = Vec3d::Zero();
  SymmetricBlock h;
  if (grad) {
    gr = mi * (p - y[i]) - static_cast<double>(m.mass[i]) * g;
    h.add_diagonal(mi);
  }
  for (uint32_t q = m.incident_begin[i]; q < m.incident_begin[i + 1]; ++q) {
    const uint32_t k = m.incident_spring[q];
    if (spring_skipped[k]) continue;
    // d = x_b - x_a with i at p; i's gradient is -d(energy)/d(d) where i is the a end, + where b.
    const bool a_end = m.spring_a[k] == i;
    const Vec3d d = a_end ? Vec3d(x[m.spring_b[k]] - p) : Vec3d(p - x[m.spring_a[k]]);
    const double l = d.norm();
    const double side = a_end ? -1.0 : 1.0;
    if (k >= seams.begin && k < seams.end) {
      // add_seam's terms.
      e += seam_energy(l, s.seam_stiffness, s.seam_force);
      if (!grad) continue;
      const double c = seam_capped(l, s.seam_stiffness, s.seam_force) ? s.seam_force / l : s.seam_stiffness;
      gr += side * c * d;
      h.add_diagonal(c);
      continue;
    }
    // add_spring's terms (the projected block), and the barrier's past the strain limit.
    const double rest = m.rest_length[k], stiff = m.stiffness[k];
    const bool barrier = k >= structural.begin && k < structural.end && l > limit * rest;
    const double kb = kLimitStiffness * stiff, lb = limit * rest;
    e += 0.5 * stiff * (l - rest) * (l - rest) + (barrier ? 0.5 * kb * (l - lb) * (l - lb) : 0.0);
    if (!grad) continue;
    if (l < 1e-12) {
      h.add_diagonal(stiff + (barrier ? kb : 0.0));
      continue;
    }
    const Vec3d u = d / l;
    double pull = stiff * (l - rest);
    double across = stiff * std::max(0.0, 1.0 - rest / l);
    double along = stiff;
    if (barrier) {
      pull += kb * (l - lb);
      across += kb * std::max(0.0, 1.0 - lb / l);
      along += kb;
    }
    gr += side * pull * u;
    h.add_diagonal(across);
    h.add_outer(along - across, u);
  }
  for (uint32_t q = stencil_begin[i]; q < stencil_begin[i + 1]; ++q) {
    const uint32_t st = stencil_slot[q] / 3, j = stencil_slot[q] % 3;
    const auto& ps = m.bend_stencil[st];
    const auto& w = m.bend_weight[st];
    Vec3d d = Vec3d::Zero();
    for (uint32_t c = 0; c < 3; ++c) d += static_cast<double>(w[c]) * (c == j ? p : x[ps[c]]);
    const double k = m.bend_stiffness[st];
    e += 0.5 * k * d.squaredNorm();
    if (!grad) continue;
    gr += (k * static_cast<double>(w[j])) * d;
    h.add_diagonal(k * static_cast<double>(w[j]) * static_cast<double>(w[j]));
  }
  if (self_valid) {
    // Self-contact pairs i is in, as the particle (a = 1) or a corner of the triangle (a = -w): the
    // depth is linear in i's position, d(p) = d(x_i) - a n.(p - x_i).
    for (uint32_t q = self_begin[i]; q < self_begin[i + 1]; ++q) {
      const sim::SelfPair& pr = self_pairs[self_entry[q] / 4];
      const uint32_t role = self_entry[q] % 4;
      const double a = role == 0 ? 1.0 : -pr.weight[role - 1];
      const double d = self_depth(pr, x) - a * pr.normal.dot(p - x[i]);
      if (d <= 0) continue;
      const double k = contact_k[pr.particle];
      e += contact_energy(k, d, kNoSkin);
      if (!grad) continue;
      gr -= (a * contact_force(k, d, kNoSkin)) * pr.normal;
      h.add_outer(a * a * contact_stiffness(k, d, kNoSkin), pr.normal);
    }
  }
  if (in_range[i]) {
    const Vec3d& nrm = plane_normal[i];
    const double pen = depth(i, p);
    if (pen > 0) {
      e += contact_energy(contact_k[i], pen, skin);
      if (grad) {
        gr -= contact_force(contact_k[i], pen, skin) * nrm;
        h.add_outer(contact_stiffness(contact_k[i], pen, skin), nrm);
      }
    }
    const double crease = in_crease[i] ? crease_depth(i, p) : 0.0;
    if (crease > 0) {
      const Vec3d& cn = crease_normal[i];
      e += contact_energy(contact_k[i], crease, skin);
      if (grad) {
        gr -= contact_force(contact_k[i], crease, skin) * cn;
        h.add_outer(contact_stiffness(contact_k[i], crease, skin), cn);
      }
    }
    if (friction_force[i] > 0) {
      const Vec3d u = tangential_slip(i, p);
      const double slip = u.norm();
      e += friction_energy(i, slip);
      if (grad) {
        // assemble()'s friction block: scale (I - n n^T), less the slip's direction where it slides.
        const double scale = friction_scale(i, slip);
        gr += scale * u;
        h.add_diagonal(scale);
        h.add_outer(-scale, nrm);
        if (slip >= friction_slip) h.add_outer(-scale, u / slip);
      }
    }
  }
  if (grad) {
    *grad = gr;
    *block = h;
  }
  return e;
}

Vec3d ImplicitSolver::Impl::block_step(size_t i, const ImplicitSettings& s, double inv_h2) const {
  Vec3d grad;
  SymmetricBlock block;
  const double e0 = block_terms(i, x[i], s, inv_h2, &grad, &block);
  // The block is positive definite (inertia plus positive semi-definite terms).
  Vec3d dx = -block.solve(grad);
  const double moved2 = dx.squaredNorm(), cap = s.max_move;
  if (moved2 > cap * cap) dx *= cap / std::sqrt(moved2);
  // Backtracking on the particle's own energy: a step that crosses the strain barrier's start or
  // leaves a contact overshoots what the block's model said. Moves under kSweepSettled are taken as
  // they are (most of a sweep's, once the cloth has settled into the step).
  if (dx.squaredNorm() < kSweepSettled * kSweepSettled) return dx;
  const double slope = grad.dot(dx);
  for (int halvings = 0; halvings < kMaxHalvings; ++halvings) {
    if (block_terms(i, x[i] + dx, s, inv_h2, nullptr, nullptr) <= e0 + kArmijo * slope) return dx;
    dx *= 0.5;
  }
  return Vec3d::Zero();
}

void ImplicitSolver::Impl::index_self_pairs() {
  self_begin.assign(n + 1, 0);
  deferred.assign(n, 0);
  if (!self_valid) return;
  const auto nodes = [&](const sim::SelfPair& pr) {
    const Tri& tri = model.triangles[pr.triangle];
    return std::array<uint32_t, 4>{pr.particle, tri[0], tri[1], tri[2]};
  };
  for (const sim::SelfPair& pr : self_pairs)
    for (uint32_t v : nodes(pr)) ++self_begin[v + 1];
  for (size_t i = 0; i < n; ++i) self_begin[i + 1] += self_begin[i];
  self_entry.resize(self_begin[n]);
  std::vector<uint32_t>& at = refresh;  // scratch of n entries
  std::copy(self_begin.begin(), self_begin.end() - 1, at.begin());
  for (size_t q = 0; q < self_pairs.size(); ++q) {
    const std::array<uint32_t, 4> v = nodes(self_pairs[q]);
    for (uint32_t r = 0; r < 4; ++r) self_entry[at[v[r]]++] = static_cast<uint32_t>(4 * q + r);
    for (uint32_t r = 0; r < 4; ++r)
      for (uint32_t t = r + 1; t < 4; ++t)
        if (particle_colour[v[r]] == particle_colour[v[t]]) deferred[v[r]] = deferred[v[t]] = 1;
  }
}

void ImplicitSolver::Impl::block_descent(std::span<Collider* const> colliders, const ImplicitSettings& s, double h,
                                         int sweeps) {
  if (colour_begin.empty()) colour_particles();
  const double inv_h2 = 1.0 / (h * h);
  index_self_pairs();
  const auto colours = static_cast<std::ptrdiff_t>(colour_begin.size() - 1);
  for (int sweep = 0; sweep < sweeps; ++sweep) {
    if (sweep > 0) detect_contacts(colliders, s, h, false);
    // Particles of one colour share no spring or stencil: each moves from its neighbours' positions
    // alone, so the result is the same on any number of threads. Those that share a self-contact
    // pair with one of their colour follow, one after another in index order. One parallel region
    // a sweep, a barrier a colour.
#pragma omp parallel if (n >= kParallelSweeps)
    for (std::ptrdiff_t c = 0; c < colours; ++c) {
      const auto first = static_cast<std::ptrdiff_t>(colour_begin[static_cast<size_t>(c)]);
      const auto last = static_cast<std::ptrdiff_t>(colour_begin[static_cast<size_t>(c) + 1]);
#pragma omp for schedule(static)
      for (std::ptrdiff_t q = first; q < last; ++q) {
        const size_t i = colour_particle[static_cast<size_t>(q)];
        if (free[i] && !deferred[i]) x[i] += block_step(i, s, inv_h2);
      }
#pragma omp single
      for (std::ptrdiff_t q = first; q < last; ++q) {
        const size_t i = colour_particle[static_cast<size_t>(q)];
        if (free[i] && deferred[i]) x[i] += block_step(i, s, inv_h2);
      }
    }
  }
}

float ImplicitSolver::Impl::residual(const ImplicitSettings& s) {
  // Net force per particle: springs, seams, gravity, contact, and static friction up to mu N.
  const ClothModel& m = model;
  const double gscale = s.gravity.norm() > 0 ? static_cast<double>(s.gravity.norm()) : 9.81;
  const double mu = std::max(0.0f, s.friction);
  spring_terms(x, s);
  bend_terms(x, true);
  if (self_valid) self_terms(x, true);
  const Vec3d gravity = s.gravity.cast<double>();
  float worst = 0;
  for (size_t i = 0; i < n; ++i) {
    if (!free[i]) continue;
    Vec3d force = static_cast<double>(m.mass[i]) * gravity - bend_gradient[i];
    if (self_valid) force -= self_gradient[i];
    for (uint32_t q = m.incident_begin[i]; q < m.incident_begin[i + 1]; ++q)
      force += static_cast<double>(m.incident_sign[q]) * spring_term[m.incident_spring[q]].gradient_b;
    if (in_range[i]) {
      const Vec3d& nrm = plane_normal[i];
      const double pen = depth(i, x[i]);
      const double normal_force = contact_force(contact_k[i], pen, skin);
      force += normal_force * nrm;
      if (in_crease[i]) force += contact_force(contact_k[i], crease_depth(i, x[i]), skin) * crease_normal[i];
      if (normal_force > 0) {
        // Static friction takes up to mu N of the tangential force.
        const Vec3d tangential = force - nrm.dot(force) * nrm;
        const double t = tangential.norm();
        if (t > 0) force -= tangential * (std::min(t, mu * normal_force) / t);
      }
    }
    const float r = static_cast<float>(force.norm() / (static_cast<double>(m.mass[i]) * gscale));
    worst = std::max(worst, r);
  }
  return worst;
}

ImplicitSolver::ImplicitSolver(const ClothModel& model, size_t max_colliders)
    : impl_(std::make_unique<Impl>(model, std::max<size_t>(max_colliders, 1))) {}
ImplicitSolver::~ImplicitSolver() = default;
ImplicitSolver::ImplicitSolver(ImplicitSolver&&) noexcept = default;
ImplicitSolver& ImplicitSolver::operator=(ImplicitSolver&&) noexcept = default;

float ImplicitSolver::residual(std::span<const Vec3f> x, std::span<Collider* const> colliders,
                               const ImplicitSettings& settings) {
  Impl& w = *impl_;
  if (x.size() != w.n) throw std::invalid_argument("ImplicitSolver::residual: positions not made for this model");
  for (size_t i = 0; i < w.n; ++i) w.x[i] = w.x0[i] = x[i].cast<double>();
  w.set_skin(settings);
  w.detect_contacts(colliders, settings, settings.time_step, true);
  w.planes_valid = true;
  w.self_valid = false;
  if (settings.self_collision) w.find_self_contacts(settings);
  return w.residual(settings);
}

void ImplicitSolver::contact_forces(std::span<Vec3f> force, std::span<Vec3f> point) const {
  const Impl& w = *impl_;
  if (force.size() != w.n || point.size() != w.n)
    throw std::invalid_argument("ImplicitSolver::contact_forces: spans not made for this solver's model");
  for (size_t i = 0; i < w.n; ++i) {
    force[i] = point[i] = Vec3f::Zero();
    if (!w.free[i] || !w.in_range[i] || !w.planes_valid) continue;
    const Vec3d& nrm = w.plane_normal[i];
    const Vec3d& x = w.x[i];
    Vec3d f = contact_force(w.contact_k[i], w.depth(i, x), w.skin) * nrm;
    if (w.in_crease[i]) f += contact_force(w.contact_k[i], w.crease_depth(i, x), w.skin) * w.crease_normal[i];
    if (w.friction_force[i] > 0) {
      // Minus the friction energy's gradient (assemble()).
      const Vec3d u = w.tangential_slip(i, x);
      f -= w.friction_scale(i, u.norm()) * u;
    }
    force[i] = f.cast<float>();
    point[i] = Vec3d(x - (nrm.dot(x) + w.plane_offset[i]) * nrm).cast<float>();
  }
}

StepStatus ImplicitSolver::step(ClothState& state, std::span<Collider* const> colliders,
                                const ImplicitSettings& s, ImplicitStepStats* stats, ImplicitProfile* profile) {
  Impl& w = *impl_;
  if (state.status != StepStatus::Ok) return state.status;
  if (state.x.size() != w.n || state.v.size() != w.n || colliders.size() > w.max_colliders)
    throw std::invalid_argument("ImplicitSolver::step: state or colliders not made for this solver's model");
  const double h = s.time_step;
  Timer timer(profile != nullptr);
  double scratch_time = 0;
  const uint64_t solves_before = w.triangular_solves, analyses_before = w.analyses;
  for (Collider* c : colliders) c->update(state.time + h);
  // Start: x0 = x_n; the inertial target y = x_n + h v_n (at rest: x_n); pinned particles follow y.
  // Newton starts at x_n, where the contacts are found: started at y, cloth falling onto a sphere
  // at 1/30 s began its steps up to 10 cm into it, and was pushed through. (On colliders that move,
  // the start is moved on below.)
  const bool rounded = state.x_rounding.size() == w.n;
  for (size_t i = 0; i < w.n; ++i) {
    w.x0[i] = state.x[i].cast<double>();
    if (rounded) w.x0[i] += state.x_rounding[i].cast<double>();
    w.y[i] = s.quasi_static ? w.x0[i] : Vec3d(w.x0[i] + h * state.v[i].cast<double>());
    w.x[i] = w.free[i] ? w.x0[i] : w.y[i];
  }
  if (!w.analysed) {
    // The first analysis (the ordering and the symbolic factorisation: 0.68 s of the 20k-vertex
    // shirt's nested dissection) is the factorisation's.
    timer.mark(profile ? profile->contacts : scratch_time);
    w.analyse_pattern();
    w.analysed = true;
    timer.mark(profile ? profile->factorize : scratch_time);
  }
  // Colliders that move carry the cloth that lies on them: Newton's iterations start (the iterate
  // only: inertia and friction still measure from x_n) with a particle within the contact layer's
  // reach of its plane where its surface's motion over the last step would take it, and every other
  // particle at its inertial target y. Started at x_n, a body moving towards the cloth is found up to
  // its whole displacement over the step past the particle, where the nearest surface of a thin part
  // (a hand, a forearm) can be its far side, and cloth swinging with the body is pulled back to
  // where it was by the first iteration's inertia: the walk needed steps of at most 1.2 cm of the
  // body's motion and 8 Newton iterations to stay within its gates; started this way, steps of 3 cm
  // and 6 iterations keep it further within them (docs/animation.md). A particle whose target lies
  // within its contact layer (falling onto the surface) starts at x_n.
  if (s.moving_colliders && !s.quasi_static && w.planes_valid && w.planes_h > 0) {
    const double scale = h / w.planes_h;
    const double reach = static_cast<double>(w.model.fabric.collision_thickness);
    for (size_t i = 0; i < w.n; ++i) {
      if (!w.free[i]) continue;
      if (w.in_range[i] && w.depth(i, w.x0[i]) > -reach)
        w.x[i] = w.x0[i] + scale * w.surface_velocity[i];
      else if (!w.in_range[i] || w.depth(i, w.y[i]) < 0)
        w.x[i] = w.y[i];
    }
  }
  ImplicitStepStats st;
  w.friction_slip = std::max(s.friction_slip, 1e-9);
  w.set_skin(s);
  w.factored = false;
  w.self_valid = false;
  const double max_move = s.max_move;
  // Contact planes are kept from step to step, and a particle's is found anew only once it moved
  // kReplane from where it was found (or max_move, out of contact): Newton then converges on fixed
  // planes (a body's interpolated normals are not the gradient of its distance, so planes found
  // anew at every iteration differ by a little each time and the iterations chatter). Colliders
  // that move have every plane found anew at the start of each step.
  w.detect_contacts(colliders, s, h, !w.planes_valid || s.moving_colliders);
  w.planes_valid = true;
  w.lag_friction(s, true);
  const bool held = state.friction_slip.size() == w.n;
  for (size_t i = 0; i < w.n; ++i) w.held_slip[i] = held ? Vec3d(state.friction_slip[i].cast<double>()) : Vec3d::Zero();
  // Quasi-static: the inertia term becomes a Levenberg-Marquardt damping m_i / (2 h_d^2) |x - x_k|^2
  // around the current iterate x_k (no force at x_k, so the fixed point is the state of rest), with
  // h_d growing while full Newton steps are taken and shrinking when the line search halves.
  double hd = h;
  bool cg_missed = false;
  int relags = 0;
  // The exact Hessian converges where the projected one crawls (compressed cloth in folds: the
  // projected matrix is stiffer than the cloth, and its Newton steps fall short by a constant
  // fraction), but it is indefinite where the cloth buckles: a factorisation that fails falls back
  // to the projected blocks for the rest of the step.
  w.exact = s.exact_hessian;
  const int sweeps = s.quasi_static ? 0 : s.block_sweeps;
  const auto sweep = [&] {
    w.block_descent(colliders, s, h, sweeps);
    if (profile) profile->block_sweeps += static_cast<uint64_t>(sweeps);
    timer.mark(profile ? profile->sweeps : scratch_time);
  };
  for (int it = 0; it < s.max_newton_iterations; ++it) {
    if (it > 0) w.detect_contacts(colliders, s, h, false);
    if (s.quasi_static)
      for (size_t i = 0; i < w.n; ++i)
        if (w.free[i]) w.y[i] = w.x[i];
    timer.mark(profile ? profile->contacts : scratch_time);
    if (s.self_collision) {
      // Found anew at each step's start (the sides come from there), then once particles moved
      // apart by more than kSelfRefind since: the spread of their displacements (half the diagonal of
      // their bounding box) bounds how far any particle moved relative to any triangle. A garment
      // carried along by a moving body keeps its pairs.
      bool again = !w.self_valid;
      if (!again) {
        Vec3d lo = Vec3d::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
        for (size_t i = 0; i < w.n; ++i) {
          const Vec3d d = w.x[i] - w.self_found_at[i];
          lo = lo.cwiseMin(d);
          hi = hi.cwiseMax(d);
        }
        again = 0.5 * (hi - lo).norm() > kSelfRefind;
      }
      if (again) w.find_self_contacts(s);
      w.add_self_blocks();
      timer.mark(profile ? profile->self_contacts : scratch_time);
    }
    if (sweeps > 0) sweep();
    w.assemble(s, hd);
    if (profile) profile->self_pairs_outside_pattern += w.loose_pairs.size();
    timer.mark(profile ? profile->assemble : scratch_time);
    if (s.quasi_static && w.force_ratio <= s.force_tolerance && relags < kMaxRelags &&
        w.friction_lag_error(s) > s.force_tolerance) {
      ++relags;
      w.lag_friction(s);
      w.assemble(s, hd);
      timer.mark(profile ? profile->assemble : scratch_time);
    }
    if (w.force_ratio <= s.force_tolerance) {
      st.converged = true;
      break;
    }
    // The Newton direction: conjugate gradients preconditioned by the last factorisation (the
    // matrix changes little from one iteration to the next), or a fresh factorisation when there is
    // none yet in this step or they do not reach the tolerance in direction_iterations. With a
    // tight tolerance, once they missed in a step, the step factorises directly: a factorisation
    // costs about 14 of their iterations, and where contacts or the strain barrier changed the
    // matrix enough for one miss, the next attempt mostly misses too (a walk's steps: every
    // attempt). A loose one is reached in a few iterations far more often: the walk took 1.9x fewer
    // factorisations and 1.4x less time with 0.5 (docs/animation.md).
    const bool kept = s.factorisation_interval > 0;
    const bool due = kept && it % s.factorisation_interval == 0;
    const bool solved = w.factored && !cg_missed && !due &&
                        (w.preconditioned_solve(s.direction_tolerance, s.direction_iterations) == Impl::Solve::Reached ||
                         kept);
    cg_missed = s.direction_tolerance < ImplicitSettings::kLooseDirection && (cg_missed || (w.factored && !solved));
    timer.mark(profile ? profile->solve : scratch_time);
    if (!solved) {
      w.cholesky.factorise(w.matrix, omp_get_max_threads());
      if (w.cholesky.info() != Eigen::Success && w.exact) {
        if (profile) ++profile->factorizations;
        w.exact = false;
        w.assemble(s, hd);
        w.cholesky.factorise(w.matrix, omp_get_max_threads());
      }
      timer.mark(profile ? profile->factorize : scratch_time);
      if (w.cholesky.info() != Eigen::Success) {
        state.status = StepStatus::NonFinite;
        break;
      }
      w.factored = true;
      if (w.far_pair.empty()) {
        w.residual_vec = -w.gradient;
        w.solve(w.residual_vec, w.direction);
      } else {
        const Impl::Solve result = w.preconditioned_solve(s.direction_tolerance, s.direction_iterations);
        // The Hessian not positive definite along P's direction (the exact one where the cloth
        // buckles): that direction, a descent direction since P is.
        if (result != Impl::Solve::Reached && w.direction.squaredNorm() == 0) w.direction = w.search;
        ++w.fresh_attempts;
        if (result == Impl::Solve::Missed) ++w.fresh_misses;
        if (w.fresh_misses >= Impl::kFreshMisses && 4 * w.fresh_misses > w.fresh_attempts) {
          w.whole_stencils = true;
          w.analyse_pattern();  // the next iteration factorises the whole Hessian
          w.factored = false;
        }
      }
      if (profile) ++profile->factorizations;
    }
    timer.mark(profile ? profile->solve : scratch_time);
    // Largest move of a particle, capped at max_move.
    double largest = 0;
    for (size_t i = 0; i < w.n; ++i)
      largest = std::max(largest, w.direction.segment<3>(static_cast<Eigen::Index>(3 * i)).squaredNorm());
    largest = std::sqrt(largest);
    if (!std::isfinite(largest)) {
      state.status = StepStatus::NonFinite;
      break;
    }
    double alpha = largest > max_move ? max_move / largest : 1.0;
    // Backtracking line search on E (Armijo).
    const double e0 = w.energy(w.x, s, hd);
    const double slope = w.gradient.dot(w.direction);
    const bool capped = alpha < 1.0;
    int halvings = 0;
    for (;; ++halvings) {
      for (size_t i = 0; i < w.n; ++i)
        w.trial[i] = w.x[i] + alpha * w.direction.segment<3>(static_cast<Eigen::Index>(3 * i));
      const double e = w.energy(w.trial, s, hd);
      if (e <= e0 + kArmijo * alpha * slope || halvings >= kMaxHalvings) break;
      alpha *= 0.5;
    }
    std::swap(w.x, w.trial);
    if (s.quasi_static) {
      if (halvings > 0) hd = std::max(h, 0.5 * hd);
      else if (!capped) hd = std::min(kMaxDampingStep, 2.0 * hd);
    }
    timer.mark(profile ? profile->line_search : scratch_time);
    ++st.newton_iterations;
    if (profile) profile->line_search_halvings += static_cast<uint64_t>(halvings);
    if (alpha * largest < kStagnation) {
      st.converged = true;
      break;
    }
  }
  // The last iteration's direction came from a matrix that did not know where it would end: the
  // sweeps take the iterate on from there.
  if (sweeps > 0 && !st.converged && state.status == StepStatus::Ok) {
    w.detect_contacts(colliders, s, h, false);
    sweep();
  }
  // The state: positions, velocities from the step (quasi-static: at rest), and the slip friction
  // holds (where it slides, the slip at which it does: the anchor follows the particle).
  state.friction_slip.resize(w.n);
  for (size_t i = 0; i < w.n; ++i) {
    Vec3d u = Vec3d::Zero();
    if (w.in_range[i] && w.friction_force[i] > 0) {
      u = w.tangential_slip(i, w.x[i]);
      const double length = u.norm();
      if (length > w.friction_slip) u *= w.friction_slip / length;
    }
    state.friction_slip[i] = u.cast<float>();
  }
  float moved2 = 0;
  double kinetic = 0;
  float speed2 = 0;
  bool finite = true;
  for (size_t i = 0; i < w.n; ++i) {
    const Vec3f xn = w.x[i].cast<float>();
    moved2 = std::max(moved2, (xn - state.x[i]).squaredNorm());
    const Vec3f v = s.quasi_static ? Vec3f::Zero() : Vec3f(((w.x[i] - w.x0[i]) / h).cast<float>());
    finite = finite && std::isfinite(xn.squaredNorm()) && std::isfinite(v.squaredNorm());
    state.x[i] = xn;
    state.v[i] = v;
    speed2 = std::max(speed2, v.squaredNorm());
    kinetic += 0.5 * static_cast<double>(w.model.mass[i]) * static_cast<double>(v.squaredNorm());
  }
  if (!finite && state.status == StepStatus::Ok) state.status = StepStatus::NonFinite;
  // What the rounding left out, from the positions as stored: in the loop above, GCC 12's
  // vectoriser at -O3 -march=native folds the double -> float -> double round trip away and
  // leaves it zero.
  state.x_rounding.resize(w.n);
  for (size_t i = 0; i < w.n; ++i) state.x_rounding[i] = (w.x[i] - state.x[i].cast<double>()).cast<float>();
  state.time += h;
  ++state.iterations;
  state.max_speed = std::sqrt(speed2);
  state.kinetic_energy = kinetic;
  if (stats) {
    st.residual = w.residual(s);
    uint32_t contacts = 0;
    for (size_t i = 0; i < w.n; ++i)
      contacts += w.in_range[i] && w.depth(i, w.x[i]) > 0 ? 1u : 0u;
    st.contacts = contacts;
    uint32_t self_contacts = 0;
    for (const sim::SelfPair& pr : w.self_pairs) self_contacts += w.self_valid && w.self_depth(pr, w.x) > 0 ? 1u : 0u;
    st.self_contacts = self_contacts;
    st.max_move = std::sqrt(moved2);
    *stats = st;
    timer.mark(profile ? profile->contacts : scratch_time);
  }
  if (profile) {
    ++profile->steps;
    profile->newton_iterations += static_cast<uint64_t>(st.newton_iterations);
    profile->triangular_solves += w.triangular_solves - solves_before;
    profile->analyses += w.analyses - analyses_before;
  }
  return state.status;
}

}  // namespace drape
