// drape beside Blender's cloth on ../shared/peers' sewing scene (blender_drape.py --scenario sew;
// drape/cloth_scene.hpp has the layout): two 0.5 x 0.6 m panels of n particles across, sewn at
// their sides and shoulders into a tube round a cylinder of radius 0.15 m, 2.0 s of simulated time,
// 0.2 kg/m^2, friction 0.3, a 10 mm contact margin, air drag 1/s, seams of 1000 N/m without a cap.
// drape runs its implicit solver (1/30 s steps, the strain limit at 5 % inside the solve, cotton's
// stiffness); Blender (Debian's 3.4.1) is not among drape's dependencies, so its figures are read from
// the peers' own runs of the same scene (../shared/peers/results.jsonl, measured on a 2-core AMD
// EPYC machine like the one drape is benchmarked on): the median wall time of its runs with one
// thread and with its default two. Reported: wall seconds for the 2 s, when drape's cloth came to
// rest, and the quality of each (strain, vertices inside the cylinder, widest seam).
//   build/bench/bench_peer_blender --benchmark_counters_tabular=true
#include <benchmark/benchmark.h>
#include <omp.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "drape/cloth_scene.hpp"
#include "peer_scene.hpp"

namespace {

using peer::kSimulatedSeconds;
constexpr float kCalmSpeed = 0.05f;  // m/s: at rest once no particle moves faster (drape scene's criterion)

struct Result {
  double wall_seconds = 0;
  double steps = 0;
  double rest_at = -1;  // simulated s from which no particle moved faster than kCalmSpeed; -1: never
  drape::SceneQuality quality;
  size_t vertices = 0;
};

Result run_drape(int n) {
  drape::ClothScene scene = drape::make_cloth_scene(peer::scene_options(drape::SceneObstacle::Sew, n, drape::Solver::Implicit));
  Result r;
  r.vertices = scene.model.particle_count();
  const auto start = std::chrono::steady_clock::now();
  const double end = kSimulatedSeconds - 0.5 * scene.time_step();
  while (scene.state.time < end) {
    if (scene.implicit->step(scene.state, scene.colliders, scene.implicit_settings) != drape::StepStatus::Ok) break;
    ++r.steps;
    if (scene.state.max_speed >= kCalmSpeed) r.rest_at = -1;
    else if (r.rest_at < 0) r.rest_at = scene.state.time;
  }
  r.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  r.quality = drape::scene_quality(scene);
  return r;
}

// Blender's runs of the scene: wall seconds (median) and the last run's quality, per n and threads.
struct BlenderRuns {
  std::vector<double> wall;
  double max_strain = 0, inside = 0, max_gap = 0;
  double median() const {
    std::vector<double> w = wall;
    std::sort(w.begin(), w.end());
    return w.empty() ? 0.0 : w[w.size() / 2];
  }
};

std::map<std::pair<int, int>, BlenderRuns> read_blender() {
  std::map<std::pair<int, int>, BlenderRuns> runs;
  std::ifstream in(std::filesystem::path(DRAPE_SHARED_DATA) / "../peers/results.jsonl");
  std::string line;
  while (std::getline(in, line)) {
    const nlohmann::json r = nlohmann::json::parse(line, nullptr, false);
    if (r.is_discarded() || !r.contains("engine") || r.value("scenario", "") != "sew") continue;
    if (r["engine"].get<std::string>().rfind("blender", 0) != 0) continue;
    BlenderRuns& b = runs[{r.value("n", 0), r.value("threads", 0)}];
    b.wall.push_back(r.value("wall_s", 0.0));
    b.max_strain = r.value("max_strain", 0.0);
    b.inside = r.value("frac_inside", 0.0);
    b.max_gap = r.value("max_sew_gap", 0.0);
  }
  return runs;
}

}  // namespace

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  std::map<int, Result> drape;
  for (int n : {32, 64}) {
    benchmark::RegisterBenchmark(("drape_implicit/n:" + std::to_string(n) + "/threads:2").c_str(), [n, &drape](benchmark::State& s) {
      omp_set_num_threads(2);
      for (auto _ : s) {
        const Result r = drape[n] = run_drape(n);
        s.SetIterationTime(r.wall_seconds);
        s.counters["vertices"] = static_cast<double>(r.vertices);
        s.counters["steps"] = r.steps;
        s.counters["wall_s_for_2s"] = r.wall_seconds;
        s.counters["at_rest_from_s"] = r.rest_at;
        s.counters["max_strain"] = r.quality.strain.max;
        s.counters["inside_fraction"] = r.quality.penetration_fraction;
        s.counters["max_seam_gap_mm"] = 1e3 * r.quality.max_seam_gap;
      }
      omp_set_num_threads(omp_get_num_procs());
    })->Iterations(1)->UseManualTime()->Unit(benchmark::kMillisecond);
  }
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();

  const auto blender = read_blender();
  if (blender.empty())
    std::printf("\nBlender's runs not found (../shared/peers/results.jsonl): drape's figures only.\n");
  std::printf("\n| n (vertices) | Blender s for 2 s, 1 thread / 2 (median) | drape implicit s for 2 s (2 threads) | at rest from | "
              "per-simulated-second ratio (Blender 1 thread / 2) | max strain Blender / drape | inside Blender / drape | "
              "widest seam mm Blender / drape |\n|---|---|---|---|---|---|---|---|\n");
  for (const auto& [n, d] : drape) {
    const auto one = blender.find({n, 1}), two = blender.find({n, 2});
    const double b1 = one != blender.end() ? one->second.median() : 0, b2 = two != blender.end() ? two->second.median() : 0;
    const BlenderRuns none;
    const BlenderRuns& b = one != blender.end() ? one->second : two != blender.end() ? two->second : none;
    std::printf("| %d (%zu) | %.2f / %.2f | %.2f | %.2f s | %.2fx / %.2fx | %.3f / %.3f | %.4f / %.4f | %.2f / %.2f |\n", n,
                d.vertices, b1, b2, d.wall_seconds, d.rest_at, b1 / d.wall_seconds, b2 / d.wall_seconds, b.max_strain,
                d.quality.strain.max, b.inside, d.quality.penetration_fraction, 1e3 * b.max_gap, 1e3 * d.quality.max_seam_gap);
  }
  return 0;
}
