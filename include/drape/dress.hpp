#pragma once
// Dressing a body in garments made from 2D cutting patterns (Vassilev & Spanlang sec. 6):
//
//   body -> garment in size -> meshed panels -> panels placed around the body -> one cloth model
//   with seam springs -> sewing (seam forces, no gravity, body collision) -> draping (gravity)
//   -> next garment (the dressed ones are colliders, sec. 6) -> quality.
//
// The pipeline is dress(); every stage is a public function so tests and benchmarks can run
// them one at a time. See docs/dressing.md for the placement, the sewing and settling criteria
// and the quality gates.
#include <algorithm>
#include <array>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "drape/body.hpp"
#include "drape/cloth.hpp"
#include "drape/collision.hpp"
#include "drape/fabric.hpp"
#include "drape/fit.hpp"
#include "drape/garment.hpp"
#include "drape/garment_transfer.hpp"
#include "drape/implicit.hpp"
#include "drape/scene.hpp"
#include "drape/soft_body.hpp"

namespace drape {

// Grid spacing that gives the built-in shirt about the paper's 1800 vertices (Table 2).
inline constexpr double kPaperEdgeLength = 0.026;

struct DressOptions {
  // implicit: Newton on the incremental potential, quasi-static steps to equilibrium (drape/implicit.hpp);
  // explicit: the paper's explicit Euler with velocity modification (sec. 3.3), and the settings
  // below that say they are its own (sewing stall, pulled-closed stitches, draping time and damping,
  // strain passes, time step, projection, mass scaling, face clearance).
  Solver solver = Solver::Implicit;
  // The implicit solver keeps the garment from passing through itself while it drapes (folds, a
  // collar, a sleeve's two layers; ImplicitSettings::self_collision). Sewing runs without it: panels
  // placed round the body overlap where they wrap, and their edges pass each other to meet.
  bool self_collision = true;
  CollisionMethod collision = CollisionMethod::image;
  MeshOptions mesh{Mesher::grid, kPaperEdgeLength};
  std::string fabric;  // empty: each garment's own
  // The fabric's contact with the body and with the garments beneath, overriding the fabric's own:
  // the distance its particles keep from them (m; 0: Fabric::collision_thickness) and its Coulomb
  // coefficient of friction on them (negative: Fabric::friction).
  float thickness = 0.0f;
  float friction = -1.0f;
  // Sewing: seam springs pull the pairs together with gravity off and frictionless contact; a pair
  // closer than `seam_closed_m` is joined (held together from then on); sewing ends when every pair
  // is joined, or after `max_sewing_seconds` of simulated time, or when it is stuck: over a window
  // of `sewing_stall_s` no pair was joined and the widest open pair, still wider than
  // `sewing_stall_gap_m`, closed by less than `sewing_stall_m`. That is a pair pressed on the body by
  // cloth at its limit, as at the crotch of jeans cut short for the body: gravity lets the cloth give
  // way, and the seam springs go on pulling while draping. Pairs within `sewing_stall_gap_m` keep
  // sewing, however slowly they close: several built-ins hover a millimetre or two above
  // `seam_closed_m` for most of a second before they join, and draping early left them open.
  // `sewing_stall_s` 0: sewing always runs to the cap.
  // When sewing ends with pairs still open, those open by at most `pull_closed_m` are pulled closed
  // (both particles to their mass-weighted mean position and velocity) and joined: the paper's "after a
  // certain number of iterations the patterns are seamed" (sec. 6.2), for the last stitches only. A
  // light corner pair whose seam spring is weaker than the cloth's tension hovers a few millimetres
  // open (the GarmentCode flare skirt's band side seam: 6.3 mm, never within seam_closed_m) and opens
  // further under gravity once draping starts (trousers L on the default male body: from under 10 mm
  // to 17.6 mm). Wider pairs, which the body holds apart, stay open and fail the seams gate. 0: off.
  float seam_closed_m = 0.005f;
  double max_sewing_seconds = 1.5;
  double sewing_stall_s = 0.2;
  float sewing_stall_m = 0.001f;
  float sewing_stall_gap_m = 0.015f;
  float pull_closed_m = 0.01f;  // at most sewing_stall_gap_m
  // Draping: gravity on until settled, for at most `max_drape_seconds` (5 s: a long hem hanging
  // from the hips creeps to rest at ~1/s under this damping, and several garments came to rest
  // between 2.5 and 3 s, so a 3 s cap decided them by rounding), with viscous damping
  // `drape_damping` (1/s; quasi-static draping: it changes how fast the rest shape is reached, not
  // the rest shape).
  double max_drape_seconds = 5.0;
  float drape_damping = 10.0f;
  // Settled: no vertex's net displacement over a window of `settle_window_s` of simulated time
  // exceeds `settle_distance_m` (an average speed below 1 cm/s for every vertex).
  float settle_distance_m = 0.001f;  // m
  double settle_window_s = 0.1;      // s
  // Strain limiting per step: velocity-modification passes (sec. 3.3), then Provot
  // position-modification passes that pull back what seam holds and contacts stretched.
  int strain_passes = 4;
  int position_passes = 4;
  // Time step: ClothModel::directional_stable_time_step() instead of stable_time_step() (eq. 4 with
  // each particle's stiffness along its stiffest direction: just as strict, ~1.15-1.35x longer
  // steps). Off by default: the longer step flips marginal cases (docs/dressing.md, Table 2).
  bool directional_time_step = false;
  // While draping: Newton iterations of the projection of the springs at the strain limit after 16
  // converge passes that have not finished (StepSettings::projection_iterations, docs/cloth.md). It
  // cuts the trousers' and the skirt's time by a third at Table 2's resolution, but at 4x the dress
  // did not settle with it, so it is off by default. 0: off.
  int projection_iterations = 0;
  // Selective mass scaling (scale_inertia(), docs/cloth.md): particles whose own stability bound is
  // below `mass_scaling` x the median particle's move as heavier particles (their weight unchanged),
  // so the step is set by the median particle, not by slivers of cells at the outline. Draping looks
  // for the state of rest, which does not depend on the inertia. 0: off.
  float mass_scaling = 0.85f;
  // Coarse-to-fine (docs/dressing.md, "Coarse-to-fine"): a garment meshed more than 1.25x finer than
  // `coarse_edge` is first sewn and draped at that grid spacing, and the fine garment starts from it
  // (each fine particle where its point of the flat pattern lies on the dressed coarse garment); it
  // then closes what the coarse seams left open and settles. The shirt and skirt at 4x and 16x the
  // paper's vertices take 1.6-2x less time. Off by default: the trousers at 16x end over the strain
  // limit, and the dress at 16x and the shirt at 16x on the 63.3k-triangle body do not settle.
  // 0: every garment starts from its placement.
  double coarse_edge = 0;
  // Faces over curved parts while draping (StepSettings::face_clearance): where the body rises
  // under the cloth's edges, its particles are kept further off, so that its faces stay this far
  // (m) off the skin and the skin does not show through a coarse mesh (the default shirt's
  // shoulders). Not while sewing: lifted panels kept seams open. Negative: off.
  float face_clearance = 0.0f;
  // Every garment's placement moved by this much (m) before sewing: a start a little off where
  // placement puts it, as the robustness tests dress from (a garment must not depend on it).
  Vec3f placement_offset = Vec3f::Zero();
  // Cap on iterations per garment over both phases (0: none). A run stopped by it is unsettled.
  uint64_t max_iterations = 0;
  // false: stop after placement (to inspect where the panels start); the run is not settled.
  bool simulate = true;
  QualityGates gates{};
  // A body that gives way (drape/soft_body.hpp, docs/soft-body.md): after dressing, the cloth's
  // pressure presses the body's soft regions in (support springs), the garments settle again on the
  // body as it gave way, and so on until the body moves less than `soft_body_settled_m` in a round
  // (at most `soft_body_rounds`); contact forces on cloth and body are equal and opposite at the
  // end. The implicit solver only.
  bool soft_body = false;
  SoftBodyOptions soft;
  int soft_body_rounds = 4;
  float soft_body_settled_m = 0.0005f;
  // Garments dressed before on other bodies of this body's mesh (drape/garment_transfer.hpp): a
  // garment with a matching transfer (its name, size and particle count, the body's mesh) starts
  // where the first such transfer puts it on this body instead of from its placement, and drapes
  // from there. The implicit solver only.
  std::vector<std::shared_ptr<const GarmentTransfer>> transfers;
};

// Where a panel ended up and why.
struct PanelPlacement {
  std::string panel;
  std::string region;   // "torso", "left_arm", ... or "transform" (the file's 3D placement)
  float clearance = 0;  // m, after growing it to clear the body
  size_t vertices_touching = 0;  // vertices still within the collision thickness after placement
};

// One garment put on the body.
struct DressedGarment {
  std::string name, size, fabric;
  std::string size_reason;  // why this size: asked for, nearest in the size chart, or the base size
  ClothModel model;
  ClothState state;
  std::vector<std::array<uint32_t, 2>> seam_pairs;  // particle pairs sewn together
  std::vector<uint32_t> seam_of_pair;               // per pair: index into seam_names
  std::vector<std::string> seam_names;              // the garment's seams, in file order
  std::vector<uint32_t> panel_first_vertex;         // particle range of each panel (+ end)
  std::vector<std::string> panel_names;
  std::vector<PanelPlacement> placement;

