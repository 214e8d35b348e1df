#pragma once
// Mass-spring cloth after Vassilev & Spanlang, "Efficient Cloth Model for Dressing Animated Virtual
// People": springs (sec. 2.1, eq. 2), explicit Euler (eq. 3) at the stability bound (eq. 4),
// velocity modification against super-elasticity (sec. 3.3), Provot's position modification as the
// baseline (sec. 3.2), and collision response by velocity (eq. 5) or by force (sec. 5).
//
// Shape (see docs/cloth.md):
//   ClothModel   immutable, built once by a builder: per-particle mass, springs as typed arrays per
//                kind (all kinds in one index space, sorted by kind), the per-particle incidence
//                lists that gather spring forces in a fixed order, and a colouring of the
//                strain-limited springs for race-free Gauss-Seidel passes.
//   ClothState   mutable: positions, velocities (contiguous Vec3f arrays), time, health.
//   StepScratch  everything a step needs besides the state, allocated once; step() allocates nothing.
//   step()       a short list of named stages, each timed into StepProfile.
// Results do not depend on the number of OpenMP threads: every per-particle sum runs over the
// model's fixed incidence order and every reduction over fixed blocks.
#include <array>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "drape/collider.hpp"
#include "drape/fabric.hpp"
#include "drape/mesh.hpp"

namespace drape {

// Spring kinds, in the order their springs are stored. Later kinds (seams, support springs, skin
// anchors) append here; a kind with no springs costs nothing.
enum class SpringKind : uint8_t {
  Structural,  // grid [i,j]-[i+1,j] and [i,j]-[i,j+1]; triangle mesh edges
  Shear,       // grid [i,j]-[i+1,j+1] and [i+1,j]-[i,j+1]
  Flexion,     // grid [i,j]-[i+2,j] and [i,j]-[i,j+2]; triangle mesh: across each interior edge
  Seam,        // sewing springs between panels (rest length usually 0)
  Count
};
inline constexpr size_t kSpringKindCount = static_cast<size_t>(SpringKind::Count);
std::string_view to_string(SpringKind kind);

// One kind's springs as a range [begin, end) of the model's spring arrays.
struct SpringRange {
  uint32_t begin = 0;
  uint32_t end = 0;
  uint32_t size() const { return end - begin; }
};

// Immutable cloth model. Build with a builder (grid_cloth, mesh_cloth) or fill a ClothSpec and
// compile it; never edit a model in place.
struct ClothModel {
  Fabric fabric;

  // Particles.
  std::vector<float> mass;          // kg
  std::vector<float> inverse_mass;  // 1/kg, of the inertial mass; 0 for pinned (kinematic) particles
  // Selective mass scaling (scale_inertia()): particle i moves as a mass of inertia_scale[i] * mass[i]
  // while its weight stays mass[i] g. Empty: 1 for every particle (inertial mass = mass).
  std::vector<float> inertia_scale;
  std::vector<float> drag_area;     // m^2 of cloth each particle represents (air drag)
  std::vector<Vec3f> rest_position; // the layout the model was built from
  std::vector<Vec2f> flat_position; // position on the flat pattern (metres); TEXCOORD_0 on output
  std::vector<Tri> triangles;       // for output and rendering (grid: two per cell)

  // Springs, sorted by kind (kind_range). Forces follow eq. 2 plus damping along the spring:
  // f_a = (stiffness (|d| - rest) + damping (v_b - v_a).u) u, u = d/|d|, d = x_b - x_a; f_b = -f_a.
  std::vector<uint32_t> spring_a, spring_b;
  std::vector<float> rest_length;  // m
  std::vector<float> stiffness;    // N/m
  std::vector<float> damping;      // N s/m
  std::array<SpringRange, kSpringKindCount> kind_range{};

  // Per-particle incidence (CSR): springs touching particle i are incident_spring[incident_begin[i]
  // .. incident_begin[i+1]), with incident_sign +1 where i is the spring's a end and -1 where b.
  std::vector<uint32_t> incident_begin;
  std::vector<uint32_t> incident_spring;
  std::vector<float> incident_sign;

  // Strain-limited springs (structural by default) grouped into colours that share no particle, so
  // a Gauss-Seidel pass runs each colour in parallel without races and in a fixed order.
  std::vector<uint32_t> limit_a, limit_b;
  std::vector<float> limit_rest;
  std::vector<uint32_t> limit_colour_begin;  // colour c is [begin[c], begin[c+1])

