// Dressing scenes: every built-in garment in every size on both default bodies must pass the
// quality gates of docs/dressing.md (seams closed <= 2 mm, <= 0.5 % of vertices inside the body,
// max strain <= fabric threshold + 1 %, settled, nothing below the floor, garment stayed on), and
// the same on the MakeHuman-derived bodies of ../shared/data (skipped where absent).
// Under sanitizers (DRAPE_SANITIZED) only the default shirt on the default body runs.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <mutex>
#include <ostream>
#include <string>
#include <vector>

#include "drape/dress.hpp"
#include "drape/error.hpp"
#include "dress/dress_support.hpp"
#include "dress/stages.hpp"
#include "support/test_support.hpp"

namespace drape {
namespace {

using test::cached_body;
using test::generator_body;
using test::explicit_options;
using test::failed_gates;
using test::sanitized;

// What every dressing must already give: a finite state, the garment on the body and outside it,
// above the floor, its seams pulled from wide open to (on average) nearly closed.
void expect_sound(const DressResult& r) {
  ASSERT_FALSE(r.garments.empty());
  const FitQuality& q = r.quality;
  EXPECT_TRUE(q.finite);
  EXPECT_LE(q.penetration_fraction, 0.005);
  EXPECT_GE(q.lowest_y, 0.0f);
  EXPECT_LE(q.drop_m, 0.15f);
  EXPECT_LE(q.mean_seam_gap_m, 0.005f);
  for (const DressedGarment& g : r.garments) {
    EXPECT_GT(g.initial_max_gap, 0.01f);  // placement really left the seams open
    EXPECT_LT(seam_gap_stats(g.state.x, g.seam_pairs).max, g.initial_max_gap);
  }
  EXPECT_GT(r.simulation.iterations, 0u);
}

// The full quality gates of docs/dressing.md.
void expect_dressed(const Body& body, const std::string& garment, const std::string& size) {
  SCOPED_TRACE(garment + " size " + size);
  const DressResult r = dress(body, {{load_garment(garment), size}});
  ASSERT_EQ(r.garments.size(), 1u);
  expect_sound(r);
  const FitQuality& q = r.quality;
  EXPECT_LE(q.max_seam_gap_m, 0.002f);
  EXPECT_LE(q.max_strain, r.garments[0].model.fabric.strain_threshold + 0.01f);
  EXPECT_TRUE(q.settled);
  EXPECT_TRUE(r.passed()) << failed_gates(r);
}

// The default dressing, run once per test program (the slowest case under sanitizers).
const DressResult& default_dressing() {
  static const DressResult result = dress(cached_body(Sex::Female), {{load_garment(default_garment_name()), ""}});
  return result;
}

TEST(DressScene, DefaultShirtOnDefaultBodyIsSound) { expect_sound(default_dressing()); }

TEST(DressScene, DefaultShirtOnDefaultBodyPassesTheGates) {
  const DressResult& r = default_dressing();
  ASSERT_EQ(r.garments.size(), 1u);
  const FitQuality& q = r.quality;
  EXPECT_LE(q.max_seam_gap_m, 0.002f);
  EXPECT_LE(q.max_strain, r.garments[0].model.fabric.strain_threshold + 0.01f);
  EXPECT_TRUE(q.settled);
  EXPECT_TRUE(r.passed()) << failed_gates(r);
}

// Self-contact (DressOptions::self_collision, docs/cloth.md): the default shirt and the dress
// draped with it pass through themselves nowhere. (Whether the shirt draped without it passes
// through itself where the sleeves fold against the sides depends on rounding: 8 edges or none
// from one build of the solver to the next. Self-contact's own effect is asserted on two sheets
// in tests/sim/implicit_test.cpp.)
TEST(DressScene, GarmentsDrapedWithSelfContactDoNotPassThroughThemselves) {
  const DressResult& shirt = default_dressing();
  ASSERT_EQ(shirt.garments.size(), 1u);
  EXPECT_EQ(shirt.garments[0].self_intersections, 0u);
  if (sanitized()) GTEST_SKIP() << "sanitized build: the default shirt only";
  const DressResult dress_m = dress(cached_body(Sex::Female), {{load_garment("dress"), "M"}});
  EXPECT_TRUE(dress_m.passed()) << failed_gates(dress_m);
  EXPECT_EQ(dress_m.garments[0].self_intersections, 0u);
}

// The explicit step on the default shirt's grid (2.6 cm), coarse for the shoulders' curvature, on
// the generator's female body (test::generator_body, where this was measured): with
// only its vertices kept off the body, the skin rose through its faces there (release build: 15 body
// vertices, up to 5.9 mm). With the faces kept off too (DressOptions::face_clearance, on by default)
// far fewer show through, by far less (release: 3, up to 1.7 mm). Both runs in the same build, since
// the exact figures follow its rounding.
TEST(DressScene, ExplicitShirtKeepsItsFacesOffTheShoulders) {
  if (sanitized()) GTEST_SKIP() << "sanitized build: only the default shirt on the default body";
  DressOptions o = explicit_options();
  const SkinThroughStats on = dress(generator_body(Sex::Female), {{load_garment(default_garment_name()), ""}}, o).quality.skin_through;
  o.face_clearance = -1.0f;
  const SkinThroughStats off = dress(generator_body(Sex::Female), {{load_garment(default_garment_name()), ""}}, o).quality.skin_through;
  EXPECT_GT(off.body_vertices, 10u);
  EXPECT_GT(off.max_depth_m, 0.005f);
  EXPECT_LE(2 * on.body_vertices, off.body_vertices);
  EXPECT_LT(on.max_depth_m, 0.004f);
}

// The size for a body when none is asked for (choose_size, docs/garment-format.md "Size chart"): the
// default female body wears the female-graded M of every built-in, the default male body the size
// drafted for him; a garment without a chart, or a body without the chart's measurements, the base size.
TEST(DressSize, EachDefaultBodyGetsItsSize) {
  const std::map<std::string, std::string> male = {
      {"shirt", "XL"}, {"dress", "XL"}, {"skirt", "L"}, {"trousers", "XL"}, {"jeans", "XL"}};
  for (const BuiltinGarment& b : builtin_garments()) {
    SCOPED_TRACE(b.name);
    GarmentSpec spec = *builtin_garment(b.name);
    const SizeChoice female_choice = choose_size(spec, cached_body(Sex::Female).measurements);
    EXPECT_EQ(female_choice.size, "M");
    EXPECT_NE(female_choice.reason.find("nearest in the size chart"), std::string::npos) << female_choice.reason;
    ASSERT_TRUE(male.count(b.name));
    EXPECT_EQ(choose_size(spec, cached_body(Sex::Male).measurements).size, male.at(b.name));
    EXPECT_EQ(choose_size(spec, Measurements{}).size, b.default_size);  // nothing measured
    spec.size_chart.clear();
    EXPECT_EQ(choose_size(spec, cached_body(Sex::Male).measurements).size, b.default_size);
  }
}

// Every key a size chart may use is a measurement the body layer takes, and an unknown one is refused
// naming the file and the key.
TEST(DressSize, ChartKeysAreBodyMeasurements) {
  for (std::string_view key : size_chart_keys()) {
    const auto& table = measurement_table();
    EXPECT_TRUE(std::any_of(table.begin(), table.end(), [&](const MeasurementInfo& m) { return m.key == key; })) << key;
  }
  const std::string text = R"({"drape_garment": 1, "name": "t", "sizes": ["M"], "size_chart": {"M": {"bicep": 0.3}},
                               "panels": [{"name": "p", "vertices": [[0, 0], [1, 0], [1, 1]]}]})";
  try {
    parse_garment(text, "chart.json");
    ADD_FAILURE() << "an unknown size chart key was accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("chart.json"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("bicep"), std::string::npos) << e.what();
  }
}

