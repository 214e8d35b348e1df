// Preview pictures: silhouette size, two-sided lighting, PNG round trip, text and legend edge
// cases, colour maps, composition, thread-count independence, clear errors on empty input.
#include <gtest/gtest.h>
#include <omp.h>
#include <stb_image.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>

#include "drape/error.hpp"
#include "drape/render.hpp"
#include "render/shapes.hpp"
#include "support/test_support.hpp"

namespace drape {
namespace {

float luminance(const uint8_t* px) {
  return 0.2126f * srgb_to_linear(px[0] / 255.0f) + 0.7152f * srgb_to_linear(px[1] / 255.0f) +
         0.0722f * srgb_to_linear(px[2] / 255.0f);
}

// A black sphere on a white backdrop: coverage per pixel is 1 - luminance (up to the specular
// highlight, which is small).
RenderOptions plain_options(int w, int h) {
  RenderOptions o;
  o.width = w;
  o.height = h;
  o.views = {{"front", 0.0f}};
  o.view_labels = false;
  o.floor_shadow = false;
  o.elevation_degrees = 0.0f;
  o.background_top = o.background_bottom = Vec3f::Ones();
  return o;
}

TEST(Render, SphereSilhouetteAreaIsPiRSquared) {
  const Mesh sphere = uv_sphere(0.5f, Vec3f(0, 1, 0), 128, 64);
  RenderItem item{&sphere, Vec3f::Zero(), {}};
  RenderOptions o = plain_options(300, 300);
  o.pixels_per_metre = 200.0f;  // radius 100 pixels
  const Image im = render_views({item}, o);
  double covered = 0;
  for (int y = 0; y < im.height; ++y)
    for (int x = 0; x < im.width; ++x) covered += 1.0 - luminance(im.pixel(x, y));
  const double disc = std::numbers::pi * 100.0 * 100.0;
  EXPECT_NEAR(covered, disc, 0.03 * disc);
  // Centred: the middle pixel is sphere, the corners are backdrop.
  EXPECT_LT(luminance(im.pixel(150, 150)), 0.2f);
  EXPECT_GT(luminance(im.pixel(2, 2)), 0.99f);
}

TEST(Render, FittedViewsShareOneScaleAndLabelsDoNotCrash) {
  const Mesh sphere = uv_sphere(0.3f, Vec3f(0.2f, 0.9f, 0.1f), 48, 24);
  RenderOptions o;  // front, side, back with labels, shadow, title
  o.width = 600;
  o.height = 300;
  o.title = std::string(300, 'W');  // far wider than the picture
  const Image im = render_views({body_item(sphere)}, o);
  ASSERT_EQ(im.width, 600);
  ASSERT_EQ(im.height, 300);
  // A sphere looks the same from every side: the three panels' darkest-pixel counts agree.
  std::array<int, 3> dark{};
  for (int y = 0; y < im.height; ++y)
    for (int x = 0; x < 600; ++x) dark[static_cast<size_t>(x / 200)] += luminance(im.pixel(x, y)) < 0.5f;
  EXPECT_GT(dark[0], 1000);
  EXPECT_NEAR(dark[1], dark[0], 0.05 * dark[0]);
  EXPECT_NEAR(dark[2], dark[0], 0.05 * dark[0]);
}

TEST(Render, ClothIsLitFromBothSides) {
  // One quad facing +Z and one facing -Z, side by side: both visible from the front.
  Mesh cloth;
  cloth.positions = {{-1, 0, 0}, {0, 0, 0}, {0, 1, 0}, {-1, 1, 0}, {0.1f, 0, 0}, {1.1f, 0, 0}, {1.1f, 1, 0}, {0.1f, 1, 0}};
  cloth.triangles = {{0, 1, 2}, {0, 2, 3}, {4, 6, 5}, {4, 7, 6}};
  RenderItem item{&cloth, Vec3f::Constant(0.5f), {}};
  RenderOptions o = plain_options(400, 200);
  o.background_top = o.background_bottom = Vec3f::Zero();
  const Image im = render_views({item}, o);
  const float facing = luminance(im.pixel(100, 100)), away = luminance(im.pixel(300, 100));
  EXPECT_GT(facing, 0.1f);
  EXPECT_GT(away, 0.05f);  // drawn, lit with the flipped normal
  EXPECT_LT(away, facing);  // and darker: the inside of the garment
}

TEST(Render, AmbientOcclusionDarkensCreasesNotPlanes) {
  // A flat sheet facing the camera, and a V-shaped fold opening towards it (crease at x = 0).
  Mesh flat, fold;
  flat.positions = {{-1, 0, 0}, {1, 0, 0}, {1, 1, 0}, {-1, 1, 0}};
  flat.triangles = {{0, 1, 2}, {0, 2, 3}};
  fold.positions = {{-1, 0, 1}, {0, 0, 0}, {0, 1, 0}, {-1, 1, 1}, {1, 0, 1}, {1, 1, 1}};
  fold.triangles = {{0, 1, 2}, {0, 2, 3}, {1, 4, 5}, {1, 5, 2}};
  RenderOptions o = plain_options(200, 100);
  const auto pair = [&](const Mesh& m) {
    const RenderItem item{&m, Vec3f::Constant(0.6f), {}};
    o.ambient_occlusion = true;
    Image with = render_views({item}, o);
    o.ambient_occlusion = false;
    return std::make_pair(with, render_views({item}, o));
  };
  const auto [flat_ao, flat_plain] = pair(flat);
  EXPECT_EQ(flat_ao.rgb, flat_plain.rgb);
  const auto [fold_ao, fold_plain] = pair(fold);
  // Just beside the crease (the picture's centre column), darker; far out on the wings, unchanged.
  EXPECT_LT(luminance(fold_ao.pixel(101, 50)) + 0.01f, luminance(fold_plain.pixel(101, 50)));
  EXPECT_NEAR(luminance(fold_ao.pixel(185, 50)), luminance(fold_plain.pixel(185, 50)), 1e-3f);
}

TEST(Render, PerVertexColoursAndLegend) {
  const Mesh sphere = uv_sphere(0.5f, Vec3f::Zero(), 32, 16);
  std::vector<float> height;
  for (const Vec3f& p : sphere.positions) height.push_back(p.y());
  RenderItem item{&sphere, Vec3f::Ones(), colorize(height, ColorMap::kBlueWhiteRed, -0.5f, 0.5f)};
  RenderOptions o = plain_options(500, 300);
  o.legend = Legend{"height (m)", ColorMap::kBlueWhiteRed, -0.5f, 0.5f};
  const Image im = render_views({item}, o);
  // Top of the sphere red, bottom blue.
  int top_y = -1, bottom_y = -1;
  for (int y = 0; y < im.height; ++y)
    if (luminance(im.pixel(im.width / 3, y)) < 0.95f) {
      if (top_y < 0) top_y = y;
      bottom_y = y;
    }
  ASSERT_GT(bottom_y, top_y + 50);
  const uint8_t* top = nullptr;
  for (int x = 0; x < im.width && !top; ++x)
    if (luminance(im.pixel(x, top_y + 8)) < 0.9f) top = im.pixel(x, top_y + 8);
  ASSERT_NE(top, nullptr);
  EXPECT_GT(top[0], top[2]);
  // Degenerate legends draw without crashing.
  o.legend = Legend{"", ColorMap::kViridis, 1.0f, 1.0f};
  EXPECT_NO_THROW(render_views({item}, o));
  o.legend = Legend{"nan", ColorMap::kViridis, std::nanf(""), 2.0f};
  EXPECT_NO_THROW(render_views({item}, o));
  // A fit map must have one value per vertex.
  const std::vector<float> too_few(3, 0.0f);
  EXPECT_THROW(scalar_item(sphere, too_few, *o.legend), std::invalid_argument);
  EXPECT_EQ(scalar_item(sphere, height, *o.legend).vertex_colors.size(), sphere.positions.size());
  o.width = 40;  // the legend leaves no room for the view
  EXPECT_THROW(render_views({item}, o), std::invalid_argument);
}

TEST(Render, ColourMaps) {
  EXPECT_TRUE(colormap(ColorMap::kBlueWhiteRed, 0.5f).isApprox(srgb8(247, 247, 247), 1e-4f));
  const Vec3f lo = colormap(ColorMap::kBlueWhiteRed, 0.0f), hi = colormap(ColorMap::kBlueWhiteRed, 1.0f);
  EXPECT_GT(lo.z(), lo.x());
  EXPECT_GT(hi.x(), hi.z());
  // Viridis brightens monotonically.
  float previous = -1;
  for (int k = 0; k <= 20; ++k) {
    const Vec3f c = colormap(ColorMap::kViridis, static_cast<float>(k) / 20);
    const float y = 0.2126f * c.x() + 0.7152f * c.y() + 0.0722f * c.z();
    EXPECT_GT(y, previous);
    previous = y;
  }
  EXPECT_EQ(colormap(ColorMap::kViridis, -5.0f), colormap(ColorMap::kViridis, 0.0f));
  const std::vector<float> values{0.0f, std::nanf(""), 10.0f};
  const auto colours = colorize(values, ColorMap::kViridis, 0.0f, 10.0f);
  ASSERT_EQ(colours.size(), 3u);
  EXPECT_TRUE(colours[1].allFinite());
  EXPECT_NEAR(linear_to_srgb(srgb_to_linear(0.3f)), 0.3f, 1e-5f);
}

TEST(Render, PngRoundTrip) {
  Image im(37, 23);
  for (int y = 0; y < im.height; ++y)
    for (int x = 0; x < im.width; ++x) {
      uint8_t* px = im.pixel(x, y);
      px[0] = static_cast<uint8_t>(x * 7);
      px[1] = static_cast<uint8_t>(y * 11);
      px[2] = static_cast<uint8_t>(x * y);
    }
  const auto dir = test::temp_dir("render_png");
  write_png(dir / "sub" / "a.png", im);
  std::ifstream in(dir / "sub" / "a.png", std::ios::binary);
  const std::vector<unsigned char> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_EQ(bytes, encode_png(im));
  int w = 0, h = 0, channels = 0;
  unsigned char* decoded = stbi_load_from_memory(bytes.data(), static_cast<int>(bytes.size()), &w, &h, &channels, 3);
  ASSERT_NE(decoded, nullptr);
  EXPECT_EQ(w, 37);
  EXPECT_EQ(h, 23);
  EXPECT_TRUE(std::equal(im.rgb.begin(), im.rgb.end(), decoded));
  stbi_image_free(decoded);
  EXPECT_THROW(encode_png(Image{}), std::invalid_argument);
}

TEST(Render, TextEdgeCases) {
  Image im(64, 32);
  EXPECT_EQ(draw_text(im, 0, 0, "", Vec3f::Zero()), 0);
  EXPECT_GT(draw_text(im, -30, -5, "clipped \xff\x01 text", Vec3f::Zero(), 3), 0);
  EXPECT_GT(draw_text(im, 60, 30, "edge", Vec3f::Zero()), 0);
  EXPECT_EQ(text_width("ab", 2), 2 * text_width("ab"));
  Image blank(64, 32);
  draw_text(blank, 2, 2, "Hi", Vec3f::Zero(), 2);
  int inked = 0;
  for (size_t i = 0; i < blank.rgb.size(); ++i) inked += blank.rgb[i] < 128;
  EXPECT_GT(inked, 20);
}

TEST(Render, ComposeSideBySide) {
  const Image a(30, 20, Vec3f::Zero()), b(50, 40, Vec3f::Zero());
  const Image c = compose_side_by_side({a, b}, {"no limit", "velocity modification"}, 10);
  EXPECT_EQ(c.width, 10 + 30 + 10 + 50 + 10);
  EXPECT_GT(c.height, 40);
  EXPECT_THROW(compose_side_by_side({a, b}, {"one"}), std::invalid_argument);
  EXPECT_THROW(compose_side_by_side({}, {}), std::invalid_argument);
  const Image d = compose_side_by_side({a}, {}, 0);
  EXPECT_EQ(d.width, 30);
}

TEST(Render, IndependentOfThreadCount) {
  const Mesh sphere = uv_sphere(0.4f, Vec3f(0, 0.4f, 0), 40, 20);
  RenderOptions o;
  o.width = 300;
  o.height = 150;
  const int threads = omp_get_max_threads();
  omp_set_num_threads(1);
  const Image one = render_views({body_item(sphere)}, o);
  omp_set_num_threads(std::max(2, threads));
  const Image many = render_views({body_item(sphere)}, o);
  omp_set_num_threads(threads);
  EXPECT_EQ(one.rgb, many.rgb);
}

TEST(Render, NothingToDrawIsAClearError) {
  const Mesh empty;
  try {
    render_views({}, RenderOptions{});
    FAIL() << "expected an error";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("nothing to draw"), std::string::npos) << e.what();
  }
  EXPECT_THROW(render_views({RenderItem{}}, RenderOptions{}), std::invalid_argument);
  EXPECT_THROW(render_views({body_item(empty)}, RenderOptions{}), std::invalid_argument);
  const Mesh sphere = uv_sphere(0.4f, Vec3f::Zero(), 8, 4);
  RenderOptions no_views;
  no_views.views.clear();
  EXPECT_THROW(render_views({body_item(sphere)}, no_views), std::invalid_argument);
  RenderOptions from_above;
  from_above.elevation_degrees = 90.0f;
  EXPECT_THROW(render_views({body_item(sphere)}, from_above), std::invalid_argument);
  RenderOptions huge;
  huge.width = huge.height = 16384;  // refused before anything is allocated
  EXPECT_THROW(render_views({body_item(sphere)}, huge), std::invalid_argument);
}

TEST(Render, ParseViews) {
  const auto views = parse_views("front, side,back");
  ASSERT_EQ(views.size(), 3u);
  EXPECT_EQ(views[1].label, "side");
  EXPECT_FLOAT_EQ(views[2].yaw_degrees, 180.0f);
  try {
    parse_views("front,top");
    FAIL() << "expected an error";
  } catch (const InputError& e) {
    EXPECT_EQ(e.source(), "--views");
    EXPECT_NE(std::string(e.what()).find("'top'"), std::string::npos);
  }
  EXPECT_THROW(parse_views(""), InputError);
}

}  // namespace
}  // namespace drape
