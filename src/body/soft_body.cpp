// Vassilev's support springs (drape/soft_body.hpp, docs/soft-body.md).
#include "drape/soft_body.hpp"

#include <Eigen/Sparse>
#include <Eigen/SparseCholesky>
#include <array>
#include <algorithm>
#include <cmath>
#include <limits>
#include <map>

namespace drape {
namespace {

// Distance of a point along the segment a-b, as a fraction of its length.
float along(const Vec3f& p, const Vec3f& a, const Vec3f& b) {
  const Vec3f d = b - a;
  return d.squaredNorm() > 0 ? (p - a).dot(d) / d.squaredNorm() : 0.0f;
}

using Mat3 = Eigen::Matrix3d;
using Vec3 = Eigen::Vector3d;


// A spring's Hessian from its length l, rest length L and unit direction u: k u u^T + k (1 - L / l)
// (I - u u^T). Compressed (l < L) the second term is negative, and `compressed` is the share of it
// kept (0: the block is positive semi-definite on its own).
Mat3 spring_hessian(double k, double l, double L, const Vec3& u, double compressed = 0.0) {
  const Mat3 uu = u * u.transpose();
  Mat3 h = k * uu;
  if (l > 0) h += (l > L ? 1.0 : compressed) * k * (1.0 - L / l) * (Mat3::Identity() - uu);
  return h;
}

}  // namespace

size_t SoftBody::soft_count() const {
  return static_cast<size_t>(std::count_if(region_of.begin(), region_of.end(), [](int r) { return r >= 0; }));
}

SoftBody make_soft_body(const Mesh& mesh, std::span<const int> labels, const std::vector<std::string>& names,
                        const SoftBodyOptions& options) {
  SoftBody soft;
  soft.options = options;
  const size_t n = mesh.positions.size();
  soft.rest = mesh.positions;
  soft.region_of.assign(n, -1);
  soft.frame = soft.rest;
  soft.weight.assign(n, 0.0f);
  soft.area.assign(n, 0.0f);
  const std::vector<Vec3f> normals = vertex_normals(mesh.positions, mesh.triangles);
  for (const Tri& t : mesh.triangles) {
    const float a = 0.5f * (mesh.positions[t[1]] - mesh.positions[t[0]]).cross(mesh.positions[t[2]] - mesh.positions[t[0]]).norm();
    for (uint32_t v : t) soft.area[v] += a / 3.0f;
  }
  // Regions in the order of `names`, without the empty ones.
  std::vector<int> renumber(names.size(), -1);
  for (size_t v = 0; v < n && v < labels.size(); ++v) {
    const int label = labels[v];
    if (label < 0 || static_cast<size_t>(label) >= names.size()) continue;
    if (renumber[static_cast<size_t>(label)] < 0) renumber[static_cast<size_t>(label)] = 0;
  }
  for (size_t k = 0; k < names.size(); ++k)
    if (renumber[k] >= 0) {
      renumber[k] = static_cast<int>(soft.regions.size());
      soft.regions.push_back({names[k], {}});
    }
  double area_sum = 0;
  for (size_t v = 0; v < n && v < labels.size(); ++v) {
    const int label = labels[v];
    if (label < 0 || static_cast<size_t>(label) >= names.size()) continue;
    const int r = renumber[static_cast<size_t>(label)];
    soft.region_of[v] = r;
    soft.regions[static_cast<size_t>(r)].vertices.push_back(static_cast<uint32_t>(v));
    soft.frame[v] = mesh.positions[v] - options.depth * normals[v];
    area_sum += soft.area[v];
  }
  const size_t count = soft.soft_count();
  const double mean_area = count ? area_sum / static_cast<double>(count) : 1.0;
  for (size_t v = 0; v < n; ++v)
    if (soft.region_of[v] >= 0) soft.weight[v] = static_cast<float>(soft.area[v] / mean_area);
  // K C c_i = tissue stiffness x the vertex's area.
  soft.collective = static_cast<float>(options.tissue_stiffness * mean_area / options.individual);

  std::map<std::pair<uint32_t, uint32_t>, bool> seen;
  for (const Tri& t : mesh.triangles)
    for (int k = 0; k < 3; ++k) {
      const uint32_t a = t[static_cast<size_t>(k)], b = t[static_cast<size_t>((k + 1) % 3)];
      if (soft.region_of[a] < 0 && soft.region_of[b] < 0) continue;
      if (!seen.emplace(std::pair{std::min(a, b), std::max(a, b)}, true).second) continue;
      soft.edges.push_back({std::min(a, b), std::max(a, b)});
      soft.edge_rest.push_back((mesh.positions[a] - mesh.positions[b]).norm());
    }
  return soft;
}

SoftBody make_soft_body(const Body& body, const SoftBodyOptions& options) {
  const Mesh& mesh = body.mesh;
  const size_t n = mesh.positions.size();
  const std::vector<Vec3f> normals = vertex_normals(mesh.positions, mesh.triangles);
  // The regions, from the landmarks and the body parts (front is +Z, up +Y).
  const Landmarks& lm = body.landmarks;
  const float bust_y = 0.5f * (lm.left_bust.y() + lm.right_bust.y());
  const std::vector<std::string> names{"belly", "buttocks", "left_thigh", "right_thigh", "bust", "left_upper_arm", "right_upper_arm"};
  std::vector<int> labels(n, -1);
  const bool parts = body.parts.size() == n;
  for (size_t v = 0; v < n && parts; ++v) {
    const Vec3f& p = mesh.positions[v];
    const Vec3f& nv = normals[v];
    const BodyPart part = body.parts[v];
    int& region = labels[v];
    if (part == BodyPart::Torso && nv.z() > 0.3f && p.y() > lm.hip.y() && p.y() < lm.underbust.y()) {
      region = 0;  // belly: the front between the hips and the bust; its sides (the hip bones) stay
    } else if ((part == BodyPart::Torso || part == BodyPart::LeftLeg || part == BodyPart::RightLeg) && nv.z() < -0.3f &&
               p.y() > lm.crotch.y() - 0.06f && p.y() < lm.hip.y() + 0.06f) {
      region = 1;  // buttocks
    } else if ((part == BodyPart::LeftLeg || part == BodyPart::RightLeg) && p.y() > lm.left_knee.y() + 0.08f &&
               p.y() < lm.crotch.y() && std::abs(nv.x()) < 0.9f) {
      region = part == BodyPart::LeftLeg ? 2 : 3;  // thighs, above the knee
    } else if (part == BodyPart::Torso && nv.z() > 0.3f && p.y() >= lm.underbust.y() && p.y() < bust_y + 0.08f &&
               std::abs(p.x()) > 0.03f) {
      region = 4;  // bust, off the breastbone
    } else if (part == BodyPart::LeftArm || part == BodyPart::RightArm) {
      const bool left = part == BodyPart::LeftArm;
      const float s = along(p, left ? lm.left_shoulder : lm.right_shoulder, left ? lm.left_elbow : lm.right_elbow);
      if (s > 0.25f && s < 0.85f) region = left ? 5 : 6;  // upper arm, off the shoulder and the elbow
    }
  }
  return make_soft_body(mesh, labels, names, options);
}

std::vector<SoftRegionState> soft_region_states(const SoftBody& soft, std::span<const Vec3f> positions) {
  std::vector<SoftRegionState> out;
  for (const SoftRegion& region : soft.regions) {
    SoftRegionState s;
    s.name = region.name;
    s.vertices = region.vertices.size();
    double change = 0, volume = 0;
    for (uint32_t v : region.vertices) {
      // Outward along the rest normal (frame to rest point).
      const Vec3f normal = (soft.rest[v] - soft.frame[v]).normalized();
      const float out_by = (positions[v] - soft.rest[v]).dot(normal);
      change += static_cast<double>(soft.area[v]) * out_by;
      volume += static_cast<double>(soft.area[v]) * soft.options.depth;
      s.compression_m = std::max(s.compression_m, -out_by);
      s.bulge_m = std::max(s.bulge_m, out_by);
    }
    s.volume_change = volume > 0 ? change / volume : 0.0;
    out.push_back(std::move(s));
  }
  return out;
}

struct SoftBodySolver::Impl {
  explicit Impl(const SoftBody& s);
  SoftSolve solve(std::span<const Vec3f> forces, std::span<const Vec3f> start, double tolerance);

