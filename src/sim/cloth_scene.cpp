// The fig. 7 scenes (a square cloth dropped over a sphere or a table) and the peers' sewing scene
// (two panels sewn round a cylinder); see drape/cloth_scene.hpp.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>

#include "drape/cloth_scene.hpp"
#include "drape/error.hpp"

namespace drape {

std::string_view to_string(SceneObstacle obstacle) {
  switch (obstacle) {
    case SceneObstacle::Sphere: return "sphere";
    case SceneObstacle::Table: return "table";
    case SceneObstacle::Sew: return "sew";
  }
  return "?";
}

namespace {

// The sewing scene's layout (../shared/peers/blender_drape.py, build_sew_scene, z up there).
constexpr float kPanelWidth = 0.5f, kPanelHeight = 0.6f, kPanelBottom = 0.45f, kPanelOffset = 0.2f;
constexpr float kShoulderFrom = 0.09f;  // |x| from which the top edges are sewn
constexpr float kTorsoRadius = 0.15f, kTorsoHeight = 1.0f;
// The seams' stiffness (N/m per pair): the peers' sewing springs, Blender's, have the structural
// springs' 1000 N/m and no cap on their pull.
constexpr float kSewSeamStiffness = 1000.0f;
constexpr uint32_t kMaxSewParticlesAcross = 256;

// Two panels of n x m particles, the front one's first, sewn at their sides and shoulders.
ClothModel sewn_panels(const Fabric& fabric, uint32_t n, std::vector<std::array<uint32_t, 2>>& pairs) {
  const uint32_t m = static_cast<uint32_t>(std::lround(kPanelHeight / kPanelWidth * static_cast<float>(n - 1))) + 1;
  GridClothOptions panel;
  panel.nx = n;
  panel.ny = m;
  panel.width = kPanelWidth;
  panel.height = kPanelHeight;
  panel.v_axis = Vec3f::UnitY();
  // Front: ix from +x to -x (its triangles face -z, outwards); back: from -x to +x (facing +z).
  panel.origin = Vec3f(0.5f * kPanelWidth, kPanelBottom, -kPanelOffset);
  panel.u_axis = -Vec3f::UnitX();
  ClothSpec spec = grid_cloth_spec(fabric, panel);
  panel.origin = Vec3f(-0.5f * kPanelWidth, kPanelBottom, kPanelOffset);
  panel.u_axis = Vec3f::UnitX();
  ClothSpec back = grid_cloth_spec(fabric, panel);
  // The back panel beside the front one on the flat pattern (TEXCOORD_0).
  for (Vec2f& f : back.flat_positions) f.x() += kPanelWidth + 0.1f;
  const uint32_t off = append(spec, back);
  // Front particle (i, j) lies at x = w/2 - i h, back particle (i', j) at -w/2 + i' h: the same x
  // for i' = n - 1 - i.
  const auto front = [&](uint32_t i, uint32_t j) { return j * n + i; };
  const auto back_at = [&](uint32_t i, uint32_t j) { return off + j * n + (n - 1 - i); };
  pairs.clear();
  for (uint32_t j = 0; j < m; ++j) {
    pairs.push_back({front(0, j), back_at(0, j)});
    pairs.push_back({front(n - 1, j), back_at(n - 1, j)});
  }
  const float h = kPanelWidth / static_cast<float>(n - 1);
  for (uint32_t i = 1; i + 1 < n; ++i)
    if (std::abs(0.5f * kPanelWidth - static_cast<float>(i) * h) >= kShoulderFrom - 1e-6f)
      pairs.push_back({front(i, m - 1), back_at(i, m - 1)});
  for (const auto& [a, b] : pairs) spec.springs.push_back({a, b, 0.0f, kSewSeamStiffness, SpringKind::Seam});
  return compile(std::move(spec));
}

}  // namespace

ClothScene make_cloth_scene(const ClothSceneOptions& o) {
  if (o.n < 3 || o.n > 2048) throw InputError("--n", "the cloth needs between 3 and 2048 vertices per side");
  if (o.obstacle == SceneObstacle::Sew && o.n > kMaxSewParticlesAcross)
    throw InputError("sew scene", "at most 256 particles across a panel (2 x 256 x 307 in all)");
  if (o.strain_passes < 1 || o.strain_passes > 1000) throw InputError("--passes", "strain passes must be 1..1000");
  ClothScene s;
  const Fabric fabric = o.fabric.name.empty() ? fabric_or_throw("cotton") : o.fabric;
  GridClothOptions grid;
  grid.nx = grid.ny = o.n;
  grid.width = grid.height = 1.0f;
  grid.origin = Vec3f(-0.5f, 0.4f, -0.5f);
  grid.u_axis = Vec3f::UnitX();
  grid.v_axis = Vec3f::UnitZ();
  s.model = o.obstacle == SceneObstacle::Sew ? sewn_panels(fabric, o.n, s.seam_pairs) : grid_cloth(fabric, grid);
  s.state = initial_state(s.model);
  s.settings = default_step_settings(s.model);
  s.settings.strain_limit = o.strain_limit;
  if (o.strain_threshold >= 0) {
    if (!(o.strain_threshold >= 1e-4f && o.strain_threshold <= 1.0f))
      throw InputError("--threshold", "the strain threshold must be between 0.0001 and 1");
    s.settings.strain_threshold = o.strain_threshold;
  }
  s.settings.strain_passes = o.strain_passes;
  s.settings.time_step = o.time_step;
  if (o.obstacle == SceneObstacle::Sphere) {
    s.obstacles.push_back(std::make_unique<SphereCollider>(Vec3f::Zero(), 0.3f));
  } else if (o.obstacle == SceneObstacle::Sew) {
    s.obstacles.push_back(std::make_unique<CylinderCollider>(Vec3f(0.0f, kTorsoHeight, 0.0f), kTorsoRadius, kTorsoHeight));
  } else {
    s.obstacles.push_back(std::make_unique<BoxCollider>(Vec3f(0.0f, 0.28f, 0.0f), Vec3f(0.3f, 0.02f, 0.3f)));
    s.obstacles.push_back(std::make_unique<PlaneCollider>(Vec3f::Zero(), Vec3f::UnitY(), 2.0f));
  }
  for (auto& ob : s.obstacles) s.colliders.push_back(ob.get());
  s.scratch.resize(s.model, s.colliders.size());
  if (o.solver == Solver::Implicit) {
    s.implicit = std::make_unique<ImplicitSolver>(s.model, s.colliders.size());
    s.implicit_settings = default_implicit_settings(s.model);
    // Without a strain limit the barrier never acts (a threshold no spring reaches).
    s.implicit_settings.strain_threshold =
        o.strain_limit == StrainLimit::None ? std::numeric_limits<float>::max() : s.settings.strain_threshold;
    if (o.time_step > 0) s.implicit_settings.time_step = o.time_step;
    // Dynamic steps as `drape animate` takes them. The sphere scene at n = 64: 8.2 s for its 2 s
    // against 14.3 s, the same strain and nothing inside (docs/benchmarks.md).
    sweep_dynamic_steps(s.implicit_settings);
    s.implicit_settings.seam_stiffness = kSewSeamStiffness;
    if (o.obstacle == SceneObstacle::Sew) s.implicit_settings.stiff_past_skin = false;
    s.implicit_settings.seam_force = 0.0f;
  }
  return s;
}

Mesh ClothScene::obstacle_mesh() const {
  Mesh merged;
  merged.name = "body";
  for (const auto& ob : obstacles) {
    const Mesh m = ob->mesh();
    const uint32_t base = static_cast<uint32_t>(merged.positions.size());
    merged.positions.insert(merged.positions.end(), m.positions.begin(), m.positions.end());
    merged.normals.insert(merged.normals.end(), m.normals.begin(), m.normals.end());
    for (const Tri& t : m.triangles) merged.triangles.push_back({t[0] + base, t[1] + base, t[2] + base});
  }
  return merged;
}

float ClothScene::time_step() const {
  if (implicit) return static_cast<float>(implicit_settings.time_step);
  return settings.time_step > 0 ? settings.time_step : model.stable_time_step();
}

float ClothScene::obstacle_distance(const Vec3f& p) const {
  float d = std::numeric_limits<float>::infinity();
  for (const auto& ob : obstacles) d = std::min(d, ob->signed_distance(p, nullptr));
  return d;
}

SceneRun run_until_settled(ClothScene& scene, const SettleCriteria& criteria,
                           const std::function<void(const ClothState&)>& progress) {
  SceneRun run;
  const auto start = std::chrono::steady_clock::now();
  double calm_since = -1, next_report = 0.25;
  while (scene.state.time < criteria.max_time) {
    run.status = scene.implicit ? scene.implicit->step(scene.state, scene.colliders, scene.implicit_settings, nullptr,
                                                       &run.implicit_profile)
                                : step(scene.model, scene.state, scene.colliders, scene.settings, scene.scratch, &run.profile);
    if (run.status != StepStatus::Ok) break;
    const double t = scene.state.time;
    // Settled: calm (every particle slower than the threshold) for the whole window.
    if (scene.state.max_speed < criteria.speed) {
      if (calm_since < 0) calm_since = t;
      if (t - calm_since >= criteria.duration && t >= criteria.min_time) {
        run.settled = true;
        run.settled_at = calm_since;
        break;
      }
    } else {
      calm_since = -1;
    }
    if (progress && t >= next_report) {
      progress(scene.state);
      next_report += 0.25;
    }
  }
  run.iterations = scene.state.iterations;
  run.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return run;
}

SceneQuality scene_quality(const ClothScene& scene) {
  SceneQuality q;
  q.strain = strain_stats(scene.model, scene.state.x, SpringKind::Structural);
  for (const Vec3f& p : scene.state.x) {
    const float d = scene.obstacle_distance(p);
    if (d < 0) {
      ++q.penetrating_vertices;
      q.max_penetration = std::max(q.max_penetration, -d);
    }
  }
  q.penetration_fraction = scene.state.x.empty() ? 0.0 : static_cast<double>(q.penetrating_vertices) / static_cast<double>(scene.state.x.size());
  double gaps = 0;
  for (const auto& [a, b] : scene.seam_pairs) {
    const float gap = (scene.state.x[a] - scene.state.x[b]).norm();
    q.max_seam_gap = std::max(q.max_seam_gap, gap);
    gaps += gap;
  }
  if (!scene.seam_pairs.empty()) q.mean_seam_gap = static_cast<float>(gaps / static_cast<double>(scene.seam_pairs.size()));
  return q;
}

}  // namespace drape
