// A size chart made from a pattern (drape/size_advice.hpp, docs/fit.md "A chart from the
// pattern"): girths at the garment's own lines, less the ease it is drafted with.
#include <gtest/gtest.h>

#include <filesystem>

#include <nlohmann/json.hpp>

#include "dress/dress_support.hpp"
#include "drape/error.hpp"
#include "drape/size_advice.hpp"
#include "support/test_support.hpp"

namespace drape {
namespace {

const PatternGirth* girth(const PatternSize& size, std::string_view key) {
  for (const PatternGirth& g : size.girths)
    if (g.key == key) return &g;
  return nullptr;
}

// GarmentCode drafts a pattern from a body's measurements; these were drafted for its mean body,
// ../shared/data/patterns/garmentcode/mean_all_body_measurements.yaml: bust 99.84 cm, waist
// 84.33 cm, hips 103.48 cm. The pencil dress's skirt and the flare skirt's waistband are drafted
// with no ease at the waist and hips, so measured at their own lines they are the body's girths.
TEST(PatternChart, GarmentCodePatternsMeasureTheBodyTheyWereDraftedFor) {
  const auto body_path = DRAPE_REQUIRE_SHARED("bodies/garmentcode/mean_all.obj");
  const auto pencil_path = DRAPE_REQUIRE_SHARED("patterns/garmentcode/dress_pencil_specification.json");
  const auto flare_path = DRAPE_REQUIRE_SHARED("patterns/garmentcode/flare_skirt_specification.json");
  const auto shirt_path = DRAPE_REQUIRE_SHARED("patterns/garmentcode/shirt_mean_specification.json");
  const Body body = load_body(body_path);
  constexpr float kBust = 0.9984f, kWaist = 0.8433f, kHips = 1.0348f;

  const std::vector<PatternSize> pencil = measure_pattern(body, read_garment(pencil_path), DressOptions{});
  ASSERT_EQ(pencil.size(), 1u);
  const PatternGirth* waist = girth(pencil[0], "waist");
  const PatternGirth* hips = girth(pencil[0], "hips");
  const PatternGirth* bust = girth(pencil[0], "bust");
  ASSERT_TRUE(waist && hips && bust);
  EXPECT_NEAR(waist->girth_m, kWaist, 0.01f) << waist->line;
  EXPECT_NEAR(hips->girth_m, kHips, 0.01f) << hips->line;
  EXPECT_EQ(waist->line, "its waist seam");
  // The bodice has ease at the bust, and less than a loose garment's.
  EXPECT_GT(bust->girth_m, kBust + 0.03f);
  EXPECT_LT(bust->girth_m, kBust + 0.15f);

  // A flared skirt: sized by its waistband; at the hips it stands far out from the body.
  const std::vector<PatternSize> flare = measure_pattern(body, read_garment(flare_path), DressOptions{});
  ASSERT_EQ(flare.size(), 1u);
  ASSERT_NE(girth(flare[0], "waist"), nullptr);
  EXPECT_NEAR(girth(flare[0], "waist")->girth_m, kWaist, 0.01f);
  EXPECT_EQ(girth(flare[0], "hips"), nullptr);

  // A straight shirt: its chest only (no shaped waist; it ends above the hips' line).
  const std::vector<PatternSize> shirt = measure_pattern(body, read_garment(shirt_path), DressOptions{});
  ASSERT_EQ(shirt.size(), 1u);
  ASSERT_NE(girth(shirt[0], "bust"), nullptr);
  EXPECT_GT(girth(shirt[0], "bust")->girth_m, kBust);
  EXPECT_EQ(girth(shirt[0], "waist"), nullptr);
}

// The built-ins' grading, measured at their own lines on the default body: the jeans' waists 4 cm
// apart (XS-L) and hips growing with the size; the shirt's chest 4 cm apart; the dress shaped at
// the waist.
TEST(PatternChart, BuiltinGradingMeasuredAtTheGarmentsOwnLines) {
  const Body& body = test::cached_body(Sex::Female);
  const std::vector<PatternSize> jeans = measure_pattern(body, *builtin_garment("jeans"), DressOptions{});
  ASSERT_EQ(jeans.size(), 5u);
  for (size_t k = 0; k + 1 < 4; ++k) {
    const PatternGirth* a = girth(jeans[k], "waist");
    const PatternGirth* b = girth(jeans[k + 1], "waist");
    ASSERT_TRUE(a && b) << jeans[k].size;
    EXPECT_NEAR(b->girth_m - a->girth_m, 0.04f, 0.005f) << jeans[k].size << " to " << jeans[k + 1].size;
    ASSERT_TRUE(girth(jeans[k], "hips") && girth(jeans[k + 1], "hips"));
    EXPECT_GT(girth(jeans[k + 1], "hips")->girth_m, girth(jeans[k], "hips")->girth_m);
  }
  const std::vector<PatternSize> shirt = measure_pattern(body, *builtin_garment("shirt"), DressOptions{});
  for (size_t k = 0; k + 1 < shirt.size(); ++k) {
    ASSERT_TRUE(girth(shirt[k], "bust") && girth(shirt[k + 1], "bust"));
    EXPECT_NEAR(girth(shirt[k + 1], "bust")->girth_m - girth(shirt[k], "bust")->girth_m, 0.04f, 0.005f);
  }
  const std::vector<PatternSize> dress = measure_pattern(body, *builtin_garment("dress"), DressOptions{});
  for (const PatternSize& s : dress) {
    const PatternGirth* bust = girth(s, "bust");
    const PatternGirth* waist = girth(s, "waist");
    const PatternGirth* hips = girth(s, "hips");
    ASSERT_TRUE(bust && waist && hips) << s.size;
    EXPECT_LT(waist->girth_m, bust->girth_m - 0.04f) << s.size;
    EXPECT_LT(waist->girth_m, hips->girth_m - 0.04f) << s.size;
  }
}

// The chart is each girth less the garment's intended ease (its own where it gives one, else the
// default).
TEST(PatternChart, ChartIsTheGirthsLessTheIntendedEase) {
  GarmentSpec skirt = *builtin_garment("skirt");
  skirt.size_chart.clear();
  skirt.intended_ease = {{"hips", 0.09}};
  const std::vector<PatternSize> sizes = measure_pattern(test::cached_body(Sex::Female), skirt, DressOptions{});
  const std::vector<SizeMeasurements> chart = chart_from_pattern(sizes);
  ASSERT_EQ(chart.size(), sizes.size());
  for (size_t k = 0; k < sizes.size(); ++k) {
    const PatternGirth* hips = girth(sizes[k], "hips");
    const PatternGirth* waist = girth(sizes[k], "waist");
    ASSERT_TRUE(hips && waist) << sizes[k].size;
    EXPECT_FLOAT_EQ(hips->ease_m, 0.09f);
    EXPECT_FLOAT_EQ(waist->ease_m, static_cast<float>(default_intended_ease().at("waist")));
    EXPECT_NEAR(chart[k].at("hips"), hips->girth_m - 0.09, 1e-6);
    EXPECT_NEAR(chart[k].at("waist"), waist->girth_m - waist->ease_m, 1e-6);
  }
}

TEST(PatternChart, GarmentFileGivesItsIntendedEase) {
  const std::string base = R"({"drape_garment": 1, "name": "tube", "panels": [{"name": "front",
      "vertices": [[0, 0], [0.5, 0], [0.5, 0.4], [0, 0.4]],
      "placement": {"body_part": "torso", "side": "front", "landmark": "waist", "anchor": [0.25, 0.4]}}])";
  const GarmentSpec spec = parse_garment(base + R"(, "intended_ease": {"bust": 0.12, "hips": -0.02}})", "tube.json");
  EXPECT_DOUBLE_EQ(intended_ease(spec, "bust"), 0.12);
  EXPECT_DOUBLE_EQ(intended_ease(spec, "hips"), -0.02);
  EXPECT_DOUBLE_EQ(intended_ease(spec, "waist"), default_intended_ease().at("waist"));
  for (const auto& [bad, message] : std::vector<std::pair<std::string, std::string>>{
           {R"({"neck": 0.02})", "unknown girth"}, {R"({"bust": 0.9})", "between -0.2 and 0.5"}, {R"([0.1])", "expected an object"}}) {
    try {
      parse_garment(base + R"(, "intended_ease": )" + bad + "}", "tube.json");
      ADD_FAILURE() << bad << " was accepted";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("tube.json"), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find(message), std::string::npos) << e.what();
    }
  }
}

