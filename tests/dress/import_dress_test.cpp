// Dressing garments whose panels span several body parts or come from other formats:
//   - the built-in trousers, dress and jeans in every size on both default bodies (the trousers'
//     placement on the hips and legs, the dress hung from the shoulders), and
//   - GarmentCode patterns on the body they were fitted to (mean_all.obj) and the 2021 templates'
//     shirt, skirt and trousers, from ../shared/data (skipped where absent).
// Each must pass the quality gates of docs/dressing.md: seams closed (<= 2 mm), <= 0.5 % of the
// vertices inside the body, max strain <= the fabric's threshold + 1 %, settled, above the floor,
// stayed on. Skipped under sanitizers (DRAPE_SANITIZED): each dressing takes seconds in Release.
#include <gtest/gtest.h>

#include <cctype>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <mutex>
#include <string>
#include <tuple>

#include "drape/dress.hpp"
#include "dress/dress_support.hpp"
#include "support/test_support.hpp"

namespace drape {
namespace {

using test::cached_body;
using test::failed_gates;
using test::sanitized;

// Every gate, and the figures behind them stated one by one so a failure says which.
void expect_gates(const DressResult& r) {
  ASSERT_EQ(r.garments.size(), 1u);
  const FitQuality& q = r.quality;
  const DressedGarment& g = r.garments[0];
  EXPECT_TRUE(q.finite);
  EXPECT_GT(g.initial_max_gap, 0.002f);  // placement left seams to sew
  EXPECT_LE(q.max_seam_gap_m, 0.002f);
  EXPECT_LE(q.penetration_fraction, 0.005);
  EXPECT_LE(q.max_strain, g.model.fabric.strain_threshold + 0.01f);
  EXPECT_TRUE(q.settled);
  EXPECT_GE(q.lowest_y, 0.0f);
  EXPECT_LE(q.drop_m, 0.15f);
  EXPECT_TRUE(r.passed()) << failed_gates(r);
}

// --- Placement ------------------------------------------------------------------------------------

// Where placement puts a garment before sewing: every vertex outside the body and at least a
// millimetre from it, front panels in front of the back panels, each panel on its side of the
// body (left panels on the body's left, +X), and the flat pattern hardly stretched by the roll
// (rolled by arc length across and by distance along the surface downwards, the lattice keeps its
// lengths; the springs of cells cut by the outline shear where the surface changes shape, up to
// ~20 %, and an underarm corner pushed off an A-posed arm up to ~35 %, which the first sewing steps
// relax). The placement before this one stretched the dress by 61 % and the trousers until they
// exploded.
void expect_placed_clear(const Body& body, const std::string& name, const std::string& size) {
  SCOPED_TRACE(name + " size " + size + " on a " + std::to_string(body.measurements.height) + " m body");
  const Garment garment = garment_in_size(load_garment(name), size);
  const auto collider = make_body_collider(body.mesh, CollisionMethod::image);
  DressOptions o;
  o.simulate = false;
  const DressedGarment g = prepare_garment(body, garment, *collider, o);
  const InsideTest inside(body.mesh);
  const GarmentMeasure m = measure_garment(g.model, g.state.x, inside);
  EXPECT_EQ(m.penetration.penetrating, 0u);
  EXPECT_LE(m.strain.max, 0.40f);
  EXPECT_LE(m.strain.p99, 0.12f);
  const float centre_z = 0.5f * (body.landmarks.waist.z() + body.landmarks.hip.z());
  for (size_t p = 0; p < garment.panels.size(); ++p) {
    const PlacementHint& h = *garment.panels[p].placement;
    Vec3f mean = Vec3f::Zero();
    for (uint32_t v = g.panel_first_vertex[p]; v < g.panel_first_vertex[p + 1]; ++v) {
      EXPECT_GT(inside.unsigned_distance(g.state.x[v]), 0.001f) << garment.panels[p].name;
      mean += g.state.x[v];
    }
    mean /= static_cast<float>(g.panel_first_vertex[p + 1] - g.panel_first_vertex[p]);
    if (h.side == PanelSide::front) {
      EXPECT_GT(mean.z(), centre_z) << garment.panels[p].name;
    }
    if (h.side == PanelSide::back) {
      EXPECT_LT(mean.z(), centre_z) << garment.panels[p].name;
    }
    if (h.body_part == BodyRegion::left_leg) {
      EXPECT_GT(mean.x(), 0.0f) << garment.panels[p].name;
    }
    if (h.body_part == BodyRegion::right_leg) {
      EXPECT_LT(mean.x(), 0.0f) << garment.panels[p].name;
    }
  }
}

TEST(Placement, TrousersDressAndJeansStartClearOfTheBody) {
  if (sanitized()) GTEST_SKIP() << "sanitized build: building both bodies takes too long";
  for (Sex sex : {Sex::Female, Sex::Male})
    for (const char* name : {"trousers", "dress", "jeans"})
      for (const char* size : {"S", "L"}) expect_placed_clear(cached_body(sex), name, size);
}

// --- Built-in garments spanning the hips and legs, or hung from the shoulders ----------------

using BuiltinCase = std::tuple<std::string, std::string, Sex>;  // garment, size, body
class SpanningBuiltin : public ::testing::TestWithParam<BuiltinCase> {};

TEST_P(SpanningBuiltin, PassesTheGates) {
  if (sanitized()) GTEST_SKIP() << "sanitized build: dressing takes too long";
  const auto& [garment, size, sex] = GetParam();
  const Body& body = cached_body(sex);
  const DressResult r = dress(body, {{load_garment(garment), size}});
  expect_gates(r);
}

std::string builtin_case_name(const ::testing::TestParamInfo<BuiltinCase>& info) {
  const auto& [garment, size, sex] = info.param;
  return garment + "_" + size + (sex == Sex::Male ? "_male" : "_female");
}

// NOT YET REACHED (DISABLED_ prefix on the suite: run with --gtest_also_run_disabled_tests),
// measured at 14:51 UTC on main: trousers on the female body close every seam but are stretched
// 10-18 % on the hips (wool: 6 %); with the sewing settings in the working tree at 14:44 (not
// committed) they passed in S, M and L (5.7 / 5.5 / 5.1 %); on the male body S kept an outseam
// 56 mm open and M, L did not settle;
// the dress (strain 3.0 %, settled, but shoulder and side corners 34 mm open) and the jeans
// (strain 3.6 %, settled, inseams 45 mm open at the crotch). Figures: docs/dressing.md, Status.
INSTANTIATE_TEST_SUITE_P(DISABLED_Garments, SpanningBuiltin,
                         ::testing::Combine(::testing::Values("dress", "jeans"), ::testing::Values("S", "M", "L"),
                                            ::testing::Values(Sex::Female, Sex::Male)),
                         builtin_case_name);
INSTANTIATE_TEST_SUITE_P(DISABLED_MaleTrousers, SpanningBuiltin,
                         ::testing::Combine(::testing::Values("trousers"), ::testing::Values("S", "M", "L"),
                                            ::testing::Values(Sex::Male)),
                         builtin_case_name);
INSTANTIATE_TEST_SUITE_P(DISABLED_FemaleTrousers, SpanningBuiltin,
                         ::testing::Combine(::testing::Values("trousers"), ::testing::Values("S", "M", "L"),
                                            ::testing::Values(Sex::Female)),
                         builtin_case_name);

// --- Imported patterns -----------------------------------------------------------------------

// GarmentCode's mean body (metres, +Y up, +Z front), the body its patterns were fitted to.
const Body& mean_all_body(const std::filesystem::path& path) {
  static std::map<std::string, Body> bodies;
  static std::mutex mutex;
  std::lock_guard lock(mutex);
  auto it = bodies.find(path.string());
  if (it == bodies.end()) it = bodies.emplace(path.string(), load_body(path)).first;
  return it->second;
}

class ImportedPattern : public ::testing::TestWithParam<std::string> {};

TEST_P(ImportedPattern, PassesTheGatesOnMeanAll) {
  if (sanitized()) GTEST_SKIP() << "sanitized build: dressing takes too long";
  const auto body_path = DRAPE_REQUIRE_SHARED("bodies/garmentcode/mean_all.obj");
  const auto pattern = DRAPE_REQUIRE_SHARED("patterns/" + GetParam());
  expect_gates(dress(mean_all_body(body_path), {{load_garment(pattern.string()), ""}}));
}

std::string pattern_case_name(const ::testing::TestParamInfo<std::string>& info) {
  std::string s = info.param.substr(info.param.rfind('/') + 1);
  s = s.substr(0, s.find('.'));
  for (char& c : s)
    if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
  return s;
}

// NOT YET REACHED (DISABLED_ prefix, as above): measured failures are listed in docs/dressing.md.
INSTANTIATE_TEST_SUITE_P(DISABLED_GarmentCode, ImportedPattern,
                         ::testing::Values("garmentcode/shirt_mean_specification.json",
                                           "garmentcode/dress_pencil_specification.json",
                                           "garmentcode/flare_skirt_specification.json",
                                           "garmentcode/hoody_mean_specification.json",
                                           "garment_pattern_generator_2021/tee.json",
                                           "garment_pattern_generator_2021/skirt_4_panels.json",
                                           "garment_pattern_generator_2021/pants_straight_sides.json"),
                         pattern_case_name);

}  // namespace
}  // namespace drape
