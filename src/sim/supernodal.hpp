#pragma once
// The numeric supernodal Cholesky factorisation on CHOLMOD's symbolic analysis, its independent
// subtrees on both cores.
//
// CHOLMOD 3 (Debian 12) factorises supernode after supernode on one thread (its OpenMP regions,
// one per large supernode, cost more than they give on two cores; OpenBLAS's own threads inside the
// factorisation likewise, and change its rounding with the thread count: docs/cloth.md). The
// elimination tree of a nested-dissection ordering splits below its top separators into subtrees
// that share nothing: this factorises them side by side. It is written here because no library of
// Debian's does it with results independent of the thread count.
//
// Left-looking, as CHOLMOD's own: a supernode's columns are A's, less the updates of the
// supernodes below it that reach its rows (the BLAS's dsyrk and dgemm on their dense blocks),
// then dpotrf on its diagonal block and dtrsm on the rows below. The supernodes are dealt into
// kParts parts (whole subtrees, balanced by their flops) and the top (the separators above them):
// each part is factorised on its own, with the sum of its updates to each top supernode; then the
// top, in order, each top supernode taking the parts' sums in part order. The parts are fixed by
// the pattern, so the arithmetic, and the factor to the bit, are the same on any number of threads.
//
// The top's large supernodes (the separators at the root, dense blocks hundreds of columns wide)
// are factorised in tiles of kTile columns, right-looking: a tile's dpotrf on one thread, then the
// dtrsm of the rows below it and the updates of the tiles to its right spread over both threads.
// The tiles, too, are fixed by the pattern: the same arithmetic on any number of threads.
#include <cholmod.h>

#include <array>
#include <cstddef>
#include <cstdint>
#include <utility>
#include <vector>

namespace drape::sim {

class SupernodalFactorisation {
 public:
  static constexpr int kParts = 2;
  // The top's supernodes of at least kTiled columns are factorised in tiles of kTile columns, their
  // rows below in blocks of kRows.
  static constexpr int kTile = 64, kTiled = 2 * kTile, kRows = 128;

  // Prepares for a supernodal LL^T symbolic factor `f` of the n x n symmetric matrix whose
  // compressed columns are (outer, inner) (both triangles or the lower one: entries above the
  // diagonal are not read). False where `f` is not such a factor (its rows unsorted).
  bool analyse(const cholmod_factor& f, const int* outer, const int* inner);
  bool ready() const { return ready_; }
  void clear() { ready_ = false; }

  // f's values = the factor of the matrix with these values (in the pattern given to analyse);
  // f must be the factor analysed, its values allocated. False where the matrix is not positive
  // definite (f->minor = the first column it failed at). `threads` 1 runs everything on the caller.
  bool factorise(cholmod_factor& f, const double* values, int threads);

  // x = A^-1 b with the last factorisation's values rounded to single precision (b and x of
  // length n, permuted here; they may not overlap), each part's supernodes on their own thread.
  // The factor is a preconditioner and gives Newton's directions, neither of which needs more than
  // single precision, and a triangular solve is bound by reading the factor: half the bytes.
  void solve(const double* b, double* x, int threads);

  // The share of the flops in the top (outside the parts): the tests check it is a minority.
  double top_share() const { return top_share_; }
  // How many of the top's supernodes are factorised in tiles.
  int tiled_supernodes() const { return tiled_; }

 private:
  struct Update {
    int from, first, end;  // the supernode below, and the range of its rows in this one's columns
  };
  struct Workspace {
    std::vector<int> relative;  // a row's position in the supernode being factorised
    std::vector<double> update;
    std::vector<float> gather, carried;  // the solves': rows below a supernode; updates to the top's rows
  };
  // Factorises supernode s into its block of f's values: -1, or the column where dpotrf found the
  // matrix not positive definite.
  int supernode(cholmod_factor& f, int s, const double* values, Workspace& work);
  // The same for a top supernode of at least kTiled columns, in tiles on `threads` threads.
  int tiled_supernode(cholmod_factor& f, int s, const double* values, int threads);
  // Whether supernode s (of the top) is factorised in tiles.
  bool tiled(int s) const;
  // A's entries in s's columns, less the parts' sums of updates to it (a top supernode), into l.
  void assemble(const cholmod_factor& f, int s, const double* values, double* l) const;
  // The updates of part's supernodes to the top supernode s, summed into `into` (s's block's shape).
  void sum_updates(const cholmod_factor& f, int s, int part, double* into, Workspace& work) const;
  // target += sign * (update u to supernode s), on s's rows (`relative` set for s), for the rows of
  // u's supernode from ja and the columns of s its rows ja to jb reach (u.first <= ja < jb <= u.end).
  void apply(const cholmod_factor& f, int s, const Update& u, int ja, int jb, double* target, double sign,
             double* buffer, const int* relative) const;

  bool ready_ = false;
  int n_ = 0, nsuper_ = 0;
  double top_share_ = 0;
  int tiled_ = 0;
  std::vector<int> part_;                    // per supernode: its part, or -1 (the top)
  std::vector<std::vector<int>> part_nodes_;  // per part: its supernodes in order
  std::vector<int> top_nodes_;
  std::vector<uint32_t> update_begin_;  // per supernode: its updates (from the supernodes below, in order)
  std::vector<Update> updates_;
  std::vector<uint32_t> entry_begin_;  // per supernode: A's lower entries in its columns
  std::vector<std::pair<uint32_t, uint32_t>> entries_;  // (index in A's values, index in its block)
  std::vector<size_t> sum_offset_;     // per (part, top supernode): its sum of updates in sums_
  size_t sum_at(int part, int s) const {  // where part's sum for s starts in sums_, or SIZE_MAX
    return sum_offset_[static_cast<size_t>(part) * static_cast<size_t>(nsuper_) + static_cast<size_t>(s)];
  }
  std::vector<double> sums_;
  std::vector<Workspace> work_;
  std::vector<std::array<uint32_t, 3>> placed_;  // analyse's: A's entries (supernode, value, block index)
  std::vector<float> single_;  // the factor's values rounded, supernode by supernode as they are made
  std::vector<float> y_;       // the solves' permuted right-hand side and solution
  std::vector<std::pair<int, int>> tasks_;  // a tiled supernode's updates of a step: (tile, first row)
  std::vector<char> top_row_;  // per row: a top supernode's
  std::vector<int> top_rows_;
  void forward(int s, float* y, float* carried, float* gather) const;
  void backward(int s, float* y, float* gather) const;
  const cholmod_factor* factor_ = nullptr;
};

}  // namespace drape::sim
