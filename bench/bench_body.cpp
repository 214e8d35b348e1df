// Body set-up speed: making a body from measurements on MakeHuman's body (the solve measures the
// blended mesh a few dozen times, mostly at pinned landmarks, and searches the landmarks a few
// times), and what `drape dress` spends before the first simulation step on the default body. The
// analysis slices the mesh thousands of times (7489 slices for the default body).
#include <benchmark/benchmark.h>

#include "body/makehuman.hpp"
#include "body/slicing.hpp"
#include "drape/body.hpp"

namespace {

// A body from measurements: height, bust, waist and hips of ready-to-wear sizes (arg: 0 = female M,
// 1 = female XXL, 2 = male M, 3 = male XXL), solved, untangled, analysed and rigged.
void BM_MakeBodyFromMeasurements(benchmark::State& state) {
  struct Request {
    drape::Sex sex;
    const char* text;
  };
  const Request requests[] = {{drape::Sex::Female, "height=1.65,bust=0.92,waist=0.74,hips=0.98"},
                              {drape::Sex::Female, "height=1.72,bust=1.14,waist=0.97,hips=1.19"},
                              {drape::Sex::Male, "height=1.77,bust=0.98,waist=0.84,hips=0.98"},
                              {drape::Sex::Male, "height=1.86,bust=1.20,waist=1.10,hips=1.16"}};
  const Request& r = requests[state.range(0)];
  const drape::MeasurementRequest request = drape::parse_measurements(r.text);
  drape::body::makehuman_model();  // the pack is decoded once per process, not per body
  for (auto _ : state) benchmark::DoNotOptimize(drape::make_human_body(r.sex, request));
}
BENCHMARK(BM_MakeBodyFromMeasurements)->DenseRange(0, 3)->Unit(benchmark::kMillisecond)->UseRealTime();

// Every key at once (a woman of 1.70 m).
void BM_MakeBodyAllKeys(benchmark::State& state) {
  const drape::MeasurementRequest request = drape::parse_measurements(
      "height=1.70,neck=0.34,bust=0.94,underbust=0.80,waist=0.76,hips=1.00,thigh=0.58,upper_arm=0.29,"
      "wrist=0.16,inseam=0.77,arm_length=0.57,shoulder_width=0.37,back_length=0.41");
  drape::body::makehuman_model();
  for (auto _ : state) benchmark::DoNotOptimize(drape::make_human_body(drape::Sex::Female, request));
}
BENCHMARK(BM_MakeBodyAllKeys)->Unit(benchmark::kMillisecond)->UseRealTime();

// MakeHuman's body at given macros, untangled, analysed and rigged: the last step of every make.
void BM_MakeHumanBodyOfAShape(benchmark::State& state) {
  drape::body::MhShape shape;
  for (auto _ : state) benchmark::DoNotOptimize(drape::body::mh_body(shape));
}
BENCHMARK(BM_MakeHumanBodyOfAShape)->Unit(benchmark::kMillisecond);

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
  const drape::body::Slicer slicer(body.mesh);  // indexed once, as the analysis does
  for (auto _ : state) benchmark::DoNotOptimize(drape::body::slice(slicer, drape::body::horizontal_plane(y)));
}
BENCHMARK(BM_SliceDefaultBody)->Unit(benchmark::kMicrosecond);

}  // namespace

BENCHMARK_MAIN();