// The shirt's other sizes on the default (female) body. NOT YET on the male body: its shoulders
// and neck are wider than the pattern's (the shoulder seams stay ~2-3 cm open), see docs/dressing.md.
// At twice the paper's resolution (--edge 0.013, ~5100 vertices) the seam forces leave the sewn
// shirt 7.5 % over its strain limit; draping's converge passes, whose corrections go into the
// velocities, used to turn that into a first draping step over 50 m/s (reported as an explosion).
// The sewn garment is now relaxed to the limit first (sewing.cpp) and dresses like the default one.
TEST(DressScene, FinerShirtIsRelaxedBeforeDrapingAndPassesTheGates) {
  if (sanitized()) GTEST_SKIP() << "sanitized build: only the default shirt on the default body";
  DressOptions o = explicit_options();
  o.mesh.edge_length = 0.013;
  const DressResult r = dress(cached_body(Sex::Female), {{load_garment(default_garment_name()), ""}}, o);
  ASSERT_EQ(r.garments.size(), 1u);
  const DressedGarment& g = r.garments[0];
  EXPECT_GT(g.model.particle_count(), 4000u);
  EXPECT_GT(g.sewn_max_strain, g.model.fabric.strain_threshold + 0.01f);
  EXPECT_GT(g.relax_passes, 0);
  expect_sound(r);
  EXPECT_TRUE(r.passed()) << failed_gates(r);
}

