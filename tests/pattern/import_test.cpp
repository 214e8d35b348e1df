// Imports: every GarmentCode specification and 2021 template in ../shared/data reads with its panel
// and stitch counts, in metres, and meshes; the DXF pieces come in at the right size and units.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <fstream>

#include "drape/error.hpp"
#include "drape/garment.hpp"
#include "support/test_support.hpp"

namespace drape {
namespace {

struct Expected {
  const char* file;
  size_t panels;
  size_t stitches;
  const char* format;
};

class Import : public ::testing::TestWithParam<Expected> {};

Eigen::AlignedBox2d vertex_box(const PanelSpec& p) {
  Eigen::AlignedBox2d box;
  for (const Vec2d& v : p.vertices[0]) box.extend(v);
  return box;
}

TEST_P(Import, ReadsValidatesAndMeshes) {
  const Expected e = GetParam();
  const auto path = DRAPE_REQUIRE_SHARED(std::string("patterns/") + e.file);
  const GarmentSpec spec = read_garment(path);
  EXPECT_EQ(spec.format, e.format);
  EXPECT_EQ(spec.panels.size(), e.panels);
  EXPECT_EQ(spec.seams.size(), e.stitches);
  for (const PanelSpec& p : spec.panels) {
    ASSERT_TRUE(p.transform.has_value());
    EXPECT_EQ(p.transform->pelvis_origin, std::string(e.format) == "garmentcode-2021");
    // Metres: every panel between 5 cm and 2 m across.
    const double size = vertex_box(p).sizes().maxCoeff();
    EXPECT_GT(size, 0.05) << p.name;
    EXPECT_LT(size, 2.0) << p.name;
  }
  for (const SeamSpec& s : spec.seams) EXPECT_LE(s.ease, kMaxSeamEase);
  const Garment g = garment_in_size(spec);
  const GarmentMesh gm = mesh_garment(g, {Mesher::grid, 0.02});
  EXPECT_EQ(gm.panels.size(), e.panels);
  EXPECT_GT(gm.seam_pairs.size(), 2 * e.stitches);
}

INSTANTIATE_TEST_SUITE_P(
    Patterns, Import,
    ::testing::Values(Expected{"garmentcode/shirt_mean_specification.json", 8, 18, "garmentcode"},
                      Expected{"garmentcode/dress_pencil_specification.json", 6, 23, "garmentcode"},
                      Expected{"garmentcode/flare_skirt_specification.json", 4, 6, "garmentcode"},
                      Expected{"garmentcode/hoody_mean_specification.json", 6, 12, "garmentcode"},
                      Expected{"garment_pattern_generator_2021/tee.json", 6, 12, "garmentcode-2021"},
                      Expected{"garment_pattern_generator_2021/tee_sleeveless.json", 2, 4, "garmentcode-2021"},
                      Expected{"garment_pattern_generator_2021/skirt_2_panels.json", 2, 4, "garmentcode-2021"},
                      Expected{"garment_pattern_generator_2021/skirt_4_panels.json", 4, 8, "garmentcode-2021"},
                      Expected{"garment_pattern_generator_2021/pants_straight_sides.json", 4, 6, "garmentcode-2021"},
                      Expected{"garment_pattern_generator_2021/dress_sleeveless.json", 4, 10, "garmentcode-2021"},
                      Expected{"garment_pattern_generator_2021/jumpsuit_sleeveless.json", 6, 14, "garmentcode-2021"},
                      Expected{"garment_pattern_generator_2021/template_spec_with_comments.json", 2, 2, "garmentcode-2021"}),
    [](const ::testing::TestParamInfo<Expected>& param) {
      std::string n = std::filesystem::path(param.param.file).stem().string();
      for (char& c : n)
        if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
      return n;
    });

TEST(Import, UnitsInMeter300AreRescaled) {
  const auto path = DRAPE_REQUIRE_SHARED("patterns/garment_pattern_generator_2021/tee.json");
  const GarmentSpec spec = read_garment(path);
  const auto front = std::find_if(spec.panels.begin(), spec.panels.end(), [](const PanelSpec& p) { return p.name == "front"; });
  ASSERT_NE(front, spec.panels.end());
  // 130 x 185 template units at 300 per metre.
  EXPECT_NEAR(vertex_box(*front).sizes().x(), 130.0 / 300.0, 1e-9);
  EXPECT_NEAR(vertex_box(*front).sizes().y(), 185.0 / 300.0, 1e-9);
  EXPECT_NEAR(front->transform->translation.z(), 0.1876, 1e-9);
}

// The file's 3D placement is kept as written: translation in metres, XYZ Euler degrees. Neither
// format names a fabric: GarmentCode's soft default material maps to jersey, the 2021 templates to cotton.
TEST(Import, PlacementAsWrittenAndDefaultFabrics) {
  const auto shirt_path = DRAPE_REQUIRE_SHARED("patterns/garmentcode/shirt_mean_specification.json");
  const auto skirt_path = DRAPE_REQUIRE_SHARED("patterns/garment_pattern_generator_2021/skirt_4_panels.json");
  const auto shirt = read_garment(shirt_path);
  EXPECT_EQ(shirt.fabric, "jersey");
  const auto sleeve = std::find_if(shirt.panels.begin(), shirt.panels.end(), [](const PanelSpec& p) { return p.name == "left_sleeve_f"; });
  ASSERT_NE(sleeve, shirt.panels.end());
  EXPECT_NEAR(sleeve->transform->translation.x(), 0.5357347770869189, 1e-9);
  EXPECT_NEAR(sleeve->transform->translation.y(), 1.111086631392047, 1e-9);
  EXPECT_NEAR(sleeve->transform->rotation_deg.z(), -50.48299999999997, 1e-9);
  EXPECT_FALSE(sleeve->transform->pelvis_origin);
  const auto skirt = read_garment(skirt_path);
  EXPECT_EQ(skirt.fabric, "cotton");
}

TEST(Import, GarmentCodeLoopsKeepTheirWinding) {
  const auto path = DRAPE_REQUIRE_SHARED("patterns/garmentcode/shirt_mean_specification.json");
  const Garment g = garment_in_size(read_garment(path));
  int ccw = 0, cw = 0;
  for (const Panel& p : g.panels) (p.signed_area() > 0 ? ccw : cw)++;
  EXPECT_EQ(ccw, 4);  // FORMAT_NOTES: 4 counter-clockwise (front) and 4 clockwise (back) panels
  EXPECT_EQ(cw, 4);
}

TEST(Import, DxfPiecesInMillimetres) {
  const auto path = DRAPE_REQUIRE_SHARED("patterns/dxf/clo-pattern.dxf");
  const GarmentSpec spec = read_garment(path);
  EXPECT_EQ(spec.format, "dxf");
  ASSERT_EQ(spec.panels.size(), 9u);
  ASSERT_EQ(spec.sizes, std::vector<std::string>{"M"});
  const Garment g = garment_in_size(spec);
  // Two pairs of leg panels of 256 x 703 and 256 x 729 mm (README), two 409 x 173 pieces.
  std::vector<std::pair<double, double>> sizes;
  for (const Panel& p : g.panels) {
    Eigen::AlignedBox2d box;
    for (const Vec2d& q : p.polygon(0.001)) box.extend(q);
    sizes.emplace_back(box.sizes().x(), box.sizes().y());
    EXPECT_GT(p.signed_area(), 0) << p.name;  // loops made counter-clockwise
  }
  const auto count = [&](double w, double h) {
    return std::count_if(sizes.begin(), sizes.end(), [&](const auto& s) {
      return std::abs(s.first - w) < 0.002 && std::abs(s.second - h) < 0.002;
    });
  };
  EXPECT_EQ(count(0.256, 0.703), 2);
  EXPECT_EQ(count(0.256, 0.729), 2);
  EXPECT_EQ(count(0.409, 0.173), 2);
  // Edges run between turn points, as straight lines or dense polylines.
  const Panel& leg = g.panels[0];
  EXPECT_GT(leg.edges.size(), 3u);
  EXPECT_TRUE(std::any_of(leg.edges.begin(), leg.edges.end(), [](const Curve& c) { return c.kind == EdgeCurve::polyline; }));
  // And it meshes.
  EXPECT_GT(mesh_garment(g, {Mesher::grid, 0.02}).vertex_count(), 1000u);
}

TEST(Import, DxfWithDoubtfulUnitsIsRefusedUnlessACompanionNamesThem) {
  const auto path = DRAPE_REQUIRE_SHARED("patterns/dxf/clo-box.dxf");
  try {
    read_garment(path);
    ADD_FAILURE() << "a 3 m box read as inches should be refused";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("units look wrong"), std::string::npos) << e.what();
  }
  // A companion garment file names the units and the pieces.
  const auto dir = test::temp_dir("dxf_companion");
  std::filesystem::copy_file(path, dir / "box.dxf");
  std::ofstream(dir / "box.json") << R"({"drape_garment": 1, "name": "box", "dxf": "box.dxf", "units": "mm",
      "panels": [{"piece": "Pattern2D_4937", "name": "box", "placement": {"body_part": "torso", "side": "front"}}]})";
  const GarmentSpec spec = read_garment(dir / "box.json");
  ASSERT_EQ(spec.panels.size(), 1u);
  EXPECT_EQ(spec.panels[0].name, "box");
  Eigen::AlignedBox2d box;
  for (const Vec2d& v : spec.panels[0].vertices[0]) box.extend(v);
  EXPECT_NEAR(box.sizes().x(), 0.1182, 0.0005);
  EXPECT_NEAR(box.sizes().y(), 0.0788, 0.0005);
}