  // The energy at `p` (every body vertex), with each region's dl_tot = sum c_i (l_i - l_i^0).
  double energy_of(const std::vector<Vec3>& p, std::span<const Vec3f> forces, std::vector<double>& tot) const;
  // The Hessian's values at x (its pattern fixed), factorised, and the Woodbury terms with it.
  bool factorise();

  struct Edge {
    uint32_t a, b;       // body vertices
    int ia, ib;          // their unknowns' blocks, -1 where the vertex stays put
    double rest;
    int ab = -1, ba = -1;  // the off-diagonal blocks' slots (both ends soft)
  };

  const SoftBody& soft;
  size_t n = 0, m = 0, regions = 0;
  double K = 0, C = 0, k_membrane = 0, k_shear = 0;
  std::vector<uint32_t> vertex;  // soft vertices, in the unknowns' order
  // Per soft vertex (the unknowns' order): its support spring's direction (the rest normal) and
  // rest length, its frame point, rest position, c_i, region and diagonal block's slot. The spring's
  // length is measured along its direction: a spring perpendicular to the surface, as the paper has
  // it, whose energy stays convex however deep the press (measured point to point, a vertex pushed
  // past its frame point would find the spring's rest length again on the other side).
  std::vector<Vec3> normal, frame, rest;
  std::vector<double> rest_length, weight;
  std::vector<int> region, diagonal;
  std::vector<Edge> edges;