// Coarse-to-fine (DressOptions::coarse_edge): the same finer shirt is first dressed at the paper's
// spacing, and starts from it with its seams already within the joining distance, so it is not
// sewn again; then every gate at the fine resolution.
TEST(DressScene, FinerShirtStartsFromTheCoarseOneAndPassesTheGates) {
  if (sanitized()) GTEST_SKIP() << "sanitized build: only the default shirt on the default body";
  DressOptions o = explicit_options();
  o.mesh.edge_length = 0.013;
  o.coarse_edge = kPaperEdgeLength;
  const DressResult r = dress(cached_body(Sex::Female), {{load_garment(default_garment_name()), ""}}, o);
  ASSERT_EQ(r.garments.size(), 1u);
  const DressedGarment& g = r.garments[0];
  EXPECT_EQ(g.coarse.edge, kPaperEdgeLength);
  EXPECT_LT(4 * g.coarse.vertices, g.model.particle_count() + g.coarse.vertices);  // ~1/4 of the vertices
  EXPECT_TRUE(g.coarse.seams_closed && g.coarse.settled);
  EXPECT_LT(g.coarse.extrapolated, g.model.particle_count() / 20);  // outline curves past the coarse chords
  EXPECT_LE(g.coarse.start_max_gap, o.seam_closed_m);  // placement leaves them ~0.18 m open
  EXPECT_EQ(g.sewing_iterations, 0u);
  EXPECT_EQ(r.simulation.iterations, g.coarse.iterations + g.state.iterations);
  expect_sound(r);
  EXPECT_TRUE(r.passed()) << failed_gates(r);
}

// start_from_coarse interpolates the coarse garment linearly over its flat pattern: a coarse garment
// lying as an affine image of its flat pattern (here rotated, sheared and lifted) puts every fine
// particle at that image of its own flat point, inside the coarse outline and (extended) beyond it.
TEST(DressScene, CoarseStartInterpolatesOverTheFlatPattern) {
  const Body& body = cached_body(Sex::Female);
  const auto collider = make_body_collider(body.mesh, CollisionMethod::image);
  const Garment garment = garment_in_size(load_garment("skirt"), "M");
  DressOptions coarse_o, fine_o;
  coarse_o.mesh.edge_length = 0.05;
  fine_o.mesh.edge_length = 0.02;
  const DressedGarment coarse = prepare_garment(body, garment, *collider, coarse_o);
  DressedGarment fine = prepare_garment(body, garment, *collider, fine_o);
  ASSERT_EQ(coarse.panel_first_vertex.size(), fine.panel_first_vertex.size());
  ASSERT_GT(fine.model.particle_count(), 4 * coarse.model.particle_count());
  // One affine map per panel (distinct, so a particle placed from the wrong panel shows).
  const auto image = [](size_t panel, const Vec2f& u) {
    const float p = static_cast<float>(panel);
    return Vec3f(0.8f * u.x() + 0.3f * u.y() + p, -0.2f * u.x() + 0.9f * u.y() + 1.0f, 0.5f * u.x() - 0.4f * u.y() - 2 * p);
  };
  ClothState coarse_state = coarse.state;
  for (size_t p = 0; p + 1 < coarse.panel_first_vertex.size(); ++p)
    for (uint32_t i = coarse.panel_first_vertex[p]; i < coarse.panel_first_vertex[p + 1]; ++i)
      coarse_state.x[i] = image(p, coarse.model.flat_position[i]);
  for (Vec3f& v : fine.state.v) v = Vec3f::Ones();
  const size_t outside = dressing::start_from_coarse(fine.state, fine.model, fine.panel_first_vertex, coarse.model,
                                                     coarse_state, coarse.panel_first_vertex);
  EXPECT_LT(outside, fine.model.particle_count() / 10);
  float worst = 0;
  for (size_t p = 0; p + 1 < fine.panel_first_vertex.size(); ++p)
    for (uint32_t i = fine.panel_first_vertex[p]; i < fine.panel_first_vertex[p + 1]; ++i) {
      worst = std::max(worst, (fine.state.x[i] - image(p, fine.model.flat_position[i])).norm());
      EXPECT_EQ(fine.state.v[i], Vec3f::Zero()) << i;
    }
  EXPECT_LT(worst, 1e-5f);
}

