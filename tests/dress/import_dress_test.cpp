// Dressing garments whose panels span several body parts or come from other formats:
//   - the built-in trousers, dress and jeans in every size on both default bodies (the trousers'
//     placement on the hips and legs, the dress hung from the shoulders), and
//   - GarmentCode patterns on the body they were fitted to (mean_all.obj) and the 2021 templates'
//     shirt, skirt and trousers, from ../shared/data (skipped where absent).
// Each must pass the quality gates of docs/dressing.md: seams closed (<= 2 mm), <= 0.5 % of the
// vertices inside the body, max strain <= the fabric's threshold + 1 %, settled, above the floor,
// stayed on. Skipped under sanitizers (DRAPE_SANITIZED): each dressing takes seconds in Release.
// Imports are also checked where placement puts them (from the file's own 3D layout, on mean_all)
// and through their first sewing steps, and `drape dress` must refuse malformed imports.
#include <gtest/gtest.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <mutex>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include <Eigen/Geometry>

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
// relax; the 99th percentile stays under 15 %: 12.4-14.4 % for the S sizes of the dress, the
// trousers and the jeans on the default female body, whose bust and seat are fuller than the
// mannequin's on which it was 12 % at most). The placement before this one stretched the dress by 61 % and the trousers until they
// exploded.
// A garment placed (not simulated) on the body, checked to start with no vertex inside or within
// 1 mm of the skin (exact inside test); its measures and each panel's mean position come back for
// the callers' own checks.
struct PlacedGarment {
  DressedGarment g;
  GarmentMeasure m;
  std::vector<Vec3f> panel_mean;
};
PlacedGarment place_clear_of_the_body(const Body& body, const Garment& garment) {
  const auto collider = make_body_collider(body.mesh, CollisionMethod::image);
  DressOptions o;
  o.simulate = false;
  PlacedGarment r{prepare_garment(body, garment, *collider, o), {}, {}};
  const InsideTest inside(body.mesh);
  r.m = measure_garment(r.g.model, r.g.state.x, inside);
  EXPECT_EQ(r.m.penetration.penetrating, 0u);
  for (size_t p = 0; p < garment.panels.size(); ++p) {
    Vec3f mean = Vec3f::Zero();
    for (uint32_t v = r.g.panel_first_vertex[p]; v < r.g.panel_first_vertex[p + 1]; ++v) {
      EXPECT_GT(inside.unsigned_distance(r.g.state.x[v]), 0.001f) << garment.panels[p].name;
      mean += r.g.state.x[v];
    }
    r.panel_mean.push_back(mean / static_cast<float>(r.g.panel_first_vertex[p + 1] - r.g.panel_first_vertex[p]));
  }
  return r;
}

