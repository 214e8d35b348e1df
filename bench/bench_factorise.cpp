// The implicit solver's sparse Cholesky factorisation and solves (src/sim/supernodal.hpp) on a
// cloth-like matrix: a grid of side x side particles, 3 unknowns each, springs to the 8 neighbours
// (tests/support/grid_matrix.hpp), ordered and analysed by CHOLMOD's supernodal analysis.
// BM_Factorise: one numeric factorisation, by drape's factorisation on 1 or 2 threads (threads 0:
// CHOLMOD's own, on one thread as the solver uses it). BM_Solve: one solve with drape's factor in
// single precision on 1 or 2 threads. Counters: unknowns, the factor's entries, the share of the
// flops in the top of the elimination tree and how many of its supernodes are factorised in tiles.
// Side 170 is about the size of the x16 shirt's system (86,700 unknowns against 59,895).
//   OMP_WAIT_POLICY=passive build/bench/bench_factorise --benchmark_counters_tabular=true
#include <benchmark/benchmark.h>
#include <omp.h>

#include <dlfcn.h>

#include <Eigen/CholmodSupport>
#include <algorithm>
#include <vector>

#include "sim/supernodal.hpp"
#include "support/grid_matrix.hpp"

namespace {

using drape::sim::SupernodalFactorisation;
using drape::test::Sparse;

// As the implicit solver runs them (src/sim/implicit.cpp): OpenBLAS on one thread (the
// factorisation's own threads call it side by side), and CHOLMOD's OpenMP regions serial.
void blas_on_one_thread() {
  if (const auto set = reinterpret_cast<void (*)(int)>(dlsym(RTLD_DEFAULT, "openblas_set_num_threads"))) set(1);
}

// The grid's matrix, CHOLMOD's symbolic analysis of it and a numeric factor to fill.
class GridSystem {
 public:
  explicit GridSystem(int side) : a_(drape::test::grid_matrix(side, 7u + static_cast<uint32_t>(side))) {
    drape::test::start_supernodal(common_);
    view_ = drape::test::lower_view(a_);
    factor_ = cholmod_analyze(&view_, &common_);
    cholmod_change_factor(CHOLMOD_REAL, true, true, true, true, factor_, &common_);
    ours_.analyse(*factor_, a_.outerIndexPtr(), a_.innerIndexPtr());
  }
  ~GridSystem() {
    cholmod_free_factor(&factor_, &common_);
    cholmod_finish(&common_);
  }
  GridSystem(const GridSystem&) = delete;
  GridSystem& operator=(const GridSystem&) = delete;

  bool factorise_cholmod() {
    const int levels = omp_get_max_active_levels();
    omp_set_max_active_levels(0);
    const bool ok = cholmod_factorize(&view_, factor_, &common_) && factor_->minor == factor_->n;
    omp_set_max_active_levels(levels);
    return ok;
  }
  bool factorise(int threads) { return ours_.factorise(*factor_, a_.valuePtr(), threads); }
  void solve(const double* b, double* x, int threads) { ours_.solve(b, x, threads); }

  void count(benchmark::State& state) const {
    state.counters["unknowns"] = static_cast<double>(a_.rows());
    state.counters["factor_entries"] = static_cast<double>(factor_->xsize);
    state.counters["top_share"] = ours_.top_share();
    state.counters["tiled"] = ours_.tiled_supernodes();
  }
  Eigen::Index unknowns() const { return a_.rows(); }

 private:
  Sparse a_;
  cholmod_common common_{};
  cholmod_sparse view_{};
  cholmod_factor* factor_ = nullptr;
  SupernodalFactorisation ours_;
};

void BM_Factorise(benchmark::State& state) {
  const int side = static_cast<int>(state.range(0));
  const int threads = static_cast<int>(state.range(1));
  omp_set_num_threads(std::max(threads, 1));
  blas_on_one_thread();
  GridSystem system(side);
  for (auto _ : state)
    if (!(threads == 0 ? system.factorise_cholmod() : system.factorise(threads))) {
      state.SkipWithError("the grid's matrix was not positive definite");
      break;
    }
  system.count(state);
  state.counters["threads"] = threads;
  omp_set_num_threads(omp_get_num_procs());
}

BENCHMARK(BM_Factorise)
    ->ArgNames({"side", "threads"})
    ->ArgsProduct({{70, 120, 170}, {0, 1, 2}})
    ->Unit(benchmark::kMillisecond)
    ->MinTime(1.0)
    ->UseRealTime();

void BM_Solve(benchmark::State& state) {
  const int side = static_cast<int>(state.range(0));
  const int threads = static_cast<int>(state.range(1));
  omp_set_num_threads(threads);
  blas_on_one_thread();
  GridSystem system(side);
  if (!system.factorise(threads)) {
    state.SkipWithError("the grid's matrix was not positive definite");
    return;
  }
  std::vector<double> b(static_cast<size_t>(system.unknowns()), 1.0), x(b.size());
  for (auto _ : state) {
    system.solve(b.data(), x.data(), threads);
    benchmark::DoNotOptimize(x.data());
  }
  system.count(state);
  state.counters["threads"] = threads;
  omp_set_num_threads(omp_get_num_procs());
}

BENCHMARK(BM_Solve)
    ->ArgNames({"side", "threads"})
    ->ArgsProduct({{70, 120, 170}, {1, 2}})
    ->Unit(benchmark::kMillisecond)
    ->MinTime(1.0)
    ->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
