// Rasterizer and preview speed: the image-space collision maps (front + back depth/normal maps of a
// body, paper sec. 4.2, redone every frame for an animated body) and a 3-view 1200x600 preview.
// The scene is a 50k-triangle closed surface shaped like a standing body's bounding box, so the
// benchmark runs without ../shared/data; with it, the MakeHuman body is measured too.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <cmath>
#include <filesystem>

#include "drape/io.hpp"
#include "drape/render.hpp"
#include "drape/shapes.hpp"
#include "geometry/rasterize.hpp"

namespace {

using drape::Mesh;
using drape::Vec3f;

// An ellipsoid 0.45 x 1.75 x 0.3 m standing on the floor: about 50k triangles.
Mesh standing_ellipsoid() { return drape::uv_ellipsoid(Vec3f(0.225f, 0.875f, 0.15f), Vec3f(0, 0.875f, 0), 224, 112); }

Mesh shared_body() {
  const auto path = std::filesystem::path(DRAPE_SHARED_DATA) / "bodies/makehuman/derived/mh_female_average.obj";
  if (!std::filesystem::exists(path)) return {};
  Mesh m = drape::read_mesh(path);
  m.normals = drape::vertex_normals(m.positions, m.triangles);
  return m;
}

void depth_normal_maps(benchmark::State& state, const Mesh& mesh) {
  if (mesh.triangles.empty()) {
    state.SkipWithError("../shared/data not found");
    return;
  }
  const float pixel = static_cast<float>(state.range(0)) * 1e-3f;  // millimetres
  drape::DepthNormalMap front, back;
  drape::VisibilityBuffer scratch;
  const drape::Bounds box = drape::bounds(mesh.positions);
  const drape::Vec2f origin(box.min.x() - 0.01f, box.min.y() - 0.01f);
  const int w = static_cast<int>(std::ceil((box.size().x() + 0.02f) / pixel));
  const int h = static_cast<int>(std::ceil((box.size().y() + 0.02f) / pixel));
  for (auto _ : state) {
    drape::render_depth_normal(mesh.positions, mesh.triangles, mesh.normals, drape::ViewDirection::kFront, origin, pixel,
                               w, h, front, scratch);
    drape::render_depth_normal(mesh.positions, mesh.triangles, mesh.normals, drape::ViewDirection::kBack, origin, pixel,
                               w, h, back, scratch);
    benchmark::DoNotOptimize(front.depth.data());
    benchmark::DoNotOptimize(back.depth.data());
  }
  state.counters["triangles"] = static_cast<double>(mesh.triangles.size());
  state.counters["pixels"] = static_cast<double>(w) * h;
}

void preview(benchmark::State& state, const Mesh& mesh) {
  if (mesh.triangles.empty()) {
    state.SkipWithError("../shared/data not found");
    return;
  }
  drape::RenderOptions options;  // 1200 x 600, front/side/back, 3x3 supersampling, shadow, labels
  options.title = "benchmark";
  for (auto _ : state) benchmark::DoNotOptimize(drape::render_views({drape::body_item(mesh)}, options).rgb.data());
  state.counters["triangles"] = static_cast<double>(mesh.triangles.size());
}

// The preview picture (two rows of three views, as `drape dress` writes it) encoded as PNG.
void BM_EncodePreviewPng(benchmark::State& state) {
  static const Mesh mesh = standing_ellipsoid();
  const drape::Image row = drape::render_views({drape::body_item(mesh)}, drape::RenderOptions{});
  drape::Image both(row.width, 2 * row.height);
  std::copy(row.rgb.begin(), row.rgb.end(), both.rgb.begin());
  std::copy(row.rgb.begin(), row.rgb.end(), both.rgb.begin() + static_cast<std::ptrdiff_t>(row.rgb.size()));
  size_t bytes = 0;
  for (auto _ : state) bytes = drape::encode_png(both).size();
  state.counters["bytes"] = static_cast<double>(bytes);
}

void BM_DepthNormalMaps_Ellipsoid50k(benchmark::State& state) {
  static const Mesh mesh = standing_ellipsoid();
  depth_normal_maps(state, mesh);
}
void BM_DepthNormalMaps_Body(benchmark::State& state) {
  static const Mesh mesh = shared_body();
  depth_normal_maps(state, mesh);
}
void BM_Preview3Views_Ellipsoid50k(benchmark::State& state) {
  static const Mesh mesh = standing_ellipsoid();
  preview(state, mesh);
}
void BM_Preview3Views_Body(benchmark::State& state) {
  static const Mesh mesh = shared_body();
  preview(state, mesh);
}

}  // namespace

// Pixel sizes 2 mm and 5 mm.
BENCHMARK(BM_DepthNormalMaps_Ellipsoid50k)->Arg(2)->Arg(5)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_DepthNormalMaps_Body)->Arg(2)->Arg(5)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Preview3Views_Ellipsoid50k)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Preview3Views_Body)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_EncodePreviewPng)->Unit(benchmark::kMillisecond);
BENCHMARK_MAIN();
