// Body collision cost (Vassilev & Spanlang sec. 4, table 1's time per iteration): per cloth vertex
// per query for each method on the 47.5k-triangle GarmentCode mean body, plus what building and
// updating each structure costs per frame of a moving body. Targets: image <= 50 ns, bvh <= 200 ns.
// Skips (with a message) when ../shared/data is absent.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <numbers>
#include <random>

#include "collision/box_bvh.hpp"
#include "collision/triangle_bvh.hpp"
#include "drape/cloth.hpp"
#include "drape/collision.hpp"
#include "drape/fabric.hpp"
#include "drape/io.hpp"

namespace drape {
namespace {

const std::filesystem::path kBody = std::filesystem::path(DRAPE_SHARED_DATA) / "bodies/garmentcode/mean_all.obj";

const Mesh* body() {
  static const Mesh mesh = std::filesystem::exists(kBody) ? read_mesh(kBody) : Mesh{};
  return mesh.positions.empty() ? nullptr : &mesh;
}

// Query points near the skin, pushed along the surface normal by -5 .. +10 mm, 50k of them, two ways:
// - cloth: uniform over the body's surface area (a garment covers area, not vertices), in rows
//   (1 cm bands of height, then x), so neighbouring queries are near each other as a cloth's are;
// - vertices: the body's own vertices in their order: weighted by mesh density, so the hands, face
//   and feet (fine triangles, hidden from the image maps) get most of them: a worst case.
const std::vector<Vec3f>& vertex_points() {
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

const std::vector<Vec3f>& cloth_points() {
  static const std::vector<Vec3f> points = [] {
    const Mesh& m = *body();
    std::vector<double> cumulative_area;
    double total = 0;
    for (const Tri& t : m.triangles) {
      total += 0.5 * static_cast<double>((m.positions[t[1]] - m.positions[t[0]]).cross(m.positions[t[2]] - m.positions[t[0]]).norm());
      cumulative_area.push_back(total);
    }
    std::mt19937 rng(5);
    std::uniform_real_distribution<float> offset(-0.005f, 0.010f), unit(0.0f, 1.0f);
    std::uniform_real_distribution<double> at(0.0, total);
    std::vector<Vec3f> out;
    while (out.size() < 50000) {
      const size_t f = static_cast<size_t>(std::lower_bound(cumulative_area.begin(), cumulative_area.end(), at(rng)) - cumulative_area.begin());
      const Tri& t = m.triangles[std::min(f, m.triangles.size() - 1)];
      float a = unit(rng), b = unit(rng);
      if (a + b > 1) a = 1 - a, b = 1 - b;
      const Vec3f p0 = m.positions[t[0]], e1 = m.positions[t[1]] - p0, e2 = m.positions[t[2]] - p0;
      out.push_back(p0 + a * e1 + b * e2 + offset(rng) * e1.cross(e2).normalized());
    }
    std::sort(out.begin(), out.end(), [](const Vec3f& p, const Vec3f& q) {
      const int row_p = static_cast<int>(std::floor(p.y() / 0.01f)), row_q = static_cast<int>(std::floor(q.y() / 0.01f));
      return row_p != row_q ? row_p < row_q : p.x() < q.x();
    });
    return out;
  }();
  return points;
}

constexpr float kQueryRadius = 0.02f;

// Collision cost per cloth vertex: one query over all points, in blocks of 1024 spread over
// `threads` OpenMP threads as the simulation's contact stage does (each answer depends only on its
// point: the same on any thread count). ns_per_vertex is wall time per point.
void BM_Query(benchmark::State& state, CollisionMethod method, bool hidden_handling, bool on_vertices) {
  if (!body()) return state.SkipWithError("needs ../shared/data/bodies/garmentcode/mean_all.obj");
  BodyColliderOptions options;
  options.hidden_region_handling = hidden_handling;
  const auto collider = make_body_collider(*body(), method, options);
  const auto& points = on_vertices ? vertex_points() : cloth_points();
  const int threads = static_cast<int>(state.range(0));
  std::vector<ContactSample> out(points.size());
  const std::span<const Vec3f> all(points);
  const std::span<ContactSample> answers(out);
  constexpr size_t kBlock = 1024;
  const auto blocks = static_cast<std::ptrdiff_t>((points.size() + kBlock - 1) / kBlock);
  for (auto _ : state) {
#pragma omp parallel for schedule(static) num_threads(threads)
    for (std::ptrdiff_t b = 0; b < blocks; ++b) {
      const size_t begin = static_cast<size_t>(b) * kBlock, count = std::min(kBlock, points.size() - begin);
      collider->query(all.subspan(begin, count), kQueryRadius, answers.subspan(begin, count));
    }
    benchmark::DoNotOptimize(out.data());
  }
  state.SetItemsProcessed(static_cast<int64_t>(state.iterations() * points.size()));
  state.counters["ns_per_vertex"] = benchmark::Counter(static_cast<double>(state.iterations() * points.size()),
                                                       benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
  state.counters["hidden_fraction"] = collider->build_stats().hidden_fraction;
  state.counters["memory_MB"] = static_cast<double>(collider->build_stats().memory_bytes) / 1e6;
  state.counters["build_s"] = collider->build_stats().build_seconds;
}
BENCHMARK_CAPTURE(BM_Query, image, CollisionMethod::image, true, false)->Arg(1)->Arg(2)->UseRealTime()->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Query, image_plain, CollisionMethod::image, false, false)->Arg(1)->Arg(2)->UseRealTime()->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Query, bvh, CollisionMethod::bvh, true, false)->Arg(1)->Arg(2)->UseRealTime()->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Query, sdf, CollisionMethod::sdf, true, false)->Arg(1)->Arg(2)->UseRealTime()->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Query, image_on_vertices, CollisionMethod::image, true, true)->Arg(1)->UseRealTime()->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Query, image_plain_on_vertices, CollisionMethod::image, false, true)->Arg(1)->UseRealTime()->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Query, bvh_on_vertices, CollisionMethod::bvh, true, true)->Arg(1)->UseRealTime()->Unit(benchmark::kMillisecond);

