// Cloth step speed (Vassilev & Spanlang fig. 10: time per iteration against the number of cloth
// vertices): the fig. 7 sphere scene with velocity modification and collisions, n x n vertices for
// n = 32, 64, 128, 256, on 1 and 2 threads. Before timing, the cloth falls for 0.2 s so that it is
// in contact with the sphere. The Time column is ms per iteration; the counter gives vertex-iterations
// per second (wall clock). On a machine shared with other jobs, run with OMP_WAIT_POLICY=passive
// (libgomp reads it at start-up): a spinning thread steals the core its partner needs and a step
// with a dozen barriers then costs up to 100x more.
//   build-sim/bench_cloth --benchmark_counters_tabular=true
#include <benchmark/benchmark.h>
#include <omp.h>

#include "drape/cloth_scene.hpp"

namespace {

void BM_SphereStep(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  const int threads = static_cast<int>(state.range(1));
  omp_set_num_threads(threads);
  drape::ClothSceneOptions options;
  options.obstacle = drape::SceneObstacle::Sphere;
  options.n = static_cast<uint32_t>(n);
  options.strain_limit = drape::StrainLimit::Velocity;
  drape::ClothScene scene = drape::make_cloth_scene(options);
  while (scene.state.time < 0.2)
    if (drape::step(scene.model, scene.state, scene.colliders, scene.settings, scene.scratch) != drape::StepStatus::Ok) {
      state.SkipWithError("the simulation failed while dropping the cloth");
      return;
    }
  drape::StepProfile profile;
  for (auto _ : state) {
    if (drape::step(scene.model, scene.state, scene.colliders, scene.settings, scene.scratch, &profile) !=
        drape::StepStatus::Ok) {
      state.SkipWithError("the simulation failed");
      break;
    }
  }
  const double vertices = static_cast<double>(scene.model.particle_count());
  state.counters["vertices"] = vertices;
  state.counters["threads"] = threads;
  state.counters["vertex_iterations_per_s"] =
      benchmark::Counter(vertices * static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
  state.counters["contacts_per_iteration"] =
      static_cast<double>(profile.contacts) / static_cast<double>(std::max<uint64_t>(profile.steps, 1));
  state.counters["strain_passes_per_iteration"] =
      static_cast<double>(profile.strain_passes) / static_cast<double>(std::max<uint64_t>(profile.steps, 1));
  omp_set_num_threads(omp_get_num_procs());
}

BENCHMARK(BM_SphereStep)
    ->ArgNames({"n", "threads"})
    ->ArgsProduct({{32, 64, 128, 256}, {1, 2}})
    ->Unit(benchmark::kMillisecond)
    ->MinTime(1.0)
    ->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
