#pragma once
// The draping scenes of Vassilev & Spanlang fig. 7 (a square cloth dropped over a sphere or a
// table), written once and shared by the `drape scene` command, the tests and the benchmarks.
//
// Sphere: radius 0.3 m at the origin; the 1 m cloth starts flat 0.1 m above its top (y = 0.4 m),
// the same layout as ../shared/peers (Blender, Bullet) with their z-up turned into drape's y-up;
// particle (ix, iy) is at x = -0.5 + ix h, z = -0.5 + iy h, index iy n + ix as in the peers.
// Table: a 0.6 m square top 0.04 m thick with its top at y = 0.3 m, over a floor at y = 0.
// Sew: ../shared/peers' sewing scene (blender_drape.py --scenario sew), y up: two flat panels 0.5 m
// wide and 0.6 m tall (y from 0.45 to 1.05 m), n particles across and round(1.2 (n - 1)) + 1 up
// (square cells), one at z = -0.2 m and one at z = +0.2 m, round an upright capped cylinder of
// radius 0.15 m from y = 0 to 1 m (a torso). Zero-length seams join the panels' side edges particle
// to particle, and their top edges where |x| >= 0.09 m (shoulders): sewn into a tube, the panels
// hang from the cylinder's top. Each panel's particle (ix, iy) is its index iy n + ix, the front
// panel's first; ix runs from +x to -x on the front and from -x to +x on the back, so that both
// panels face outwards.
#include <array>
#include <functional>
#include <memory>
#include <string_view>
#include <vector>

#include "drape/analytic_colliders.hpp"
#include "drape/cloth.hpp"
#include "drape/implicit.hpp"

namespace drape {

enum class SceneObstacle { Sphere, Table, Sew };
std::string_view to_string(SceneObstacle obstacle);

struct ClothSceneOptions {
  SceneObstacle obstacle = SceneObstacle::Sphere;
  uint32_t n = 64;          // particles along each side (sew: across each panel's width)
  Fabric fabric = {};       // default: the "cotton" preset (make_cloth_scene fills it when name is empty)
  StrainLimit strain_limit = StrainLimit::Velocity;
  float strain_threshold = -1;  // < 0: the fabric's
  int strain_passes = 2;
  float time_step = 0;          // 0: the stability bound (eq. 4); implicit: 1/30 s
  Solver solver = Solver::Explicit;  // implicit: implicit Euler steps (the strain limit inside the solve)
};

struct ClothScene {
  ClothModel model;
  ClothState state;
  StepSettings settings;
  StepScratch scratch;
  std::unique_ptr<ImplicitSolver> implicit;  // set when the scene runs on the implicit solver
  ImplicitSettings implicit_settings;
  std::vector<std::unique_ptr<AnalyticCollider>> obstacles;
  std::vector<Collider*> colliders;  // the obstacles, as step() takes them
  std::vector<std::array<uint32_t, 2>> seam_pairs;  // sewn particle pairs (sew)

  float time_step() const;  // s, of either solver
  // Obstacles merged into one mesh (the `body` node of scene.glb).
  Mesh obstacle_mesh() const;
  // Exact inside test against the obstacles: > 0 outside.
  float obstacle_distance(const Vec3f& p) const;
};
ClothScene make_cloth_scene(const ClothSceneOptions& options);

// When a run counts as settled: the fastest particle slower than `speed` for `duration` seconds of
// simulated time, after at least `min_time`. Runs stop at `max_time` unsettled.
struct SettleCriteria {
  float speed = 0.05f;      // m/s
  double duration = 0.3;    // s
  double min_time = 0.5;    // s
  double max_time = 12.0;   // s
};

struct SceneRun {
  bool settled = false;
  double settled_at = 0;  // simulated seconds when the settling window began
  StepStatus status = StepStatus::Ok;
  uint64_t iterations = 0;
  double wall_seconds = 0;  // stepping only
  StepProfile profile;              // the explicit step's stages
  ImplicitProfile implicit_profile;  // the implicit solver's
};
// Steps until settled, failed (status) or max_time. `progress` (may be empty) is called about every
// 0.25 s of simulated time.
SceneRun run_until_settled(ClothScene& scene, const SettleCriteria& criteria = {},
                           const std::function<void(const ClothState&)>& progress = {});

// DESIGN.md's `quality` measures for a scene (the seam gaps 0 where nothing is sewn).
struct SceneQuality {
  StrainStats strain;  // structural springs
  size_t penetrating_vertices = 0;
  double penetration_fraction = 0;
  float max_penetration = 0;  // m
  float max_seam_gap = 0, mean_seam_gap = 0;  // m
};
SceneQuality scene_quality(const ClothScene& scene);

}  // namespace drape
