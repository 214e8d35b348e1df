// Fit metrics on scenes with known answers: a stretched grid, sewn pairs a known distance apart,
// points inside and outside a sphere; gates and the report.json keys.
#include <gtest/gtest.h>

#include <cmath>
#include <nlohmann/json.hpp>

#include "drape/analytic_colliders.hpp"
#include "drape/cloth.hpp"
#include "drape/fit.hpp"
#include "drape/shapes.hpp"

namespace drape {
namespace {

Fabric test_fabric() {
  const Fabric* f = find_fabric("cotton");
  return f ? *f : Fabric{};
}

TEST(SeamGap, MeasuresEveryPair) {
  const std::vector<Vec3f> x{{0, 0, 0}, {0.003f, 0, 0}, {1, 1, 1}, {1, 1.001f, 1}};
  const std::vector<std::array<uint32_t, 2>> pairs{{0, 1}, {2, 3}};
  const SeamGapStats s = seam_gap_stats(x, pairs);
  EXPECT_EQ(s.pairs, 2u);
  EXPECT_NEAR(s.max, 0.003f, 1e-6f);
  EXPECT_NEAR(s.mean, 0.002f, 1e-6f);
  EXPECT_EQ(seam_gap_stats(x, {}).max, 0.0f);
}

TEST(MeasureGarment, StrainOfAStretchedGridIsTheStretch) {
  GridClothOptions o;
  o.nx = o.ny = 11;
  o.origin = Vec3f(2, 0.5f, 2);  // far from the sphere below: nothing penetrates
  const ClothModel model = grid_cloth(test_fabric(), o);
  std::vector<Vec3f> x = model.rest_position;
  // 3 % along x (weft): weft springs stretch by 3 %, warp springs keep their length.
  for (Vec3f& p : x) p.x() = o.origin.x() + 1.03f * (p.x() - o.origin.x());
  const SphereCollider sphere(Vec3f::Zero(), 0.3f);
  const InsideTest inside(sphere.mesh());
  const GarmentMeasure m = measure_garment(model, x, inside);
  EXPECT_NEAR(m.strain.max, 0.03f, 1e-4f);
  EXPECT_NEAR(m.strain.min, 0.0f, 1e-4f);
  EXPECT_EQ(m.penetration.penetrating, 0u);
  EXPECT_NEAR(m.lowest_y, 0.5f, 1e-6f);
  EXPECT_TRUE(m.finite);
  EXPECT_EQ(m.structural_strain.size(), model.range(SpringKind::Structural).size());
}

TEST(MeasureGarment, PointsInsideASphereArePenetrating) {
  GridClothOptions o;
  o.nx = o.ny = 5;
  o.width = o.height = 0.2f;
  o.origin = Vec3f(-0.1f, 0.0f, -0.1f);  // through the centre of the sphere
  const ClothModel model = grid_cloth(test_fabric(), o);
  std::vector<Vec3f> x = model.rest_position;
  x[0] = Vec3f(0, 2, 0);  // one point well outside
  const SphereCollider sphere(Vec3f::Zero(), 0.3f);
  const InsideTest inside(sphere.mesh());
  const GarmentMeasure m = measure_garment(model, x, inside);
  EXPECT_EQ(m.penetration.penetrating, x.size() - 1);
  EXPECT_NEAR(m.penetration.fraction, static_cast<double>(x.size() - 1) / static_cast<double>(x.size()), 1e-9);
  // The centre is the deepest point: about the radius (the sphere mesh is a polygon).
  EXPECT_NEAR(m.penetration.max_depth_m, 0.3f, 0.01f);
}

// A flat square of cloth (20 x 20 cells, 6 cm wide) across the top of a 10 cm sphere, at height h.
struct CapScene {
  Mesh sphere = uv_sphere(0.1f, Vec3f::Zero(), 96, 48);
  std::vector<Vec3f> cloth;
  std::vector<Tri> triangles;
  explicit CapScene(float h, float width = 0.06f) {
    constexpr uint32_t n = 21;
    for (uint32_t j = 0; j < n; ++j)
      for (uint32_t i = 0; i < n; ++i)
        cloth.emplace_back(width * (static_cast<float>(i) / (n - 1) - 0.5f), h, width * (static_cast<float>(j) / (n - 1) - 0.5f));
    for (uint32_t j = 0; j + 1 < n; ++j)
      for (uint32_t i = 0; i + 1 < n; ++i) {
        const uint32_t a = j * n + i;
        triangles.push_back({a, a + n, a + 1});
        triangles.push_back({a + 1, a + n, a + n + 1});
      }
  }
};

TEST(SkinThrough, CapRisingThroughTheClothIsMeasured) {
  // The cloth 3 mm below the sphere's top: the cap above it shows through, 3 mm at the pole.
  const CapScene through(0.097f);
  const SkinThroughStats s = measure_skin_through(through.sphere, through.cloth, through.triangles);
  EXPECT_GT(s.body_vertices, 10u);
  EXPECT_NEAR(s.max_depth_m, 0.003f, 0.0003f);
  // 4 mm above it (where the collision keeps cloth vertices): nothing shows.
  const CapScene above(0.104f);
  EXPECT_EQ(measure_skin_through(above.sphere, above.cloth, above.triangles).body_vertices, 0u);
  // 0.5 mm into the skin: within the 1 mm tolerance.
  const CapScene grazing(0.0995f);
  EXPECT_EQ(measure_skin_through(grazing.sphere, grazing.cloth, grazing.triangles).body_vertices, 0u);
  // Skin the cloth does not cover: the same square moved 20 cm to the side, off the sphere.
  CapScene beside(0.097f);
  for (Vec3f& p : beside.cloth) p.x() += 0.2f;
  EXPECT_EQ(measure_skin_through(beside.sphere, beside.cloth, beside.triangles).body_vertices, 0u);
}

// Damped settings for cloth coming to rest, with the faces kept `face_clearance` off (negative: off).
StepSettings settling_settings(const ClothModel& model, float face_clearance) {
  StepSettings settings = default_step_settings(model);
  settings.air_damping = 10.0f;
  settings.face_clearance = face_clearance;
  return settings;
}

// The model from its rest layout against one collider for `seconds`, every step healthy.
ClothState run_from_rest(const ClothModel& model, Collider& collider, const StepSettings& settings, double seconds) {
  ClothState state = initial_state(model);
  StepScratch scratch(model, 1);
  Collider* colliders[] = {&collider};
  while (state.time < seconds) EXPECT_EQ(step(model, state, colliders, settings, scratch), StepStatus::Ok);
  return state;
}

// A coarse cloth (3 cm cells) hung over a thin bar (1.5 cm radius, along x), as a shirt's grid hangs
// over a shoulder, its two middle rows 1.5 cm either side of the bar's top. Keeping the vertices
// 4 mm off the bar is not enough: the cells across the top cut 3 mm into it. With
// StepSettings::face_clearance = 0 the particles there are lifted until the faces clear the bar;
// nothing gets inside and the strain stays at the limit.
TEST(SkinThrough, FaceClearanceLiftsCoarseClothOffASharpBar) {
  constexpr float radius = 0.015f;
  CapsuleCollider bar(Vec3f(-0.5f, 0, 0), Vec3f(0.5f, 0, 0), radius);
  // The skin to look for: the bar's surface under the cloth, a vertex every 2.5 mm along it and
  // round it (the capsule's own mesh has rings only at its ends).
  Mesh bar_mesh;
  constexpr int rings = 121, segments = 40;
  for (int r = 0; r < rings; ++r)
    for (int k = 0; k < segments; ++k) {
      const float phi = 6.2831853f * static_cast<float>(k) / segments;
      const Vec3f n(0, std::cos(phi), std::sin(phi));
      bar_mesh.positions.emplace_back(-0.15f + 0.0025f * static_cast<float>(r), radius * n.y(), radius * n.z());
      bar_mesh.normals.push_back(n);
    }
  for (int r = 0; r + 1 < rings; ++r)
    for (int k = 0; k < segments; ++k) {
      const auto at = [&](int rr, int kk) { return static_cast<uint32_t>(rr * segments + kk % segments); };
      bar_mesh.triangles.push_back({at(r, k), at(r, k + 1), at(r + 1, k)});
      bar_mesh.triangles.push_back({at(r, k + 1), at(r + 1, k + 1), at(r + 1, k)});
    }
  GridClothOptions o;
  o.nx = o.ny = 8;
  o.width = o.height = 0.21f;  // 3 cm cells
  o.origin = Vec3f(-0.105f, 0.025f, -0.105f);
  const ClothModel model = grid_cloth(test_fabric(), o);
  const auto drape_over_bar = [&](float face_clearance) {
    StepSettings settings = settling_settings(model, face_clearance);
    settings.position_passes = 4;
    settings.converge_passes = 128;
    return run_from_rest(model, bar, settings, 1.5);
  };
  const ClothState plain = drape_over_bar(-1.0f);
  const SkinThroughStats through = measure_skin_through(bar_mesh, plain.x, model.triangles);
  EXPECT_GT(through.body_vertices, 0u);
  EXPECT_GT(through.max_depth_m, 0.002f);

  const ClothState lifted = drape_over_bar(0.0f);
  const SkinThroughStats clear = measure_skin_through(bar_mesh, lifted.x, model.triangles);
  EXPECT_EQ(clear.body_vertices, 0u) << "up to " << clear.max_depth_m << " m";
  const InsideTest inside(bar.mesh());
  EXPECT_EQ(measure_garment(model, lifted.x, inside).penetration.penetrating, 0u);
  EXPECT_LT(strain_stats(model, lifted.x).max, model.fabric.strain_threshold + 0.01f);
  // The lift is only where the faces need it: the hanging sides are where they were.
  EXPECT_NEAR(lifted.x.front().y(), plain.x.front().y(), 0.01f);
}

// A clearance beyond the collision thickness lifts cloth lying on flat ground by the difference:
// a small sheet dropped on a table rests 4 mm above it (the thickness) with the lift off, 6 mm with
// face_clearance = 6 mm (flat, so no edge needs more).
TEST(SkinThrough, FaceClearanceBeyondTheThicknessLiftsFlatCloth) {
  BoxCollider table(Vec3f(0, -0.5f, 0), Vec3f(1, 0.5f, 1));
  GridClothOptions o;
  o.nx = o.ny = 10;
  o.width = o.height = 0.2f;
  o.origin = Vec3f(-0.1f, 0.005f, -0.1f);
  const ClothModel model = grid_cloth(test_fabric(), o);
  const auto rest_height = [&](float face_clearance) {
    const ClothState state = run_from_rest(model, table, settling_settings(model, face_clearance), 0.5);
    float lowest = 1, highest = -1;
    for (const Vec3f& x : state.x) {
      lowest = std::min(lowest, x.y());
      highest = std::max(highest, x.y());
    }
    EXPECT_LT(highest - lowest, 1e-4f);
    return lowest;
  };
  const float thickness = model.fabric.collision_thickness;
  EXPECT_NEAR(rest_height(-1.0f), thickness, 1e-4f);
  EXPECT_NEAR(rest_height(thickness), thickness, 1e-4f);
  EXPECT_NEAR(rest_height(thickness + 0.002f), thickness + 0.002f, 1e-4f);
}

TEST(MeasureGarment, NonFiniteStateIsReported) {
  GridClothOptions o;
  o.nx = o.ny = 4;
  const ClothModel model = grid_cloth(test_fabric(), o);
  std::vector<Vec3f> x = model.rest_position;
  x[3].y() = std::nanf("");
  const SphereCollider sphere(Vec3f(5, 5, 5), 0.1f);
  const InsideTest inside(sphere.mesh());
  EXPECT_FALSE(measure_garment(model, x, inside).finite);
}

FitQuality good_quality() {
  FitQuality q;
  q.max_strain = 0.05f;
  q.p99_strain = 0.02f;
  q.max_seam_gap_m = 0.001f;
  q.mean_seam_gap_m = 0.0005f;
  q.settled = true;
  q.lowest_y = 0.5f;
  q.vertices = 1000;
  return q;
}

TEST(Gates, GoodQualityPassesAndEachFailureIsNamed) {
  EXPECT_TRUE(all_passed(evaluate_gates(good_quality(), 0.05f)));
  const auto failed = [](const FitQuality& q) {
    std::vector<std::string> names;
    for (const GateResult& g : evaluate_gates(q, 0.05f))
      if (!g.passed) names.push_back(g.name);
    return names;
  };
  FitQuality q = good_quality();
  q.max_seam_gap_m = 0.0025f;
  EXPECT_EQ(failed(q), std::vector<std::string>{"seams_closed"});
  q = good_quality();
  q.penetrating_vertices = 6;
  q.penetration_fraction = 0.006;
  EXPECT_EQ(failed(q), std::vector<std::string>{"penetration"});
  q = good_quality();
  q.max_strain = 0.061f;  // threshold 5 % + 1 %
  EXPECT_EQ(failed(q), std::vector<std::string>{"strain"});
  q = good_quality();
  q.settled = false;
  EXPECT_EQ(failed(q), std::vector<std::string>{"settled"});
  q = good_quality();
  q.lowest_y = -0.01f;
  EXPECT_EQ(failed(q), std::vector<std::string>{"above_floor"});
  q = good_quality();
  q.drop_m = 0.5f;
  EXPECT_EQ(failed(q), std::vector<std::string>{"stayed_on"});
}

TEST(Report, QualityHasExactlyTheContractKeys) {
  FitQuality q = good_quality();
  q.settled = false;
  const auto gates = evaluate_gates(q, 0.05f);
  const nlohmann::json r = nlohmann::json::parse(report_json(q, {120, 4e-4, 0.05, 0.05 / 120}, gates, R"({"extra": 1})"));
  std::vector<std::string> keys;
  for (auto it = r["quality"].begin(); it != r["quality"].end(); ++it) keys.push_back(it.key());
  std::sort(keys.begin(), keys.end());
  EXPECT_EQ(keys, (std::vector<std::string>{"max_penetration_m", "max_seam_gap_m", "max_strain", "mean_seam_gap_m",
                                            "p99_strain", "penetrating_vertices", "penetration_fraction", "residual", "settled"}));
  EXPECT_EQ(r["simulation"]["iterations"], 120);
  EXPECT_TRUE(r["simulation"].contains("time_step_s"));
  EXPECT_TRUE(r["simulation"].contains("wall_seconds"));
  EXPECT_TRUE(r["simulation"].contains("seconds_per_iteration"));
  EXPECT_EQ(r["gates"]["failed"], nlohmann::json::array({"settled"}));
  EXPECT_FALSE(r["gates"]["passed"].get<bool>());
  EXPECT_EQ(r["extra"], 1);
}

}  // namespace
}  // namespace drape
