// Garment validation: every kind of bad garment gives an InputError that names the file and the
// element, and the CLI turns it into exit status 2 with one line on stderr.
#include <gtest/gtest.h>

#include <fstream>

#include "drape/error.hpp"
#include "drape/garment.hpp"
#include "support/test_support.hpp"

namespace drape {
namespace {

// Two rectangles 0.4 x 0.6 sewn along their long sides; `patch` edits the text before parsing.
std::string two_panels(const std::string& fabric = "cotton", const std::string& seam_b_edge = "1",
                       const std::string& back_height = "0.6", const std::string& extra = "") {
  return R"({"drape_garment": 1, "name": "tube", "fabric": ")" + fabric + R"(",
    "panels": [
      {"name": "front", "vertices": [[0, 0], [0.4, 0], [0.4, 0.6], [0, 0.6]]},
      {"name": "back", "vertices": [[0, 0], [0.4, 0], [0.4, )" + back_height + R"(], [0, )" + back_height + R"(]]})" +
         extra + R"(
    ],
    "seams": [
      {"name": "left", "a": {"panel": "front", "edge": 3}, "b": {"panel": "back", "edge": )" + seam_b_edge + R"(}},
      {"name": "right", "a": {"panel": "front", "edge": 1}, "b": {"panel": "back", "edge": 3}}
    ]})";
}

std::string error_of(const std::string& text, const std::string& source = "g.json") {
  try {
    parse_garment(text, source);
  } catch (const InputError& e) {
    EXPECT_EQ(e.source(), source);
    return e.what();
  }
  return "(no error)";
}

TEST(Validation, AValidGarmentParses) {
  const GarmentSpec spec = parse_garment(two_panels(), "g.json");
  EXPECT_EQ(spec.panels.size(), 2u);
  EXPECT_EQ(spec.seams.size(), 2u);
  EXPECT_EQ(spec.format, "drape");
}

TEST(Validation, SeamLengthMismatchNamesTheSeam) {
  const std::string e = error_of(two_panels("cotton", "1", "0.55"));
  EXPECT_NE(e.find("seam 'left'"), std::string::npos) << e;
  EXPECT_NE(e.find("differ in length by 50.0 mm"), std::string::npos) << e;
}

TEST(Validation, EaseAllowsGathering) {
  std::string text = two_panels("cotton", "1", "0.55");
  const std::string seam = R"("b": {"panel": "back", "edge": 1}})";
  text.replace(text.find(seam), seam.size(), R"("b": {"panel": "back", "edge": 1}, "ease": 0.1})");
  const std::string seam2 = R"("b": {"panel": "back", "edge": 3}})";
  text.replace(text.find(seam2), seam2.size(), R"("b": {"panel": "back", "edge": 3}, "ease": 0.1})");
  EXPECT_NO_THROW(parse_garment(text, "g.json"));
}

TEST(Validation, MissingEdgeIsNamed) {
  const std::string e = error_of(two_panels("cotton", "7"));
  EXPECT_NE(e.find("edge 7 does not exist"), std::string::npos) << e;
  EXPECT_NE(e.find("seam 'left'"), std::string::npos) << e;
}

TEST(Validation, EdgeSewnTwiceIsRefused) {
  const std::string e = error_of(two_panels("cotton", "3"));
  EXPECT_NE(e.find("already sewn by seam 'left'"), std::string::npos) << e;
}

TEST(Validation, UnknownFabric) {
  const std::string e = error_of(two_panels("velvet"));
  EXPECT_NE(e.find("unknown fabric \"velvet\""), std::string::npos) << e;
}

TEST(Validation, PanelWithoutSeams) {
  const std::string e = error_of(two_panels("cotton", "1", "0.6", R"(, {"name": "pocket", "vertices": [[0, 0], [0.1, 0], [0.1, 0.1]]})"));
  EXPECT_NE(e.find("panel 'pocket' has no seams"), std::string::npos) << e;
}

TEST(Validation, SelfIntersectingOutline) {
  const std::string text = R"({"drape_garment": 1, "name": "bow", "panels": [
      {"name": "bowtie", "vertices": [[0, 0], [0.3, 0.3], [0.3, 0], [0, 0.4]]}]})";
  const std::string e = error_of(text);
  EXPECT_NE(e.find("panel 'bowtie': outline intersects itself"), std::string::npos) << e;
}

TEST(Validation, BadJsonGivesLineAndColumn) {
  const std::string e = error_of("{\n  \"drape_garment\": 1,\n  \"name\": oops\n}");
  EXPECT_NE(e.find("invalid JSON at line 3"), std::string::npos) << e;
  EXPECT_EQ(e.find('\n'), std::string::npos) << e;
}

TEST(Validation, GradeRulesMoveVerticesPerSize) {
  const std::string text = R"({"drape_garment": 1, "name": "graded", "sizes": ["S", "M", "L"], "base_size": "M",
    "grade_rules": {"side": {"step": [0.02, 0]}, "top": {"deltas": {"S": [0, -0.01], "L": [0, 0.03]}}},
    "panels": [{"name": "p", "vertices": [[0, 0], {"at": [0.4, 0], "grade": "side"},
                                          {"at": [0.4, 0.6], "grade": "side"}, {"at": [0, 0.6], "grade": "top"}]}]})";
  const GarmentSpec spec = parse_garment(text, "graded.json");
  ASSERT_EQ(spec.sizes.size(), 3u);
  EXPECT_NEAR(spec.panels[0].vertices[0][1].x(), 0.38, 1e-12);
  EXPECT_NEAR(spec.panels[0].vertices[2][1].x(), 0.42, 1e-12);
  EXPECT_NEAR(spec.panels[0].vertices[0][3].y(), 0.59, 1e-12);
  EXPECT_NEAR(spec.panels[0].vertices[2][3].y(), 0.63, 1e-12);
  EXPECT_GT(std::abs(garment_in_size(spec, "L").panels[0].signed_area()),
            std::abs(garment_in_size(spec, "S").panels[0].signed_area()));
  EXPECT_THROW(garment_in_size(spec, "XL"), InputError);
}

TEST(Validation, CliExitsTwoWithOneLineNamingTheFile) {
  const auto dir = test::temp_dir("garment_cli");
  const auto file = dir / "mismatch.json";
  std::ofstream(file) << two_panels("cotton", "1", "0.5");
  const auto r = test::run_drape("garment check " + file.string());
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find(file.string()), std::string::npos) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
}

}  // namespace
}  // namespace drape