TEST(Import, DxfCompanionSewsPieces) {
  const auto path = DRAPE_REQUIRE_SHARED("patterns/dxf/clo-pattern.dxf");
  const auto dir = test::temp_dir("dxf_seams");
  std::filesystem::copy_file(path, dir / "clo-pattern.dxf");
  // The two 409 x 173 pieces (Pattern2D_768516 and Pattern2D_768528) are 4-vertex rectangles:
  // sew their short ends into a loop (a waistband).
  std::ofstream(dir / "band.json") << R"({"drape_garment": 1, "name": "band", "dxf": "clo-pattern.dxf", "fabric": "denim",
      "panels": [{"piece": "Pattern2D_768516", "name": "band_front"}, {"piece": "Pattern2D_768528", "name": "band_back"}],
      "seams": [{"a": {"panel": "band_front", "edge": 1}, "b": {"panel": "band_back", "edge": 3}},
                {"a": {"panel": "band_front", "edge": 3}, "b": {"panel": "band_back", "edge": 1}}]})";
  const GarmentSpec spec = read_garment(dir / "band.json");
  EXPECT_EQ(spec.panels.size(), 2u);
  EXPECT_EQ(spec.seams.size(), 2u);
  const GarmentMesh gm = mesh_garment(garment_in_size(spec), {Mesher::triangle, 0.02});
  EXPECT_EQ(gm.seam_pairs.size() % 2, 0u);
}

