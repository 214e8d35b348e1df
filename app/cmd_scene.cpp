// `drape scene sphere|table`: Vassilev & Spanlang fig. 7. Drops a square cloth over a sphere or a
// table, runs until it settles and writes DIR/report.json (DESIGN.md's quality and simulation
// keys), DIR/scene.glb and DIR/preview.png. Exit 3 when a gate failed (NaN, explosion, not settled).
// `drape scene sew`: ../shared/peers' sewing scene, two panels sewn into a tube round a cylinder
// (drape/cloth_scene.hpp), on the implicit solver; the same outputs with the seams' gaps.
// `drape scene cusick`: the Cusick drape test of a fabric (drape/cusick.hpp), the same outputs with
// the drape coefficient in report.json and the specimen's shadow in preview.png.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <numbers>
#include <optional>
#include <nlohmann/json.hpp>
#include <string>

#include "commands.hpp"
#include "drape/cloth_scene.hpp"
#include "drape/cusick.hpp"
#include "drape/implicit.hpp"
#include "drape/error.hpp"
#include "drape/files.hpp"
#include "drape/io.hpp"
#include "drape/render.hpp"

namespace drape::app {
namespace {

struct SceneArgs {
  std::string obstacle = "sphere";
  uint32_t n = 64;
  std::string strain_limit = "velocity";
  float threshold = -1;
  int passes = 2;
  std::string fabric = "cotton";
  float time_step = 0;
  std::string solver;  // empty: explicit for sphere and table, implicit for sew and cusick
  double max_time = 12;
  double edge = 0.01;
  std::string out = "out";
  bool compare = true;
};

// One finished run of the scene, for the report and the picture.
struct Finished {
  ClothScene scene;
  SceneRun run;
  SceneQuality quality;
  std::string label;
};

Finished simulate(const ClothSceneOptions& o, double max_time, const std::string& label) {
  Finished f{make_cloth_scene(o), {}, {}, label};
  const float dt = f.scene.time_step();
  std::fprintf(stderr, "scene %s: %zu particles (%s), %s solver, %s, dt %.3g s\n", std::string(to_string(o.obstacle)).c_str(),
               f.scene.model.particle_count(), o.fabric.name.c_str(), std::string(to_string(o.solver)).c_str(), label.c_str(), dt);
  SettleCriteria settle;
  settle.max_time = max_time;
  f.run = run_until_settled(f.scene, settle, [](const ClothState& s) {
    std::fprintf(stderr, "  t = %5.2f s  iterations %8llu  max speed %.3f m/s\n", s.time,
                 static_cast<unsigned long long>(s.iterations), s.max_speed);
  });
  f.quality = scene_quality(f.scene);
  std::fprintf(stderr, "  %s after %llu iterations (%.2f s simulated, %.2f s wall): max strain %.4f, p99 %.4f, %zu inside",
               f.run.status != StepStatus::Ok ? "FAILED" : f.run.settled ? "settled" : "NOT settled",
               static_cast<unsigned long long>(f.run.iterations), f.scene.state.time, f.run.wall_seconds,
               f.quality.strain.max, f.quality.strain.p99, f.quality.penetrating_vertices);
  if (!f.scene.seam_pairs.empty()) std::fprintf(stderr, ", widest seam %.2f mm", 1e3 * f.quality.max_seam_gap);
  std::fprintf(stderr, "\n");
  return f;
}

std::string limit_label(StrainLimit limit, float threshold, Solver solver) {
  if (limit == StrainLimit::None) return "no strain limit";
  char buf[96];
  if (solver == Solver::Implicit)
    std::snprintf(buf, sizeof buf, "strain limit at %.3g %% (in the solve)", 100.0 * threshold);
  else
    std::snprintf(buf, sizeof buf, "%s modification at %.3g %%", limit == StrainLimit::Velocity ? "velocity" : "position",
                  100.0 * threshold);
  return buf;
}

// The cloth coloured by structural strain (white unstretched, red stretched), over the obstacle.
Image picture(const Finished& f, float strain_range) {
  const Mesh cloth = cloth_mesh(f.scene.model, f.scene.state);
  const Mesh body = f.scene.obstacle_mesh();
  RenderItem cloth_item = garment_item(cloth, 0);
  const std::vector<float> strain = particle_strain(f.scene.model, f.scene.state.x);
  cloth_item.vertex_colors = colorize(strain, ColorMap::kBlueWhiteRed, -strain_range, strain_range);
  RenderOptions options;
  options.width = 960;
  options.height = 480;
  options.views = {{"front", 0.0f}, {"three-quarter", 45.0f}};
  options.elevation_degrees = 25.0f;
  options.pixels_per_metre = 330.0f;
  char title[160];
  std::snprintf(title, sizeof title, "%s: max strain %.1f %%, p99 %.1f %%", f.label.c_str(), 100.0 * f.quality.strain.max,
                100.0 * f.quality.strain.p99);
  options.title = title;
  options.legend = Legend{"structural strain", ColorMap::kBlueWhiteRed, -strain_range, strain_range};
  return render_views({body_item(body), cloth_item}, options);
}

nlohmann::json strain_json(const StrainStats& s) {
  return {{"max", s.max}, {"p99", s.p99}, {"mean_abs", s.mean_abs}, {"min", s.min}, {"global", s.global}};
}

// The specimen's shadow seen from above, as the tester's light casts it: the specimen's flat
// outline and the support disc drawn over it. `pixels` across the specimen's diameter.
Image shadow_picture(const CusickResult& r, double specimen_radius, int pixels) {
  const int size = pixels + 40;
  Image image(size, size, Vec3f::Ones());
  const double scale = pixels / (2.0 * specimen_radius);  // pixels per metre
  const double centre = 0.5 * size;
  const auto put = [&](int x, int y, const Vec3f& linear) {
    if (x < 0 || y < 0 || x >= size || y >= size) return;
    uint8_t* p = image.pixel(x, y);
    for (int k = 0; k < 3; ++k) p[k] = static_cast<uint8_t>(std::lround(255.0f * linear_to_srgb(linear[k])));
  };
  // The shadow, one cell per pixel (the picture's y is the scene's z).
  const double cell = 1.0 / scale, corner = -centre * cell;
  const std::vector<uint8_t> shadow =
      shadow_raster(r.specimen.state.x, r.specimen.model.triangles, corner, corner, cell, size, size);
  const Vec3f shade = srgb8(70, 78, 96);
  for (int py = 0; py < size; ++py)
    for (int px = 0; px < size; ++px)
      if (shadow[static_cast<size_t>(py) * static_cast<size_t>(size) + static_cast<size_t>(px)]) put(px, py, shade);
  // The flat specimen's outline and the support disc.
  const auto circle = [&](double radius, const Vec3f& colour) {
    const int steps = static_cast<int>(8 * radius * scale) + 16;
    for (int k = 0; k < steps; ++k) {
      const double a = 2 * std::numbers::pi * k / steps;
      put(static_cast<int>(centre + radius * scale * std::cos(a)), static_cast<int>(centre + radius * scale * std::sin(a)), colour);
    }
  };
  circle(specimen_radius, srgb8(40, 40, 40));
  circle(r.support->radius(), srgb8(230, 160, 40));
  return image;
}

void run_cusick_scene(const SceneArgs& a) {
  CusickOptions o;
  o.fabric = fabric_or_throw(a.fabric);
  o.solver = a.solver == "explicit" ? Solver::Explicit : Solver::Implicit;
  o.edge_length = a.edge;
  if (!(a.max_time > 0 && a.max_time <= 600)) throw InputError("--max-time", "must be in (0, 600] s");
  o.max_seconds = a.max_time;
  std::fprintf(stderr, "scene cusick: %s, a %.0f cm disc on a %.0f cm support, %s solver, grid %.3g m\n",
               o.fabric.name.c_str(), 100 * o.specimen_diameter, 100 * o.support_diameter,
               std::string(to_string(o.solver)).c_str(), o.edge_length);
  const CusickResult r = run_cusick(o, [](const DressProgress& p) {
    std::fprintf(stderr, "  %s: t = %5.2f s  iterations %6llu\n", p.phase, p.simulated_seconds,
                 static_cast<unsigned long long>(p.iterations));
  });
  const DressedGarment& g = r.specimen;
  const StrainStats strain = strain_stats(g.model, g.state.x, SpringKind::Structural);
  size_t inside = 0;
  float deepest = 0;
  for (const Vec3f& p : g.state.x) {
    const float d = r.support->signed_distance(p, nullptr);
    if (d < 0) {
      ++inside;
      deepest = std::max(deepest, -d);
    }
  }
  const double wall = r.wall_seconds;
  const uint64_t iterations = g.state.iterations;
  std::fprintf(stderr, "  %s after %llu iterations (%.2f s wall): drape coefficient %.1f %%, %d nodes, max strain %.2f %%\n",
               g.status != StepStatus::Ok ? "FAILED" : g.settled ? "settled" : "NOT settled",
               static_cast<unsigned long long>(iterations), wall, 100 * r.drape_coefficient, r.nodes, 100 * strain.max);

  nlohmann::json report;
  report["drape_coefficient"] = r.drape_coefficient;
  report["nodes"] = r.nodes;
  report["areas_m2"] = {{"specimen", r.specimen_area}, {"support", r.support_area}, {"shadow", r.shadow_area}};
  report["quality"] = {{"max_strain", strain.max},
                       {"p99_strain", strain.p99},
                       {"penetrating_vertices", inside},
                       {"penetration_fraction", g.state.x.empty() ? 0.0 : static_cast<double>(inside) / static_cast<double>(g.state.x.size())},
                       {"max_penetration_m", deepest},
                       {"max_seam_gap_m", 0.0},
                       {"mean_seam_gap_m", 0.0},
                       {"settled", g.settled},
                       {"residual", g.residual}};
  report["simulation"] = {{"iterations", iterations},
                          {"time_step_s", g.time_step},
                          {"wall_seconds", wall},
                          {"seconds_per_iteration", iterations ? wall / static_cast<double>(iterations) : 0.0},
                          {"simulated_seconds", g.state.time},
                          {"status", std::string(to_string(g.status))},
                          {"vertices", g.model.particle_count()},
                          {"springs", g.model.spring_count()}};
  if (o.solver == Solver::Implicit)
    report["simulation"]["newton_iterations"] = g.implicit_profile.newton_iterations;
  report["scene"] = {{"obstacle", "cusick"},
                     {"fabric", o.fabric.name},
                     {"solver", std::string(to_string(o.solver))},
                     {"specimen_diameter_m", o.specimen_diameter},
                     {"support_diameter_m", o.support_diameter},
                     {"edge_length_m", o.edge_length}};
  report["gates"] = {{"finite", g.status == StepStatus::Ok}, {"settled", g.settled}};

  const std::filesystem::path dir(a.out);
  if (g.status != StepStatus::NonFinite) {
    Scene gltf;
    const Mesh cloth = g.mesh(), support = r.support->mesh();
    add_mesh_node(gltf, cloth, "cloth");
    add_mesh_node(gltf, support, "body");
    write_scene(dir / "scene.glb", gltf);
    RenderOptions view;
    view.width = 640;
    view.height = 480;
    view.views = {{"three-quarter", 30.0f}};
    view.elevation_degrees = 25.0f;
    view.floor_shadow = false;
    view.view_labels = false;
    const Image side = render_views({body_item(support), garment_item(cloth, 0)}, view);
    char caption[160];
    std::snprintf(caption, sizeof caption, "%s: drape coefficient %.1f %%, %d nodes", o.fabric.name.c_str(),
                  100 * r.drape_coefficient, r.nodes);
    write_png(dir / "preview.png", compose_side_by_side({side, shadow_picture(r, 0.5 * o.specimen_diameter, 440)},
                                                        {caption, "shadow from above (circles: specimen, support)"}));
  }
  write_file_atomic(dir / "report.json", report.dump(2) + "\n");
  if (g.status != StepStatus::Ok) {
    std::fprintf(stderr, "drape: scene: simulation failed: %s\n", std::string(to_string(g.status)).c_str());
    std::exit(kExitQualityGate);
  }
  if (!g.settled) {
    std::fprintf(stderr, "drape: scene: the specimen did not settle\n");
    std::exit(kExitQualityGate);
  }
}

void run_scene(const SceneArgs& a) {
  if (a.obstacle == "cusick") return run_cusick_scene(a);
  ClothSceneOptions o;
  static const std::map<std::string, SceneObstacle> obstacles = {
      {"sphere", SceneObstacle::Sphere}, {"table", SceneObstacle::Table}, {"sew", SceneObstacle::Sew}};
  const auto obstacle = obstacles.find(a.obstacle);
  if (obstacle == obstacles.end())
    throw InputError("scene", "unknown scene '" + a.obstacle + "' (sphere, table, sew or cusick)");
  o.obstacle = obstacle->second;
  const bool sew = o.obstacle == SceneObstacle::Sew;
  o.n = a.n;
  o.fabric = fabric_or_throw(a.fabric);
  static const std::map<std::string, StrainLimit> limits = {
      {"none", StrainLimit::None}, {"position", StrainLimit::Position}, {"velocity", StrainLimit::Velocity}};
  const auto limit = limits.find(a.strain_limit);
  if (limit == limits.end()) throw InputError("--strain-limit", "'" + a.strain_limit + "' is not none, position or velocity");
  o.strain_limit = limit->second;
  o.strain_threshold = a.threshold;
  o.strain_passes = a.passes;
  if (!(a.time_step >= 0 && a.time_step < 0.1f)) throw InputError("--dt", "the time step must be in [0, 0.1) s");
  o.time_step = a.time_step;
  // Empty: explicit for fig. 7's scenes, implicit for sewing (its 1000 N/m seams on particles of a
  // few grams hold the explicit step to steps of about 0.1 ms).
  o.solver = a.solver == "implicit" || (sew && a.solver.empty()) ? Solver::Implicit : Solver::Explicit;
  if (!(a.max_time > 0 && a.max_time <= 600)) throw InputError("--max-time", "must be in (0, 600] s");
  const float threshold = a.threshold >= 0 ? a.threshold : o.fabric.strain_threshold;

  Finished main_run = simulate(o, a.max_time, limit_label(o.strain_limit, threshold, o.solver));
  // The paper's point in one picture: the same cloth without a limit, or with velocity modification.
  std::optional<Finished> other;
  if (a.compare && !sew) {
    ClothSceneOptions c = o;
    c.strain_limit = o.strain_limit == StrainLimit::None ? StrainLimit::Velocity : StrainLimit::None;
    other = simulate(c, a.max_time, limit_label(c.strain_limit, threshold, c.solver));
  }
  const ClothScene& scene = main_run.scene;
  const SceneRun& run = main_run.run;
  const SceneQuality& q = main_run.quality;
  const float dt = scene.time_step();

  // report.json: DESIGN.md's quality and simulation keys, then what this scene adds.
  nlohmann::json report;
  report["quality"] = {{"max_strain", q.strain.max},
                       {"p99_strain", q.strain.p99},
                       {"penetrating_vertices", q.penetrating_vertices},
                       {"penetration_fraction", q.penetration_fraction},
                       {"max_penetration_m", q.max_penetration},
                       {"max_seam_gap_m", q.max_seam_gap},
                       {"mean_seam_gap_m", q.mean_seam_gap},
                       {"settled", run.settled},
                       {"residual", ImplicitSolver(scene.model, scene.colliders.size())
                                        .residual(scene.state.x, scene.colliders,
                                                  scene.implicit ? scene.implicit_settings : default_implicit_settings(scene.model))}};
  const auto per_iteration = [&](double total) { return run.iterations ? total / static_cast<double>(run.iterations) : 0.0; };
  report["simulation"] = {{"iterations", run.iterations},
                          {"time_step_s", dt},
                          {"wall_seconds", run.wall_seconds},
                          {"seconds_per_iteration", per_iteration(run.wall_seconds)},
                          {"simulated_seconds", scene.state.time},
                          {"settled_at_s", run.settled ? nlohmann::json(run.settled_at) : nlohmann::json(nullptr)},
                          {"status", std::string(to_string(run.status))},
                          {"vertices", scene.model.particle_count()},
                          {"springs", scene.model.spring_count()},
                          {"seam_pairs", scene.seam_pairs.size()},
                          {"strain_passes_per_iteration", per_iteration(static_cast<double>(run.profile.strain_passes))},
                          {"iterations_at_pass_limit", run.profile.steps_at_pass_limit},
                          {"contacts_per_iteration", per_iteration(static_cast<double>(run.profile.contacts))}};
  nlohmann::json stages;
  for (int st = 0; st < StepProfile::StageCount; ++st)
    stages[std::string(StepProfile::name(static_cast<StepProfile::Stage>(st)))] = run.profile.seconds[st];
  report["simulation"]["stage_seconds"] = stages;
  if (scene.implicit) {
    const ImplicitProfile& p = run.implicit_profile;
    report["simulation"]["newton_iterations"] = p.newton_iterations;
    report["simulation"]["factorizations"] = p.factorizations;
    report["simulation"]["implicit_stage_seconds"] = {{"contacts", p.contacts}, {"assemble", p.assemble},
                                                      {"factorize", p.factorize}, {"solve", p.solve},
                                                      {"line_search", p.line_search}, {"block_sweeps", p.sweeps}};
    report["simulation"]["block_sweeps"] = p.block_sweeps;
  }
  report["scene"] = {{"obstacle", a.obstacle},
                     {"n", a.n},
                     {"fabric", o.fabric.name},
                     {"strain_limit", a.strain_limit},
                     {"strain_threshold", threshold},
                     {"strain_passes", a.passes}};
  report["strain"] = {{"structural", strain_json(q.strain)},
                      {"shear", strain_json(strain_stats(scene.model, scene.state.x, SpringKind::Shear))}};
  report["gates"] = {{"finite", run.status == StepStatus::Ok}, {"settled", run.settled}};
  if (other)
    report["comparison"] = {{"strain_limit", std::string(to_string(other->scene.settings.strain_limit))},
                            {"max_strain", other->quality.strain.max},
                            {"p99_strain", other->quality.strain.p99},
                            {"global_strain", other->quality.strain.global},
                            {"settled", other->run.settled},
                            {"iterations", other->run.iterations}};

  // scene.glb and preview.png need finite positions; a failed run writes its report only.
  const std::filesystem::path dir(a.out);
  const bool finite = run.status != StepStatus::NonFinite && (!other || other->run.status != StepStatus::NonFinite);
  if (finite) {
    Scene gltf;
    add_mesh_node(gltf, cloth_mesh(scene.model, scene.state), "cloth");
    add_mesh_node(gltf, scene.obstacle_mesh(), "body");
    write_scene(dir / "scene.glb", gltf);
    const float range = std::max(0.1f, 2.0f * threshold);
    if (other) {
      const Finished& unlimited = o.strain_limit == StrainLimit::None ? main_run : *other;
      const Finished& limited = o.strain_limit == StrainLimit::None ? *other : main_run;
      write_png(dir / "preview.png", compose_side_by_side({picture(unlimited, range), picture(limited, range)}, {}));
    } else {
      write_png(dir / "preview.png", picture(main_run, range));
    }
  }
  write_file_atomic(dir / "report.json", report.dump(2) + "\n");

  if (run.status != StepStatus::Ok) {
    std::fprintf(stderr, "drape: scene: simulation failed: %s\n", std::string(to_string(run.status)).c_str());
    std::exit(kExitQualityGate);
  }
  if (!run.settled) {
    std::fprintf(stderr, "drape: scene: the cloth did not settle within %.3g s\n", a.max_time);
    std::exit(kExitQualityGate);
  }
}

}  // namespace

void add_scene_command(CLI::App& app) {
  auto args = std::make_shared<SceneArgs>();
  CLI::App* cmd = app.add_subcommand(
      "scene", "Drop a square cloth over a sphere or a table (paper fig. 7), sew two panels round a cylinder, or hang a "
               "fabric in the Cusick drape test, until it settles");
  cmd->add_option("obstacle", args->obstacle,
                  "sphere or table (fig. 7); sew: two 0.5 x 0.6 m panels sewn at their sides and shoulders into a tube "
                  "round a 0.3 m cylinder (the sewing scene of ../shared/peers, Blender's); or cusick: a 30 cm disc of "
                  "the fabric clamped on an 18 cm support, report.json gives its drape_coefficient")
      ->check(CLI::IsMember({"sphere", "table", "sew", "cusick"}));
  cmd->add_option("--n", args->n, "cloth vertices per side (sphere, table); sew: across each panel (64: 9856 vertices)")->capture_default_str()->check(CLI::Range(3u, 2048u));
  cmd->add_option("--strain-limit", args->strain_limit, "none, position (Provot) or velocity (paper sec. 3.3)")
      ->capture_default_str()->check(CLI::IsMember({"none", "position", "velocity"}));
  cmd->add_option("--threshold", args->threshold, "stretch threshold as a fraction (default: the fabric's)")
      ->check(CLI::Range(0.0001f, 1.0f));
  cmd->add_option("--passes", args->passes, "maximum strain-limit passes per iteration")->capture_default_str()
      ->check(CLI::Range(1, 1000));
  cmd->add_option("--fabric", args->fabric, "fabric preset (cotton, denim, silk, jersey, rib_knit, wool, polyester)")
      ->capture_default_str();
  cmd->add_option("--solver", args->solver,
                  "explicit (the paper's explicit Euler with velocity modification) or implicit (implicit Euler, "
                  "Newton on the incremental potential); default: explicit for sphere and table, implicit for sew and cusick")
      ->check(CLI::IsMember({"explicit", "implicit"}));
  cmd->add_option("--dt", args->time_step, "time step in seconds (default: the stability bound, eq. 4)");
  cmd->add_option("--edge", args->edge, "cusick: the specimen's grid spacing in metres")->capture_default_str()
      ->check(CLI::Range(0.0015, 0.0375));
  cmd->add_option("--max-time", args->max_time, "simulated seconds before giving up on settling")->capture_default_str();
  cmd->add_option("--out", args->out, "output directory")->capture_default_str();
  cmd->add_flag("!--no-compare", args->compare,
                "skip the companion run (no limit vs velocity modification) shown beside this one in preview.png");
  cmd->callback([args] { run_scene(*args); });
}

}  // namespace drape::app
