// `drape dress`: dresses a body in garments (Vassilev & Spanlang sec. 6) and writes DIR/dressed.glb,
// DIR/preview.png and DIR/report.json (DESIGN.md). With no arguments: the default female body in
// the default shirt, into ./out/. Exit 2 on bad input (nothing written), 3 when the dressing ran but
// failed a quality gate (outputs written, report.json's `gates.failed` names it).
#include <omp.h>

#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "commands.hpp"
#include "drape/dress.hpp"
#include "drape/error.hpp"
#include "drape/files.hpp"
#include "drape/size_advice.hpp"
#include "progress.hpp"

namespace drape::app {
namespace {

struct DressArgs {
  std::string body = "female";
  std::string measurements;
  std::vector<std::string> garments;
  std::vector<std::string> sizes;
  std::string fabric;
  float thickness = 0;
  float friction = -1;
  std::string collision = "image";
  std::string solver = std::string(to_string(DressOptions{}.solver));
  std::string mesher = "grid";
  double edge = kPaperEdgeLength;
  double coarse_edge = DressOptions{}.coarse_edge;
  int threads = 0;
  uint64_t max_iterations = 0;
  float mass_scaling = DressOptions{}.mass_scaling;
  float face_clearance = DressOptions{}.face_clearance;
  double sewing_stall = DressOptions{}.sewing_stall_s;
  float pull_closed = DressOptions{}.pull_closed_m;
  bool placement_only = false;
  bool soft_body = false;
  bool no_self_collision = false;
  std::string out = "out";
  LoadOptions load;
};

void run_dress(const DressArgs& a) {
  // Everything the user gave is checked before the (long) simulation starts.
  DressOptions o;
  const auto method = parse_collision_method(a.collision);
  if (!method) throw InputError("--collision", "'" + a.collision + "' is not image, bvh or sdf");
  o.collision = *method;
  o.solver = a.solver == "explicit" ? Solver::Explicit : Solver::Implicit;
  o.mesh.mesher = a.mesher == "triangle" ? Mesher::triangle : Mesher::grid;
  if (!(a.edge >= 0.002 && a.edge <= 0.2)) throw InputError("--edge", "the edge length must be in [0.002, 0.2] m");
  o.mesh.edge_length = a.edge;
  if (a.coarse_edge != 0 && !(a.coarse_edge >= 0.002 && a.coarse_edge <= 0.2))
    throw InputError("--coarse-edge", "the coarse edge length must be 0 (off) or in [0.002, 0.2] m");
  o.coarse_edge = a.coarse_edge;
  if (!a.fabric.empty()) o.fabric = fabric_or_throw(a.fabric).name;
  if (a.thickness != 0 && !(a.thickness >= 0.0005f && a.thickness <= 0.02f))
    throw InputError("--thickness", "the distance the cloth keeps from the body must be in [0.0005, 0.02] m");
  o.thickness = a.thickness;
  if (a.friction != -1 && !(a.friction >= 0 && a.friction <= 2))
    throw InputError("--friction", "the coefficient of friction must be in [0, 2]");
  o.friction = a.friction;
  o.max_iterations = a.max_iterations;
  if (!(a.mass_scaling >= 0 && a.mass_scaling <= 1))
    throw InputError("--mass-scaling", "must be in [0, 1] (a fraction of the median particle's time step; 0: off)");
  o.mass_scaling = a.mass_scaling;
  if (!(a.face_clearance <= 0.01)) throw InputError("--face-clearance", "must be at most 0.01 m (negative: off)");
  o.face_clearance = a.face_clearance;
  if (!(a.sewing_stall >= 0 && a.sewing_stall <= o.max_sewing_seconds))
    throw InputError("--sewing-stall", "must be in [0, 1.5] s (0: sew until every pair is joined or 1.5 s have passed)");
  o.sewing_stall_s = a.sewing_stall;
  if (!(a.pull_closed >= 0 && a.pull_closed <= o.sewing_stall_gap_m))
    throw InputError("--pull-closed", "must be in [0, 0.015] m (0: leave every open pair to the seam springs)");
  o.pull_closed_m = a.pull_closed;
  o.simulate = !a.placement_only;
  o.soft_body = a.soft_body;
  o.self_collision = !a.no_self_collision;
  if (a.soft_body && o.solver != Solver::Implicit) throw InputError("--soft-body", "needs the implicit solver (--solver implicit)");
  if (a.threads > 0) omp_set_num_threads(a.threads);

  std::vector<std::string> names = a.garments;
  if (names.empty()) names.push_back(default_garment_name());
  if (a.sizes.size() > 1 && a.sizes.size() != names.size())
    throw InputError("--size", "give one size for all garments or one per --garment");
  std::vector<GarmentRequest> requests;
  for (size_t i = 0; i < names.size(); ++i) {
    GarmentRequest r{load_garment(names[i]), a.sizes.empty() ? std::string() : a.sizes.size() == 1 ? a.sizes[0] : a.sizes[i]};
    garment_in_size(r.spec, r.size);  // validates the size now (InputError naming the file)
    requests.push_back(std::move(r));
  }
  const Body body = load_command_body(a.body, a.measurements, a.load);

  std::fprintf(stderr, "dressing a %.2f m body (%zu triangles) in", static_cast<double>(body.measurements.height),
               body.mesh.triangle_count());
  for (const GarmentRequest& r : requests)
    std::fprintf(stderr, " %s %s", r.spec.name.c_str(),
                 (r.size.empty() ? choose_size(r.spec, body.measurements).size : r.size).c_str());
  std::fprintf(stderr, " (collision %s, solver %s)\n", a.collision.c_str(), a.solver.c_str());

  Progress progress("dressing", 2.0 * static_cast<double>(requests.size()));
  // Per garment: sewing [0, 1), draping [1, 2); a coarse run (--coarse-edge) fills the sewing half
  // first and the bar does not step back when the fine garment's sewing begins.
  double shown = 0;
  const DressResult result = dress(body, requests, o, [&](const DressProgress& p) {
    const std::string_view name(p.phase);
    const double phase = name.ends_with("draping") ? 1.0 : 0.0;
    const double frac = p.phase_limit_seconds > 0 ? std::min(1.0, p.simulated_seconds / p.phase_limit_seconds) : 0.0;
    const double at = 2.0 * static_cast<double>(p.garment) + (name.starts_with("coarse") ? 0.5 * (phase + frac) : phase + frac);
    shown = std::max(shown, at);
    progress.update(shown, p.phase);
  });
  progress.finish();
  // The fit per region (docs/fit.md) goes into report.json's `fit` and onto the terminal.
  std::vector<Garment> made;
  for (size_t i = 0; i < requests.size() && i < result.garments.size(); ++i)
    made.push_back(garment_in_size(requests[i].spec, result.garments[i].size));
  const FitAnalysis fit = analyse_dress_fit(result.soft_body ? result.soft_body->body : body, result, made);
  write_dress_outputs(a.out, body, result, o);
  write_file_atomic(std::filesystem::path(a.out) / "report.json", report_with_fit(dress_report_json(body, result, o), fit));
  std::fprintf(stderr, "%s", fit_table(fit).c_str());
  if (result.soft_body) {
    std::fprintf(stderr, "soft body: %d rounds (last move %.2f mm), %.1f s\n", result.soft_body->rounds,
                 1e3 * static_cast<double>(result.soft_body->last_move_m), result.soft_body->seconds);
    for (const SoftRegionState& r : result.soft_body->regions)
      std::fprintf(stderr, "  %-16s pressed in %.1f mm, out %.1f mm, volume %+.2f %%\n", r.name.c_str(),
                   1e3 * static_cast<double>(r.compression_m), 1e3 * static_cast<double>(r.bulge_m), 100 * r.volume_change);
  }

  const FitQuality& q = result.quality;
  std::fprintf(stderr,
               "%s: %llu iterations in %.3f s (%.1f us each); max strain %.2f %%, seam gap max %.2f mm, "
               "%zu vertices inside the body, residual %.3f, %s\n",
               result.passed() ? "dressed" : "FAILED quality gates",
               static_cast<unsigned long long>(result.simulation.iterations), result.simulation.wall_seconds,
               1e6 * result.simulation.seconds_per_iteration, 100.0 * q.max_strain, 1e3 * q.max_seam_gap_m,
               q.penetrating_vertices, static_cast<double>(q.residual), q.settled ? "settled" : "not settled");
  if (q.skin_through.body_vertices > 0)
    std::fprintf(stderr, "skin shows through the cloth at %zu body vertices (up to %.1f mm; not a gate: report.json skin_through_cloth)\n",
                 q.skin_through.body_vertices, 1e3 * q.skin_through.max_depth_m);
  std::fprintf(stderr, "wrote %s/dressed.glb, preview.png, report.json\n", a.out.c_str());
  if (!result.passed()) {
    for (const GateResult& g : result.gates)
      if (!g.passed) std::fprintf(stderr, "drape: dress: gate %s failed: %s\n", g.name.c_str(), g.detail.c_str());
    // A seam that sewing could no longer close: name it, and say what that usually means (the
    // implicit solver sews and drapes to equilibrium: a seam open there, unless the run was capped,
    // is held open by the body).
    for (const DressedGarment& g : result.garments) {
      const size_t seam = g.widest_seam();
      if (seam >= g.seam_names.size() || g.seam_gaps()[seam] <= o.gates.max_seam_gap_m) continue;
      if (o.solver == Solver::Implicit) {
        if (o.max_iterations && g.state.iterations >= o.max_iterations) continue;
        std::fprintf(stderr,
                     "drape: dress: %s %s: seam '%s' stays %.1f mm open: the body holds it apart; a larger size "
                     "may fit\n",
                     g.name.c_str(), g.size.c_str(), g.seam_names[seam].c_str(), 1000.0 * g.seam_gaps()[seam]);
        continue;
      }
      if (!g.sewing_stalled || g.seam_gaps()[seam] <= o.seam_closed_m) continue;
      std::fprintf(stderr,
                   "drape: dress: %s %s: sewing stopped after %llu iterations with seam '%s' open: the cloth "
                   "around it was held at its stretch limit by the body; a larger size may fit\n",
                   g.name.c_str(), g.size.c_str(), static_cast<unsigned long long>(g.sewing_iterations),
                   g.seam_names[seam].c_str());
    }
    std::exit(kExitQualityGate);
  }
}

}  // namespace

// Settings only the explicit step uses: listed under their own heading in --help.
constexpr const char* kExplicitGroup = "Explicit solver (--solver explicit)";
// How the run goes rather than what is dressed: under their own heading in --help.
constexpr const char* kRunGroup = "Running and inspecting";

void add_dress_command(CLI::App& app) {
  auto args = std::make_shared<DressArgs>();
  CLI::App* cmd = app.add_subcommand(
      "dress", "Dress a body in garments: sew the cutting patterns around it, drape them, report the fit");
  cmd->add_option("--body", args->body, "female, male (built-in bodies) or a body file (OBJ, PLY, glTF, GLB)")
      ->capture_default_str();
  cmd->add_option("--measurements", args->measurements,
                  "build the body from measurements in metres, e.g. height=1.70,bust=0.92,waist=0.74,hips=0.98");
  cmd->add_option("--garment", args->garments,
                  "built-in garment name (see `drape garments`) or garment file; repeat for layers, outermost last");
  cmd->add_option("--size", args->sizes,
                  "size to make (one for all garments, or one per --garment); default: the size whose size chart "
                  "entry is nearest to the body's measurements (docs/garment-format.md), report.json says why");
  cmd->add_option("--fabric", args->fabric, "fabric preset overriding the garments' own: " + fabric_preset_names());
  cmd->add_option("--thickness", args->thickness,
                  "distance in metres the cloth keeps from the body and the garments beneath (its contact "
                  "thickness; default: the fabric's, 0.004 for the presets)");
  cmd->add_option("--friction", args->friction,
                  "Coulomb coefficient of friction of the cloth on the body and the garments beneath "
                  "(default: the fabric's, e.g. 0.3 for cotton; 0: frictionless)");
  cmd->add_option("--solver", args->solver,
                  "implicit (Newton on the incremental potential: quasi-static steps to equilibrium, the strain "
                  "limit, contact and friction inside the solve) or explicit (the paper's explicit Euler with "
                  "velocity modification, sec. 3.3, with the settings under its own heading below)")
      ->capture_default_str()->check(CLI::IsMember({"implicit", "explicit"}));
  cmd->add_flag("--no-self-collision", args->no_self_collision,
               "let the garment pass through itself while it drapes (implicit solver; by default its folds, "
               "collar and sleeves keep the fabric's contact thickness from the rest of it)");
  cmd->add_option("--collision", args->collision, "body collision: image (paper sec. 4.2), bvh (sec. 4.1) or sdf")
      ->capture_default_str()->check(CLI::IsMember({"image", "bvh", "sdf"}));
  cmd->add_option("--mesher", args->mesher, "grid (the paper's rectangular topology) or triangle")
      ->capture_default_str()->check(CLI::IsMember({"grid", "triangle"}));
  cmd->add_option("--edge", args->edge, "cloth edge length in metres (0.026 gives the paper's 1800-vertex shirt)")
      ->capture_default_str();
  cmd->add_option("--coarse-edge", args->coarse_edge,
                  "coarse-to-fine: a garment meshed more than 1.25x finer than this is first sewn and draped at "
                  "this edge length, and the --edge garment starts from it (e.g. 0.026: the shirt and skirt at "
                  "16x the paper's vertices ~2x faster; see docs/dressing.md); 0: off")
      ->capture_default_str()
      ->group(kRunGroup);
  cmd->add_option("--threads", args->threads, "OpenMP threads (0: all cores)")->check(CLI::Range(0, 1024))->group(kRunGroup);
  cmd->add_option("--max-iterations", args->max_iterations,
                  "stop each garment after this many iterations (0: no cap); a capped run fails the settled gate")
      ->group(kRunGroup);
  cmd->add_option("--mass-scaling", args->mass_scaling,
                  "particles whose stability bound is below this fraction of the median particle's get more inertia "
                  "(weight unchanged), for a longer time step; the state of rest is the same (0: off)")
      ->capture_default_str()
      ->group(kExplicitGroup);
  cmd->add_option("--sewing-stall", args->sewing_stall,
                  "stop sewing when for this many seconds of simulated time no seam pair was joined and the widest "
                  "open pair (over 15 mm) closed by less than 1 mm: the body holds it open, usually a size too small; "
                  "draping then starts with the seam springs still pulling (0: sew to the 1.5 s cap)")
      ->capture_default_str()
      ->group(kExplicitGroup);
  cmd->add_option("--pull-closed", args->pull_closed,
                  "when sewing ends, pull the seam pairs still open by at most this many metres closed and join them, "
                  "as a sewer closes the last stitches (the paper's seaming after a number of iterations); wider "
                  "pairs are left to the seam springs and reported (0: none)")
      ->capture_default_str()
      ->group(kExplicitGroup);
  cmd->add_option("--face-clearance", args->face_clearance,
                  "while draping, keep the cloth's faces, not only its vertices, this many metres off the body where "
                  "it curves under them (the particles are lifted by at most 6 mm; above the fabric's 4 mm "
                  "collision thickness every particle in contact is lifted by the difference), so the skin does "
                  "not show through a coarse mesh; negative: off")
      ->capture_default_str()
      ->group(kExplicitGroup);
  cmd->add_flag("--placement-only", args->placement_only,
                "write the garments where placement put them, before sewing (fails the settled gate)")
      ->group(kRunGroup);
  cmd->add_flag("--soft-body", args->soft_body,
                "let the body give way: its soft regions (belly, buttocks, thighs, bust, upper arms) are pressed in by the "
                "cloth and bulge elsewhere, keeping their volume (support springs, docs/soft-body.md); report.json soft_body");
  cmd->add_option("--out", args->out, "output directory")->capture_default_str();
  add_load_options(*cmd, args->load);
  cmd->callback([args] { run_dress(*args); });
}

}  // namespace drape::app