  // Slot of block (i, j): the position in H's values of its entry (3i, 3j + c) is at[c], the next
  // two rows following it (the pattern holds whole 3x3 blocks, each column's rows sorted).
  std::vector<std::array<int, 3>> slots;
  Eigen::SparseMatrix<double> H;
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> cholesky;
  bool factored = false;
  // The regions' collective terms K A A^T, A holding one column c_i u_i per region (a rank-one
  // term each, kept out of the sparse factorisation); H^-1 A and (1/K + A^T H^-1 A)^-1 per
  // factorisation, for Woodbury's identity.
  Eigen::MatrixXd A, HA;
  Eigen::LDLT<Eigen::MatrixXd> small;

  std::vector<Vec3> x, trial;  // every body vertex, in double
  std::vector<double> dl_tot, trial_tot;
  std::vector<double> compressed_sum;  // per soft vertex: its compressed springs' negative curvature
  Eigen::VectorXd gradient, step;
};

SoftBodySolver::Impl::Impl(const SoftBody& s) : soft(s) {
  n = soft.rest.size();
  regions = soft.regions.size();
  K = soft.collective;
  C = soft.options.individual;
  k_membrane = soft.options.membrane;
  // The tissue's resistance to sliding along the skin, per unit c_i: the support springs hold a
  // vertex only along their direction, the membrane only where it is stretched.
  k_shear = soft.options.shear * K * C;
  std::vector<int> index(n, -1);
  for (size_t v = 0; v < n; ++v)
    if (soft.region_of[v] >= 0) {
      index[v] = static_cast<int>(vertex.size());
      vertex.push_back(static_cast<uint32_t>(v));
    }
  m = vertex.size();
  for (const uint32_t v : vertex) {
    const Vec3 d = soft.rest[v].cast<double>() - soft.frame[v].cast<double>();
    rest_length.push_back(d.norm());
    normal.push_back(d / std::max(rest_length.back(), 1e-12));
    frame.push_back(soft.frame[v].cast<double>());
    rest.push_back(soft.rest[v].cast<double>());
    weight.push_back(soft.weight[v]);
    region.push_back(soft.region_of[v]);
  }
  for (size_t k = 0; k < soft.edges.size(); ++k) {
    const auto [a, b] = soft.edges[k];
    edges.push_back({a, b, index[a], index[b], (soft.rest[a].cast<double>() - soft.rest[b].cast<double>()).norm()});
  }
  x.resize(n);
  trial.resize(n);
  for (size_t v = 0; v < n; ++v) x[v] = trial[v] = soft.rest[v].cast<double>();
  if (m == 0) return;

  // The pattern: each soft vertex's diagonal block and a block each way per membrane spring
  // between two soft vertices; analysed once.
  const auto rows = static_cast<Eigen::Index>(3 * m);
  std::vector<Eigen::Triplet<double>> pattern;
  const auto add_block = [&](int i, int j) {
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) pattern.emplace_back(3 * i + r, 3 * j + c, 0.0);
  };
  for (size_t i = 0; i < m; ++i) add_block(static_cast<int>(i), static_cast<int>(i));
  for (const Edge& e : edges)
    if (e.ia >= 0 && e.ib >= 0) {
      add_block(e.ia, e.ib);
      add_block(e.ib, e.ia);
    }
  H.resize(rows, rows);
  H.setFromTriplets(pattern.begin(), pattern.end());
  H.makeCompressed();
  const auto slot_of = [&](int i, int j) {
    std::array<int, 3> at{};
    for (int c = 0; c < 3; ++c) {
      const int col = 3 * j + c;
      const int* begin = H.innerIndexPtr() + H.outerIndexPtr()[col];
      const int* end = H.innerIndexPtr() + H.outerIndexPtr()[col + 1];
      at[static_cast<size_t>(c)] = static_cast<int>(std::lower_bound(begin, end, 3 * i) - H.innerIndexPtr());
    }
    slots.push_back(at);
    return static_cast<int>(slots.size() - 1);
  };
  for (size_t i = 0; i < m; ++i) diagonal.push_back(slot_of(static_cast<int>(i), static_cast<int>(i)));
  for (Edge& e : edges)
    if (e.ia >= 0 && e.ib >= 0) {
      e.ab = slot_of(e.ia, e.ib);
      e.ba = slot_of(e.ib, e.ia);
    }
  cholesky.analyzePattern(H);

