#include "sim/supernodal.hpp"

#include <omp.h>

#include <Eigen/Core>
#include <algorithm>
#include <array>
#include <numeric>

// The reference BLAS and LAPACK interface (OpenBLAS behind it where the system has it); the string
// lengths gfortran passes last.
extern "C" {
void dsyrk_(const char* uplo, const char* trans, const int* n, const int* k, const double* alpha, const double* a,
            const int* lda, const double* beta, double* c, const int* ldc, size_t, size_t);
void dgemm_(const char* transa, const char* transb, const int* m, const int* n, const int* k, const double* alpha,
            const double* a, const int* lda, const double* b, const int* ldb, const double* beta, double* c,
            const int* ldc, size_t, size_t);
void dtrsm_(const char* side, const char* uplo, const char* transa, const char* diag, const int* m, const int* n,
            const double* alpha, const double* a, const int* lda, double* b, const int* ldb, size_t, size_t, size_t,
            size_t);
void dpotrf_(const char* uplo, const int* n, double* a, const int* lda, int* info, size_t);
}

namespace drape::sim {
namespace {

// A partition is good enough once its largest part holds at most this much over an even share.
constexpr double kBalance = 1.05;

// v = `size` copies of `value`, its storage grown with room to spare: the pattern is analysed anew
// whenever self-contact brings new blocks, its factor a little larger or smaller each time, and
// storage made anew for each (tens of megabytes on the 20k-vertex shirt) cost more in the pages'
// first touch than the rest of the analysis.
template <class T, class A>
void assign_with_room(std::vector<T, A>& v, size_t size, T value) {
  if (v.capacity() < size) {
    v.clear();
    v.shrink_to_fit();
    v.reserve(size + size / 4);
  }
  v.assign(size, value);
}

struct View {
  const int *super, *pi, *px, *rows;
  explicit View(const cholmod_factor& f)
      : super(static_cast<const int*>(f.super)), pi(static_cast<const int*>(f.pi)),
        px(static_cast<const int*>(f.px)), rows(static_cast<const int*>(f.s)) {}
  int columns(int s) const { return super[s + 1] - super[s]; }
  int height(int s) const { return pi[s + 1] - pi[s]; }
};

}  // namespace

bool SupernodalFactorisation::analyse(const cholmod_factor& f, const int* outer, const int* inner) {
  ready_ = false;
  if (!f.is_super || !f.is_ll || f.itype != CHOLMOD_INT || f.nsuper == 0) return false;
  const View v(f);
  n_ = static_cast<int>(f.n);
  nsuper_ = static_cast<int>(f.nsuper);
  std::vector<int> column_super(static_cast<size_t>(n_));
  for (int s = 0; s < nsuper_; ++s) {
    const int* r = v.rows + v.pi[s];
    for (int k = 0; k < v.height(s); ++k)
      if ((k < v.columns(s) && r[k] != v.super[s] + k) || (k > 0 && r[k] <= r[k - 1])) return false;
    for (int k = v.super[s]; k < v.super[s + 1]; ++k) column_super[static_cast<size_t>(k)] = s;
  }
  // A's lower entries, each to its place in its supernode's block (P A P^T's lower triangle).
  const int* perm = static_cast<const int*>(f.Perm);
  std::vector<int> inverse(static_cast<size_t>(n_));
  for (int k = 0; k < n_; ++k) inverse[static_cast<size_t>(perm[k])] = k;
  std::vector<std::array<uint32_t, 3>>& placed = placed_;  // supernode, value index, block index
  placed.clear();
  for (int j = 0; j < n_; ++j)
    for (int q = outer[j]; q < outer[j + 1]; ++q) {
      const int i = inner[q];
      if (i < j) continue;
      const int a = inverse[static_cast<size_t>(i)], b = inverse[static_cast<size_t>(j)];
      const int col = std::min(a, b), row = std::max(a, b), s = column_super[static_cast<size_t>(col)];
      const int* r = v.rows + v.pi[s];
      const int* at = std::lower_bound(r, r + v.height(s), row);
      if (at == r + v.height(s) || *at != row) return false;
      placed.push_back({static_cast<uint32_t>(s), static_cast<uint32_t>(q),
                        static_cast<uint32_t>((col - v.super[s]) * v.height(s) + (at - r))});
    }
  // Grouped by supernode, in A's order within each (a counting sort: linear in A's entries, and
  // the pattern is analysed anew whenever self-contact brings new blocks).
  entry_begin_.assign(static_cast<size_t>(nsuper_) + 1, 0);
  for (const auto& e : placed) ++entry_begin_[e[0] + 1];
  std::partial_sum(entry_begin_.begin(), entry_begin_.end(), entry_begin_.begin());
  entries_.resize(placed.size());
  std::vector<uint32_t> fill(entry_begin_.begin(), entry_begin_.end() - 1);
  for (const auto& [s, q, at] : placed) entries_[fill[s]++] = {q, at};

  // Each supernode's updates, from the supernodes below whose rows reach its columns, in order; the
  // elimination tree (a supernode's parent: the one its first row below reaches); the flops, each
  // update's counted with the supernode it comes from (its part makes it).
  std::vector<std::vector<Update>> into(static_cast<size_t>(nsuper_));
  std::vector<int> parent(static_cast<size_t>(nsuper_), -1);
  std::vector<double> flops(static_cast<size_t>(nsuper_), 0.0);
  size_t largest_update = 1;
  for (int d = 0; d < nsuper_; ++d) {
    const double c = v.columns(d), below = v.height(d) - v.columns(d);
    flops[static_cast<size_t>(d)] += c * c * c / 3 + c * c * below;
    const int* r = v.rows + v.pi[d];
    for (int p = v.columns(d); p < v.height(d);) {
      const int s = column_super[static_cast<size_t>(r[p])], first = p;
      while (p < v.height(d) && r[p] < v.super[s + 1]) ++p;
      if (parent[static_cast<size_t>(d)] < 0) parent[static_cast<size_t>(d)] = s;
      into[static_cast<size_t>(s)].push_back({d, first, p});
      const size_t rows_reached = static_cast<size_t>(v.height(d) - first), columns_reached = static_cast<size_t>(p - first);
      largest_update = std::max(largest_update, rows_reached * columns_reached);
      flops[static_cast<size_t>(d)] += static_cast<double>(rows_reached * columns_reached) * c;
    }
  }
  update_begin_.assign(static_cast<size_t>(nsuper_) + 1, 0);
  updates_.clear();
  for (int s = 0; s < nsuper_; ++s) {
    updates_.insert(updates_.end(), into[static_cast<size_t>(s)].begin(), into[static_cast<size_t>(s)].end());
    update_begin_[static_cast<size_t>(s) + 1] = static_cast<uint32_t>(updates_.size());
  }

  // The parts: from the roots down, the costliest subtree gives its root to the top and its children
  // to the frontier, until the frontier's subtrees deal (largest first, each to the lightest part)
  // into parts within kBalance of even.
  std::vector<double> subtree(flops);
  std::vector<std::vector<int>> children(static_cast<size_t>(nsuper_));
  std::vector<int> frontier;
  for (int s = 0; s < nsuper_; ++s) {
    const int up = parent[static_cast<size_t>(s)];
    if (up < 0) {
      frontier.push_back(s);
      continue;
    }
    subtree[static_cast<size_t>(up)] += subtree[static_cast<size_t>(s)];
    children[static_cast<size_t>(up)].push_back(s);
  }
  part_.assign(static_cast<size_t>(nsuper_), -1);
  std::vector<int> root_part;
  for (;;) {
    std::sort(frontier.begin(), frontier.end(), [&](int x, int y) {
      return subtree[static_cast<size_t>(x)] != subtree[static_cast<size_t>(y)] ? subtree[static_cast<size_t>(x)] > subtree[static_cast<size_t>(y)] : x < y;
    });
    std::array<double, kParts> load{};
    root_part.assign(frontier.size(), 0);
    double total = 0;
    for (size_t k = 0; k < frontier.size(); ++k) {
      const auto lightest = static_cast<int>(std::min_element(load.begin(), load.end()) - load.begin());
      root_part[k] = lightest;
      load[static_cast<size_t>(lightest)] += subtree[static_cast<size_t>(frontier[k])];
      total += subtree[static_cast<size_t>(frontier[k])];
    }
    const double heaviest = *std::max_element(load.begin(), load.end());
    if (frontier.empty() || heaviest <= kBalance * total / kParts || children[static_cast<size_t>(frontier[0])].empty()) break;
    const int root = frontier[0];
    frontier.erase(frontier.begin());
    for (const int c : children[static_cast<size_t>(root)]) frontier.push_back(c);
  }
  // Each frontier subtree's supernodes take its part; the rest are the top (parents come after
  // their children, so each supernode's is settled before theirs).
  std::vector<char> is_root(static_cast<size_t>(nsuper_), 0);
  for (size_t k = 0; k < frontier.size(); ++k) {
    is_root[static_cast<size_t>(frontier[k])] = 1;
    part_[static_cast<size_t>(frontier[k])] = root_part[k];
  }
  for (int s = nsuper_ - 1; s >= 0; --s) {
    const int up = parent[static_cast<size_t>(s)];
    if (!is_root[static_cast<size_t>(s)]) part_[static_cast<size_t>(s)] = up < 0 ? -1 : part_[static_cast<size_t>(up)];
  }
  part_nodes_.assign(kParts, {});
  top_nodes_.clear();
  double top_flops = 0, all_flops = 0;
  for (int s = 0; s < nsuper_; ++s) {
    all_flops += flops[static_cast<size_t>(s)];
    if (part_[static_cast<size_t>(s)] < 0) {
      top_nodes_.push_back(s);
      top_flops += flops[static_cast<size_t>(s)];
    } else {
      part_nodes_[static_cast<size_t>(part_[static_cast<size_t>(s)])].push_back(s);
    }
  }
  top_share_ = all_flops > 0 ? top_flops / all_flops : 0;

  // Where each part sums its updates to each top supernode.
  sum_offset_.assign(static_cast<size_t>(kParts) * static_cast<size_t>(nsuper_), SIZE_MAX);
  size_t size = 0;
  for (const int s : top_nodes_)
    for (uint32_t k = update_begin_[static_cast<size_t>(s)]; k < update_begin_[static_cast<size_t>(s) + 1]; ++k) {
      const int p = part_[static_cast<size_t>(updates_[k].from)];
      if (p < 0 || sum_at(p, s) != SIZE_MAX) continue;
      sum_offset_[static_cast<size_t>(p) * static_cast<size_t>(nsuper_) + static_cast<size_t>(s)] = size;
      size += static_cast<size_t>(v.height(s)) * static_cast<size_t>(v.columns(s));
    }
  assign_with_room(sums_, size, 0.0);
  work_.resize(kParts);
  for (Workspace& w : work_) {
    w.relative.assign(static_cast<size_t>(n_), 0);
    assign_with_room(w.update, largest_update, 0.0);
    w.gather.assign(std::max<size_t>(f.maxesize, 1), 0.0f);
    w.carried.assign(static_cast<size_t>(n_), 0.0f);
  }
  size_t most_tasks = 0;
  tiled_ = 0;
  factor_ = &f;
  for (const int s : top_nodes_)
    if (tiled(s)) {
      ++tiled_;
      const size_t tiles = static_cast<size_t>((v.columns(s) + kTile - 1) / kTile);
      most_tasks = std::max(most_tasks, tiles * (2 + static_cast<size_t>(v.height(s) / kRows)));
    }
  tasks_.clear();
  tasks_.reserve(most_tasks);
  assign_with_room(single_, f.xsize, 0.0f);
  y_.assign(static_cast<size_t>(n_), 0.0f);
  top_row_.assign(static_cast<size_t>(n_), 0);
  top_rows_.clear();
  for (const int s : top_nodes_)
    for (int k = v.super[s]; k < v.super[s + 1]; ++k) {
      top_row_[static_cast<size_t>(k)] = 1;
      top_rows_.push_back(k);
    }
  ready_ = true;
  return true;
}

void SupernodalFactorisation::apply(const cholmod_factor& f, int s, const Update& u, int ja, int jb, double* target,
                                    double sign, double* buffer, const int* relative) const {
  const View v(f);
  const double* x = static_cast<const double*>(f.x);
  const int d = u.from, columns = v.columns(d), height = v.height(d);
  const int reached = jb - ja, rows = height - ja, rest = rows - reached;
  const double* l = x + v.px[d];
  const double one = 1, zero = 0;
  dsyrk_("L", "N", &reached, &columns, &one, l + ja, &height, &zero, buffer, &rows, 1, 1);
  if (rest > 0)
    dgemm_("N", "T", &rest, &reached, &columns, &one, l + jb, &height, l + ja, &height, &zero, buffer + reached, &rows,
           1, 1);
  const int* r = v.rows + v.pi[d] + ja;
  const int first_column = v.super[s], target_height = v.height(s);
  for (int j = 0; j < reached; ++j) {
    double* t = target + static_cast<size_t>(r[j] - first_column) * static_cast<size_t>(target_height);
    const double* cj = buffer + static_cast<size_t>(j) * static_cast<size_t>(rows);
    for (int i = j; i < rows; ++i) t[relative[r[i]]] += sign * cj[i];
  }
}

void SupernodalFactorisation::sum_updates(const cholmod_factor& f, int s, int part, double* into, Workspace& work) const {
  const View v(f);
  for (int k = 0; k < v.height(s); ++k) work.relative[static_cast<size_t>(v.rows[v.pi[s] + k])] = k;
  for (uint32_t k = update_begin_[static_cast<size_t>(s)]; k < update_begin_[static_cast<size_t>(s) + 1]; ++k) {
    const Update& u = updates_[k];
    if (part_[static_cast<size_t>(u.from)] == part)
      apply(f, s, u, u.first, u.end, into, 1.0, work.update.data(), work.relative.data());
  }
}

void SupernodalFactorisation::assemble(const cholmod_factor& f, int s, const double* values, double* l) const {
  const View v(f);
  const size_t size = static_cast<size_t>(v.height(s)) * static_cast<size_t>(v.columns(s));
  std::fill(l, l + size, 0.0);
  for (uint32_t k = entry_begin_[static_cast<size_t>(s)]; k < entry_begin_[static_cast<size_t>(s) + 1]; ++k)
    l[entries_[k].second] += values[entries_[k].first];
  if (part_[static_cast<size_t>(s)] >= 0) return;
  for (int p = 0; p < kParts; ++p) {
    const size_t at = sum_at(p, s);
    if (at == SIZE_MAX) continue;
    const double* sum = sums_.data() + at;
    for (size_t k = 0; k < size; ++k) l[k] -= sum[k];
  }
}

int SupernodalFactorisation::supernode(cholmod_factor& f, int s, const double* values, Workspace& work) {
  const View v(f);
  const int columns = v.columns(s), height = v.height(s), below = height - columns;
  double* l = static_cast<double*>(f.x) + v.px[s];
  assemble(f, s, values, l);
  const int part = part_[static_cast<size_t>(s)];
  for (int k = 0; k < height; ++k) work.relative[static_cast<size_t>(v.rows[v.pi[s] + k])] = k;
  for (uint32_t k = update_begin_[static_cast<size_t>(s)]; k < update_begin_[static_cast<size_t>(s) + 1]; ++k) {
    const Update& u = updates_[k];
    if (part_[static_cast<size_t>(u.from)] == part)
      apply(f, s, u, u.first, u.end, l, -1.0, work.update.data(), work.relative.data());
  }
  int info = 0;
  dpotrf_("L", &columns, l, &height, &info, 1);
  if (info != 0) return v.super[s] + info - 1;
  if (below > 0) {
    const double one = 1;
    dtrsm_("R", "L", "T", "N", &below, &columns, &one, l, &height, l + columns, &height, 1, 1, 1, 1);
  }
  std::copy(l, l + static_cast<size_t>(height) * static_cast<size_t>(columns), single_.begin() + v.px[s]);
  return -1;
}

bool SupernodalFactorisation::tiled(int s) const { return View(*factor_).columns(s) >= kTiled; }

int SupernodalFactorisation::tiled_supernode(cholmod_factor& f, int s, const double* values, int threads) {
  const View v(f);
  const int columns = v.columns(s), height = v.height(s), tiles = (columns + kTile - 1) / kTile;
  double* l = static_cast<double*>(f.x) + v.px[s];
  assemble(f, s, values, l);
  int* relative = work_[0].relative.data();
  for (int k = 0; k < height; ++k) relative[v.rows[v.pi[s] + k]] = k;
  const auto at = [&](int row, int column) { return l + static_cast<size_t>(column) * static_cast<size_t>(height) + row; };
  int failed = -1;
#pragma omp parallel num_threads(std::max(1, std::min(threads, kParts)))
  {
    double* buffer = work_[static_cast<size_t>(omp_get_thread_num())].update.data();
    // The updates of the top's supernodes below (the parts' are summed in already), tile by tile of
    // s's columns, each tile's in the updates' order.
#pragma omp for schedule(dynamic, 1)
    for (int t = 0; t < tiles; ++t) {
      const int c0 = v.super[s] + t * kTile, c1 = std::min(v.super[s + 1], c0 + kTile);
      for (uint32_t k = update_begin_[static_cast<size_t>(s)]; k < update_begin_[static_cast<size_t>(s) + 1]; ++k) {
        const Update& u = updates_[k];
        if (part_[static_cast<size_t>(u.from)] >= 0) continue;
        const int* r = v.rows + v.pi[u.from];
        const int ja = static_cast<int>(std::lower_bound(r + u.first, r + u.end, c0) - r);
        const int jb = static_cast<int>(std::lower_bound(r + ja, r + u.end, c1) - r);
        if (ja < jb) apply(f, s, u, ja, jb, l, -1.0, buffer, relative);
      }
    }
    for (int t = 0; t < tiles; ++t) {
      const int k0 = t * kTile, kc = std::min(kTile, columns - k0), k1 = k0 + kc;
#pragma omp single
      {
        int info = 0;
        dpotrf_("L", &kc, at(k0, k0), &height, &info, 1);
        if (info != 0) failed = v.super[s] + k0 + info - 1;
        // The next steps' tasks: each tile to the right, its diagonal block and its rows below in blocks.
        tasks_.clear();
        for (int j0 = k1; j0 < columns; j0 += kTile)
          for (int r0 = j0; r0 < height; r0 += r0 == j0 ? std::min(kTile, columns - j0) : kRows) tasks_.emplace_back(j0, r0);
      }
      if (failed >= 0) break;
      const int below = height - k1, blocks = (below + kRows - 1) / kRows;
#pragma omp for schedule(dynamic, 1)
      for (int b = 0; b < blocks; ++b) {
        const int r0 = k1 + b * kRows, rows = std::min(kRows, height - r0);
        const double one = 1;
        dtrsm_("R", "L", "T", "N", &rows, &kc, &one, at(k0, k0), &height, at(r0, k0), &height, 1, 1, 1, 1);
      }
#pragma omp for schedule(dynamic, 1)
      for (size_t k = 0; k < tasks_.size(); ++k) {
        const auto [j0, r0] = tasks_[k];
        const int jc = std::min(kTile, columns - j0);
        const double minus = -1, one = 1;
        if (r0 == j0) {
          dsyrk_("L", "N", &jc, &kc, &minus, at(j0, k0), &height, &one, at(j0, j0), &height, 1, 1);
        } else {
          const int rows = std::min(kRows, height - r0);
          dgemm_("N", "T", &rows, &jc, &kc, &minus, at(r0, k0), &height, at(j0, k0), &height, &one, at(r0, j0), &height,
                 1, 1);
        }
      }
    }
  }
  if (failed >= 0) return failed;
  std::copy(l, l + static_cast<size_t>(height) * static_cast<size_t>(columns), single_.begin() + v.px[s]);
  return -1;
}

bool SupernodalFactorisation::factorise(cholmod_factor& f, const double* values, int threads) {
  std::array<int, kParts> failed;  // per part: the column it failed at, or -1
  failed.fill(-1);
  std::fill(sums_.begin(), sums_.end(), 0.0);
#pragma omp parallel for num_threads(std::max(1, std::min(threads, kParts))) schedule(static, 1)
  for (int p = 0; p < kParts; ++p) {
    Workspace& work = work_[static_cast<size_t>(p)];
    for (const int s : part_nodes_[static_cast<size_t>(p)])
      if ((failed[static_cast<size_t>(p)] = supernode(f, s, values, work)) >= 0) break;
    if (failed[static_cast<size_t>(p)] < 0)
      for (const int s : top_nodes_) {
        const size_t at = sum_at(p, s);
        if (at != SIZE_MAX) sum_updates(f, s, p, sums_.data() + at, work);
      }
  }
  // The matrix not positive definite: f.minor = the first part's column that failed.
  for (const int column : failed)
    if (column >= 0) {
      f.minor = static_cast<size_t>(column);
      return false;
    }
  for (const int s : top_nodes_)
    if (const int column = tiled(s) ? tiled_supernode(f, s, values, threads) : supernode(f, s, values, work_[0]);
        column >= 0) {
      f.minor = static_cast<size_t>(column);
      return false;
    }
  f.minor = f.n;
  return true;
}


using FloatBlock = Eigen::Map<const Eigen::MatrixXf, 0, Eigen::OuterStride<>>;

void SupernodalFactorisation::forward(int s, float* y, float* carried, float* gather) const {
  const View v(*factor_);
  const int k1 = v.super[s], columns = v.columns(s), height = v.height(s), below = height - columns;
  const float* l = single_.data() + v.px[s];
  Eigen::Map<Eigen::VectorXf> ys(y + k1, columns);
  FloatBlock(l, columns, columns, Eigen::OuterStride<>(height)).triangularView<Eigen::Lower>().solveInPlace(ys);
  if (below == 0) return;
  Eigen::Map<Eigen::VectorXf> t(gather, below);
  t.noalias() = FloatBlock(l + columns, below, columns, Eigen::OuterStride<>(height)) * ys;
  const int* r = v.rows + v.pi[s] + columns;
  for (int i = 0; i < below; ++i) {
    if (carried && top_row_[static_cast<size_t>(r[i])]) carried[r[i]] += t[i];
    else y[r[i]] -= t[i];
  }
}

void SupernodalFactorisation::backward(int s, float* y, float* gather) const {
  const View v(*factor_);
  const int k1 = v.super[s], columns = v.columns(s), height = v.height(s), below = height - columns;
  const float* l = single_.data() + v.px[s];
  Eigen::Map<Eigen::VectorXf> ys(y + k1, columns);
  if (below > 0) {
    const int* r = v.rows + v.pi[s] + columns;
    for (int i = 0; i < below; ++i) gather[i] = y[r[i]];
    ys.noalias() -= FloatBlock(l + columns, below, columns, Eigen::OuterStride<>(height)).transpose() *
                    Eigen::Map<const Eigen::VectorXf>(gather, below);
  }
  FloatBlock(l, columns, columns, Eigen::OuterStride<>(height)).transpose().triangularView<Eigen::Upper>().solveInPlace(ys);
}

// Forward (L y = P b): each part on its own, its updates to the top's rows carried apart and
// subtracted part by part before the top's supernodes; back (L^T z = y): the top first, then each
// part on its own (reading only its own rows and the top's). x = P^T z.
void SupernodalFactorisation::solve(const double* b, double* x, int threads) {
  const int* perm = static_cast<const int*>(factor_->Perm);
  float* y = y_.data();
  for (int k = 0; k < n_; ++k) y[k] = static_cast<float>(b[perm[k]]);
  const int team = std::max(1, std::min(threads, kParts));
#pragma omp parallel for num_threads(team) schedule(static, 1)
  for (int p = 0; p < kParts; ++p) {
    Workspace& work = work_[static_cast<size_t>(p)];
    for (const int r : top_rows_) work.carried[static_cast<size_t>(r)] = 0.0f;
    for (const int s : part_nodes_[static_cast<size_t>(p)]) forward(s, y, work.carried.data(), work.gather.data());
  }
  for (const int r : top_rows_)
    for (const Workspace& work : work_) y[r] -= work.carried[static_cast<size_t>(r)];
  for (const int s : top_nodes_) forward(s, y, nullptr, work_[0].gather.data());
  for (auto s = top_nodes_.rbegin(); s != top_nodes_.rend(); ++s) backward(*s, y, work_[0].gather.data());
#pragma omp parallel for num_threads(team) schedule(static, 1)
  for (int p = 0; p < kParts; ++p) {
    Workspace& work = work_[static_cast<size_t>(p)];
    const std::vector<int>& nodes = part_nodes_[static_cast<size_t>(p)];
    for (auto s = nodes.rbegin(); s != nodes.rend(); ++s) backward(*s, y, work.gather.data());
  }
  for (int k = 0; k < n_; ++k) x[perm[k]] = static_cast<double>(y[k]);
}

}  // namespace drape::sim
