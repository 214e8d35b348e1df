// Vassilev's support springs (drape/soft_body.hpp, docs/soft-body.md).
#include "drape/soft_body.hpp"

#include <Eigen/Sparse>
#include <Eigen/SparseCholesky>
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

constexpr double kConverged = 1e-5;  // N: the largest force left on a soft vertex

// A spring's Hessian from its length l, rest length L and unit direction u, kept positive
// semi-definite: k u u^T, plus k (1 - L / l) (I - u u^T) while it is stretched.
Mat3 spring_hessian(double k, double l, double L, const Vec3& u) {
  const Mat3 uu = u * u.transpose();
  Mat3 h = k * uu;
  if (l > L && l > 0) h += k * (1.0 - L / l) * (Mat3::Identity() - uu);
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

SoftSolve solve_soft_body(const SoftBody& soft, std::span<const Vec3f> forces, std::span<const Vec3f> start) {
  const size_t n = soft.rest.size();
  SoftSolve out;
  // Positions in double through the solve: the collective term multiplies a region's summed
  // length change by a large K, and float positions would leave its force at a few 1e-4 N.
  std::vector<Vec3> x(n);
  for (size_t v = 0; v < n; ++v) x[v] = (start.size() == n && soft.region_of[v] >= 0 ? start[v] : soft.rest[v]).cast<double>();
  std::vector<int> index(n, -1);
  std::vector<uint32_t> vertex;
  for (size_t v = 0; v < n; ++v)
    if (soft.region_of[v] >= 0) {
      index[v] = static_cast<int>(vertex.size());
      vertex.push_back(static_cast<uint32_t>(v));
    }
  const size_t m = vertex.size();
  const auto finish = [&] {
    out.positions.resize(n);
    for (size_t v = 0; v < n; ++v) out.positions[v] = soft.region_of[v] >= 0 ? Vec3f(x[v].cast<float>()) : soft.rest[v];
    out.regions = soft_region_states(soft, out.positions);
    return out;
  };
  if (m == 0) return finish();
  const double K = soft.collective, C = soft.options.individual;
  const double k_membrane = soft.options.membrane;
  const size_t regions = soft.regions.size();
  const auto force = [&](uint32_t v) -> Vec3 { return v < forces.size() ? Vec3(forces[v].cast<double>()) : Vec3(Vec3::Zero()); };
  // Each support spring's direction (the rest normal) and rest length. Its length is measured
  // along that direction: a spring perpendicular to the surface, as the paper has it, whose
  // energy stays convex however deep the press (measured point to point, a vertex pushed past its
  // frame point would find the spring's rest length again on the other side).
  std::vector<double> rest_length(n, 0.0);
  std::vector<Vec3> normal(n, Vec3::Zero());
  for (uint32_t v : vertex) {
    const Vec3 d = soft.rest[v].cast<double>() - soft.frame[v].cast<double>();
    rest_length[v] = d.norm();
    normal[v] = d / std::max(rest_length[v], 1e-12);
  }
  // The tissue's resistance to sliding along the skin, per unit c_i: the support springs hold a
  // vertex only along their direction, the membrane only where it is stretched.
  const double k_shear = soft.options.shear * K * C;
  std::vector<double> edge_rest(soft.edges.size());
  for (size_t k = 0; k < soft.edges.size(); ++k)
    edge_rest[k] = (soft.rest[soft.edges[k][0]].cast<double>() - soft.rest[soft.edges[k][1]].cast<double>()).norm();

  // Per region: dl_tot = sum c_i (l_i - l_i^0).
  const auto energy_of = [&](const std::vector<Vec3>& p, std::vector<double>* dl_tot) {
    double e = 0;
    std::vector<double> tot(regions, 0.0);
    for (uint32_t v : vertex) {
      const double dl = (p[v] - soft.frame[v].cast<double>()).dot(normal[v]) - rest_length[v];
      tot[static_cast<size_t>(soft.region_of[v])] += soft.weight[v] * dl;
      e += 0.5 * K * C * soft.weight[v] * dl * dl;
      const Vec3 moved = p[v] - soft.rest[v].cast<double>();
      e += 0.5 * k_shear * soft.weight[v] * (moved - moved.dot(normal[v]) * normal[v]).squaredNorm();
      e -= force(v).dot(moved);
    }
    for (double t : tot) e += 0.5 * K * t * t;
    for (size_t k = 0; k < soft.edges.size(); ++k) {
      const auto [a, b] = soft.edges[k];
      const double d = (p[a] - p[b]).norm() - edge_rest[k];
      e += 0.5 * k_membrane * d * d;
    }
    if (dl_tot) *dl_tot = std::move(tot);
    return e;
  };

  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> solver;
  bool analysed = false, factored = false;
  double last_residual = std::numeric_limits<double>::infinity();
  std::vector<double> dl_tot;
  double energy = energy_of(x, &dl_tot);
  std::vector<Eigen::Triplet<double>> triplets;
  for (int iteration = 0; iteration < 80; ++iteration) {
    Eigen::VectorXd gradient = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(3 * m));
    std::vector<Eigen::VectorXd> collective(regions, Eigen::VectorXd::Zero(static_cast<Eigen::Index>(3 * m)));
    triplets.clear();
    const auto add_block = [&](int i, int j, const Mat3& h) {
      for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c) triplets.emplace_back(3 * i + r, 3 * j + c, h(r, c));
    };
    for (size_t s = 0; s < m; ++s) {
      const uint32_t v = vertex[s];
      const auto r = static_cast<size_t>(soft.region_of[v]);
      const Vec3& u = normal[v];
      const double c = soft.weight[v];
      const double dl = (x[v] - soft.frame[v].cast<double>()).dot(u) - rest_length[v];
      const auto at = static_cast<Eigen::Index>(3 * s);
      // Eq. 6 (its negative: the energy's gradient) and the applied force.
      gradient.segment<3>(at) += c * K * (dl_tot[r] + C * dl) * u - force(v);
      collective[r].segment<3>(at) = c * u;
      const Vec3 moved = x[v] - soft.rest[v].cast<double>();
      const Mat3 tangent = Mat3::Identity() - normal[v] * normal[v].transpose();
      gradient.segment<3>(at) += k_shear * c * (tangent * moved);
      add_block(static_cast<int>(s), static_cast<int>(s), K * C * c * u * u.transpose() + k_shear * c * tangent);
    }
    for (size_t k = 0; k < soft.edges.size(); ++k) {
      const auto [a, b] = soft.edges[k];
      const Vec3 d = x[a] - x[b];
      const double l = std::max(d.norm(), 1e-12);
      const Vec3 u = d / l;
      const Vec3 f = k_membrane * (l - edge_rest[k]) * u;  // the gradient with respect to a
      const Mat3 h = spring_hessian(k_membrane, l, edge_rest[k], u);
      const int ia = index[a], ib = index[b];
      if (ia >= 0) {
        gradient.segment<3>(3 * ia) += f;
        add_block(ia, ia, h);
      }
      if (ib >= 0) {
        gradient.segment<3>(3 * ib) -= f;
        add_block(ib, ib, h);
      }
      if (ia >= 0 && ib >= 0) {
        add_block(ia, ib, -h);
        add_block(ib, ia, -h);
      }
    }
    double largest = 0;
    for (size_t s = 0; s < m; ++s) largest = std::max(largest, gradient.segment<3>(static_cast<Eigen::Index>(3 * s)).norm());
    out.residual_n = largest;
    if (largest < kConverged) break;

    // The factorisation is most of a Newton iteration's cost: it is kept while full steps go on
    // cutting the residual by 30 % or more (the Hessian changes little near the rest; with the
    // compressed springs' negative curvature left out, fresh ones converge linearly too, about
    // halving it), and made anew otherwise.
    const bool refactor = !factored || largest > 0.7 * last_residual;
    last_residual = largest;
    if (refactor) {
      Eigen::SparseMatrix<double> H(static_cast<Eigen::Index>(3 * m), static_cast<Eigen::Index>(3 * m));
      H.setFromTriplets(triplets.begin(), triplets.end());
      if (!analysed) {
        solver.analyzePattern(H);
        analysed = true;
      }
      solver.factorize(H);
      if (solver.info() != Eigen::Success) break;
      factored = true;
      ++out.factorisations;
    }
    // (H + K A A^T)^-1 g by Woodbury's identity, A holding one column per region (a few: the
    // products are taken column by column).
    const Eigen::VectorXd hg = solver.solve(gradient);
    std::vector<Eigen::VectorXd> ha(regions);
    for (size_t r = 0; r < regions; ++r) ha[r] = solver.solve(collective[r]);
    Eigen::MatrixXd small(static_cast<Eigen::Index>(regions), static_cast<Eigen::Index>(regions));
    Eigen::VectorXd rhs(static_cast<Eigen::Index>(regions));
    for (size_t i = 0; i < regions; ++i) {
      const auto a = static_cast<Eigen::Index>(i);
      for (size_t j = 0; j < regions; ++j) small(a, static_cast<Eigen::Index>(j)) = collective[i].dot(ha[j]);
      small(a, a) += 1.0 / K;
      rhs(a) = collective[i].dot(hg);
    }
    const Eigen::VectorXd y = small.ldlt().solve(rhs);
    Eigen::VectorXd step = -hg;
    for (size_t r = 0; r < regions; ++r) step += y(static_cast<Eigen::Index>(r)) * ha[r];

    // Backtracking on the energy.
    std::vector<Vec3> trial = x;
    double alpha = 1.0, trial_energy = energy;
    std::vector<double> trial_tot;
    bool lower = false;
    for (int tries = 0; tries < 30; ++tries) {
      for (size_t s = 0; s < m; ++s) trial[vertex[s]] = x[vertex[s]] + alpha * step.segment<3>(static_cast<Eigen::Index>(3 * s));
      trial_energy = energy_of(trial, &trial_tot);
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
    x.swap(trial);
    dl_tot.swap(trial_tot);
    energy = trial_energy;
  }
  return finish();
}

}  // namespace drape