TEST(DressScene, ShirtOtherSizesOnDefaultBody) {
  if (sanitized()) GTEST_SKIP() << "sanitized build: only the default shirt on the default body";
  for (const char* size : {"S", "L"}) expect_dressed(cached_body(Sex::Female), "shirt", size);
}

// A built-in garment in one size on one default body.
struct Fit {
  std::string garment, size;
  Sex sex;
};
void PrintTo(const Fit& f, std::ostream* os) { *os << f.garment << ' ' << f.size << (f.sex == Sex::Female ? " female" : " male"); }
std::string fit_name(const ::testing::TestParamInfo<Fit>& p) {
  return p.param.garment + "_" + p.param.size + (p.param.sex == Sex::Female ? "_female" : "_male");
}

// Every gate passed (the shirt's S/M/L on the female body are asserted above).
class BuiltinFit : public ::testing::TestWithParam<Fit> {};
TEST_P(BuiltinFit, PassesTheGates) {
  if (sanitized()) GTEST_SKIP() << "sanitized build: only the default shirt on the default body";
  expect_dressed(cached_body(GetParam().sex), GetParam().garment, GetParam().size);
}
INSTANTIATE_TEST_SUITE_P(Garments, BuiltinFit,
                         ::testing::Values(Fit{"shirt", "XL", Sex::Male}, Fit{"dress", "L", Sex::Female}, Fit{"dress", "XL", Sex::Male},
                                           Fit{"skirt", "M", Sex::Female}, Fit{"skirt", "L", Sex::Female},
                                           Fit{"trousers", "S", Sex::Female},
                                           Fit{"jeans", "M", Sex::Female},
                                           Fit{"dress", "S", Sex::Female}, Fit{"dress", "M", Sex::Female},
                                           Fit{"skirt", "S", Sex::Female}, Fit{"skirt", "L", Sex::Male},
                                           Fit{"dress", "L", Sex::Male},
                                           // The bottoms in the size their chart gives each body: the
                                           // trousers M (held by their waistband) on the female body,
                                           // the trousers and jeans XL (his waist girth + 2 cm) on the
                                           // male body; and the trousers' L on the female body.
                                           Fit{"trousers", "M", Sex::Female}, Fit{"trousers", "XL", Sex::Male},
                                           Fit{"jeans", "XL", Sex::Male},
                                           Fit{"trousers", "L", Sex::Female},
                                           // Sizes not cut for the body: the shirt S/M/L and the dress
                                           // S/M on the male body (his shoulders and neck are wider),
                                           // the jeans S on the female body.
                                           Fit{"shirt", "S", Sex::Male}, Fit{"shirt", "M", Sex::Male}, Fit{"shirt", "L", Sex::Male},
                                           Fit{"dress", "S", Sex::Male}, Fit{"dress", "M", Sex::Male},
                                           Fit{"jeans", "S", Sex::Female},
                                           // The jeans' L, a size too loose for both: held by their
                                           // waistband (without it they slid 0.189 m down her hips and
                                           // 0.160 m down his).
                                           Fit{"jeans", "L", Sex::Female}, Fit{"jeans", "L", Sex::Male},
                                           // A size under his chart's XL: the trousers L (1.4 cm of
                                           // ease at the hips), since the strain barrier is 1000x the
                                           // spring (6.04 % at 300x).
                                           Fit{"trousers", "L", Sex::Male},
                                           // Two sizes under his XL: the skirt M (a 0.82 m waist on
                                           // his 0.86 m), the trousers M and the jeans M (0.82 and
                                           // 0.85 m on his 0.87 m), their bands at the strain limit,
                                           // the contact layer pressed thin and kept out of his skin by
                                           // the contact's stiffening past it (docs/cloth.md).
                                           Fit{"skirt", "M", Sex::Male}, Fit{"trousers", "M", Sex::Male},
                                           Fit{"jeans", "M", Sex::Male}),
                         fit_name);