  A = Eigen::MatrixXd::Zero(rows, static_cast<Eigen::Index>(regions));
  for (size_t i = 0; i < m; ++i)
    A.block<3, 1>(static_cast<Eigen::Index>(3 * i), region[i]) = weight[i] * normal[i];
  gradient.resize(rows);
  step.resize(rows);
  compressed_sum.assign(m, 0.0);
}

double SoftBodySolver::Impl::energy_of(const std::vector<Vec3>& p, std::span<const Vec3f> forces,
                                       std::vector<double>& tot) const {
  double e = 0;
  tot.assign(regions, 0.0);
  for (size_t i = 0; i < m; ++i) {
    const uint32_t v = vertex[i];
    const Vec3& u = normal[i];
    const double dl = (p[v] - frame[i]).dot(u) - rest_length[i];
    tot[static_cast<size_t>(region[i])] += weight[i] * dl;
    e += 0.5 * K * C * weight[i] * dl * dl;
    const Vec3 moved = p[v] - rest[i];
    e += 0.5 * k_shear * weight[i] * (moved - moved.dot(u) * u).squaredNorm();
    if (v < forces.size()) e -= forces[v].cast<double>().dot(moved);
  }
  for (const double t : tot) e += 0.5 * K * t * t;
  for (const Edge& edge : edges) {
    const double d = (p[edge.a] - p[edge.b]).norm() - edge.rest;
    e += 0.5 * k_membrane * d * d;
  }
  return e;
}

