// The rasterizer's accuracy properties: exact coverage (fill rule), depth and normal maps of an
// analytic sphere, perspective-correct interpolation, independence from threads and band size.
#include <gtest/gtest.h>
#include <omp.h>

#include <cmath>
#include <numbers>
#include <random>

#include "geometry/rasterize.hpp"
#include "render/shapes.hpp"

namespace drape {
namespace {

TEST(Rasterize, SphereDepthAndNormalMatchAnalytic) {
  const float r = 0.3f, pixel = 0.005f;
  const Vec3f c(0.1f, 1.2f, -0.05f);
  const Mesh sphere = uv_sphere(r, c, 96, 48);
  const auto maps = render_front_back(sphere.positions, sphere.triangles, sphere.normals, pixel, 0.02f);
  ASSERT_EQ(maps.front.width, maps.back.width);
  size_t covered = 0, checked = 0;
  for (int j = 0; j < maps.front.height; ++j)
    for (int i = 0; i < maps.front.width; ++i) {
      const int q = j * maps.front.width + i;
      const Vec2f xy = maps.front.pixel_center(i, j);
      const Vec2f d = xy - c.head<2>();
      EXPECT_EQ(maps.front.covered(q), maps.back.covered(q));
      if (maps.front.covered(q)) ++covered;
      if (d.norm() > 0.9f * r) continue;
      ASSERT_TRUE(maps.front.covered(q)) << i << "," << j;
      // Within half a pixel of the analytic sphere, front and back.
      const float dz = std::sqrt(r * r - d.squaredNorm());
      EXPECT_NEAR(maps.front.depth[static_cast<size_t>(q)], c.z() + dz, 0.5f * pixel);
      EXPECT_NEAR(maps.back.depth[static_cast<size_t>(q)], c.z() - dz, 0.5f * pixel);
      const Vec3f n_true = Vec3f(d.x(), d.y(), dz) / r;
      EXPECT_GT(maps.front.normal[static_cast<size_t>(q)].dot(n_true), std::cos(2.0f * std::numbers::pi_v<float> / 180));
      ++checked;
    }
  EXPECT_GT(checked, 5000u);
  // Silhouette: the covered pixel count is the disc's area in pixels (the inscribed polygon is a
  // little smaller).
  const double disc = std::numbers::pi * r * r / (pixel * pixel);
  EXPECT_NEAR(static_cast<double>(covered), disc, 0.01 * disc);
  // Empty pixels hold the values that make "behind the surface" false.
  EXPECT_EQ(maps.front.depth[0], -std::numeric_limits<float>::infinity());
  EXPECT_EQ(maps.back.depth[0], std::numeric_limits<float>::infinity());
  EXPECT_EQ(maps.front.index_of(c.x(), c.y()), maps.back.index_of(c.x(), c.y()));
  EXPECT_EQ(maps.front.index_of(c.x() - 10, c.y()), -1);
}

// Each triangle drawn alone into its own buffer: the per-pixel counts over a triangulated square
// must be exactly one inside and zero outside, even with vertices and edges on pixel centres.
TEST(Rasterize, SharedEdgesAreDrawnExactlyOnce) {
  std::mt19937 rng(7);
  const int n = 9, size = 64;
  std::vector<ScreenVertex> v;
  std::uniform_real_distribution<float> jitter(-2.5f, 2.5f);
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) {
      float x = 4.25f + 6.0f * static_cast<float>(i), y = 4.25f + 6.0f * static_cast<float>(j);
      const bool border_x = i == 0 || i == n, border_y = j == 0 || j == n;
      if (!border_x) x = (i % 3 == 0) ? std::round(x + jitter(rng)) + 0.5f : x + jitter(rng);  // some on centres
      if (!border_y) y = (j % 2 == 0) ? std::round(y + jitter(rng)) + 0.5f : y + jitter(rng);
      v.push_back({x, y, 0.0f, 1.0f});
    }
  std::vector<Tri> tris;
  const auto id = [&](int i, int j) { return static_cast<uint32_t>(j * (n + 1) + i); };
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      // Alternate the diagonal and the winding: the fill rule must not depend on either.
      if ((i + j) % 2 == 0) {
        tris.push_back({id(i, j), id(i + 1, j), id(i + 1, j + 1)});
        tris.push_back({id(i, j), id(i, j + 1), id(i + 1, j + 1)});
      } else {
        tris.push_back({id(i, j), id(i + 1, j), id(i, j + 1)});
        tris.push_back({id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)});
      }
    }
  std::vector<int> count(size * size, 0);
  VisibilityBuffer vis;
  for (const Tri& t : tris) {
    rasterize(v, std::span<const Tri>(&t, 1), size, size, vis);
    for (size_t p = 0; p < vis.pixel_count(); ++p) count[p] += vis.covered(p) ? 1 : 0;
  }
  const float lo = 4.25f, hi = 4.25f + 6.0f * n;
  for (int j = 0; j < size; ++j)
    for (int i = 0; i < size; ++i) {
      const float x = static_cast<float>(i) + 0.5f, y = static_cast<float>(j) + 0.5f;
      const int expected = (x > lo && x < hi && y > lo && y < hi) ? 1 : 0;
      ASSERT_EQ(count[static_cast<size_t>(j * size + i)], expected) << "pixel " << i << "," << j;
    }
}