// NOT YET REACHED (measured failures on the default bodies, see docs/dressing.md "Status"): sizes too
// small for the body, three under the male body's chart sizes (`build/drape dress --body male
// --garment G --size S`, 2026-12-01):
// - skirt S (cut for a 0.78 m waist, his is 0.86 m): 8.1 % stretched, seams 6.4 mm open;
// - trousers S (a 0.78 m waist where he is 0.87 m round): 8.5 %, seams 6.9 mm open, 0.64 % of
//   its vertices in his body;
// - jeans S (0.81 m where he is 0.87 m): 4.1 % (denim's 2 % + 1 % allowed), a seam 8.7 mm open.
class BuiltinNotYet : public BuiltinFit {};
TEST_P(BuiltinNotYet, DISABLED_PassesTheGates) {
  if (sanitized()) GTEST_SKIP() << "sanitized build: only the default shirt on the default body";
  expect_dressed(cached_body(GetParam().sex), GetParam().garment, GetParam().size);
}
INSTANTIATE_TEST_SUITE_P(Garments, BuiltinNotYet,
                         ::testing::Values(Fit{"skirt", "S", Sex::Male}, Fit{"trousers", "S", Sex::Male},
                                           Fit{"jeans", "S", Sex::Male}),
                         fit_name);

// The default shirt (M) on the MakeHuman-derived bodies and on GarmentCode's mean body (metres, +Y up).
class SharedBody : public ::testing::TestWithParam<std::string> {};
std::string body_stem(const ::testing::TestParamInfo<std::string>& p) {
  return std::filesystem::path(p.param).stem().string();
}

TEST_P(SharedBody, DefaultShirt) {
  if (sanitized()) GTEST_SKIP() << "sanitized build: only the default shirt on the default body";
  const auto path = DRAPE_REQUIRE_SHARED(GetParam());
  expect_dressed(load_body(path), default_garment_name(), "M");
}
INSTANTIATE_TEST_SUITE_P(Bodies, SharedBody,
                         ::testing::Values("bodies/garmentcode/mean_all.obj", "bodies/makehuman/derived/mh_female_average.obj"),
                         body_stem);

// Each garment in the size its size chart gives a shared body (what `drape dress --body FILE` makes
// without --size): the chosen size, then every gate.
struct SharedFit {
  std::string garment, body, size;
};
void PrintTo(const SharedFit& f, std::ostream* os) { *os << f.garment << ' ' << f.size << " on " << f.body; }
class SharedBodyOwnSize : public ::testing::TestWithParam<SharedFit> {};
TEST_P(SharedBodyOwnSize, PassesTheGates) {
  if (sanitized()) GTEST_SKIP() << "sanitized build: only the default shirt on the default body";
  const auto path = DRAPE_REQUIRE_SHARED("bodies/" + GetParam().body);
  const Body body = load_body(path);
  EXPECT_EQ(choose_size(load_garment(GetParam().garment), body.measurements).size, GetParam().size);
  expect_dressed(body, GetParam().garment, "");
}
std::string shared_fit_name(const ::testing::TestParamInfo<SharedFit>& p) {
  return p.param.garment + "_" + p.param.size + "_" + std::filesystem::path(p.param.body).stem().string();
}
constexpr const char* kMeanAll = "garmentcode/mean_all.obj";
constexpr const char* kFemaleAverage = "makehuman/derived/mh_female_average.obj";
constexpr const char* kFemaleHeavy = "makehuman/derived/mh_female_heavy.obj";
constexpr const char* kMaleAverage = "makehuman/derived/mh_male_average.obj";
constexpr const char* kMaleThin = "makehuman/derived/mh_male_thin.obj";
// The trousers' XS is the men's cut for the slim man (mh_male_thin: waist 0.69 m, hips 0.88 m):
// a 0.74 m waist gathered by the waistband, the crotch 1 cm lower. (Before the waistband, XS and
// S were cut 6 and 4 cm lower with waists of 0.84 and 0.87 m, so that they started near the hips
// where they came to rest; at M's height without the band the S slid 0.165 m down the average
// female MakeHuman body.)
// The jeans' XS likewise: a 0.77 m waist gathered by the waistband, hips 0.97 m, the crotch 1 cm
// lower. (Before the waistband it was cut 6 cm lower with a 0.855 m waist; the S slid 0.195 m on him.)
INSTANTIATE_TEST_SUITE_P(Bodies, SharedBodyOwnSize,
                         ::testing::Values(SharedFit{"dress", kMeanAll, "XL"}, SharedFit{"trousers", kMeanAll, "XL"},
                                           SharedFit{"shirt", kFemaleAverage, "S"}, SharedFit{"dress", kFemaleAverage, "S"},
                                           SharedFit{"skirt", kFemaleAverage, "S"}, SharedFit{"jeans", kFemaleAverage, "S"},
                                           SharedFit{"shirt", kFemaleHeavy, "S"}, SharedFit{"dress", kFemaleHeavy, "S"},
                                           SharedFit{"skirt", kFemaleHeavy, "M"}, SharedFit{"trousers", kFemaleHeavy, "M"},
                                           SharedFit{"skirt", kMaleAverage, "M"}, SharedFit{"trousers", kMaleThin, "XS"},
                                           SharedFit{"trousers", kFemaleAverage, "S"}, SharedFit{"jeans", kMaleThin, "XS"},
                                           // Since 0e1e0b8 (23:28 UTC, 4072b38): before, neither settled
                                           // within 3 s (the skirt's waist trembled at up to 7.9 m/s).
                                           SharedFit{"shirt", kMeanAll, "XL"},
                                           // Since the last stitches are pulled closed (3ff9523): before,
                                           // both outseams stayed 8 mm open at her hips.
                                           SharedFit{"jeans", kFemaleHeavy, "M"},
                                           // Since the implicit solver is the default: before, an outseam's
                                           // top corner stayed 11-16 mm open.
                                           SharedFit{"jeans", kMeanAll, "XL"},
                                           // Since skirts looser than the waist are placed where the
                                           // body's girth fills their band (placement.cpp,
                                           // waistband_drop): before, it came to rest on her hips
                                           // 0.155 m below where it was placed.
                                           SharedFit{"skirt", kMeanAll, "L"},
                                           // Since the trousers have a waistband (their waist held at
                                           // his): before, they slid 0.245 m down his hips.
                                           SharedFit{"trousers", kMaleAverage, "M"}),
                         shared_fit_name);

