// Table 2 of Vassilev & Spanlang, reproduced: the default female body dressed in the paper's four
// garments (skirt, shirt, trousers, dress) at the paper's cloth vertex counts (1152, 1800, 2048,
// 3840), and at 4x and 16x those. The grid spacing is solved per garment so the mesh has the
// wanted number of vertices (within a few percent). Times are the simulation only (sewing +
// draping), as the paper's table excludes set-up (reading files, building trees); set-up is
// reported separately. The 16x shirt also runs on a 50k-triangle body (the 2 s target).
//
//   build-*/bench_dress --benchmark_counters_tabular=true
#include <benchmark/benchmark.h>

#include <cmath>
#include <cstdio>
#include <map>
#include <string>

#include "drape/dress.hpp"

namespace drape {
namespace {

struct PaperRow {
  const char* garment;
  size_t vertices;
  int iterations;
  double total_s, ms_per_iteration;
};
constexpr PaperRow kTable2[] = {{"skirt", 1152, 80, 1.25, 15.6},
                                {"shirt", 1800, 149, 4.4, 29.5},
                                {"trousers", 2048, 147, 4.7, 31.9},
                                {"dress", 3840, 150, 7.8, 52.0}};

const Body& body(bool fine) {
  static std::map<bool, Body> bodies;
  auto it = bodies.find(fine);
  if (it == bodies.end()) {
    BodyBuildOptions o;
    o.grid_step = 0.0095f;  // the default body with 50.1k triangles (the 50k-triangle body)
    it = bodies.emplace(fine, fine ? generate_default_body(Sex::Female, o) : default_body(Sex::Female)).first;
  }
  return it->second;
}

// Grid spacing giving the garment about `vertices` vertices (vertex count ~ 1 / h^2).
double edge_for(const Garment& g, size_t vertices) {
  double h = kPaperEdgeLength;
  for (int i = 0; i < 6; ++i) {
    const size_t n = mesh_garment(g, {Mesher::grid, h}).vertex_count();
    h *= std::sqrt(static_cast<double>(n) / static_cast<double>(vertices));
  }
  return h;
}

// How a Table 2 row is run: `coarse` dresses the garment at the paper's spacing first and starts the
// fine one from it (DressOptions::coarse_edge); the plain rows start every garment from its placement.
struct RowRun {
  int scale = 1;
  bool fine_body = false, directional = false, coarse = false, projected = false, implicit = false;
};

void BM_Table2(benchmark::State& state, const PaperRow& row, RowRun run) {
  const int scale = run.scale;
  const GarmentSpec spec = *builtin_garment(row.garment);
  const Garment g = garment_in_size(spec, {});
  DressOptions o;
  o.solver = run.implicit ? Solver::Implicit : Solver::Explicit;
  o.directional_time_step = run.directional;
  o.projection_iterations = run.projected ? 8 : 0;
  o.coarse_edge = run.coarse ? kPaperEdgeLength : 0.0;
  o.mesh.edge_length = edge_for(g, row.vertices * static_cast<size_t>(scale));
  const Body& b = body(run.fine_body);
  DressResult r;
  for (auto _ : state) {
    r = dress(b, {{spec, ""}}, o);
    state.SetIterationTime(r.simulation.wall_seconds);
  }
  const DressedGarment& d = r.garments.at(0);
  state.counters["vertices"] = static_cast<double>(d.model.particle_count());
  state.counters["body_tris"] = static_cast<double>(b.mesh.triangle_count());
  state.counters["iterations"] = static_cast<double>(r.simulation.iterations);
  state.counters["sew_iter"] = static_cast<double>(d.sewing_iterations);
  state.counters["coarse_iter"] = static_cast<double>(d.coarse.iterations);  // included in iterations
  state.counters["coarse_verts"] = static_cast<double>(d.coarse.vertices);
  state.counters["total_s"] = r.simulation.wall_seconds;
  state.counters["ms_per_iter"] = 1e3 * r.simulation.seconds_per_iteration;
  state.counters["setup_s"] = r.setup_seconds;
  state.counters["dt_ms"] = 1e3 * r.simulation.time_step_s;
  state.counters["max_strain"] = r.quality.max_strain;
  state.counters["gap_mm"] = 1e3 * r.quality.max_seam_gap_m;
  state.counters["inside_pct"] = 100 * r.quality.penetration_fraction;
  state.counters["settled"] = r.quality.settled ? 1 : 0;
  state.counters["gates_ok"] = r.passed() ? 1 : 0;
  state.counters["residual"] = r.quality.residual;
  state.counters["newton_iter"] = static_cast<double>(d.implicit_profile.newton_iterations);
  state.counters["paper_verts"] = static_cast<double>(row.vertices);
  state.counters["paper_iter"] = row.iterations;
  state.counters["paper_total_s"] = row.total_s;
  state.counters["paper_ms_iter"] = row.ms_per_iteration;
}

int register_table2() {
  const auto add = [](const std::string& name, const PaperRow& row, RowRun run) {
    benchmark::RegisterBenchmark(("Table2/" + name).c_str(), [&row, run](benchmark::State& s) { BM_Table2(s, row, run); })
        ->UseManualTime()->Iterations(1)->Unit(benchmark::kMillisecond);
  };
  for (const PaperRow& row : kTable2)
    for (int scale : {1, 4, 16}) add(std::string(row.garment) + "/x" + std::to_string(scale), row, {.scale = scale});
  // The implicit solver (drape/implicit.hpp) beside the explicit rows above: x1 and x4 (the shirt's
  // x16 rows are below; the others take minutes each while the factorisation dominates).
  for (const PaperRow& row : kTable2)
    for (int scale : {1, 4})
      add(std::string(row.garment) + "/x" + std::to_string(scale) + "/implicit", row, {.scale = scale, .implicit = true});
  // Coarse-to-fine: the finer rows started from the garment dressed at the paper's spacing. The
  // skirt and shirt only: the trousers and dress at 16x fail from it (docs/dressing.md,
  // "Coarse-to-fine") after 5 s of draping, which would add ~15 minutes to `make bench`.
  for (const PaperRow& row : kTable2) {
    if (std::string(row.garment) != "skirt" && std::string(row.garment) != "shirt") continue;
    for (int scale : {4, 16})
      add(std::string(row.garment) + "/x" + std::to_string(scale) + "/coarse", row, {.scale = scale, .coarse = true});
  }
  // DressOptions::projection_iterations (8 Newton iterations where the converge passes stall): the
  // x1 rows, and the dress at x4, which does not settle with it (why it is off by default).
  for (const PaperRow& row : kTable2) add(std::string(row.garment) + "/x1/projected", row, {.projected = true});
  add("dress/x4/projected", kTable2[3], {.scale = 4, .projected = true});
  // The same shirt with DressOptions::directional_time_step (a longer step from the same bound).
  add("shirt/x1/directional_dt", kTable2[1], {.directional = true});
  add("shirt/x16/body50k", kTable2[1], {.scale = 16, .fine_body = true});
  add("shirt/x16/body50k/coarse", kTable2[1], {.scale = 16, .fine_body = true, .coarse = true});
  // The implicit solver's 29k-vertex shirt, on the default body and on the 50k-triangle one.
  add("shirt/x16/implicit", kTable2[1], {.scale = 16, .implicit = true});
  add("shirt/x16/body50k/implicit", kTable2[1], {.scale = 16, .fine_body = true, .implicit = true});
  return 0;
}
[[maybe_unused]] const int registered = register_table2();

}  // namespace
}  // namespace drape

BENCHMARK_MAIN();