// The closest-point search alone: Embree's rtcPointQuery, the same with the candidate grid in front
// one point at a time and batched (what the bvh method uses for a static body), and the hand-made
// box BVH; same points, same radius.
template <class Bvh, bool kGrid = false, bool kBatch = false>
void BM_ClosestPoint(benchmark::State& state) {
  if (!body()) return state.SkipWithError("needs ../shared/data/bodies/garmentcode/mean_all.obj");
  const collision::BodySurface surface(body()->positions, body()->triangles);
  std::unique_ptr<Bvh> bvh;
  if constexpr (std::is_same_v<Bvh, collision::TriangleBvh>) {
    bvh = std::make_unique<Bvh>(surface, true);
    if (kGrid) bvh->build_candidate_grid();
  } else {
    bvh = std::make_unique<Bvh>(surface);
  }
  const auto& points = cloth_points();
  std::vector<collision::SurfaceHit> hits(points.size());
  std::vector<uint8_t> found(points.size());
  for (auto _ : state) {
    if constexpr (kBatch) {
      bvh->closest_batch(points, kQueryRadius, hits, found);
      benchmark::DoNotOptimize(found.data());
    } else {
      collision::SurfaceHit hit;
      for (const Vec3f& p : points) benchmark::DoNotOptimize(bvh->closest(p, kQueryRadius, hit));
    }
  }
  state.counters["ns_per_vertex"] = benchmark::Counter(static_cast<double>(state.iterations() * points.size()),
                                                       benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}
BENCHMARK_TEMPLATE(BM_ClosestPoint, collision::TriangleBvh)->Name("BM_ClosestPoint/embree")->Unit(benchmark::kMillisecond);
BENCHMARK_TEMPLATE(BM_ClosestPoint, collision::TriangleBvh, true)->Name("BM_ClosestPoint/embree_grid")->Unit(benchmark::kMillisecond);
BENCHMARK_TEMPLATE(BM_ClosestPoint, collision::TriangleBvh, true, true)->Name("BM_ClosestPoint/embree_grid_batch")->Unit(benchmark::kMillisecond);
BENCHMARK_TEMPLATE(BM_ClosestPoint, collision::BoxBvh)->Name("BM_ClosestPoint/box_bvh")->Unit(benchmark::kMillisecond);

// Per frame of a moving body: new vertex positions, then maps re-rendered / BVH refitted / field
// updated. The whole body moves (a small translation), or only its left arm (x > 0.25 m rises 1 mm
// per frame), where the distance field re-samples only the bricks near the arm.
void BM_Update(benchmark::State& state, CollisionMethod method, bool arm_only) {
  if (!body()) return state.SkipWithError("needs ../shared/data/bodies/garmentcode/mean_all.obj");
  const auto collider = make_body_collider(*body(), method);
  std::vector<Vec3f> moved = body()->positions;
  double t = 0;
  for (auto _ : state) {
    t += 1.0 / 30.0;
    for (Vec3f& p : moved)
      if (!arm_only)
        p.x() += 0.001f;
      else if (p.x() > 0.25f)
        p.y() += 0.001f;
    collider->set_surface(moved, t);
  }
  state.counters["build_ms"] = collider->build_stats().build_seconds * 1e3;
  state.counters["rebuilt_fraction"] = collider->build_stats().rebuilt_fraction;
}
BENCHMARK_CAPTURE(BM_Update, image, CollisionMethod::image, false)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Update, bvh, CollisionMethod::bvh, false)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Update, sdf, CollisionMethod::sdf, false)->Unit(benchmark::kMillisecond)->Iterations(2);
BENCHMARK_CAPTURE(BM_Update, sdf_arm, CollisionMethod::sdf, true)
    ->Name("BM_UpdateArm/sdf")
    ->Unit(benchmark::kMillisecond)
    ->Iterations(3);

