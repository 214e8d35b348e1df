// Cloth step speed (Vassilev & Spanlang fig. 10: time per iteration against the number of cloth
// vertices): the fig. 7 sphere scene with velocity modification and collisions, n x n vertices for
// n = 32, 64, 128, 256, on 1 and 2 threads. Before timing, the cloth falls for 0.2 s so that it is
// in contact with the sphere. The Time column is ms per iteration; the counter gives vertex-iterations
// per second (wall clock). On a machine shared with other jobs, run with OMP_WAIT_POLICY=passive
// (libgomp reads it at start-up): a spinning thread steals the core its partner needs and a step
// with a dozen barriers then costs up to 100x more.
//   build-sim/bench_cloth --benchmark_counters_tabular=true
// BM_ShirtDrapeStep: one draping step of `drape dress`'s default shirt (size M, ~1400 vertices; scale
// 4 divides the edge length by 2) on the default female body with the image collider, with the
// settings sew_and_drape uses while draping (4 velocity passes, 4 position passes, 128 converge
// passes, the seams held). The shirt is sewn and draped for 1500 iterations first, so the step is a
// step of a garment resting on the body with springs at the limit; the same 2000 steps are timed in
// every run; `faces` 1 keeps the faces off the body too (DressOptions::face_clearance, on while
// draping), 0 only the vertices. Counters: microseconds per step per stage (wall). On 2026-11-21 the scale 4 shirt
// exploded while sewing (as `drape dress --edge 0.013` did): the benchmark reports that as an error.
#include <benchmark/benchmark.h>
#include <omp.h>

#include <cmath>
#include <memory>
#include <string>

#include "drape/body.hpp"
#include "drape/cloth_scene.hpp"
#include "drape/collision.hpp"
#include "drape/dress.hpp"
#include "drape/garment.hpp"

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

void BM_ShirtDrapeStep(benchmark::State& state) {
  const int scale = static_cast<int>(state.range(0));  // vertex count factor (edge length / sqrt)
  const int threads = static_cast<int>(state.range(1));
  const bool faces = state.range(2) != 0;  // DressOptions::face_clearance, or off
  omp_set_num_threads(threads);
  const drape::Body body = drape::default_body(drape::Sex::Female);
  const std::unique_ptr<drape::BodyCollider> collider = drape::make_body_collider(body.mesh, drape::CollisionMethod::image);
  const drape::Garment garment = drape::garment_in_size(*drape::builtin_garment("shirt"), "M");
  drape::DressOptions o;
  o.mesh.edge_length = drape::kPaperEdgeLength / std::sqrt(static_cast<double>(scale));
  o.max_iterations = 1500;
  drape::DressedGarment g = drape::prepare_garment(body, garment, *collider, o);
  drape::Collider* colliders[] = {collider.get()};
  drape::sew_and_drape(g, colliders, o);
  if (g.status != drape::StepStatus::Ok) {
    state.SkipWithError(("the shirt failed while sewing: " + std::string(drape::to_string(g.status))).c_str());
    return;
  }
  drape::StepSettings settings = drape::default_step_settings(g.model);
  settings.strain_passes = o.strain_passes;
  settings.position_passes = o.position_passes;
  settings.time_step = g.model.stable_time_step();
  settings.air_damping = o.drape_damping;
  settings.converge_passes = 128;
  settings.joined_pairs = g.seam_pairs;
  settings.face_clearance = faces ? o.face_clearance : -1.0f;
  drape::StepScratch scratch(g.model, 1);
  drape::StepProfile profile;
  for (auto _ : state) {
    if (drape::step(g.model, g.state, colliders, settings, scratch, &profile) != drape::StepStatus::Ok) {
      state.SkipWithError("the simulation failed");
      break;
    }
  }
  const double steps = static_cast<double>(std::max<uint64_t>(profile.steps, 1));
  state.counters["vertices"] = static_cast<double>(g.model.particle_count());
  state.counters["threads"] = threads;
  state.counters["faces"] = faces ? 1 : 0;
  state.counters["passes"] = static_cast<double>(profile.strain_passes) / steps;
  for (const auto stage : {drape::StepProfile::DetectContacts, drape::StepProfile::SpringForces,
                           drape::StepProfile::IntegrateVelocities, drape::StepProfile::LimitStrainVelocity,
                           drape::StepProfile::LimitStrainPosition})
    state.counters[std::string(drape::StepProfile::name(stage)) + "_us"] = 1e6 * profile.seconds[stage] / steps;
  omp_set_num_threads(omp_get_num_procs());
}

BENCHMARK(BM_ShirtDrapeStep)
    ->ArgNames({"scale", "threads", "faces"})
    ->ArgsProduct({{1, 4}, {1, 2}, {0, 1}})
    ->Unit(benchmark::kMicrosecond)
    ->Iterations(2000)  // the same 2000 steps from the same state in every run: comparable runs
    ->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