// `drape fit` on a pattern without a chart: the chart its pattern makes, in report.json; `drape
// garment chart` prints it.
TEST(PatternChart, FitCommandMakesTheChartFromThePattern) {
  if (test::sanitized()) GTEST_SKIP() << "sanitized build: dressing is too slow";
  const auto skirt = DRAPE_REQUIRE_SHARED("patterns/garment_pattern_generator_2021/skirt_2_panels.json");
  const auto dir = test::temp_dir("pattern_chart_fit");
  const auto r = test::run_drape("fit --garment " + skirt.string() + " --out " + dir.string());
  ASSERT_TRUE(r.exit_code == 0 || r.exit_code == 3) << r.err;
  EXPECT_NE(r.err.find("has no size chart: its pattern made one"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("cut for a body with waist"), std::string::npos) << r.err;
  const nlohmann::json j = test::read_json(dir / "report.json");
  EXPECT_EQ(j["chart_source"], "pattern");
  EXPECT_EQ(j["chart_size"], "as drafted");
  ASSERT_EQ(j["sizes"].size(), 1u);
  const auto& girths = j["sizes"][0]["pattern_girths"];
  ASSERT_EQ(girths.size(), 2u);
  for (const auto& g : girths) {
    EXPECT_NEAR(g["body_m"].get<double>(), g["garment_girth_m"].get<double>() - g["intended_ease_m"].get<double>(), 1e-6);
    EXPECT_TRUE(g["line"].is_string());
  }
  EXPECT_GE(j["sizes"][0]["chart_distance"].get<double>(), 0.0);

  const auto chart = test::run_drape("garment chart jeans");
  ASSERT_EQ(chart.exit_code, 0) << chart.err;
  EXPECT_NE(chart.out.find("waist  0.81"), std::string::npos) << chart.out;  // M: 0.843 m less 3 cm
  EXPECT_NE(chart.out.find("the garment's chart: 0.740 m"), std::string::npos) << chart.out;
  const auto bad = test::run_drape("garment chart no_such_garment");
  EXPECT_EQ(bad.exit_code, 2);
}

}  // namespace
}  // namespace drape