// Elastic bands. GarmentCode's `lower_interface` edges (which its simulator attaches to the body)
// become a band: the flare skirt's waistband top edges, 0.84 m round; a 2021 bottom's unsewn top
// edges (the trousers' four waist edges, 0.80 m); a top (the tee) gets none.
TEST(Import, WaistEdgesBecomeAnElasticBand) {
  const auto flare = DRAPE_REQUIRE_SHARED("patterns/garmentcode/flare_skirt_specification.json");
  const auto pants = DRAPE_REQUIRE_SHARED("patterns/garment_pattern_generator_2021/pants_straight_sides.json");
  const auto tee = DRAPE_REQUIRE_SHARED("patterns/garment_pattern_generator_2021/tee.json");
  const auto band_length = [](const Garment& g) {
    EXPECT_EQ(g.bands.size(), 1u);
    double length = 0;
    if (g.bands.empty()) return length;
    for (const SeamSide& side : g.bands[0].edges) {
      EXPECT_EQ(side.edge_count, 1u);
      length += g.panels[side.panel].edges[side.first_edge].length();
    }
    return length;
  };
  const Garment skirt = garment_in_size(read_garment(flare));
  EXPECT_NEAR(band_length(skirt), 0.843, 0.005);
  for (const SeamSide& side : skirt.bands[0].edges) EXPECT_EQ(skirt.panels[side.panel].edge_names[side.first_edge], "lower_interface");
  const Garment trousers = garment_in_size(read_garment(pants));
  EXPECT_EQ(trousers.bands.at(0).edges.size(), 4u);
  EXPECT_NEAR(band_length(trousers), 0.80, 0.005);
  EXPECT_TRUE(garment_in_size(read_garment(tee)).bands.empty());
}