bool SoftBodySolver::Impl::factorise() {
  double* values = H.valuePtr();
  std::fill(values, values + H.nonZeros(), 0.0);
  const auto add = [&](int slot, const Mat3& h) {
    const std::array<int, 3>& at = slots[static_cast<size_t>(slot)];
    for (int c = 0; c < 3; ++c)
      for (int r = 0; r < 3; ++r) values[at[static_cast<size_t>(c)] + r] += h(r, c);
  };
  for (size_t i = 0; i < m; ++i) {
    const Vec3& u = normal[i];
    const Mat3 tangent = Mat3::Identity() - u * u.transpose();
    add(diagonal[i], K * C * weight[i] * u * u.transpose() + k_shear * weight[i] * tangent);
  }
  // The membrane's compressed springs have negative curvature across them. Left out, the Hessian
  // is stiffer than the body wherever a press compresses the skin, and Newton's steps fall short by
  // a constant share; kept whole, it is indefinite where they outweigh the tissue's resistance to
  // sliding (the skin buckles), and the factorisation fails. Each spring keeps as much of it as its
  // ends' sliding resistance carries: an edge's term -n (I - u u^T) on x_a - x_b is at least -2 n
  // (I - u u^T) on each end, so ends whose compressed terms sum to at most half their sliding
  // stiffness leave the matrix positive definite.
  std::fill(compressed_sum.begin(), compressed_sum.end(), 0.0);
  for (const Edge& e : edges) {
    const double l = std::max((x[e.a] - x[e.b]).norm(), 1e-12);
    if (l >= e.rest) continue;
    const double negative = k_membrane * (e.rest / l - 1.0);
    if (e.ia >= 0) compressed_sum[static_cast<size_t>(e.ia)] += negative;
    if (e.ib >= 0) compressed_sum[static_cast<size_t>(e.ib)] += negative;
  }
  const auto share = [&](int i) {
    if (i < 0) return 1.0;
    const double sum = compressed_sum[static_cast<size_t>(i)];
    const double carried = 0.5 * k_shear * weight[static_cast<size_t>(i)];
    return sum > carried ? carried / sum : 1.0;
  };
  for (const Edge& e : edges) {
    const Vec3 d = x[e.a] - x[e.b];
    const double l = std::max(d.norm(), 1e-12);
    const Mat3 h = spring_hessian(k_membrane, l, e.rest, d / l, std::min(share(e.ia), share(e.ib)));
    if (e.ia >= 0) add(diagonal[static_cast<size_t>(e.ia)], h);
    if (e.ib >= 0) add(diagonal[static_cast<size_t>(e.ib)], h);
    if (e.ab >= 0) {
      add(e.ab, -h);
      add(e.ba, -h);
    }
  }
  cholesky.factorize(H);
  if (cholesky.info() != Eigen::Success) return false;
  // (H + K A A^T)^-1 by Woodbury's identity: H^-1 - H^-1 A (1/K + A^T H^-1 A)^-1 A^T H^-1.
  HA = cholesky.solve(A);
  Eigen::MatrixXd inner = A.transpose() * HA;
  inner.diagonal().array() += 1.0 / K;
  small.compute(inner);
  return true;
}