  // Measured on the way.
  uint64_t sewing_iterations = 0, drape_iterations = 0;
  bool sewing_stalled = false;  // sewing ended with pairs open that no longer closed (DressOptions::sewing_stall_s)
  size_t pulled_closed = 0;     // pairs pulled closed when sewing ended (DressOptions::pull_closed_m)
  // Coarse-to-fine (DressOptions::coarse_edge): the coarse run this garment started from.
  struct CoarseRun {
    double edge = 0;            // m, 0: none (started from the placement)
    size_t vertices = 0;
    uint64_t iterations = 0;
    double wall_seconds = 0;    // sewing and draping
    double setup_seconds = 0;   // meshing, placement
    bool seams_closed = false, settled = false;
    StepStatus status = StepStatus::Ok;
    size_t extrapolated = 0;    // fine particles outside every coarse triangle
    float start_max_gap = 0;    // m, widest seam gap the fine garment started from
  } coarse;
  float sewn_max_strain = 0;   // structural strain when sewing ended (the seams may pull past the limit)
  int relax_passes = 0;        // position passes that relaxed the sewn garment to the strain limit (0: none needed)
  size_t mass_scaled = 0;      // particles given more inertia by DressOptions::mass_scaling
  double sewing_seconds = 0, drape_seconds = 0;  // wall
  bool seams_closed = false, settled = false;
  StepStatus status = StepStatus::Ok;
  float initial_max_gap = 0;   // m, right after placement (prepare_garment) or the transfer
  bool transferred = false;    // started from a garment dressed on another body (DressOptions::transfers)
  bool transfer_failed = false;  // a transferred start ended outside the gates: dressed again from the placement
  float time_step = 0;         // s
  float placed_centre_y = 0, sewn_centre_y = 0, final_centre_y = 0;  // m, the centre of mass's height
  StepProfile profile;                // explicit solver
  ImplicitProfile implicit_profile;   // implicit solver
  float residual = 0;                 // largest |net force| / (m g) over the particles at the end
  size_t self_intersections = 0;      // edges through a triangle of the garment at the end (self_intersections())

