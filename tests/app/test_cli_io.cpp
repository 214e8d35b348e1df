// `drape info` and `drape convert` as a user runs them.
#include <gtest/gtest.h>

#include <fstream>
#include <nlohmann/json.hpp>

#include "support/gltf_validator.hpp"
#include "support/test_support.hpp"

namespace fs = std::filesystem;
using drape::test::run_drape;

namespace {

std::string quoted(const fs::path& p) {
  std::string q(1, '"');
  q += p.string();
  q += '"';
  return q;
}

size_t lines(const std::string& s) {
  return static_cast<size_t>(std::count(s.begin(), s.end(), '\n'));
}

}  // namespace

TEST(CliInfo, EveryBodyMeshLoadsWithAPlausibleHeight) {
  const fs::path bodies = DRAPE_REQUIRE_SHARED("bodies");
  size_t checked = 0;
  for (const auto& entry : fs::recursive_directory_iterator(bodies)) {
    const std::string ext = entry.path().extension().string();
    if (ext != ".obj" && ext != ".glb" && ext != ".ply" && ext != ".gltf") continue;
    // The raw MakeHuman base mesh is in decimetres (and carries helper geometry).
    const bool decimetres = entry.path().filename() == "base.obj";
    const auto r =
        run_drape("info --json " + std::string(decimetres ? "--units dm " : "") + quoted(entry.path()));
    ASSERT_EQ(r.exit_code, 0) << entry.path() << ": " << r.err;
    const auto j = nlohmann::json::parse(r.out);
    const double height = j["height_m"].get<double>();
    EXPECT_GT(height, 1.4) << entry.path();
    EXPECT_LT(height, 2.0) << entry.path();
    EXPECT_GT(j["triangles"].get<size_t>(), 10000u) << entry.path();
    if (!decimetres) {
      // The derived and GarmentCode bodies are watertight, feet on the floor (data/README.md).
      EXPECT_EQ(j["boundary_loops"].get<size_t>(), 0u) << entry.path();
      EXPECT_EQ(j["non_manifold_edges"].get<size_t>(), 0u) << entry.path();
      EXPECT_NEAR(j["bounds_m"]["min"][1].get<double>(), 0.0, 1e-3) << entry.path();
    }
    ++checked;
  }
  EXPECT_GE(checked, 7u);
}

TEST(CliInfo, ReportsSkinOnTheRiggedBody) {
  const fs::path glb = DRAPE_REQUIRE_SHARED("bodies/makehuman/derived/mh_female_average_cmu_mb.glb");
  const auto r = run_drape("info --json " + quoted(glb));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  ASSERT_EQ(j["skins"].size(), 1u);
  EXPECT_EQ(j["skins"][0]["joints"].get<int>(), 31);
  EXPECT_EQ(j["vertices"].get<int>(), 13380);
  EXPECT_EQ(j["triangles"].get<int>(), 26756);
  const auto text = run_drape("info " + quoted(glb));
  EXPECT_EQ(text.exit_code, 0);
  EXPECT_NE(text.out.find("31 joints"), std::string::npos) << text.out;
}

TEST(CliConvert, ObjToGlbToPlyKeepsTheMeshAndValidates) {
  const fs::path dir = drape::test::temp_dir("cli_convert");
  {
    std::ofstream f(dir / "quad.obj");
    f << "v 0 0 0\nv 100 0 0\nv 100 0 -100\nv 0 0 -100\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nf 1/1 2/2 3/3 4/4\n";
  }
  // Centimetres, Z-up: (x, y, z) cm -> (x, z, -y) m, so the 1 m quad in y = 0 ends up in z = 0.
  auto r =
      run_drape("convert --units cm --up z " + quoted(dir / "quad.obj") + " " + quoted(dir / "quad.glb"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(drape::test::gltf_is_valid(dir / "quad.glb"));
  r = run_drape("convert " + quoted(dir / "quad.glb") + " " + quoted(dir / "quad.ply"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  r = run_drape("info --json " + quoted(dir / "quad.ply"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["vertices"].get<int>(), 4);
  EXPECT_EQ(j["triangles"].get<int>(), 2);
  EXPECT_EQ(j["boundary_loops"].get<int>(), 1);
  EXPECT_NEAR(j["bounds_m"]["max"][0].get<double>(), 1.0, 1e-6);
  EXPECT_NEAR(j["bounds_m"]["max"][2].get<double>(), 0.0, 1e-6);
  EXPECT_NEAR(j["bounds_m"]["min"][1].get<double>(), -1.0, 1e-6);
  fs::remove_all(dir);
}

TEST(CliConvert, BadInputExitsTwoWithOneLineAndWritesNothing) {
  const fs::path dir = drape::test::temp_dir("cli_bad");
  {
    std::ofstream f(dir / "broken.obj");
    f << "v 0 0 0\nv 1 0 0\nf 1 2 3\n";
  }
  const auto r = run_drape("convert " + quoted(dir / "broken.obj") + " " + quoted(dir / "out.glb"));
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_EQ(lines(r.err), 1u) << r.err;
  EXPECT_NE(r.err.find("broken.obj"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("out of range"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir / "out.glb"));
  EXPECT_EQ(std::distance(fs::directory_iterator(dir), fs::directory_iterator()), 1);  // no temp files either

  const auto ext = run_drape("convert " + quoted(dir / "broken.obj") + " " + quoted(dir / "out.stl"));
  EXPECT_EQ(ext.exit_code, 2);
  EXPECT_NE(ext.err.find("out.stl"), std::string::npos) << ext.err;

  const auto units = run_drape("info --units inch " + quoted(dir / "broken.obj"));
  EXPECT_EQ(units.exit_code, 2);
  const auto missing = run_drape("info " + quoted(dir / "nothing.obj"));
  EXPECT_EQ(missing.exit_code, 2);
  EXPECT_NE(missing.err.find("nothing.obj"), std::string::npos);
  fs::remove_all(dir);
}

TEST(CliInfo, HelpDescribesOptions) {
  const auto r = run_drape("info --help");
  EXPECT_EQ(r.exit_code, 0);
  EXPECT_NE(r.out.find("--units"), std::string::npos);
  EXPECT_NE(r.out.find("--json"), std::string::npos);
}
