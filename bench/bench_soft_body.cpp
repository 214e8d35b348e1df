// Soft body speed (docs/soft-body.md): Vassilev's Table 1 measured the time per frame of body
// deformation for bodies of 1152, 2592, 4608 and 6728 surface triangles (11.7-36.7 ms on a 1.3 GHz
// Duron). Here the same triangle counts (UV ellipsoids the size of a torso, 2 x slices x (stacks -
// 1) triangles) and the default bodies, pressed by a band: the time to the body's rest from its
// rest shape (cold), and per frame of a press that changes by 10 % a frame, each solve starting
// from the last rest (what an animation pays per frame).
#include <benchmark/benchmark.h>

#include <cmath>

#include "drape/shapes.hpp"
#include "drape/soft_body.hpp"

namespace {

using drape::Vec3f;

struct Scene {
  drape::SoftBody soft;
  std::vector<Vec3f> press;  // 10 N in all, inward over a 4 cm band
  size_t triangles = 0;
};

// Inward forces on the soft vertices within 2 cm of height `y` whose normal faces +Z, `total`
// newtons spread by area.
std::vector<Vec3f> band(const drape::SoftBody& soft, float y, float total) {
  std::vector<Vec3f> f(soft.rest.size(), Vec3f::Zero());
  double area = 0;
  for (size_t v = 0; v < soft.rest.size(); ++v)
    if (soft.region_of[v] >= 0 && std::abs(soft.rest[v].y() - y) < 0.02f && (soft.rest[v] - soft.frame[v]).z() > 0)
      area += soft.area[v];
  for (size_t v = 0; v < soft.rest.size(); ++v)
    if (soft.region_of[v] >= 0 && std::abs(soft.rest[v].y() - y) < 0.02f && (soft.rest[v] - soft.frame[v]).z() > 0)
      f[v] = static_cast<float>(total * soft.area[v] / area) * (soft.frame[v] - soft.rest[v]).normalized();
  return f;
}

// A torso-sized ellipsoid (0.32 x 0.5 x 0.24 m), soft but for its lowest tenth.
Scene ellipsoid(int slices) {
  const drape::Mesh mesh = drape::uv_ellipsoid(Vec3f(0.16f, 0.25f, 0.12f), Vec3f::Zero(), slices, slices + 1);
  std::vector<int> labels(mesh.positions.size(), 0);
  for (size_t v = 0; v < mesh.positions.size(); ++v)
    if (mesh.positions[v].y() < -0.2f) labels[v] = -1;
  Scene s{drape::make_soft_body(mesh, labels, {"torso"}), {}, mesh.triangles.size()};
  s.press = band(s.soft, 0.0f, 10.0f);
  return s;
}

Scene default_body(int sex) {
  const drape::Body body = drape::default_body(sex == 0 ? drape::Sex::Female : drape::Sex::Male);
  Scene s{drape::make_soft_body(body), {}, body.mesh.triangles.size()};
  s.press = band(s.soft, body.landmarks.waist.y(), 10.0f);
  return s;
}

void cold(benchmark::State& state, const Scene& s) {
  int newton = 0, factorisations = 0;
  for (auto _ : state) {
    const drape::SoftSolve solved = drape::solve_soft_body(s.soft, s.press);
    newton = solved.newton_iterations;
    factorisations = solved.factorisations;
    benchmark::DoNotOptimize(solved.positions.data());
  }
  state.counters["triangles"] = static_cast<double>(s.triangles);
  state.counters["soft_vertices"] = static_cast<double>(s.soft.soft_count());
  state.counters["newton"] = newton;
  state.counters["factorisations"] = factorisations;
}

void frames(benchmark::State& state, const Scene& s) {
  // The solver of a motion: its factorisation kept from frame to frame.
  drape::SoftBodySolver solver(s.soft);
  std::vector<Vec3f> at = solver.solve(s.press).positions;
  std::vector<Vec3f> press = s.press;
  bool stronger = true;
  double newton = 0, factorisations = 0, count = 0;
  for (auto _ : state) {
    for (size_t v = 0; v < press.size(); ++v) press[v] = (stronger ? 1.1f : 1.0f) * s.press[v];
    stronger = !stronger;
    drape::SoftSolve solved = solver.solve(press, at);
    newton += solved.newton_iterations;
    factorisations += solved.factorisations;
    count += 1;
    at.swap(solved.positions);
  }
  state.counters["triangles"] = static_cast<double>(s.triangles);
  state.counters["newton"] = count > 0 ? newton / count : 0.0;
  state.counters["factorisations"] = count > 0 ? factorisations / count : 0.0;
}

void BM_SoftBodyEllipsoidCold(benchmark::State& state) {
  const Scene s = ellipsoid(static_cast<int>(state.range(0)));
  cold(state, s);
}
void BM_SoftBodyEllipsoidFrame(benchmark::State& state) {
  const Scene s = ellipsoid(static_cast<int>(state.range(0)));
  frames(state, s);
}
// Table 1's triangle counts: 2 x 24^2 = 1152, 2 x 36^2 = 2592, 2 x 48^2 = 4608, 2 x 58^2 = 6728.
BENCHMARK(BM_SoftBodyEllipsoidCold)->Arg(24)->Arg(36)->Arg(48)->Arg(58)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_SoftBodyEllipsoidFrame)->Arg(24)->Arg(36)->Arg(48)->Arg(58)->Unit(benchmark::kMillisecond)->UseRealTime();

// The default bodies (0 female, 1 male) at full resolution, the band round the waist.
void BM_SoftBodyDefaultCold(benchmark::State& state) {
  const Scene s = default_body(static_cast<int>(state.range(0)));
  cold(state, s);
}
void BM_SoftBodyDefaultFrame(benchmark::State& state) {
  const Scene s = default_body(static_cast<int>(state.range(0)));
  frames(state, s);
}
BENCHMARK(BM_SoftBodyDefaultCold)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_SoftBodyDefaultFrame)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