// Building a collider for a static body, what `drape dress` does once per body before the first
// step (the image collider's candidate grid lists only the cells over its hidden pixels).
void BM_Build(benchmark::State& state, CollisionMethod method) {
  if (!body()) return state.SkipWithError("needs ../shared/data/bodies/garmentcode/mean_all.obj");
  size_t memory = 0;
  for (auto _ : state) memory = make_body_collider(*body(), method)->build_stats().memory_bytes;
  state.counters["memory_MB"] = static_cast<double>(memory) / 1e6;
}
BENCHMARK_CAPTURE(BM_Build, image, CollisionMethod::image)->UseRealTime()->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Build, bvh, CollisionMethod::bvh)->UseRealTime()->Unit(benchmark::kMillisecond);

void BM_InsideTest(benchmark::State& state) {
  if (!body()) return state.SkipWithError("needs ../shared/data/bodies/garmentcode/mean_all.obj");
  const InsideTest test(*body());
  const auto& points = cloth_points();
  for (auto _ : state) benchmark::DoNotOptimize(measure_penetration(test, points));
  state.counters["ns_per_vertex"] = benchmark::Counter(static_cast<double>(state.iterations() * points.size()),
                                                       benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}
BENCHMARK(BM_InsideTest)->Unit(benchmark::kMillisecond);

// Times every query of the collider it wraps: collision cost per cloth vertex per iteration inside
// a real simulation (the step calls it from one thread for a cloth this small; atomic anyway).
class TimedCollider final : public Collider {
 public:
  explicit TimedCollider(Collider& inner) : inner_(inner) {}
  std::string_view name() const override { return inner_.name(); }
  void update(double t) override { inner_.update(t); }
  void query(std::span<const Vec3f> points, float radius, std::span<ContactSample> out) const override {
    const auto start = std::chrono::steady_clock::now();
    inner_.query(points, radius, out);
    nanoseconds_ += std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now() - start).count();
    vertices_ += static_cast<int64_t>(points.size());
  }
  double ns_per_vertex() const { return vertices_ ? static_cast<double>(nanoseconds_) / static_cast<double>(vertices_.load()) : 0.0; }

 private:
  Collider& inner_;
  mutable std::atomic<int64_t> nanoseconds_{0}, vertices_{0};
};

