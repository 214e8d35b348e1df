// Body set-up speed: what `drape dress` spends before the first simulation step on the default body.
// Making a body from measurements polygonises the generator's implicit surface and analyses it
// (landmarks, measurements) several times while it fits the measurements; the analysis slices the
// mesh thousands of times (7489 slices for the default body).
#include <benchmark/benchmark.h>

#include "body/slicing.hpp"
#include "drape/body.hpp"

namespace {

const drape::Body& female() {
  static const drape::Body body = drape::default_body(drape::Sex::Female);
  return body;
}

// The default female body from its measurements: generation, fitting, analysis and rig (what the
// build does once, tools/bake_default_bodies.cpp).
void BM_MakeDefaultBody(benchmark::State& state) {
  for (auto _ : state) benchmark::DoNotOptimize(drape::generate_default_body(drape::Sex::Female));
}
BENCHMARK(BM_MakeDefaultBody)->Unit(benchmark::kMillisecond)->Iterations(3);

// The default female body as drape gets it: the baked mesh, analysed and rigged.
void BM_LoadDefaultBody(benchmark::State& state) {
  for (auto _ : state) benchmark::DoNotOptimize(drape::default_body(drape::Sex::Female));
}
BENCHMARK(BM_LoadDefaultBody)->Unit(benchmark::kMillisecond);

// Landmarks and measurements of the default body's mesh (done on every candidate while fitting).
void BM_AnalyseDefaultBody(benchmark::State& state) {
  const drape::Mesh& mesh = female().mesh;
  for (auto _ : state) {
    const drape::Landmarks lm = drape::find_landmarks(mesh, "default body");
    benchmark::DoNotOptimize(drape::measure_body(mesh, lm));
  }
  state.counters["triangles"] = static_cast<double>(mesh.triangle_count());
}
BENCHMARK(BM_AnalyseDefaultBody)->Unit(benchmark::kMillisecond);

// One horizontal cross-section of the default body (the analysis' unit of work), at the waist.
void BM_SliceDefaultBody(benchmark::State& state) {
  const drape::Body& body = female();
  const float y = body.landmarks.waist.y();
  for (auto _ : state) benchmark::DoNotOptimize(drape::body::slice(body.mesh, drape::body::horizontal_plane(y)));
}
BENCHMARK(BM_SliceDefaultBody)->Unit(benchmark::kMicrosecond);

}  // namespace

BENCHMARK_MAIN();