void expect_placed_clear(const Body& body, const std::string& name, const std::string& size) {
  SCOPED_TRACE(name + " size " + size + " on a " + std::to_string(body.measurements.height) + " m body");
  const Garment garment = garment_in_size(load_garment(name), size);
  const PlacedGarment placed = place_clear_of_the_body(body, garment);
  EXPECT_LE(placed.m.strain.max, 0.40f);
  EXPECT_LE(placed.m.strain.p99, 0.15f);
  const float centre_z = 0.5f * (body.landmarks.waist.z() + body.landmarks.hip.z());
  for (size_t p = 0; p < garment.panels.size(); ++p) {
    const PlacementHint& h = *garment.panels[p].placement;
    const Vec3f& mean = placed.panel_mean[p];
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

// NOT YET REACHED as a whole (DISABLED_ prefix on the suite: run with
// --gtest_also_run_disabled_tests). The passing garment/size/body cases of these suites are
// asserted in dress_scene_test.cpp (BuiltinFit: dress S/M/L, jeans and trousers M/L on the female
// body, jeans L/XL and trousers XL on the male body) and the others are listed there (BuiltinNotYet)
// with their current figures (22:38 UTC, a6f396c). History, measured at 14:51 UTC on main:
// trousers on the female body close every seam but are stretched 10-18 % on the hips (wool: 6 %);
// with the sewing settings in the working tree at 14:44 (not committed) they passed in S, M and L
// (5.7 / 5.5 / 5.1 %); on the male body S kept an outseam 56 mm open and M, L did not settle;
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
class ImportedPlacement : public ::testing::TestWithParam<std::string> {};

// The file's 3D layout, where a panel's centre lies (p = R (x, y, 0) + T, in metres).
Vec3f file_centre(const Panel& panel) {
  const PanelTransform& t = *panel.transform;
  constexpr double kDeg = 3.14159265358979323846 / 180;
  const Eigen::Matrix3d r = (Eigen::AngleAxisd(t.rotation_deg.z() * kDeg, Vec3d::UnitZ()) *
                             Eigen::AngleAxisd(t.rotation_deg.y() * kDeg, Vec3d::UnitY()) *
                             Eigen::AngleAxisd(t.rotation_deg.x() * kDeg, Vec3d::UnitX()))
                                .toRotationMatrix();
  Vec3d c = Vec3d::Zero();
  const auto loop = panel.polygon(0.01);
  for (const Vec2d& q : loop) c += r * Vec3d(q.x(), q.y(), 0);
  return (c / static_cast<double>(loop.size()) + t.translation).cast<float>();
}

// Placement from the file's own 3D layout: every vertex outside the body and at least a millimetre
// from it, each panel on the side of the body where the file puts it (left/right of the midline,
// in front of/behind the body's centre, where the file's centre is more than 5 cm off), the flat
// pattern hardly stretched, and the first sewing steps finite with the seams closing (before it
// was read, the importer's guessed hints mirrored clockwise back panels across the body and the
// sewing exploded in its first step).
TEST_P(ImportedPlacement, StartsClearOfTheBodyWhereTheFilePutsIt) {
  if (sanitized() && GetParam().find("shirt") == std::string::npos)
    GTEST_SKIP() << "sanitized build: the GarmentCode shirt only";
  const auto body_path = DRAPE_REQUIRE_SHARED("bodies/garmentcode/mean_all.obj");
  const auto pattern = DRAPE_REQUIRE_SHARED("patterns/" + GetParam());
  const Body& body = mean_all_body(body_path);
  const Garment garment = garment_in_size(load_garment(pattern.string()), "");
  const PlacedGarment placed = place_clear_of_the_body(body, garment);
  // Rolled with flat y as height where a garment has sleeves, the springs of a shirt stretch over
  // the sloped shoulders (p99 measured: shirt 0.44, tee 0.51, pants 0.16; the built-in shirt 0.18
  // with the same roll); the first sewing steps relax it. A flat layout is not stretched.
  EXPECT_LE(placed.m.strain.p99, 0.6f);
  const float centre_z = 0.5f * (body.landmarks.waist.z() + body.landmarks.hip.z());
  for (size_t p = 0; p < garment.panels.size(); ++p) {
    SCOPED_TRACE(garment.panels[p].name);
    EXPECT_NE(placed.g.placement[p].region.find("transform"), std::string::npos);
    const Vec3f& mean = placed.panel_mean[p];
    const Vec3f file = file_centre(garment.panels[p]);
    if (std::abs(file.x()) > 0.05f) {
      EXPECT_EQ(mean.x() > 0, file.x() > 0);
    }
    if (std::abs(file.z() - centre_z) > 0.05f) {
      EXPECT_EQ(mean.z() > centre_z, file.z() > centre_z);
    }
  }

  // The first sewing steps: finite, and the widest seam closing.
  if (sanitized()) return;
  DressOptions o;
  o.max_iterations = 400;
  const DressResult r = dress(body, {{load_garment(pattern.string()), ""}}, o);
  ASSERT_EQ(r.garments.size(), 1u);
  EXPECT_TRUE(r.quality.finite);
  EXPECT_EQ(r.garments[0].status, StepStatus::Ok);
  EXPECT_LT(r.quality.max_seam_gap_m, 0.8f * r.garments[0].initial_max_gap);
}

TEST_P(ImportedPattern, PassesTheGatesOnMeanAll) {
  if (sanitized()) GTEST_SKIP() << "sanitized build: dressing takes too long";
  const auto body_path = DRAPE_REQUIRE_SHARED("bodies/garmentcode/mean_all.obj");
  const auto pattern = DRAPE_REQUIRE_SHARED("patterns/" + GetParam());
  expect_gates(dress(mean_all_body(body_path), {{load_garment(pattern.string()), ""}}));
}

// `drape dress --garment FILE` on a malformed import (the corpus's GarmentCode and 2021 files):
// exit 2, one stderr line naming the file, nothing written.
TEST(ImportedPatternCli, MalformedImportsAreRefusedAndNothingWritten) {
  const std::filesystem::path corpus = std::filesystem::path(DRAPE_SOURCE_DIR) / "tests/corpus/garment";
  size_t files = 0;
  for (const auto& entry : std::filesystem::directory_iterator(corpus)) {
    const std::string name = entry.path().filename().string();
    if (name.rfind("garmentcode_", 0) != 0 && name.rfind("template2021_", 0) != 0) continue;
    SCOPED_TRACE(name);
    ++files;
    const auto out = test::temp_dir("import_cli") / "out";
    const auto r = test::run_drape("dress --garment " + entry.path().string() + " --out " + out.string());
    EXPECT_EQ(r.exit_code, 2);
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_NE(r.err.find(entry.path().string()), std::string::npos) << r.err;
    EXPECT_FALSE(std::filesystem::exists(out));
  }
  EXPECT_GE(files, 3u);
}

std::string pattern_case_name(const ::testing::TestParamInfo<std::string>& info) {
  std::string s = info.param.substr(info.param.rfind('/') + 1);
  s = s.substr(0, s.find('.'));
  for (char& c : s)
    if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
  return s;
}

const auto kImportedPatterns = ::testing::Values("garmentcode/shirt_mean_specification.json",
                                                 "garmentcode/dress_pencil_specification.json",
                                                 "garmentcode/flare_skirt_specification.json",
                                                 "garmentcode/hoody_mean_specification.json",
                                                 "garment_pattern_generator_2021/tee.json",
                                                 "garment_pattern_generator_2021/skirt_4_panels.json",
                                                 "garment_pattern_generator_2021/pants_straight_sides.json");

INSTANTIATE_TEST_SUITE_P(Files, ImportedPlacement, kImportedPatterns, pattern_case_name);

// Pass every gate, in jersey (GarmentCode's soft default material), rolled at the file's heights:
// the shirt, the hoody, the flare skirt, its waistband an elastic band (2026-11-29: strain 10.8 %
// against jersey's 10 % + 1 %, seams 0.25 mm, nothing inside, settled, 4.7 s of simulation), and
// the pencil dress, its waist seam an elastic band at the hips (2026-11-30: strain 10.5 %, seams
// 0.19 mm, nothing inside, settled). The file lays the hoody's and the dress's front and back flat
// with their shoulder seams 3-4 cm below mean_all's shoulders; from there the dress's straps closed
// under her arms and it slid 0.25 m down (docs/garment-format.md, Dressing an import).
INSTANTIATE_TEST_SUITE_P(GarmentCode, ImportedPattern,
                         ::testing::Values("garmentcode/shirt_mean_specification.json",
                                           "garmentcode/hoody_mean_specification.json",
                                           "garmentcode/flare_skirt_specification.json",
                                           "garmentcode/dress_pencil_specification.json"),
                         pattern_case_name);

// NOT YET REACHED (DISABLED_ prefix, as above), measured with the explicit step at 19:07 UTC on
// mean_all with the placement from the file (docs/garment-format.md, Dressing an import) and the
// `lower_interface` edges imported as an elastic band (docs/dressing.md, Elastic bands): no
// explosion, but (the flare skirt, which now passes above, as it was then)
//   flare_skirt (jersey): every seam closed, strain 10.4 %, drop 0.135 m, but not settled: light
//     corner vertices at the band's side seams tremble at 35 m/s (without the band: not settled
//     either, and the waistband slid; with the elastic springs ending on their own corner the
//     corners were pulled 45-58 mm open). The same at 22:30 UTC (main 9b044f3 with the band's
//     softer seam-crossing springs: 10.42 %, 0.135 m, report.json final_max_speed 37 m/s): the
//     fastest vertices are where the band's side seams meet the panel seams, a vertex joined to
//     two partners at one point; a mass floor on the band's vertices did not settle it. Later
//     (the drop measured from the placement, the last stitches pulled closed): settled, stayed on
//     (0.044 m), every seam closed (0.13 mm), but the skirt's top edge 11.86 % stretched at her
//     upper hips (the converge passes at their cap; 10.34 % with a cap of 512 in a trial build);
//   tee (2021, rolled, cotton): side and shoulder seams 63-82 mm open: 0.87 m round the chest on
//     a 1.01 m bust (sized for the SMPL female body);
//   skirt_4_panels (2021): seams 15-23 mm open (mean_all's waist 0.84 m; 23.4 mm, 5.24 %, settled
//     at 22:30 UTC);
//   pants_straight_sides (2021, 22:30 UTC, centre front/back on the midline): the crotch seams
//     close, but the outseams stay 68-69 mm and the inseams 47 mm open at the top, not settled
//     (waist 0.80 m on mean_all's 0.84 m, hips 1.04 m: the template is a size too small for her).
// `drape dress --body ../shared/data/bodies/garmentcode/mean_all.obj --garment FILE`, report.json.
INSTANTIATE_TEST_SUITE_P(DISABLED_GarmentCode, ImportedPattern,
                         ::testing::Values("garment_pattern_generator_2021/tee.json",
                                           "garment_pattern_generator_2021/skirt_4_panels.json",
                                           "garment_pattern_generator_2021/pants_straight_sides.json"),
                         pattern_case_name);

// The flare skirt's hem hangs, it does not slide: sewn by the explicit step (its sewing runs for
// simulated time, without gravity) its circle-skirt panels stand
// out like a lampshade (the centre of mass rises while sewing), and when draping starts the flare
// falls by more than the stayed_on limit while its waistband moves a few centimetres. The drop
// that gate reads is measured from the placement, so it sees the band, not the hem (before, from
// the end of sewing: "garment centre fell 0.193 m", a skirt that had not slid off). The skirt
// still fails its strain gate (DISABLED_GarmentCode above).
TEST(ImportedPatternDrop, AFlareThatHangsIsNotASkirtThatSlid) {
  if (sanitized()) GTEST_SKIP() << "sanitized build: dressing takes too long";
  const auto body_path = DRAPE_REQUIRE_SHARED("bodies/garmentcode/mean_all.obj");
  const auto pattern = DRAPE_REQUIRE_SHARED("patterns/garmentcode/flare_skirt_specification.json");
  const DressResult r = dress(mean_all_body(body_path), {{load_garment(pattern.string()), ""}}, test::explicit_options());
  ASSERT_EQ(r.garments.size(), 1u);
  const DressedGarment& g = r.garments[0];
  EXPECT_TRUE(r.quality.finite);
  EXPECT_TRUE(g.settled);
  EXPECT_GT(g.sewn_centre_y - g.placed_centre_y, 0.10f);  // the flare stood out while sewing
  EXPECT_GT(g.sewn_centre_y - g.final_centre_y, DressOptions{}.gates.max_drop_m);  // and fell while draping
  EXPECT_NEAR(r.quality.drop_m, std::max(0.0f, g.placed_centre_y - g.final_centre_y), 1e-6f);
  EXPECT_LT(g.drop_m(), 0.08f);
  EXPECT_EQ(failed_gates(r).find("stayed_on"), std::string::npos) << failed_gates(r);
  // Where the band went: its top a few centimetres below where the file put it (1.088 m), well above
  // mean_all's hip line.
  float top = -1;
  for (const Vec3f& x : g.state.x) top = std::max(top, x.y());
  EXPECT_GT(top, 1.088f - 0.06f);
}

// --- The 2021 templates on a body of our choice --------------------------------------------------

// A slim 1.70 m female body from drape's parametric generator (mean_all is 1.01 m round the bust
// against the 2021 tee's 0.87 m): the elastic band's and the T-pose's tests below.
const Body& template_body() {
  static const Body body = make_body(Sex::Female, {{"height", 1.70f}, {"bust", 0.82f}, {"waist", 0.66f}, {"hips", 0.90f}});
  return body;
}

// The body the templates were drafted round, as near as their own girths tell (`drape garment chart
// FILE`: the tees and the jumpsuit a 0.79 m bust, the sleeveless dress 0.84 m and a waist under
// 0.72 m, the skirts' and the trousers' waists 0.74-0.78 m and hips 0.90-1.05 m): MakeHuman's
// female body, 1.65 m, bust 0.85 m, waist 0.71 m, hips 1.01 m, in its A-pose (the SMPL body is not
// in the data). `drape dress --measurements height=1.65,bust=0.85,waist=0.71,hips=1.01 --garment
// FILE` dresses the same body.
const Body& smpl_proportioned_body() {
  static const Body body =
      make_human_body(Sex::Female, {{"height", 1.65f}, {"bust", 0.85f}, {"waist", 0.71f}, {"hips", 1.01f}});
  return body;
}

class Template2021 : public ::testing::TestWithParam<std::string> {};

TEST_P(Template2021, PassesTheGatesOnTheBodyTheyWereDraftedFor) {
  if (sanitized()) GTEST_SKIP() << "sanitized build: dressing takes too long";
  const auto pattern = DRAPE_REQUIRE_SHARED("patterns/" + GetParam());
  expect_gates(dress(smpl_proportioned_body(), {{load_garment(pattern.string()), ""}}));
}

// Every 2021 template in the shared data passes every gate in cotton (measured 2026-11-30 23:28
// UTC): strain 5.11-5.25 % (limit 6 %), seams 0.1-0.6 mm, at most 0.06 % of the vertices inside
// (the jumpsuit), settled; the skirts rest 0.129 m (skirt_2_panels, a 0.81 m waist on her 0.71 m,
// on her hips) and 0.112 m below where the file puts them (the stayed_on gate allows 0.15 m),
// the trousers 0.05 m on their elastic waist. Narrower in the hips the two-panel skirt slides
// further (hips 0.96 m: 0.157 m); 2 cm wider in the waist the sleeveless dress presses into her
// (waist 0.73 m: 1.9 % of its vertices inside). The tee's sleeves are laid out for a T-pose and
// close over this A-posed body's shoulders; on the older generator's slim body (`template_body`
// above) its shoulder seams stayed 90 mm open and the three sleeveless ones went 1.5-2.3 % inside.
INSTANTIATE_TEST_SUITE_P(Files, Template2021,
                         ::testing::Values("garment_pattern_generator_2021/tee.json",
                                           "garment_pattern_generator_2021/tee_sleeveless.json",
                                           "garment_pattern_generator_2021/dress_sleeveless.json",
                                           "garment_pattern_generator_2021/jumpsuit_sleeveless.json",
                                           "garment_pattern_generator_2021/skirt_2_panels.json",
                                           "garment_pattern_generator_2021/skirt_4_panels.json",
                                           "garment_pattern_generator_2021/pants_straight_sides.json"),
                         pattern_case_name);

// The elastic waist holds the trousers up by its tension alone (nothing pinned): after two seconds
// of draping on the slim body they have dropped a few centimetres with their band. Without it they
// are placed where they would rest, lower on the hips (placed at the waist, they fell down the legs:
// 0.52 m and off the body). The band's springs are not fabric: the strain gate still reads
// cotton's limit.
TEST(ElasticBand, HoldsTheTrousersUp) {
  if (sanitized()) GTEST_SKIP() << "sanitized build: dressing takes too long";
  const auto pattern = DRAPE_REQUIRE_SHARED("patterns/garment_pattern_generator_2021/pants_straight_sides.json");
  GarmentSpec with_band = load_garment(pattern.string());
  ASSERT_EQ(with_band.bands.size(), 1u);
  GarmentSpec without_band = with_band;
  without_band.bands.clear();
  DressOptions o = test::explicit_options();  // two seconds of draping: the explicit step's simulated time
  o.max_drape_seconds = 2.0;
  const DressResult held = dress(template_body(), {{with_band, ""}}, o);
  const DressResult fell = dress(template_body(), {{without_band, ""}}, o);
  EXPECT_TRUE(held.quality.finite);
  EXPECT_LT(held.garments[0].drop_m(), 0.10f);
  // Without it they start lower, where the body's girth fills their waist (placement.cpp,
  // waistband_drop), and rest there, below the held pair (2.9 cm on this slim body).
  EXPECT_GT(held.garments[0].final_centre_y - fell.garments[0].final_centre_y, 0.02f);
  EXPECT_LT(fell.garments[0].drop_m(), 0.10f);
  EXPECT_LE(held.quality.max_strain, held.garments[0].model.fabric.strain_threshold + 0.01f);
}

// With the centre front and back of each trouser panel on the midline (placement from the file)
// and the elastic crossing the seams that start open, the 2021 pants close every seam while sewing
// on the slim body and stay up on their band within cotton's strain limit (19:07 UTC, before: the
// front crotch seam stayed 59-100 mm open at the band; 22:45 UTC: sewn in 1221 iterations, at
// the default grid only, see DISABLED_TeeAndTrousers above). One second of draping: the full run
// is not settled yet.
TEST(ElasticBand, PantsCloseEverySeamWhileSewing) {
  if (sanitized()) GTEST_SKIP() << "sanitized build: dressing takes too long";
  const auto pattern = DRAPE_REQUIRE_SHARED("patterns/garment_pattern_generator_2021/pants_straight_sides.json");
  DressOptions o;
  o.max_drape_seconds = 1.0;
  const DressResult r = dress(template_body(), {{load_garment(pattern.string()), ""}}, o);
  ASSERT_EQ(r.garments.size(), 1u);
  const DressedGarment& g = r.garments[0];
  EXPECT_TRUE(r.quality.finite);
  EXPECT_TRUE(g.seams_closed) << "sewing ended after " << g.sewing_iterations << " iterations";
  EXPECT_LE(r.quality.max_seam_gap_m, 0.002f);
  EXPECT_LE(r.quality.max_strain, g.model.fabric.strain_threshold + 0.01f);
  EXPECT_LE(r.quality.penetration_fraction, 0.005);
  EXPECT_LT(g.drop_m(), 0.15f);
}

// --- The 2021 tee on a T-posed body ----------------------------------------------------------------

// The body with its arms raised to the horizontal (a T-pose, as the 2021 tee's sleeves are laid
// out) by linear blend skinning of its own rig: every joint from the upper arm down turned about
// the upper-arm joint in the frontal plane, then landmarks, measurements and parts found again.
Body t_posed(const Body& a_pose) {
  Body body = a_pose;
  const Skeleton& s = a_pose.skeleton;
  std::vector<Eigen::Affine3f> pose(s.joints.size(), Eigen::Affine3f::Identity());
  for (const char* side : {"Left", "Right"}) {
    const int arm = s.find(std::string(side) + "Arm");
    const int hand = s.find(std::string(side) + "Hand");
    if (arm < 0 || hand < 0) continue;
    const Vec3f pivot = s.joints[static_cast<size_t>(arm)].position;
    const Vec3f axis = s.joints[static_cast<size_t>(hand)].position - pivot;
    // The arm's angle below the horizontal, turned back up about the body's front axis (+Z).
    const float up = (axis.x() > 0 ? 1.0f : -1.0f) * std::atan2(-axis.y(), std::abs(axis.x()));
    const Eigen::Affine3f turn = Eigen::Translation3f(pivot) * Eigen::AngleAxisf(up, Vec3f::UnitZ()) * Eigen::Translation3f(-pivot);
    for (size_t j = 0; j < s.joints.size(); ++j)
      for (int k = static_cast<int>(j); k >= 0; k = s.joints[static_cast<size_t>(k)].parent)
        if (k == arm) {
          pose[j] = turn;
          break;
        }
  }
  Mesh& m = body.mesh;
  for (size_t v = 0; v < m.positions.size(); ++v) {
    Vec3f p = Vec3f::Zero();
    for (size_t k = 0; k < 4; ++k) p += m.weights[v][static_cast<Eigen::Index>(k)] * (pose[m.joints[v][k]] * a_pose.mesh.positions[v]);
    m.positions[v] = p;
  }
  for (size_t j = 0; j < s.joints.size(); ++j) body.skeleton.joints[j].position = pose[j] * s.joints[j].position;
  m.normals = vertex_normals(m.positions, m.triangles);
  analyse_body(body, "T-posed body");
  return body;
}

// The pose itself: the arms horizontal (wrists level with the shoulders), the legs and torso as
// they were, the rig's skin weights summing to one so the torso does not move.
TEST(TPosedBody, ArmsHorizontalTorsoUnmoved) {
  if (sanitized()) GTEST_SKIP() << "sanitized build: building a body takes too long";
  const Body& a = template_body();
  const Body t = t_posed(a);
  for (const auto& [shoulder, wrist] : {std::pair{t.landmarks.left_shoulder, t.landmarks.left_wrist},
                                        std::pair{t.landmarks.right_shoulder, t.landmarks.right_wrist}})
    EXPECT_NEAR(wrist.y(), shoulder.y(), 0.05f);
  EXPECT_NEAR(t.measurements.waist, a.measurements.waist, 0.01f);
  EXPECT_NEAR(t.measurements.hips, a.measurements.hips, 0.01f);
  EXPECT_NEAR(t.landmarks.crotch.y(), a.landmarks.crotch.y(), 0.01f);
}

// The tee's sleeves are laid out for a T-pose (arms horizontal): on a T-posed body they hang from
// the shoulders as drafted. The templates were drafted round the SMPL female average, which is not
// in the data; a small 1.60 m body built from measurements stands in for it (bust 0.76 m against the
// tee's 0.87 m chest, shoulders 0.32 m). Passes every gate (measured 19:10 UTC): seams 0.0 mm,
// strain 5.0 % (cotton, limit 6 %), 0 inside, settled, dropped 2 cm. Not yet on larger bodies:
// bust 0.78-0.80 m and shoulders 0.33-0.34 m leave the shoulder seams 22-27 mm open (the tee at
// cotton's strain limit round the chest and shoulders), the A-posed slim body 90 mm.
TEST(Template2021TPose, TeePassesTheGatesOnATPosedBody) {
  if (sanitized()) GTEST_SKIP() << "sanitized build: dressing takes too long";
  const auto pattern = DRAPE_REQUIRE_SHARED("patterns/garment_pattern_generator_2021/tee.json");
  const Body body = t_posed(make_body(Sex::Female, {{"height", 1.60f}, {"bust", 0.76f}, {"waist", 0.62f},
                                                    {"hips", 0.86f}, {"shoulder_width", 0.32f}}));
  expect_gates(dress(body, {{load_garment(pattern.string()), ""}}));
}

}  // namespace
}  // namespace drape