// The heavy female body (upper arm 0.30 m) wears the shirt's L: in M a sleeve's armhole corner
// stays 35 mm open round her arm.
TEST(DressScene, ShirtLOnHeavyFemaleBody) {
  if (sanitized()) GTEST_SKIP() << "sanitized build: only the default shirt on the default body";
  const auto path = DRAPE_REQUIRE_SHARED("bodies/makehuman/derived/mh_female_heavy.obj");
  expect_dressed(load_body(path), default_garment_name(), "L");
}

// The jeans' L (drafted for 1.03 m hips) on the heavy female body (hips 1.03 m): every gate. Her
// size by the chart is M (nearest over waist and hips), which passes too (SharedBodyOwnSize).
TEST(DressScene, JeansLOnHeavyFemaleBody) {
  if (sanitized()) GTEST_SKIP() << "sanitized build: only the default shirt on the default body";
  const auto path = DRAPE_REQUIRE_SHARED("bodies/makehuman/derived/mh_female_heavy.obj");
  expect_dressed(load_body(path), "jeans", "L");
}

// The male MakeHuman bodies wear the shirt's men's cut, XL (their shoulders and armpits are too
// wide and low for the female-graded S/M/L: a shoulder/armhole corner stays 8-9 cm open).
class SharedMaleBody : public SharedBody {};
TEST_P(SharedMaleBody, ShirtMensCut) {
  if (sanitized()) GTEST_SKIP() << "sanitized build: only the default shirt on the default body";
  const auto path = DRAPE_REQUIRE_SHARED(GetParam());
  const Body body = load_body(path);
  EXPECT_EQ(choose_size(load_garment(default_garment_name()), body.measurements).size, "XL");  // his size by the chart
  expect_dressed(body, default_garment_name(), "XL");
}
// And the dress's cut for the male body, XL.
TEST_P(SharedMaleBody, DressMensCut) {
  if (sanitized()) GTEST_SKIP() << "sanitized build: only the default shirt on the default body";
  const auto path = DRAPE_REQUIRE_SHARED(GetParam());
  const Body body = load_body(path);
  EXPECT_EQ(choose_size(load_garment("dress"), body.measurements).size, "XL");
  expect_dressed(body, "dress", "XL");
}
INSTANTIATE_TEST_SUITE_P(Bodies, SharedMaleBody,
                         ::testing::Values("bodies/makehuman/derived/mh_male_average.obj",
                                           "bodies/makehuman/derived/mh_male_thin.obj"),
                         body_stem);

// The dress (M) on the female MakeHuman bodies. NOT YET on mean_all: a side seam stays 10-11 mm
// open under the arm in M and L.
class SharedFemaleBody : public SharedBody {};
TEST_P(SharedFemaleBody, Dress) {
  if (sanitized()) GTEST_SKIP() << "sanitized build: only the default shirt on the default body";
  const auto path = DRAPE_REQUIRE_SHARED(GetParam());
  expect_dressed(load_body(path), "dress", "M");
}
INSTANTIATE_TEST_SUITE_P(Bodies, SharedFemaleBody,
                         ::testing::Values("bodies/makehuman/derived/mh_female_average.obj",
                                           "bodies/makehuman/derived/mh_female_heavy.obj"),
                         body_stem);