  // Bending stencils: three particles a, m, b along a line of the flat pattern, l1 = |m - a| and
  // l2 = |b - m| apart there, with the energy k/2 |w_a x_a + w_m x_m + w_b x_b|^2 for the weights
  // w = (1/l1, -(1/l1 + 1/l2), 1/l2): the curvature times (l1 + l2)/2, so k = B width / ((l1 + l2)/2)
  // gives the bending energy B kappa^2 / 2 per area of a fabric of bending rigidity B. Linear in the
  // curvature and of constant Hessian. The implicit solver bends with these and leaves out the
  // flexion springs between the same a and b; the explicit step keeps the paper's flexion springs.
  // Grid builders make one per flexion spring; empty for triangle meshes.
  std::vector<std::array<uint32_t, 3>> bend_stencil;
  std::vector<std::array<float, 3>> bend_weight;
  std::vector<float> bend_stiffness;  // N m (the weights are in 1/m)

  // Grid builders fill these (0 for meshes): particle index of grid vertex (ix, iy) is iy * nx + ix.
  uint32_t grid_nx = 0, grid_ny = 0;

  size_t particle_count() const { return mass.size(); }
  size_t spring_count() const { return spring_a.size(); }
  SpringRange range(SpringKind kind) const { return kind_range[static_cast<size_t>(kind)]; }
  float total_mass() const;
  // Largest time step the stability bound allows (eq. 4), see stable_time_step().
  float stable_time_step() const;
  // The same bound with each particle's stiffness along its stiffest direction on the flat pattern
  // instead of the sum over its springs (~1.15-1.35x longer steps, just as strict; see cloth_model.cpp).
  float directional_stable_time_step() const;
  // Mass particle i moves as (mass[i] unless scale_inertia() raised it).
  float inertial_mass(size_t i) const { return inertia_scale.empty() ? mass[i] : inertia_scale[i] * mass[i]; }
};

// Selective mass scaling for quasi-static runs (draping to rest), as explicit finite-element codes do
// it: eq. 4 bounds the time step by the particle with the least mass per stiffness, which on a
// pattern clipped to its outline is a sliver of a cell at the edge (the default shirt: 0.55 ms against
// a median particle's 1.24 ms). Every free particle whose own bound (stiffness and damping terms of
// stable_time_step()) is below `ratio` x the median particle's gets just enough inertial mass to reach
// it; its weight stays mass[i] g, so the forces, and with them every state of rest, are those of the
// unscaled model: only how fast such a particle is accelerated changes. Call before simulating;
// returns how many particles were scaled (0 for ratio <= 0).
size_t scale_inertia(ClothModel& model, float ratio);

// A model under construction: particles and springs in any order. compile() sorts the springs by
// kind, builds the incidence lists, the colouring and the damping, and checks every index.
struct ClothSpec {
  Fabric fabric;
  std::vector<Vec3f> positions;
  std::vector<Vec2f> flat_positions;  // empty: derived from positions (x, z)
  std::vector<float> mass;            // kg per particle
  std::vector<float> drag_area;       // m^2 per particle
  std::vector<uint8_t> pinned;        // empty or one per particle
  std::vector<Tri> triangles;
  struct Spring {
    uint32_t a, b;
    float rest_length, stiffness;
    SpringKind kind;
  };
  std::vector<Spring> springs;
  struct Bend {
    uint32_t a, m, b;
    float stiffness;  // N m, see ClothModel::bend_stencil
  };
  std::vector<Bend> bends;  // weights from the flat positions
  // Kinds whose springs velocity / position modification limit (bit i = SpringKind i).
  uint32_t limited_kinds = 1u << static_cast<unsigned>(SpringKind::Structural);
  uint32_t grid_nx = 0, grid_ny = 0;
};
ClothModel compile(ClothSpec spec);
// Appends `part` (another piece of cloth: a panel) to `into`, its indices moved past into's particles.
// The two stay unjoined until springs between them (seams) are added. Returns the first index of part.
uint32_t append(ClothSpec& into, const ClothSpec& part);

// Rectangular-topology cloth (sec. 2.1): nx x ny particles over width x height metres, structural,
// shear and flexion springs exactly as the paper lists them. The cloth lies in the plane spanned by
// `u_axis` (weft, ix) and `v_axis` (warp, iy) through `origin` (the corner of particle 0).
struct GridClothOptions {
  uint32_t nx = 64, ny = 64;
  float width = 1.0f, height = 1.0f;
  Vec3f origin{-0.5f, 0.4f, -0.5f};
  Vec3f u_axis{1.0f, 0.0f, 0.0f};
  Vec3f v_axis{0.0f, 0.0f, 1.0f};
};
ClothSpec grid_cloth_spec(const Fabric& fabric, const GridClothOptions& options);
ClothModel grid_cloth(const Fabric& fabric, const GridClothOptions& options);

// Triangle-mesh cloth: a spring on every edge (structural), a bending spring across every interior
// edge between the two opposite vertices (flexion). Rest lengths, masses and warp/weft anisotropy
// come from the flat pattern coordinates (mesh.uvs, metres) when the mesh has them, else from the
// 3D positions. InputError(source, ...) for an empty mesh, bad indices or degenerate triangles.
ClothSpec mesh_cloth_spec(const Mesh& mesh, const Fabric& fabric, const std::string& source);
ClothModel mesh_cloth(const Mesh& mesh, const Fabric& fabric, const std::string& source);

// Why a simulation stopped being trustworthy. Sticky: once set, step() refuses to continue.
enum class StepStatus : uint8_t { Ok, NonFinite, Exploded };
std::string_view to_string(StepStatus status);

struct ClothState {
  std::vector<Vec3f> x;  // positions (m)
  std::vector<Vec3f> v;  // velocities (m/s)
  double time = 0;       // simulated seconds
  uint64_t iterations = 0;
  StepStatus status = StepStatus::Ok;
  // The implicit solver's static friction, carried from step to step: each particle's tangential
  // slip from where friction holds it (m, at most the slip at which it slides; empty: none).
  std::vector<Vec3f> friction_slip;
  // What rounding the implicit solver's positions to x left out: its double-precision positions are
  // x + x_rounding, carried into the next step (empty: none). A stiff spring at the strain
  // barrier turns the float rounding of its ends (~1e-8 m) into a force of several times a
  // particle's weight, which a step converged to a hundredth of one would otherwise start from.
  std::vector<Vec3f> x_rounding;
  // Measured at the end of the last step.
  float max_speed = 0;        // m/s
  double kinetic_energy = 0;  // J
};
// The model's rest layout, at rest.
ClothState initial_state(const ClothModel& model);

enum class StrainLimit : uint8_t { None, Position, Velocity };
std::string_view to_string(StrainLimit limit);
enum class CollisionResponse : uint8_t { Velocity, Force };

struct StepSettings {
  float time_step = 0;  // s; 0: the model's stable_time_step()
  Vec3f gravity{0.0f, -9.81f, 0.0f};
  StrainLimit strain_limit = StrainLimit::Velocity;
  float strain_threshold = 0.05f;  // fraction of rest length
  int strain_passes = 2;           // maximum Gauss-Seidel passes per step (1: the paper; 2 measured enough)
  // With Velocity limiting: Provot position-modification passes after the position update (0: none),
  // which pull back springs that velocity modification alone leaves past the threshold (it only
  // stops further stretching), e.g. where seam forces or contacts pulled them.
  int position_passes = 0;
  // With position modification (either kind): after the regular passes, further Gauss-Seidel passes
  // over only the springs still at or near the limit (and the joined pairs), until none is over it
  // by more than the tolerance or this many passes ran (0: none). A ring of springs (a waistband
  // held by its hoop tension) gives up a widening only at ~(pi/n)^2 per pass for n springs round it,
  // so holding it needs tens of passes, which would cost tens of full passes over the cloth. These
  // corrections also change the velocities by the displacement over the step (dx / dt), so use them
  // where corrections are small (draping), not where seams pull panels far past the limit.
  int converge_passes = 0;
  // After 16 converge passes that have not finished: at most this many Newton iterations of a
  // global projection of the springs at the limit back to it (0: none; project_to_limit in
  // strain_limit.cpp). Each solves the linearised constraints of all of them together by conjugate
  // gradients, so a ring converges in a few iterations over its few hundred springs where
  // Gauss-Seidel passes stall.
  int projection_iterations = 0;
  // In the converge passes a joined pair counts as a correction (one that keeps the passes going)
  // only when open by more than this (m; it is held whenever open by more than 0.01 mm). Where a
  // seam crosses a band on the hips, the pair's two particles have their own contact planes: holding
  // them together and keeping each out of the body opened them by 0.01-0.05 mm again on every pass,
  // so the passes never found nothing to correct and ran to their cap on every draping step (the
  // trousers: 3-9 such pairs a pass). 0: any pair held counts.
  float converge_pair_tolerance = 0.0f;
  // Viscous damping -gamma m v (1/s, sec. 2.2); negative: the fabric's air_damping. Quasi-static
  // draping raises it: the rest shape does not depend on it, only how fast the cloth gets there.
  float air_damping = -1.0f;
  // Particle pairs held together (sewn seams, sec. 6.2): in every strain-limit pass, after the
  // springs, each pair's ends get one velocity that closes their gap within the step (velocity
  // passes) and are moved to their mass-weighted mean (position passes). Pairs may share particles
  // (seams meeting at a corner); they run in the given order, on one thread.
  std::span<const std::array<uint32_t, 2>> joined_pairs{};
  // Coulomb coefficient of the velocity contact response; negative: the fabric's. (Sewing puts a
  // garment on with frictionless contact, as a tailor slides it into place.)
  float friction = -1.0f;
  // Velocity: eq. 5 with Coulomb friction, relative to the surface velocity, for static and slowly
  // moving bodies. Force: sec. 5's response for animated bodies, a force along the surface normal
  // proportional to the depth inside the collision thickness.
  CollisionResponse collision_response = CollisionResponse::Velocity;
  float max_speed = 50.0f;  // m/s; faster means the integration exploded
  // Faces over curved bodies: contacts keep the cloth's vertices collision_thickness off a body,
  // but the flat faces between them come nearer a convex part by the rise of the surface under
  // them (the skin shows through a coarse mesh at the shoulders). >= 0: particles in contact are kept
  // further off (by at most 6 mm) where the body's rise under their edges (structural and shear
  // springs, measured at each edge's midpoint) would bring a face nearer the body than this (m; 0:
  // faces may touch the skin, not pass it; above the collision thickness every particle in contact
  // is lifted by the difference as well). Negative: off, vertices only.
  float face_clearance = -1.0f;
};
// Settings with the fabric's strain threshold.
StepSettings default_step_settings(const ClothModel& model);

// Wall-clock seconds per stage, summed over steps, and what the stages measured.
struct StepProfile {
  enum Stage : uint8_t {
    UpdateColliders,
    DetectContacts,
    SpringForces,
    IntegrateVelocities,
    ContactForces,
    LimitStrainVelocity,
    RespondToContacts,
    IntegratePositions,
    LimitStrainPosition,
    CheckHealth,
    StageCount
  };
  std::array<double, StageCount> seconds{};
  uint64_t steps = 0;
  uint64_t strain_passes = 0;        // Gauss-Seidel passes run (velocity or position modification)
  uint64_t strain_corrections = 0;   // spring corrections applied in those passes
  uint64_t steps_at_pass_limit = 0;  // steps whose last pass still had to correct springs
  uint64_t contacts = 0;             // particle-steps in contact
  static std::string_view name(Stage stage);
  double total_seconds() const;
};

// Working memory for step(), sized for one model (and at most `max_colliders` colliders).
class StepScratch {
 public:
  StepScratch() = default;
  explicit StepScratch(const ClothModel& model, size_t max_colliders = 4);
  void resize(const ClothModel& model, size_t max_colliders = 4);