SoftSolve SoftBodySolver::Impl::solve(std::span<const Vec3f> forces, std::span<const Vec3f> start, double tolerance) {
  SoftSolve out;
  for (size_t i = 0; i < m; ++i) {
    const uint32_t v = vertex[i];
    x[v] = start.size() == n ? start[v].cast<double>() : rest[i];
  }
  const auto finish = [&] {
    out.positions.resize(n);
    for (size_t v = 0; v < n; ++v) out.positions[v] = soft.region_of[v] >= 0 ? Vec3f(x[v].cast<float>()) : soft.rest[v];
    out.regions = soft_region_states(soft, out.positions);
    return out;
  };
  if (m == 0) return finish();

  double last_residual = std::numeric_limits<double>::infinity();
  double energy = energy_of(x, forces, dl_tot);
  for (int iteration = 0; iteration < 80; ++iteration) {
    // The gradient: eq. 6 (its negative), the sliding and the applied force, then the membrane.
    double largest = 0;
    for (size_t i = 0; i < m; ++i) {
      const uint32_t v = vertex[i];
      const Vec3& u = normal[i];
      const double c = weight[i];
      const double dl = (x[v] - frame[i]).dot(u) - rest_length[i];
      const Vec3 moved = x[v] - rest[i];
      Vec3 g = c * K * (dl_tot[static_cast<size_t>(region[i])] + C * dl) * u + k_shear * c * (moved - moved.dot(u) * u);
      if (v < forces.size()) g -= forces[v].cast<double>();
      gradient.segment<3>(static_cast<Eigen::Index>(3 * i)) = g;
    }
    for (const Edge& e : edges) {
      const Vec3 d = x[e.a] - x[e.b];
      const double l = std::max(d.norm(), 1e-12);
      const Vec3 f = k_membrane * (l - e.rest) / l * d;  // the gradient with respect to a
      if (e.ia >= 0) gradient.segment<3>(3 * e.ia) += f;
      if (e.ib >= 0) gradient.segment<3>(3 * e.ib) -= f;
    }
    for (size_t i = 0; i < m; ++i) largest = std::max(largest, gradient.segment<3>(static_cast<Eigen::Index>(3 * i)).norm());
    out.residual_n = largest;
    if (largest < tolerance) break;

    // The factorisation is most of a Newton iteration's cost: it is kept, from one iteration and
    // one solve to the next, while full steps go on cutting the residual by 30 % or more (the
    // Hessian changes little near the rest; where the compressed springs' negative curvature is
    // cut short, fresh ones converge linearly too), and made anew otherwise.
    const bool refactor = !factored || largest > 0.7 * last_residual;
    last_residual = largest;
    if (refactor) {
      factored = factorise();
      if (!factored) break;
      ++out.factorisations;
    }
    step = -cholesky.solve(gradient);
    step += HA * small.solve(A.transpose() * (-step));

    // Backtracking on the energy.
    double alpha = 1.0, trial_energy = energy;
    bool lower = false;
    for (int tries = 0; tries < 30; ++tries) {
      for (size_t i = 0; i < m; ++i) trial[vertex[i]] = x[vertex[i]] + alpha * step.segment<3>(static_cast<Eigen::Index>(3 * i));
      trial_energy = energy_of(trial, forces, trial_tot);
      lower = trial_energy <= energy;
      if (lower) break;
      alpha *= 0.5;
    }
    ++out.newton_iterations;
    if (!lower && !refactor) {
      factored = false;  // the kept factorisation led nowhere: a fresh one
      continue;
    }
    if (!lower) break;
    if (alpha < 0.75) factored = false;  // a shortened step: the Hessian has moved on
    for (size_t i = 0; i < m; ++i) x[vertex[i]] = trial[vertex[i]];
    dl_tot.swap(trial_tot);
    energy = trial_energy;
  }
  return finish();
}

SoftBodySolver::SoftBodySolver(const SoftBody& soft) : impl_(std::make_unique<Impl>(soft)) {}
SoftBodySolver::~SoftBodySolver() = default;
SoftSolve SoftBodySolver::solve(std::span<const Vec3f> forces, std::span<const Vec3f> start, double tolerance) {
  return impl_->solve(forces, start, tolerance);
}

SoftSolve solve_soft_body(const SoftBody& soft, std::span<const Vec3f> forces, std::span<const Vec3f> start) {
  return SoftBodySolver(soft).solve(forces, start);
}

}  // namespace drape
