// A cloth-like sparse matrix for the factorisation's tests and benchmark (bench_factorise), and
// CHOLMOD's view of it.
#pragma once

#include <cholmod.h>

#include <Eigen/Sparse>
#include <cstdint>
#include <random>
#include <vector>

namespace drape::test {

using Sparse = Eigen::SparseMatrix<double, Eigen::ColMajor, int>;

// A cloth-like matrix: a grid of side x side particles, 3 unknowns each, a mass on the diagonal
// and a spring's stiffness k (I + u u^T) between neighbours, diagonals included (both triangles
// stored, as the implicit solver stores its Hessian).
inline Sparse grid_matrix(int side, uint32_t seed) {
  std::mt19937 random(seed);
  std::uniform_real_distribution<double> stiffness(10.0, 1000.0), component(-1.0, 1.0);
  const int n = side * side;
  std::vector<Eigen::Triplet<double>> t;
  const auto couple = [&](int a, int b) {
    Eigen::Vector3d u(component(random), component(random), component(random));
    u.normalize();
    const Eigen::Matrix3d block = stiffness(random) * (Eigen::Matrix3d::Identity() + u * u.transpose());
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) {
        t.emplace_back(3 * a + i, 3 * a + j, block(i, j));
        t.emplace_back(3 * b + i, 3 * b + j, block(i, j));
        t.emplace_back(3 * a + i, 3 * b + j, -block(i, j));
        t.emplace_back(3 * b + i, 3 * a + j, -block(i, j));
      }
  };
  for (int y = 0; y < side; ++y)
    for (int x = 0; x < side; ++x) {
      const int p = y * side + x;
      for (int i = 0; i < 3; ++i) t.emplace_back(3 * p + i, 3 * p + i, 1.0);
      if (x + 1 < side) couple(p, p + 1);
      if (y + 1 < side) couple(p, p + side);
      if (x + 1 < side && y + 1 < side) couple(p, p + side + 1);
      if (x > 0 && y + 1 < side) couple(p, p + side - 1);
    }
  Sparse a(3 * n, 3 * n);
  a.setFromTriplets(t.begin(), t.end());
  a.makeCompressed();
  return a;
}

// CHOLMOD's view of a's lower triangle (a's own storage), for its supernodal analysis.
inline cholmod_sparse lower_view(Sparse& a) {
  cholmod_sparse view{};
  view.nrow = view.ncol = static_cast<size_t>(a.rows());
  view.nzmax = static_cast<size_t>(a.nonZeros());
  view.p = a.outerIndexPtr();
  view.i = a.innerIndexPtr();
  view.x = a.valuePtr();
  view.stype = -1;  // the lower triangle
  view.itype = CHOLMOD_INT;
  view.xtype = CHOLMOD_REAL;
  view.dtype = CHOLMOD_DOUBLE;
  view.sorted = view.packed = 1;
  return view;
}

// CHOLMOD started for a supernodal factorisation, quietly.
inline void start_supernodal(cholmod_common& common) {
  cholmod_start(&common);
  common.supernodal = CHOLMOD_SUPERNODAL;
  common.print = 0;
}

}  // namespace drape::test