// Table 1, reproduced in spirit: the paper sewed a shirt of 1800 vertices (IS: 82 iterations,
// 1.3 s, 15.8 ms per iteration; OS: 149 iterations, 4.6 s, 30.8 ms). Until garments are sewn here,
// a cloth tube of 1800 vertices (60 around x 30 high) around mean_all's waist shrinks by a quarter
// onto the body (no gravity). Converged: the tube's mean radius about the body's vertical axis
// changes by less than 2 mm/s, measured over 10 ms of simulated time, for 5 checks in a row (the
// tube may keep creeping along the body; every vertex coming to rest is too strict a test for that).
// Reports iterations, total time, time per iteration, the collider's own time per vertex per
// iteration and the final penetration (independent inside test) per method.
void BM_Table1_TubeShrink(benchmark::State& state, CollisionMethod method) {
  if (!body()) return state.SkipWithError("needs ../shared/data/bodies/garmentcode/mean_all.obj");
  const Mesh& mesh = *body();
  const InsideTest truth(mesh);
  const auto collider = make_body_collider(mesh, method);
  TimedCollider timed(*collider);
  const Fabric fabric;
  const uint32_t around = 60, high = 30;
  const float radius = 0.22f, y0 = 0.90f, tube_height = 0.20f;
  const float circumference = 2 * std::numbers::pi_v<float> * radius;
  GridClothOptions grid;
  grid.nx = around;
  grid.ny = high;
  grid.width = circumference * static_cast<float>(around - 1) / static_cast<float>(around);
  grid.height = tube_height;
  ClothSpec spec = grid_cloth_spec(fabric, grid);
  // Wrap the grid round the body and close it with a seam of structural springs.
  for (uint32_t iy = 0; iy < high; ++iy)
    for (uint32_t ix = 0; ix < around; ++ix) {
      const float theta = 2 * std::numbers::pi_v<float> * static_cast<float>(ix) / static_cast<float>(around);
      spec.positions[iy * around + ix] = Vec3f(radius * std::sin(theta), y0 + tube_height * static_cast<float>(iy) / static_cast<float>(high - 1), radius * std::cos(theta));
    }
  float seam_stiffness = 0;
  for (const auto& spring : spec.springs)
    if (spring.kind == SpringKind::Structural) seam_stiffness = std::max(seam_stiffness, spring.stiffness);
  for (uint32_t iy = 0; iy < high; ++iy)
    spec.springs.push_back({iy * around + around - 1, iy * around, circumference / static_cast<float>(around), seam_stiffness, SpringKind::Structural});
  for (auto& spring : spec.springs) spring.rest_length *= 0.75f;  // shrink onto the body
  spec.grid_nx = spec.grid_ny = 0;
  const ClothModel model = compile(spec);
  StepSettings settings = default_step_settings(model);
  settings.gravity = Vec3f::Zero();
  StepScratch scratch(model);
  Collider* colliders[] = {&timed};
  const double dt = settings.time_step > 0 ? settings.time_step : model.stable_time_step();
  const int check_every = std::max(1, static_cast<int>(std::lround(0.010 / dt)));
  constexpr uint64_t kCap = 20000;
  constexpr double kRestRate = 0.002;  // m/s
  const auto mean_radius = [](const std::vector<Vec3f>& x) {
    double sum = 0;
    for (const Vec3f& p : x) sum += std::hypot(p.x(), p.z());
    return sum / static_cast<double>(x.size());
  };
  uint64_t iterations = 0;
  double seconds = 0;
  bool converged = false;
  PenetrationStats penetration;
  for (auto _ : state) {
    ClothState cloth = initial_state(model);
    double last_radius = mean_radius(cloth.x);
    int quiet_checks = 0;
    converged = false;
    const auto start = std::chrono::steady_clock::now();
    while (cloth.iterations < kCap && !converged) {
      if (step(model, cloth, colliders, settings, scratch) != StepStatus::Ok) return state.SkipWithError("simulation failed");
      if (cloth.iterations % static_cast<uint64_t>(check_every) != 0) continue;
      const double r = mean_radius(cloth.x);
      quiet_checks = std::abs(r - last_radius) / (check_every * dt) < kRestRate ? quiet_checks + 1 : 0;
      last_radius = r;
      converged = quiet_checks >= 5;
    }
    seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    iterations = cloth.iterations;
    penetration = measure_penetration(truth, cloth.x, fabric.collision_thickness);
  }
  state.counters["converged"] = converged ? 1 : 0;
  state.counters["iterations"] = static_cast<double>(iterations);
  state.counters["total_s"] = seconds;
  state.counters["ms_per_iteration"] = 1e3 * seconds / static_cast<double>(std::max<uint64_t>(iterations, 1));
  state.counters["collision_ns_per_vertex"] = timed.ns_per_vertex();
  state.counters["penetrating"] = static_cast<double>(penetration.penetrating);
  state.counters["max_depth_mm"] = 1e3 * penetration.max_depth_m;
}
BENCHMARK_CAPTURE(BM_Table1_TubeShrink, image, CollisionMethod::image)->Unit(benchmark::kSecond)->Iterations(1);
BENCHMARK_CAPTURE(BM_Table1_TubeShrink, bvh, CollisionMethod::bvh)->Unit(benchmark::kSecond)->Iterations(1);
BENCHMARK_CAPTURE(BM_Table1_TubeShrink, sdf, CollisionMethod::sdf)->Unit(benchmark::kSecond)->Iterations(1);

}  // namespace
}  // namespace drape

BENCHMARK_MAIN();