TEST(Rasterize, TriangleCoverageEqualsArea) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> coord(0.0f, 200.0f);
  VisibilityBuffer vis;
  for (int trial = 0; trial < 20; ++trial) {
    std::vector<ScreenVertex> v(3);
    for (auto& p : v) p = {coord(rng), coord(rng), 0.0f, 1.0f};
    const Vec2f a(v[0].x, v[0].y), b(v[1].x, v[1].y), c(v[2].x, v[2].y);
    const Vec2f ab = b - a, ac = c - a;
    const double area = 0.5 * std::abs(ab.x() * ac.y() - ab.y() * ac.x());
    const double perimeter = ab.norm() + ac.norm() + (c - b).norm();
    const Tri t{0, 1, 2};
    rasterize(v, std::span<const Tri>(&t, 1), 200, 200, vis);
    size_t covered = 0;
    for (size_t p = 0; p < vis.pixel_count(); ++p) covered += vis.covered(p) ? 1 : 0;
    // Rasterization error of a convex shape is bounded by about half its perimeter in pixels.
    EXPECT_NEAR(static_cast<double>(covered), area, 0.5 * perimeter + 1.0) << "trial " << trial;
  }
}

TEST(Rasterize, BackFaceCullingAndBarycentrics) {
  std::vector<ScreenVertex> v{{10, 10, 1}, {90, 10, 1}, {10, 90, 1}};
  std::vector<Tri> ccw{{0, 1, 2}}, cw{{0, 2, 1}};
  VisibilityBuffer vis;
  RasterOptions cull;
  cull.culling = FaceCulling::kBack;
  rasterize(v, cw, 100, 100, vis, cull);
  EXPECT_FALSE(vis.covered(50 * 100 + 20));
  rasterize(v, cw, 100, 100, vis);
  ASSERT_TRUE(vis.covered(30 * 100 + 20));
  // Attribute = x: interpolation reproduces the pixel centre for either winding.
  const std::vector<float> xs{10, 90, 10};
  EXPECT_NEAR(interpolate<float>(vis, 30 * 100 + 20, cw, xs), 20.5f, 1e-3f);
  rasterize(v, ccw, 100, 100, vis, cull);
  EXPECT_NEAR(interpolate<float>(vis, 30 * 100 + 20, ccw, xs), 20.5f, 1e-3f);
}

TEST(Rasterize, PerspectiveCorrectInterpolation) {
  // A plane receding in depth: world x from 0 to 1 along the screen, w from 1 to 4.
  const float w0 = 1.0f, w1 = 4.0f;
  std::vector<ScreenVertex> v{{0, 0, 0, 1 / w0}, {100, 0, 0, 1 / w1}, {100, 100, 0, 1 / w1}, {0, 100, 0, 1 / w0}};
  std::vector<Tri> tris{{0, 1, 2}, {0, 2, 3}};
  const std::vector<float> world_x{0, 1, 1, 0};
  VisibilityBuffer vis;
  rasterize(v, tris, 100, 100, vis);
  for (int i = 0; i < 100; i += 7) {
    // Screen s in [0, 1] maps to world t with s = (t / w(t)) / (t / w(t) + (1 - t) / w0) ... solved:
    const float s = (static_cast<float>(i) + 0.5f) / 100.0f;
    const float t = s * w0 / (s * w0 + (1 - s) * w1);
    EXPECT_NEAR(interpolate<float>(vis, 50 * 100 + static_cast<size_t>(i), tris, world_x), t, 1e-4f);
  }
}

TEST(Rasterize, ResultIndependentOfThreadsAndBands) {
  const Mesh sphere = uv_sphere(1.0f, Vec3f::Zero(), 64, 32);
  std::vector<ScreenVertex> v;
  for (const Vec3f& p : sphere.positions) v.push_back({p.x() * 90 + 100, p.y() * 90 + 100, p.z(), 1.0f});
  VisibilityBuffer a, b;
  const int threads = omp_get_max_threads();
  omp_set_num_threads(1);
  RasterOptions one_band;
  one_band.band_rows = 1000;
  rasterize(v, sphere.triangles, 200, 200, a, one_band);
  omp_set_num_threads(std::max(2, threads));
  RasterOptions small_bands;
  small_bands.band_rows = 3;
  rasterize(v, sphere.triangles, 200, 200, b, small_bands);
  omp_set_num_threads(threads);
  EXPECT_EQ(a.triangle, b.triangle);
  EXPECT_EQ(a.depth, b.depth);
  EXPECT_EQ(a.bary1, b.bary1);
}

TEST(Rasterize, RefusesBadInput) {
  VisibilityBuffer vis;
  std::vector<ScreenVertex> v{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  std::vector<Tri> bad{{0, 1, 5}};
  EXPECT_THROW(rasterize(v, bad, 0, 10, vis), std::invalid_argument);
  rasterize(v, bad, 10, 10, vis);  // out-of-range index: skipped, not read
  for (size_t p = 0; p < vis.pixel_count(); ++p) EXPECT_FALSE(vis.covered(p));
  const std::vector<Vec3f> none;
  EXPECT_THROW(render_front_back(none, {}, none, 0.01f, 0.0f), std::invalid_argument);
}

}  // namespace
}  // namespace drape
