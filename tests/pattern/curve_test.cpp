// Outline curves: arc construction from SVG-style flags, lengths, equal-length sampling and the
// exact area of curved outlines.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "drape/error.hpp"
#include "drape/garment.hpp"

namespace drape {
namespace {

constexpr double kPi = std::numbers::pi;

// A garment JSON with one panel whose edges are given, plus optional seams.
std::string one_panel(const std::string& vertices, const std::string& edges) {
  return R"({"drape_garment": 1, "name": "t", "panels": [{"name": "p", "vertices": )" + vertices +
         (edges.empty() ? "" : R"(, "edges": )" + edges) + "}]}";
}

TEST(Curves, CircleFromTwoSemicircularArcsHasExactAreaAndLength) {
  // Two counter-clockwise half circles of radius 0.1 through (+-0.1, 0).
  const auto spec = parse_garment(one_panel("[[0.1, 0], [-0.1, 0]]",
                                            R"([{"curve": "arc", "radius": 0.1, "direction": "ccw"},
                                                {"curve": "arc", "radius": 0.1, "direction": "ccw"}])"),
                                  "circle.json");
  const Garment g = garment_in_size(spec);
  const Panel& p = g.panels[0];
  EXPECT_NEAR(p.signed_area(), kPi * 0.01, 1e-9);
  EXPECT_NEAR(p.perimeter(), 2 * kPi * 0.1, 1e-7);
  // The first arc passes through the top of the circle.
  EXPECT_NEAR(p.edges[0].point(0.5).y(), 0.1, 1e-7);
  EXPECT_NEAR(p.edges[0].point(0.5).x(), 0.0, 1e-7);
}

TEST(Curves, ArcFlagsPickTheFourArcs) {
  // Chord from (0,0) to (1,0), radius 1: going counter-clockwise from left to right passes below the
  // chord, the short way (centre above, on the left) or the long way (centre below).
  const auto length_and_mid = [](bool large, bool ccw) {
    const std::string edges = std::string(R"([{"curve": "arc", "radius": 1, "large_arc": )") + (large ? "true" : "false") +
                              R"(, "direction": ")" + (ccw ? "ccw" : "cw") + R"("}, {}])";
    const Garment g = garment_in_size(parse_garment(one_panel("[[0, 0], [1, 0]]", edges), "arc.json"));
    return std::pair{g.panels[0].edges[0].length(), g.panels[0].edges[0].point(0.5).y()};
  };
  const double small = 2 * std::asin(0.5), big = 2 * kPi - small;
  EXPECT_NEAR(length_and_mid(false, true).first, small, 1e-12);
  EXPECT_LT(length_and_mid(false, true).second, 0.0);
  EXPECT_NEAR(length_and_mid(false, false).first, small, 1e-12);
  EXPECT_GT(length_and_mid(false, false).second, 0.0);
  EXPECT_NEAR(length_and_mid(true, true).first, big, 1e-12);
  EXPECT_NEAR(length_and_mid(true, true).second, -1 - std::sqrt(0.75), 1e-9);
  EXPECT_NEAR(length_and_mid(true, false).first, big, 1e-12);
  EXPECT_NEAR(length_and_mid(true, false).second, 1 + std::sqrt(0.75), 1e-9);
}

TEST(Curves, BezierLengthAndAreaMatchFineFlattening) {
  const auto spec = parse_garment(one_panel("[[0, 0], [0.4, 0], [0.4, 0.3], [0, 0.3]]",
                                            R"([{"curve": "quadratic", "control": [[0.5, -0.3]]},
                                                {"curve": "cubic", "control": [[0.2, 0.4], [0.8, -0.4]]},
                                                {}, {"curve": "cubic", "control": [[0.3, 0.2], [0.6, 0.1]]}])"),
                                  "bezier.json");
  const Panel p = garment_in_size(spec).panels[0];
  // Reference: a polyline of 20000 points per edge.
  double length = 0, twice_area = 0;
  for (const Curve& c : p.edges) {
    Vec2d prev = c.point(0);
    for (int i = 1; i <= 20000; ++i) {
      const Vec2d q = c.point(i / 20000.0);
      length += (q - prev).norm();
      twice_area += prev.x() * q.y() - q.x() * prev.y();
      prev = q;
    }
  }
  EXPECT_NEAR(p.perimeter(), length, 1e-7);
  EXPECT_NEAR(p.signed_area(), 0.5 * twice_area, 1e-7);
}

TEST(Curves, SamplingByLengthGivesEqualChords) {
  Curve c;
  c.kind = EdgeCurve::cubic;
  c.start = {0, 0};
  c.control = {Vec2d(0.05, 0.3), Vec2d(0.5, -0.2)};
  c.end = {0.6, 0.1};
  const auto pts = c.sample_by_length(40);
  ASSERT_EQ(pts.size(), 41u);
  EXPECT_EQ(pts.front(), c.start);
  EXPECT_EQ(pts.back(), c.end);
  const double step = c.length() / 40;
  for (size_t i = 1; i < pts.size(); ++i) EXPECT_NEAR((pts[i] - pts[i - 1]).norm(), step, 0.01 * step) << i;
}

}  // namespace
}  // namespace drape
