// The supernodal factorisation on both cores (src/sim/supernodal.hpp): the factor solves the system
// as CHOLMOD's does, it is the same to the bit on one thread and on two, and a matrix that is not
// positive definite is found out.
#include "sim/supernodal.hpp"

#include "support/grid_matrix.hpp"

#include <gtest/gtest.h>

#include <Eigen/CholmodSupport>
#include <Eigen/Sparse>
#include <cstring>
#include <random>
#include <vector>

namespace drape::sim {
namespace {

using test::grid_matrix;
using test::Sparse;

class Factor {
 public:
  explicit Factor(Sparse& a) {
    test::start_supernodal(common_);
    view_ = test::lower_view(a);
    symbolic_ = cholmod_analyze(&view_, &common_);
  }
  ~Factor() {
    cholmod_free_factor(&symbolic_, &common_);
    cholmod_finish(&common_);
  }
  Factor(const Factor&) = delete;
  Factor& operator=(const Factor&) = delete;

  // CHOLMOD's own factor, or one with SupernodalFactorisation on `threads` threads.
  cholmod_factor* cholmod() {
    cholmod_factor* f = cholmod_copy_factor(symbolic_, &common_);
    cholmod_factorize(&view_, f, &common_);
    return f;
  }
  cholmod_factor* ours(const Sparse& a, int threads, bool* positive = nullptr, double* top = nullptr,
                       int* tiled = nullptr) {
    cholmod_factor* f = cholmod_copy_factor(symbolic_, &common_);
    cholmod_change_factor(CHOLMOD_REAL, true, true, true, true, f, &common_);
    SupernodalFactorisation s;
    EXPECT_TRUE(s.analyse(*f, a.outerIndexPtr(), a.innerIndexPtr()));
    const bool ok = s.factorise(*f, a.valuePtr(), threads);
    if (positive) *positive = ok;
    if (top) *top = s.top_share();
    if (tiled) *tiled = s.tiled_supernodes();
    return f;
  }
  // A^-1 b by the single-precision solves on `threads` threads.
  Eigen::VectorXd solve(const Sparse& a, const Eigen::VectorXd& b, int threads) {
    cholmod_factor* f = cholmod_copy_factor(symbolic_, &common_);
    cholmod_change_factor(CHOLMOD_REAL, true, true, true, true, f, &common_);
    SupernodalFactorisation s;
    EXPECT_TRUE(s.analyse(*f, a.outerIndexPtr(), a.innerIndexPtr()));
    EXPECT_TRUE(s.factorise(*f, a.valuePtr(), threads));
    Eigen::VectorXd x(b.size());
    s.solve(b.data(), x.data(), threads);
    cholmod_free_factor(&f, &common_);
    return x;
  }
  // |A x - b| / |b| for x solved with f.
  double residual(cholmod_factor* f, const Sparse& a) {
    Eigen::VectorXd b = Eigen::VectorXd::LinSpaced(a.rows(), -1.0, 2.0);
    cholmod_dense rhs = Eigen::viewAsCholmod(b);
    cholmod_dense* x = cholmod_solve(CHOLMOD_A, f, &rhs, &common_);
    const Eigen::VectorXd solution = Eigen::Map<Eigen::VectorXd>(static_cast<double*>(x->x), a.rows());
    cholmod_free_dense(&x, &common_);
    const Eigen::VectorXd full = a.selfadjointView<Eigen::Lower>() * solution;
    return (full - b).norm() / b.norm();
  }
  void free(cholmod_factor* f) { cholmod_free_factor(&f, &common_); }
  // The unknown eliminated last (the last column of the top separator).
  int last_eliminated() const { return static_cast<const int*>(symbolic_->Perm)[symbolic_->n - 1]; }

 private:
  cholmod_common common_{};
  cholmod_sparse view_{};
  cholmod_factor* symbolic_ = nullptr;
};

TEST(SupernodalFactorisation, SolvesAsCholmodDoes) {
  for (const int side : {6, 30, 70}) {
    Sparse a = grid_matrix(side, 7u + static_cast<uint32_t>(side));
    Factor factor(a);
    cholmod_factor* theirs = factor.cholmod();
    bool positive = false;
    double top = 1;
    cholmod_factor* ours = factor.ours(a, 2, &positive, &top);
    EXPECT_TRUE(positive);
    EXPECT_EQ(ours->minor, ours->n);
    EXPECT_LT(factor.residual(theirs, a), 1e-12);
    EXPECT_LT(factor.residual(ours, a), 1e-12) << "side " << side;
    if (side >= 30) {
      EXPECT_LT(top, 0.5) << "the subtrees below the top separators should hold most of the work";
    }
    factor.free(theirs);
    factor.free(ours);
  }
}

TEST(SupernodalFactorisation, SameFactorBitForBitOnOneAndTwoThreads) {
  // Large enough for the separators at the top to be factorised in tiles.
  Sparse a = grid_matrix(70, 3u);
  Factor factor(a);
  int tiled = 0;
  cholmod_factor* one = factor.ours(a, 1, nullptr, nullptr, &tiled);
  cholmod_factor* two = factor.ours(a, 2);
  EXPECT_GT(tiled, 0);
  ASSERT_EQ(one->xsize, two->xsize);
  EXPECT_EQ(std::memcmp(one->x, two->x, one->xsize * sizeof(double)), 0);
  EXPECT_LT(factor.residual(two, a), 1e-12);
  factor.free(one);
  factor.free(two);
}

TEST(SupernodalFactorisation, SinglePrecisionSolvesTheSystemAndAreTheSameOnOneAndTwoThreads) {
  Sparse a = grid_matrix(70, 11u);
  Factor factor(a);
  const Eigen::VectorXd b = Eigen::VectorXd::LinSpaced(a.rows(), -1.0, 2.0);
  const Eigen::VectorXd one = factor.solve(a, b, 1), two = factor.solve(a, b, 2);
  EXPECT_EQ(std::memcmp(one.data(), two.data(), static_cast<size_t>(one.size()) * sizeof(double)), 0);
  const Eigen::VectorXd residual = a.selfadjointView<Eigen::Lower>() * two - b;
  // A single-precision factor of this matrix (its stiffest springs 10^3 its masses) leaves ~2e-4.
  EXPECT_LT(residual.norm() / b.norm(), 1e-3);
}

TEST(SupernodalFactorisation, FindsAMatrixThatIsNotPositiveDefinite) {
  Sparse a = grid_matrix(30, 5u);
  // One unknown's diagonal far below what its springs need.
  a.coeffRef(1000, 1000) = -1e6;
  Factor factor(a);
  bool positive = true;
  cholmod_factor* ours = factor.ours(a, 2, &positive);
  EXPECT_FALSE(positive);
  EXPECT_LT(ours->minor, ours->n);
  factor.free(ours);
}

TEST(SupernodalFactorisation, FindsAMatrixThatIsNotPositiveDefiniteInATiledSupernode) {
  Sparse a = grid_matrix(70, 5u);
  Factor factor(a);
  const int last = factor.last_eliminated();
  a.coeffRef(last, last) = -1e6;
  for (const int threads : {1, 2}) {
    bool positive = true;
    int tiled = 0;
    cholmod_factor* ours = factor.ours(a, threads, &positive, nullptr, &tiled);
    EXPECT_GT(tiled, 0);
    EXPECT_FALSE(positive);
    EXPECT_EQ(ours->minor, ours->n - 1) << "the leading minors up to the last column are positive definite";
    factor.free(ours);
  }
}

}  // namespace
}  // namespace drape::sim