  std::vector<Vec3f> spring_force;        // per spring: force on its a end
  std::vector<ContactSample> contact;     // per particle: nearest contact this step
  std::vector<ContactSample> contact_tmp; // per particle: second and later colliders
  std::vector<float> contact_plane;       // per particle: d(x) = normal . x + plane, its contact's tangent plane
  std::vector<double> block_energy;       // per block: kinetic energy (fixed-order reduction)
  std::vector<float> block_speed;         // per block: max speed squared
  std::vector<uint32_t> block_count;      // per block: counters (contacts, corrections)
  std::vector<uint32_t> active_spring;    // strain-limited springs near the limit (converge passes)
  // The converge passes' regathering of that set: per particle the strain-limited springs touching
  // it (CSR), and one bit per strain-limited spring for the springs found near the limit.
  std::vector<uint32_t> limit_incident_begin, limit_incident;
  std::vector<uint64_t> near_limit_bits;
  std::vector<Vec3f> converge_start;      // per particle: position before the converge passes
  std::vector<Vec3f> step_start;          // per particle: position before this step's position update
  std::vector<uint32_t> changed_in_pass;  // per particle: 1 + the strain pass that last changed it
  // StepSettings::face_clearance: the edges measured this step (spring index, midpoint, its
  // contact; per block of edges, at the start of its range, block_measured of them), and per
  // particle the lift its edges need and the lift it has, which is carried from step to step (it
  // falls slowly: see lift_over_curvature).
  struct FaceLift {
    std::vector<uint32_t> edge, block_measured;
    std::vector<Vec3f> midpoint;
    std::vector<ContactSample> contact, contact_tmp;
    std::vector<float> need, lift;
  } face_lift;
  // The converge passes' global projection (strain_limit.cpp, project_to_limit): per particle its
  // node (the particles of joined pairs are one) and the node's inverse mass; per constraint row
  // (a spring at the limit) its nodes, direction and right-hand side, and the conjugate-gradient
  // vectors; per node the rows gathered (J^T v). Room for every strain-limited spring.
  struct Projection {
    std::vector<uint32_t> node, a, b, seam_row;
    std::vector<uint8_t> merged;
    std::vector<float> node_inverse_mass;
    std::vector<Vec3f> direction;
    std::vector<float> rhs, lambda, residual, search, product, diagonal;
    std::vector<Vec3f> gathered;
    std::vector<Vec3f> saved;  // per particle: positions before the current iteration
  } projection;
  size_t max_colliders = 0;
};

// Advances the state by one time step. Colliders are brought to the new time (update()), queried
// once per step, and answered with the chosen response. Returns the state's status: anything but
// Ok means the state is no longer physical and the caller must stop and report it.
StepStatus step(const ClothModel& model, ClothState& state, std::span<Collider* const> colliders,
                const StepSettings& settings, StepScratch& scratch, StepProfile* profile = nullptr);

// Pulls every strain-limited spring longer than (1 + settings.strain_threshold) l0 back to that
// length, and every pair in settings.joined_pairs together, by Gauss-Seidel position passes (at
// most `max_passes`, until nothing is over by more than 0.1 % strain); velocities are left as they
// are. For a change of regime, not for every step: a garment that the seam forces pulled past the
// limit while sewing is relaxed once before gravity and the converge passes (whose corrections go
// into the velocities) take over. Returns the passes run.
int relax_to_strain_limit(const ClothModel& model, ClothState& state, const StepSettings& settings, int max_passes);

// --- Measurements -------------------------------------------------------------------------------

// Stretch (l - l0) / l0 of one kind's springs (structural by default).
struct StrainStats {
  float max = 0;     // largest stretch
  float p99 = 0;     // 99th percentile of stretch
  float mean_abs = 0;
  float min = 0;     // largest compression (negative)
  float global = 0;  // (sum l - sum l0) / sum l0: whether the cloth as a whole grew
};
StrainStats strain_stats(const ClothModel& model, std::span<const Vec3f> x,
                         SpringKind kind = SpringKind::Structural);

// How many edges of the cloth's triangles pass through one of its triangles at `x`, leaving out
// triangles within twice the mean structural rest length of the edge's ends along the sewn cloth
// (where the cloth is continuous): 0 for a cloth that does not pass through itself.
size_t self_intersections(const ClothModel& model, std::span<const Vec3f> x);
// Per particle: the largest stretch of its incident springs of `kind` (for colouring pictures).
std::vector<float> particle_strain(const ClothModel& model, std::span<const Vec3f> x,
                                   SpringKind kind = SpringKind::Structural);

// Kinetic + spring potential energy (J), and the work gravity could still do (m g . x with g).
struct ClothEnergy {
  double kinetic = 0, elastic = 0, gravitational = 0;
  double total() const { return kinetic + elastic + gravitational; }
};
ClothEnergy cloth_energy(const ClothModel& model, const ClothState& state, const Vec3f& gravity);

// Sum of all spring forces (internal forces: zero up to rounding) and per-particle spring force.
std::vector<Vec3f> spring_forces_per_particle(const ClothModel& model, std::span<const Vec3f> x,
                                              std::span<const Vec3f> v);

// FNV-1a over the bits of positions and velocities: equal states, equal hashes.
uint64_t state_hash(const ClothState& state);

// The cloth as a mesh: current positions, TEXCOORD_0 = flat coordinates (metres), normals.
Mesh cloth_mesh(const ClothModel& model, const ClothState& state, std::string name = "cloth");

}  // namespace drape
