// `drape render` as a user runs it: a picture of the right size, exit 2 naming the file on bad
// input, nothing written then.
#include <gtest/gtest.h>
#include <stb_image.h>

#include <algorithm>
#include <filesystem>
#include <fstream>

#include "drape/io.hpp"
#include "render/shapes.hpp"
#include "support/test_support.hpp"

namespace drape {
namespace {

int count_lines(const std::string& s) { return static_cast<int>(std::count(s.begin(), s.end(), '\n')); }

TEST(RenderCommand, WritesAPictureOfAMeshFile) {
  const auto dir = test::temp_dir("cmd_render");
  Mesh sphere = uv_sphere(0.3f, Vec3f(0, 0.3f, 0), 32, 16);
  write_mesh(dir / "ball.obj", sphere);
  const auto png = dir / "pictures" / "ball.png";
  const auto r = test::run_drape("render \"" + (dir / "ball.obj").string() + "\" --width 300 --height 150 -o \"" +
                                 png.string() + "\"");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  int w = 0, h = 0, channels = 0;
  unsigned char* pixels = stbi_load(png.c_str(), &w, &h, &channels, 3);
  ASSERT_NE(pixels, nullptr);
  EXPECT_EQ(w, 300);
  EXPECT_EQ(h, 150);
  // The ball is in the middle of the front view (left third), darker than the backdrop corner.
  const auto lum = [&](int x, int y) { const unsigned char* p = pixels + 3 * (y * w + x); return p[0] + p[1] + p[2]; };
  EXPECT_LT(lum(50, 75), lum(2, 2));
  stbi_image_free(pixels);
}

TEST(RenderCommand, BadInputExitsTwoNamingTheFileAndWritesNothing) {
  const auto dir = test::temp_dir("cmd_render_bad");
  const auto png = dir / "out.png";
  const auto missing = test::run_drape("render \"" + (dir / "missing.obj").string() + "\" -o \"" + png.string() + "\"");
  EXPECT_EQ(missing.exit_code, 2);
  EXPECT_EQ(count_lines(missing.err), 1) << missing.err;
  EXPECT_NE(missing.err.find("missing.obj"), std::string::npos) << missing.err;

  std::ofstream(dir / "points.obj") << "v 0 0 0\nv 1 0 0\nv 0 1 0\n";
  const auto points = test::run_drape("render \"" + (dir / "points.obj").string() + "\" -o \"" + png.string() + "\"");
  EXPECT_EQ(points.exit_code, 2);
  EXPECT_EQ(count_lines(points.err), 1) << points.err;
  EXPECT_NE(points.err.find("points.obj"), std::string::npos) << points.err;

  write_mesh(dir / "ball.obj", uv_sphere(0.3f, Vec3f::Zero(), 8, 4));
  const auto views = test::run_drape("render \"" + (dir / "ball.obj").string() + "\" --views front,top -o \"" + png.string() + "\"");
  EXPECT_EQ(views.exit_code, 2);
  EXPECT_NE(views.err.find("top"), std::string::npos) << views.err;
  EXPECT_FALSE(std::filesystem::exists(png));
}

}  // namespace
}  // namespace drape