// One built-in garment on a default body dressed twice by the explicit step: with its default
// settings, then with one of them set to `value`.
template <class T>
std::pair<DressResult, DressResult> dress_both_ways(Sex sex, const std::string& garment, const std::string& size,
                                                    T DressOptions::*option, T value) {
  const GarmentSpec spec = load_garment(garment);
  const DressOptions base = explicit_options();
  DressOptions other = base;
  other.*option = value;
  return {dress(generator_body(sex), {{spec, size}}, base), dress(generator_body(sex), {{spec, size}}, other)};
}

// The explicit step's sewing ends when a pair no longer closes (DressOptions::sewing_stall_s): the women's S shirt on the
// generator's male body, a size too small for him, keeps its seams open at his armpits, where the side
// seam, the sleeve's underarm seam and the armhole meet (14.5 mm). Sewing stops well before its
// 1.5 s cap, and sewing to the cap instead leaves every seam as open (within a millimetre): stopping
// gave up no pair that would still have closed. Its draping then settles, so the verdict is a seam,
// not motion.
TEST(DressScene, SewingStopsWhenAPairNoLongerCloses) {
  if (sanitized()) GTEST_SKIP() << "sanitized build: only the default shirt on the default body";
  const auto [stopped, capped] = dress_both_ways(Sex::Male, "shirt", "S", &DressOptions::sewing_stall_s, 0.0);  // to the cap
  const DressedGarment &s = stopped.garments.at(0), &c = capped.garments.at(0);
  EXPECT_TRUE(s.sewing_stalled);
  EXPECT_FALSE(c.sewing_stalled);
  EXPECT_LT(s.sewing_iterations * 2, c.sewing_iterations);
  EXPECT_GT(stopped.quality.max_seam_gap_m, 0.01f);
  EXPECT_GT(capped.quality.max_seam_gap_m, 0.01f);
  ASSERT_LT(s.widest_seam(), s.seam_names.size());
  const std::vector<float> s_gaps = s.seam_gaps(), c_gaps = c.seam_gaps();
  ASSERT_EQ(s_gaps.size(), c_gaps.size());
  for (size_t k = 0; k < s_gaps.size(); ++k) EXPECT_NEAR(s_gaps[k], c_gaps[k], 0.001f) << s.seam_names[k];
  EXPECT_NEAR(s.seam_gaps()[s.widest_seam()], stopped.quality.max_seam_gap_m, 1e-6f);
  EXPECT_TRUE(stopped.quality.settled);
}

// The explicit step's last stitches (DressOptions::pull_closed_m): the dress's L on the generator's male body ends its
// sewing with a few pairs still open by under a centimetre, light corner pairs whose seam springs
// cannot beat the cloth's tension there. Pulled closed and joined, they stay closed and every gate
// passes within silk's strain limit; left to the seam springs (pull_closed_m 0) they stay over 1 cm
// open. (The trousers' L showed this before they had a waistband; the band now closes their ring.)
TEST(DressScene, LastStitchesArePulledClosedWhenSewingEnds) {
  if (sanitized()) GTEST_SKIP() << "sanitized build: only the default shirt on the default body";
  const auto [pulled, open] = dress_both_ways(Sex::Male, "dress", "L", &DressOptions::pull_closed_m, 0.0f);
  const DressedGarment &p = pulled.garments.at(0), &o = open.garments.at(0);
  EXPECT_FALSE(p.sewing_stalled);
  EXPECT_GT(p.pulled_closed, 0u);
  EXPECT_EQ(o.pulled_closed, 0u);
  EXPECT_EQ(p.sewing_iterations, o.sewing_iterations);  // the same sewing, up to its end
  EXPECT_LE(pulled.quality.max_seam_gap_m, 0.002f);
  EXPECT_LE(pulled.quality.max_strain, p.model.fabric.strain_threshold + 0.01f);
  EXPECT_TRUE(pulled.passed()) << test::failed_gates(pulled);
  EXPECT_GT(open.quality.max_seam_gap_m, DressOptions{}.pull_closed_m);
}