// A drape garment file declares bands by edge, with ease, width and stiffness; bad values are
// refused naming the file and the field.
TEST(Import, DrapeGarmentBandsAreReadAndChecked) {
  const std::string head = R"({"drape_garment": 1, "name": "tube", "fabric": "jersey",
      "panels": [{"name": "front", "vertices": [[0, 0], [0.4, 0], [0.4, 0.3], [0, 0.3]], "edges": [{}, {}, {"name": "waist"}, {}]},
                 {"name": "back", "vertices": [[0, 0], [0.4, 0], [0.4, 0.3], [0, 0.3]], "edges": [{}, {}, {"name": "waist"}, {}]}],
      "seams": [{"a": {"panel": "front", "edge": 1}, "b": {"panel": "back", "edge": 3}},
                {"a": {"panel": "front", "edge": 3}, "b": {"panel": "back", "edge": 1}}],
      "bands": [{"edges": [{"panel": "front", "edge": "waist"}, {"panel": "back", "edge": "waist"}])";
  const GarmentSpec spec = parse_garment(head + R"(, "ease": -0.08, "width": 0.04, "stiffness": 6}]})", "tube.json");
  ASSERT_EQ(spec.bands.size(), 1u);
  EXPECT_EQ(spec.bands[0].edges.size(), 2u);
  EXPECT_EQ(spec.bands[0].edges[1].panel, 1u);
  EXPECT_EQ(spec.bands[0].edges[1].first_edge, 2u);
  EXPECT_DOUBLE_EQ(spec.bands[0].ease, -0.08);
  EXPECT_DOUBLE_EQ(spec.bands[0].width, 0.04);
  EXPECT_DOUBLE_EQ(spec.bands[0].stiffness, 6.0);
  EXPECT_EQ(garment_in_size(spec).bands.size(), 1u);
  for (const char* bad : {R"(, "ease": 0.1}]})", R"(, "width": 0}]})", R"(, "stiffness": -1}]})"}) {
    try {
      parse_garment(head + bad, "tube.json");
      ADD_FAILURE() << bad;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("tube.json"), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find("bands[0]"), std::string::npos) << e.what();
    }
  }
  const std::string unknown_panel = R"({"drape_garment": 1, "name": "tube",
      "panels": [{"name": "front", "vertices": [[0, 0], [0.4, 0], [0.4, 0.3], [0, 0.3]]}],
      "bands": [{"edges": [{"panel": "side", "edge": 0}]}]})";
  EXPECT_THROW(parse_garment(unknown_panel, "tube.json"), InputError);
}

}  // namespace
}  // namespace drape