  // How far the centre of mass fell from where placement put the garment to the end (0 if it rose):
  // a garment that slid down the body. Measured from the placement, not from the end of sewing:
  // sewing has no gravity, so a flared hem sewn into a cone stands out like a lampshade and only
  // hangs once draping starts (the GarmentCode flare skirt's centre rises 0.14 m while sewing and
  // falls 0.19 m while draping, its waistband 3 cm); that fall is the skirt hanging, not sliding.
  float drop_m() const { return std::max(0.0f, placed_centre_y - final_centre_y); }

  Mesh mesh() const;  // positions, normals, TEXCOORD_0 = flat pattern coordinates (m)
  std::vector<float> seam_gaps() const;  // per seam (seam_names): the widest gap of its pairs now, m
  size_t widest_seam() const;            // the seam with the widest gap (seam_names.size() if none)
};

struct DressProgress {
  size_t garment = 0, garments = 0;
  const char* phase = "";  // "sewing" or "draping"
  uint64_t iterations = 0;
  double simulated_seconds = 0, phase_limit_seconds = 0;
};
using DressProgressCallback = std::function<void(const DressProgress&)>;

// The soft body at the end of a dressing (DressOptions::soft_body).
struct SoftBodyResult {
  Body body;                             // the body as the garments left it: its soft regions given way
  std::vector<SoftRegionState> regions;  // per soft region: volume change, compression
  int rounds = 0;                        // body-and-cloth rounds run
  float last_move_m = 0;                 // the body's largest move in the last round
  double seconds = 0;                    // wall time of the rounds (body solves and re-draping)
};

struct DressResult {
  std::vector<DressedGarment> garments;  // innermost first
  FitQuality quality;
  SimulationSummary simulation;
  std::vector<GateResult> gates;
  double setup_seconds = 0;  // body analysis, meshing, placement, colliders (not in Table 2's times)
  std::optional<SoftBodyResult> soft_body;  // with DressOptions::soft_body
  bool passed() const { return all_passed(gates); }
};

// A garment request: a loaded spec and the size to make (empty: the size for the body, choose_size).
struct GarmentRequest {
  GarmentSpec spec;
  std::string size;
};

// The size a garment is made in for a body when none is asked for: the size whose size-chart entry
// is nearest to the body's measurements (root mean square of the relative differences over the
// entry's measurements, as a shop's size chart is read); the spec's base size when it has no chart
// or the body has none of the chart's measurements. `reason` says which and by how much.
struct SizeChoice {
  std::string size;
  std::string reason;
};
SizeChoice choose_size(const GarmentSpec& spec, const Measurements& body);

// --- The stages ---------------------------------------------------------------------------------

// Panels meshed flat (stage 2) and rolled around the body (stage 3): a cloth model whose springs
// include zero-length seam springs between the sewn pairs (stage 4), ready to sew.
DressedGarment prepare_garment(const Body& body, const Garment& garment, const Collider& body_collider,
                               const DressOptions& options);

// Instead of its placement, the garment starts where the first matching transfer puts it on `body`,
// every particle at least the fabric's thickness outside it (DressedGarment::transferred says
// whether one matched).
void start_from_transfer(DressedGarment& garment, const Body& body, const Collider& body_collider,
                         std::span<const std::shared_ptr<const GarmentTransfer>> transfers);

// Stages 5: sews then drapes `garment` on the colliders (body first, then dressed garments).
void sew_and_drape(DressedGarment& garment, std::span<Collider* const> colliders, const DressOptions& options,
                   const DressProgressCallback& progress = {}, size_t index = 0, size_t count = 1);

// Stage 5 with the implicit solver: quasi-static sewing, then draping to equilibrium (sew_implicit.cpp).
void sew_and_drape_implicit(DressedGarment& garment, std::span<Collider* const> colliders, const DressOptions& options,
                            const DressProgressCallback& progress = {}, size_t index = 0, size_t count = 1);

// A dressed garment as a collider for the next layer: its surface pushed out by its thickness.
std::unique_ptr<Collider> garment_collider(const DressedGarment& garment);

// The same for a garment in motion: its surface follows `positions` (its particles, which must
// outlive the collider), read at each update to a new time, with their velocity since the last.
std::unique_ptr<Collider> moving_garment_collider(const DressedGarment& garment, const std::vector<Vec3f>& positions);

// How many of an outer garment's vertices have gone through the inner garment (at
// `inner_positions`): more than `tolerance` past its surface, on the body's side (within 2 cm of
// it; the side from its angle-weighted pseudo-normals).
size_t vertices_beneath(const DressedGarment& inner, std::span<const Vec3f> inner_positions,
                        std::span<const Vec3f> outer, float tolerance = 0.002f);

// Stage 7: quality over all garments against the body.
FitQuality measure_fit(const Body& body, std::span<const DressedGarment> garments);

// The whole pipeline. Layer order = request order (innermost first). Throws InputError for bad
// garments (naming the file) and for meshing failures.
DressResult dress(const Body& body, const std::vector<GarmentRequest>& garments, const DressOptions& options = {},
                  const DressProgressCallback& progress = {});

// --- Outputs --------------------------------------------------------------------------------------

// glTF scene: node `body`, then one node per garment (named after it).
Scene dressed_scene(const Body& body, const DressResult& result);
// report.json text: DESIGN.md's keys, gates, per-garment details and the stage profile.
std::string dress_report_json(const Body& body, const DressResult& result, const DressOptions& options);
// What preview.png draws, copied out of a dressing so that it can be drawn later (the web service
// draws it once the shopper has the dressed body): the body and the garments as dressed, and each
// garment particle's structural strain.
struct DressPreview {
  Mesh body;
  std::vector<Mesh> garments;
  std::vector<std::vector<float>> strain;  // per garment, per particle
  float strain_threshold = 0.05f;          // the strain row's scale ends 1 % above it
};
DressPreview dress_preview(const Body& body, const DressResult& result);
// preview.png: front, side and back; a second row coloured by structural strain.
std::vector<uint8_t> encode_preview_png(const DressPreview& preview);

enum class PreviewOutput : uint8_t { Write, Leave };
// Writes dressed.glb, preview.png (unless left for later) and report.json into `dir`, each
// atomically.
void write_dress_outputs(const std::filesystem::path& dir, const Body& body, const DressResult& result,
                         const DressOptions& options, PreviewOutput preview = PreviewOutput::Write);

}  // namespace drape