// The fabric's contact with the body, set for the dressing (DressOptions::friction, thickness;
// `drape dress --friction --thickness`): the skirt on the default female body slides lower
// without friction than with a grippy 0.8 (measured: 0.615 against 0.634 m for its centre), and
// with an 8 mm contact thickness its cloth rests about twice as far off the skin as with the
// fabric's 4 mm.
TEST(DressScene, FrictionAndThicknessOverrideTheFabricsOwn) {
  if (sanitized()) GTEST_SKIP() << "sanitized build: only the default shirt on the default body";
  const Body& body = cached_body(Sex::Female);
  const GarmentSpec skirt = load_garment("skirt");
  const auto dressed = [&](float friction, float thickness) {
    DressOptions o;
    o.friction = friction;
    o.thickness = thickness;
    return dress(body, {{skirt, "M"}}, o);
  };
  const DressResult slippery = dressed(0.0f, 0.0f), grippy = dressed(0.8f, 0.0f), thick = dressed(-1.0f, 0.008f);
  for (const DressResult* r : {&slippery, &grippy, &thick}) EXPECT_TRUE(r->passed()) << failed_gates(*r);
  const DressedGarment &s = slippery.garments.at(0), &g = grippy.garments.at(0), &t = thick.garments.at(0);
  EXPECT_EQ(s.model.fabric.friction, 0.0f);
  EXPECT_EQ(g.model.fabric.friction, 0.8f);
  EXPECT_EQ(t.model.fabric.friction, fabric_or_throw(skirt.fabric).friction);
  EXPECT_EQ(t.model.fabric.collision_thickness, 0.008f);
  EXPECT_LT(s.final_centre_y, g.final_centre_y - 0.005f);
  // The cloth's distance from the skin where it rests on the body (particles within 2 cm of it).
  const auto collider = make_body_collider(body.mesh, CollisionMethod::bvh);
  const auto resting = [&](const DressedGarment& garment) {
    std::vector<ContactSample> near(garment.state.x.size());
    collider->query(garment.state.x, 0.02f, near);
    std::vector<float> d;
    for (const ContactSample& c : near)
      if (c.distance < 0.02f) d.push_back(c.distance);
    std::nth_element(d.begin(), d.begin() + static_cast<long>(d.size() / 10), d.end());
    return d.at(d.size() / 10);  // the closest tenth
  };
  const float at_4mm = resting(s), at_8mm = resting(t);
  EXPECT_GT(at_8mm, at_4mm + 0.003f);
  EXPECT_GT(at_8mm, 0.006f);
  std::fprintf(stderr, "centre %.3f m without friction, %.3f m at 0.8; the closest tenth of the cloth %.1f mm off the skin at 4 mm, %.1f mm at 8 mm\n",
               static_cast<double>(s.final_centre_y), static_cast<double>(g.final_centre_y), 1e3 * at_4mm, 1e3 * at_8mm);
}

// Layers: a skirt, then a shirt over it (outermost last); the shirt must not sink into the skirt.
TEST(DressScene, TwoLayers) {
  if (sanitized()) GTEST_SKIP() << "sanitized build: only the default shirt on the default body";
  const DressResult r = dress(cached_body(Sex::Female), {{load_garment("skirt"), ""}, {load_garment("shirt"), ""}});
  ASSERT_EQ(r.garments.size(), 2u);
  expect_sound(r);
  const DressedGarment &skirt = r.garments[0], &shirt = r.garments[1];
  EXPECT_EQ(vertices_beneath(skirt, skirt.state.x, shirt.state.x), 0u);
  // The count sees what went through: the skirt's own surface 5 mm inside it is beneath it (but
  // at its waist and hem, where the nearest point is an edge), 5 mm outside is not.
  const std::vector<Vec3f> normals = vertex_normals(skirt.state.x, skirt.model.triangles);
  std::vector<Vec3f> inside(skirt.state.x), outside(skirt.state.x);
  for (size_t i = 0; i < inside.size(); ++i) {
    inside[i] -= 0.005f * normals[i];
    outside[i] += 0.005f * normals[i];
  }
  EXPECT_GT(vertices_beneath(skirt, skirt.state.x, inside), 9 * inside.size() / 10);
  EXPECT_EQ(vertices_beneath(skirt, skirt.state.x, outside), 0u);
}

// The run is deterministic: the same input gives the same final state (bit for bit).
TEST(DressScene, Deterministic) {
  DressOptions o;
  o.max_iterations = sanitized() ? 50 : 400;
  const Body& body = cached_body(Sex::Female);
  const DressResult a = dress(body, {{load_garment("shirt"), ""}}, o);
  const DressResult b = dress(body, {{load_garment("shirt"), ""}}, o);
  EXPECT_EQ(state_hash(a.garments[0].state), state_hash(b.garments[0].state));
}

}  // namespace
}  // namespace drape
