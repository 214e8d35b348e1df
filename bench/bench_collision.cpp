// Body collision cost (Vassilev & Spanlang sec. 4, table 1's time per iteration): per cloth vertex
// per query for each method on the 47.5k-triangle GarmentCode mean body, plus what building and
// updating each structure costs per frame of a moving body. Targets: image <= 50 ns, bvh <= 200 ns.
// Skips (with a message) when ../shared/data is absent.
#include <benchmark/benchmark.h>

#include <filesystem>
#include <random>

#include "collision/box_bvh.hpp"
#include "collision/triangle_bvh.hpp"
#include "drape/collision.hpp"
#include "drape/io.hpp"

namespace drape {
namespace {

const std::filesystem::path kBody = std::filesystem::path(DRAPE_SHARED_DATA) / "bodies/garmentcode/mean_all.obj";

const Mesh* body() {
  static const Mesh mesh = std::filesystem::exists(kBody) ? read_mesh(kBody) : Mesh{};
  return mesh.positions.empty() ? nullptr : &mesh;
}

// Cloth-like query points: 50k body vertices pushed along their normals by -5 .. +10 mm, in the
// body's vertex order (neighbouring queries are near each other, as a cloth's are).
const std::vector<Vec3f>& cloth_points() {
  static const std::vector<Vec3f> points = [] {
    std::vector<Vec3f> out;
    const Mesh& m = *body();
    const auto normals = vertex_normals(m.positions, m.triangles);
    std::mt19937 rng(5);
    std::uniform_real_distribution<float> offset(-0.005f, 0.010f);
    for (size_t i = 0; out.size() < 50000; i = (i + 1) % m.positions.size())
      out.push_back(m.positions[i] + offset(rng) * normals[i]);
    return out;
  }();
  return points;
}

constexpr float kQueryRadius = 0.02f;

void BM_Query(benchmark::State& state, CollisionMethod method, bool hidden_handling) {
  if (!body()) return state.SkipWithError("needs ../shared/data/bodies/garmentcode/mean_all.obj");
  BodyColliderOptions options;
  options.hidden_region_handling = hidden_handling;
  const auto collider = make_body_collider(*body(), method, options);
  const auto& points = cloth_points();
  std::vector<ContactSample> out(points.size());
  for (auto _ : state) {
    collider->query(points, kQueryRadius, out);
    benchmark::DoNotOptimize(out.data());
  }
  state.SetItemsProcessed(static_cast<int64_t>(state.iterations() * points.size()));
  state.counters["ns_per_vertex"] = benchmark::Counter(static_cast<double>(state.iterations() * points.size()),
                                                       benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
  state.counters["hidden_fraction"] = collider->build_stats().hidden_fraction;
  state.counters["memory_MB"] = static_cast<double>(collider->build_stats().memory_bytes) / 1e6;
}
BENCHMARK_CAPTURE(BM_Query, image, CollisionMethod::image, true)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Query, image_plain, CollisionMethod::image, false)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Query, bvh, CollisionMethod::bvh, true)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Query, sdf, CollisionMethod::sdf, true)->Unit(benchmark::kMillisecond);

// Embree's rtcPointQuery against the hand-made box BVH, same points, same radius.
template <class Bvh>
void BM_ClosestPoint(benchmark::State& state) {
  if (!body()) return state.SkipWithError("needs ../shared/data/bodies/garmentcode/mean_all.obj");
  const collision::BodySurface surface(body()->positions, body()->triangles);
  std::unique_ptr<Bvh> bvh;
  if constexpr (std::is_same_v<Bvh, collision::TriangleBvh>) {
    bvh = std::make_unique<Bvh>(surface, true);
  } else {
    bvh = std::make_unique<Bvh>(surface);
  }
  const auto& points = cloth_points();
  for (auto _ : state) {
    collision::SurfaceHit hit;
    for (const Vec3f& p : points) benchmark::DoNotOptimize(bvh->closest(p, kQueryRadius, hit));
  }
  state.counters["ns_per_vertex"] = benchmark::Counter(static_cast<double>(state.iterations() * points.size()),
                                                       benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}
BENCHMARK_TEMPLATE(BM_ClosestPoint, collision::TriangleBvh)->Name("BM_ClosestPoint/embree")->Unit(benchmark::kMillisecond);
BENCHMARK_TEMPLATE(BM_ClosestPoint, collision::BoxBvh)->Name("BM_ClosestPoint/box_bvh")->Unit(benchmark::kMillisecond);

// Per frame of a moving body: new vertex positions (a small translation), then maps re-rendered /
// BVH refitted / field rebuilt.
void BM_Update(benchmark::State& state, CollisionMethod method) {
  if (!body()) return state.SkipWithError("needs ../shared/data/bodies/garmentcode/mean_all.obj");
  const auto collider = make_body_collider(*body(), method);
  std::vector<Vec3f> moved = body()->positions;
  double t = 0;
  for (auto _ : state) {
    t += 1.0 / 30.0;
    for (Vec3f& p : moved) p.x() += 0.001f;
    collider->set_surface(moved, t);
  }
  state.counters["build_ms"] = collider->build_stats().build_seconds * 1e3;
}
BENCHMARK_CAPTURE(BM_Update, image, CollisionMethod::image)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Update, bvh, CollisionMethod::bvh)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Update, sdf, CollisionMethod::sdf)->Unit(benchmark::kMillisecond)->Iterations(2);

void BM_InsideTest(benchmark::State& state) {
  if (!body()) return state.SkipWithError("needs ../shared/data/bodies/garmentcode/mean_all.obj");
  const InsideTest test(*body());
  const auto& points = cloth_points();
  for (auto _ : state) benchmark::DoNotOptimize(measure_penetration(test, points));
  state.counters["ns_per_vertex"] = benchmark::Counter(static_cast<double>(state.iterations() * points.size()),
                                                       benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}
BENCHMARK(BM_InsideTest)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace drape

BENCHMARK_MAIN();
