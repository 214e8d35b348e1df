// The fig. 7 scene (a square cloth dropped over a sphere): the paper's claims as assertions.
// Velocity modification at 5 % holds the structural strain near 5 % where the plain mass-spring
// cloth stretches well beyond; nothing passes into the sphere; the cloth settles; and the result
// is the same bit for bit on one and two threads. The peers' sewing scene: two panels sewn into a
// tube that hangs on a cylinder.
#include <gtest/gtest.h>
#include <omp.h>

#include <cstdlib>
#include <fstream>
#include <nlohmann/json.hpp>

#include "drape/cloth_scene.hpp"
#include "support/test_support.hpp"

namespace drape {
namespace {

using test::sanitized;

ClothSceneOptions sphere_scene(StrainLimit limit) {
  ClothSceneOptions o;
  o.obstacle = SceneObstacle::Sphere;
  o.n = 32;  // also under sanitizers: at n = 20 the plain cloth stretches only 7 % (coarser folds)
  o.fabric = fabric_or_throw("cotton");
  o.strain_limit = limit;
  o.strain_threshold = 0.05f;
  return o;
}

struct Dropped {
  SceneRun run;
  SceneQuality quality;
  float min_distance;
};

Dropped drop(const ClothSceneOptions& o) {
  ClothScene scene = make_cloth_scene(o);
  Dropped d{run_until_settled(scene), scene_quality(scene), 1e9f};
  for (const Vec3f& p : scene.state.x) d.min_distance = std::min(d.min_distance, scene.obstacle_distance(p));
  return d;
}

TEST(SphereScene, VelocityModificationHoldsTheStrainThreshold) {
  const Dropped limited = drop(sphere_scene(StrainLimit::Velocity));
  ASSERT_EQ(limited.run.status, StepStatus::Ok);
  EXPECT_TRUE(limited.run.settled);
  EXPECT_LE(limited.quality.strain.max, 0.055f);
  EXPECT_EQ(limited.quality.penetrating_vertices, 0u);
  // No vertex inside the sphere beyond the collision thickness (it is kept at the thickness).
  EXPECT_GE(limited.min_distance, 0.0f);
  EXPECT_GT(limited.run.profile.strain_passes, 0u);

  const Dropped free = drop(sphere_scene(StrainLimit::None));
  ASSERT_EQ(free.run.status, StepStatus::Ok);
  EXPECT_GT(free.quality.strain.max, 0.075f) << "the plain mass-spring cloth should stretch clearly more";
  EXPECT_GT(free.quality.strain.p99, limited.quality.strain.p99);
}

TEST(SphereScene, SameResultBitForBitOnOneAndTwoThreads) {
  ClothSceneOptions o = sphere_scene(StrainLimit::Velocity);
  o.n = sanitized() ? 64 : 96;  // enough blocks of particles and springs that the threads split the work
  // With the faces kept off the sphere too (StepSettings::face_clearance): its edges are picked,
  // measured and scattered per fixed block.
  const auto run = [&](int threads, float face_clearance) {
    omp_set_num_threads(threads);
    ClothScene scene = make_cloth_scene(o);
    scene.settings.face_clearance = face_clearance;
    for (int k = 0; k < (sanitized() ? 20 : 100); ++k) EXPECT_EQ(step(scene.model, scene.state, scene.colliders, scene.settings, scene.scratch), StepStatus::Ok);
    return state_hash(scene.state);
  };
  const int previous = omp_get_max_threads();
  const uint64_t one = run(1, -1.0f), two = run(2, -1.0f);
  const uint64_t faces_one = run(1, 0.0f), faces_two = run(2, 0.0f);
  omp_set_num_threads(previous);
  EXPECT_EQ(one, two);
  EXPECT_EQ(faces_one, faces_two);
}

TEST(TableScene, SettlesOnTheTableWithoutPenetration) {
  ClothSceneOptions o = sphere_scene(StrainLimit::Velocity);
  o.obstacle = SceneObstacle::Table;
  const Dropped d = drop(o);
  ASSERT_EQ(d.run.status, StepStatus::Ok);
  EXPECT_TRUE(d.run.settled);
  EXPECT_EQ(d.quality.penetrating_vertices, 0u);
  // Over the table's sharp corners a few springs exceed the threshold (docs/cloth.md); the bulk does not.
  EXPECT_LE(d.quality.strain.p99, 0.055f);
}

// Two panels 0.4 m apart round the cylinder: the implicit solver closes every seam (side seams from
// 0.4 m, the shoulders over the top) and the tube comes to rest hanging on the cylinder's top, within
// the strain limit. The shoulder seams pull the cloth over the top's sharp rim, where at this
// spacing (2.2 cm cells) a few particles of the cloth end up to 4.5 mm inside it; 9856 particles
// (n = 64) leave 0.06 % inside, 0.8 mm deep (docs/benchmarks.md).
TEST(SewScene, PanelsSewnIntoATubeHangOnTheCylinder) {
  ClothSceneOptions o;
  o.obstacle = SceneObstacle::Sew;
  o.n = 24;  // 2 x 24 x 29 particles
  o.solver = Solver::Implicit;
  o.fabric = fabric_or_throw("cotton");
  ClothScene scene = make_cloth_scene(o);
  ASSERT_EQ(scene.model.particle_count(), 2u * 24u * 29u);
  // Side seams on every row (29 each), shoulders where |x| >= 9 cm: 2 x 7 of the 22 inner top particles.
  EXPECT_EQ(scene.seam_pairs.size(), 2u * 29u + 14u);
  float widest = 0;
  for (const auto& [a, b] : scene.seam_pairs) widest = std::max(widest, (scene.state.x[a] - scene.state.x[b]).norm());
  EXPECT_NEAR(widest, 0.4f, 1e-4f);
  SettleCriteria settle;
  settle.max_time = 4;
  const SceneRun run = run_until_settled(scene, settle);
  ASSERT_EQ(run.status, StepStatus::Ok);
  EXPECT_TRUE(run.settled);
  const SceneQuality q = scene_quality(scene);
  EXPECT_LE(q.max_seam_gap, 0.005f) << "a seam left open";
  EXPECT_LE(q.penetration_fraction, 0.01);
  EXPECT_LE(q.max_penetration, 0.005f);
  EXPECT_LE(q.strain.max, 0.05f + 0.01f);
  // Hanging on the top (y = 1 m): its highest particle over it, the hem (cut at 0.45 m, pulled up
  // by the shoulders over the top) well above the cylinder's foot.
  float top = -1, bottom = 2;
  for (const Vec3f& p : scene.state.x) {
    top = std::max(top, p.y());
    bottom = std::min(bottom, p.y());
  }
  EXPECT_GT(top, 1.0f);
  EXPECT_GT(bottom, 0.35f);
  EXPECT_LT(bottom, 0.6f);
}

// `drape scene ARGS --out DIR`, which must succeed, and its report.json (null if it failed).
nlohmann::json scene_report(const std::string& args, const std::filesystem::path& dir) {
  const auto r = test::run_drape("scene " + args + " --out " + dir.string());
  EXPECT_EQ(r.exit_code, 0) << r.err;
  if (r.exit_code != 0) return nullptr;
  std::ifstream in(dir / "report.json");
  return nlohmann::json::parse(in);
}

TEST(SceneCommand, WritesTheReportWithDesignKeys) {
  const auto dir = test::temp_dir("scene_cmd");
  const nlohmann::json report = scene_report("sphere --n 16", dir);
  ASSERT_FALSE(report.is_null());
  for (const char* key : {"max_strain", "p99_strain", "penetrating_vertices", "penetration_fraction", "max_penetration_m",
                          "max_seam_gap_m", "mean_seam_gap_m", "settled", "residual"})
    EXPECT_TRUE(report["quality"].contains(key)) << key;
  EXPECT_EQ(report["quality"].size(), 9u);
  for (const char* key : {"iterations", "time_step_s", "wall_seconds", "seconds_per_iteration"})
    EXPECT_TRUE(report["simulation"].contains(key)) << key;
  EXPECT_TRUE(report["quality"]["settled"].get<bool>());
  EXPECT_TRUE(std::filesystem::exists(dir / "scene.glb"));
  EXPECT_TRUE(std::filesystem::exists(dir / "preview.png"));
}

// The same scene on the implicit solver: implicit Euler at 1/30 s, the strain limit inside the solve.
TEST(SceneCommand, ImplicitSolverSettlesWithinTheStrainLimit) {
  const nlohmann::json report = scene_report("sphere --n 16 --solver implicit", test::temp_dir("scene_implicit"));
  ASSERT_FALSE(report.is_null());
  EXPECT_TRUE(report["quality"]["settled"].get<bool>());
  EXPECT_EQ(report["quality"]["penetrating_vertices"].get<int>(), 0);
  EXPECT_LE(report["quality"]["max_strain"].get<double>(), 0.05 + 0.01);
  EXPECT_NEAR(report["simulation"]["time_step_s"].get<double>(), 1.0 / 30.0, 1e-6);
}

TEST(SceneCommand, SewSceneReportsItsSeams) {
  const auto dir = test::temp_dir("scene_sew");
  const nlohmann::json report = scene_report("sew --n 10", dir);
  ASSERT_FALSE(report.is_null());
  EXPECT_EQ(report["simulation"]["vertices"].get<int>(), 2 * 10 * 12);
  EXPECT_EQ(report["simulation"]["seam_pairs"].get<int>(), 2 * 12 + 4);  // shoulders: x = 0.194 and 0.139 m each side
  EXPECT_TRUE(report["simulation"].contains("newton_iterations")) << "sew runs on the implicit solver by default";
  EXPECT_TRUE(report["quality"]["settled"].get<bool>());
  // At 55 mm a particle the innermost shoulder seams can catch 3-5 cm short, the row below them
  // held on the cylinder by friction (-O1 and -O2 builds differ in which); the rest close.
  EXPECT_LT(report["quality"]["max_seam_gap_m"].get<double>(), 0.1) << "from 0.4 m apart";
  EXPECT_LT(report["quality"]["mean_seam_gap_m"].get<double>(), 0.005);
  EXPECT_GT(report["quality"]["max_seam_gap_m"].get<double>(), 0.0);
  EXPECT_TRUE(std::filesystem::exists(dir / "preview.png"));
}

TEST(SceneCommand, BadOptionsExitWithStatus2AndWriteNothing) {
  const auto dir = test::temp_dir("scene_bad");
  const auto r = test::run_drape("scene sphere --fabric tweed --out " + (dir / "o").string());
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("tweed"), std::string::npos) << r.err;
  EXPECT_FALSE(std::filesystem::exists(dir / "o"));
  const auto big = test::run_drape("scene sew --n 300 --out " + (dir / "s").string());
  EXPECT_EQ(big.exit_code, 2);
  EXPECT_NE(big.err.find("256 particles across"), std::string::npos) << big.err;
  EXPECT_FALSE(std::filesystem::exists(dir / "s"));
}

}  // namespace
}  // namespace drape
