// The skin layer; see drape/skin_layer.hpp and docs/soft-body.md, "The skin layer".
#include "drape/skin_layer.hpp"

#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <vector>

#include "collision/body_surface.hpp"
#include "collision/triangle_bvh.hpp"
#include "drape/soft_body.hpp"
#include "sim/parallel.hpp"

namespace drape {
namespace {

using collision::BodySurface;
using collision::SurfaceHit;
using collision::TriangleBvh;
using Vec3d = Eigen::Vector3d;

// How far from a vertex another part's surface is looked for (m): deeper than an arm is driven into
// the torso by skinning, well under a limb's width.
constexpr float kReach = 0.03f;
// Contacts are kept as candidates up to this much past the gap (m): the solve's moves can close them.
constexpr float kCandidateMargin = 0.005f;
// The contact penalty per contact, over the anchor stiffness of its vertex: two skins pushed 3 cm
// apart end within 0.03 mm of the gap.
constexpr double kContactFactor = 1000.0;
// Rings of mesh neighbours round a contact's vertices that the solve moves, at first: the membrane
// spreads a dent over its neighbours, falling by about e each two or three rings. Where the last ring
// still moves by more than kBoundaryMove, twice as many (at most kMaxRings): the ring beyond, held on
// its reference, would take the membrane's pull that the anchors must carry.
constexpr int kRings = 6;
constexpr int kMaxRings = 48;
constexpr double kBoundaryMove = 1e-6;  // m
constexpr int kMaxActiveSetIterations = 12;
// Rounds of finding the contacts again where the last round left the skin (a vertex pushed past the
// edge of the triangle it met meets the next one).
constexpr int kRounds = 3;
// A vertex the solve moved less than this (m) stays on its reference (the membrane's reach decays
// fast: the rings round a contact move by micrometres).
constexpr float kStill = 1e-5f;

struct Candidate {
  uint32_t vertex = 0;
  std::array<uint32_t, 3> corner{};  // the other part's triangle
  std::array<double, 3> weight{};    // barycentric weights of the contact point
  Vec3d normal = Vec3d::Zero();      // the other part's outward normal there
  double distance = 0;               // signed, along the normal, where it was found
  double base = 0;                   // J u there: the gap at u is distance + J u - base
};

// J u for a contact: the vertex's move against its contact point's, along the normal.
double relative_move(const Candidate& c, const std::vector<Vec3d>& u) {
  Vec3d rel = u[c.vertex];
  for (size_t j = 0; j < 3; ++j) rel -= c.weight[j] * u[c.corner[j]];
  return c.normal.dot(rel);
}
// The contact's gap at u, less the gap kept: < 0 where it is closed.
double gap_at(const Candidate& c, const std::vector<Vec3d>& u, double gap) {
  return c.distance - gap + relative_move(c, u) - c.base;
}

}  // namespace

struct SkinLayer::Impl {
  SkinLayerOptions options;
  std::vector<Vec3f> bind;
  std::vector<Tri> triangles;
  std::vector<uint8_t> part;        // per vertex
  std::vector<double> anchor;       // per vertex: N/m
  std::vector<uint32_t> adjacency_begin, adjacency;  // CSR over the mesh's edges
  // Per body part: its triangles, its surface over every vertex, its tree.
  struct Part {
    std::vector<uint32_t> triangle;  // local -> global
    std::unique_ptr<BodySurface> surface;
    std::unique_ptr<TriangleBvh> tree;
    Eigen::AlignedBox3f box;
  };
  std::array<Part, kBodyPartCount> parts;
  double time = 0;  // the surfaces' pose counter (their velocities are not used)

  // Scratch, kept between calls.
  std::vector<Candidate> slot;       // vertex * kBodyPartCount + other part: solve()'s, frame to frame
  std::vector<uint8_t> slot_used;
  std::vector<Candidate> seen;       // the same, inside()'s
  std::vector<uint8_t> seen_used;
  std::vector<Candidate> candidates;
  std::vector<int> index;            // vertex -> unknown block, -1 when fixed
  std::vector<uint32_t> active_vertices;
  std::vector<uint8_t> closed;

  // u minimising the quadratic with the `closed` candidates' penalty (growing `closed` by those that
  // close on the way); false when the system cannot be factorised.
  bool solve_closed(double gap, std::vector<Vec3d>& u, SkinContactStats& s);

  void pose(std::span<const Vec3f> x) {
    time += 1.0;
    for (Part& p : parts) {
      if (!p.surface) continue;
      p.surface->set_positions(x, time);
      p.tree->update();
      p.box.setEmpty();
      for (uint32_t t : p.triangle)
        for (uint32_t v : triangles[t]) p.box.extend(x[v]);
    }
  }
  // Into into[v * kBodyPartCount + q]: vertex v's nearest point on part q within kReach, away from
  // the joints. `keep(distance)` decides which to keep.
  // `facing`: only where the vertex's own surface faces the other part's (a vertex driven through a
  // thin part, a hand, is nearest its far side, which would push it on through).
  // `clear`: forget what earlier calls found (else a slot found again is replaced, the rest kept).
  template <class Keep>
  void find(std::span<const Vec3f> x, bool facing, bool clear, Keep&& keep, std::vector<Candidate>& into,
            std::vector<uint8_t>& into_used) {
    const size_t n = x.size();
    into.resize(n * kBodyPartCount);
    if (clear || into_used.size() != n * kBodyPartCount) into_used.assign(n * kBodyPartCount, 0);
    sim::parallel_blocks(n, [&](size_t, size_t begin, size_t end) {
      for (size_t v = begin; v < end; ++v) {
        const Vec3f& p = x[v];
        for (size_t q = 0; q < kBodyPartCount; ++q) {
          const Part& other = parts[q];
          if (q == part[v] || !other.tree) continue;
          if (other.box.exteriorDistance(p) > kReach) continue;
          SurfaceHit hit;
          if (!other.tree->closest(p, kReach, hit)) continue;
          const Tri& tri = triangles[other.triangle[hit.triangle]];
          // Parts that meet at a joint: never in contact there.
          const collision::TrianglePoint at_bind = collision::closest_on_triangle(bind[v], bind[tri[0]], bind[tri[1]], bind[tri[2]]);
          if ((at_bind.point - bind[v]).norm() < options.joint_separation) continue;
          // Inside only where the interpolated normal agrees: a part's surface is open where it
          // was cut from the body, and near the hand's many small features the sign of the
          // pseudo-normals and winding number alone put points 3 cm off the hand inside it.
          float sign = other.surface->sign(hit, p);
          if (sign < 0 && hit.distance > 1e-4f && other.surface->smooth_normal(hit).dot(p - hit.where.point) > 0) sign = 1.0f;
          const double distance = static_cast<double>(sign * hit.distance);
          if (!keep(distance)) continue;
          const Vec3f away = p - hit.where.point;
          const Vec3d normal = hit.distance > 1e-4f ? Vec3d((sign * away / hit.distance).cast<double>())
                                                    : Vec3d(other.surface->smooth_normal(hit).cast<double>());
          const BodySurface* own = parts[part[v]].surface.get();
          if (facing && own && normal.dot(own->smooth_normals()[v].cast<double>()) > 0) continue;
          Candidate& c = into[v * kBodyPartCount + q];
          c.vertex = static_cast<uint32_t>(v);
          c.corner = tri;
          const double b1 = hit.where.b1, b2 = hit.where.b2;
          c.weight = {1.0 - b1 - b2, b1, b2};
          c.normal = normal;
          c.distance = distance;
          c.base = std::numeric_limits<double>::quiet_NaN();  // set by the caller, where u is known
          into_used[v * kBodyPartCount + q] = 1;
        }
      }
    });
  }
};

SkinLayer::SkinLayer(const Body& body, const SkinLayerOptions& options) : impl_(std::make_unique<Impl>()) {
  Impl& w = *impl_;
  const Mesh& mesh = body.mesh;
  const size_t n = mesh.vertex_count();
  if (body.parts.size() != n) throw std::invalid_argument("skin layer: the body has no body parts (analyse_body finds them)");
  w.options = options;
  w.bind = mesh.positions;
  w.triangles = mesh.triangles;
  w.part.resize(n);
  for (size_t v = 0; v < n; ++v) w.part[v] = static_cast<uint8_t>(body.parts[v]);
  // Anchors: stiffness per area times each vertex's area (a third of its triangles').
  std::vector<double> area(n, 0.0);
  for (const Tri& t : mesh.triangles) {
    const double a = 0.5 * static_cast<double>((mesh.positions[t[1]] - mesh.positions[t[0]]).cross(mesh.positions[t[2]] - mesh.positions[t[0]]).norm());
    for (uint32_t v : t) area[v] += a / 3.0;
  }
  const SoftBody soft = make_soft_body(body);
  w.anchor.resize(n);
  for (size_t v = 0; v < n; ++v) {
    const bool is_soft = v < soft.region_of.size() && soft.region_of[v] >= 0;
    w.anchor[v] = static_cast<double>(is_soft ? options.soft_stiffness : options.firm_stiffness) * std::max(area[v], 1e-8);
  }
  // Edges, each once, as adjacency.
  std::vector<std::array<uint32_t, 2>> edges;
  edges.reserve(3 * mesh.triangles.size());
  for (const Tri& t : mesh.triangles)
    for (int k = 0; k < 3; ++k) {
      const uint32_t a = t[static_cast<size_t>(k)], b = t[static_cast<size_t>((k + 1) % 3)];
      edges.push_back({std::min(a, b), std::max(a, b)});
    }
  std::sort(edges.begin(), edges.end());
  edges.erase(std::unique(edges.begin(), edges.end()), edges.end());
  w.adjacency_begin.assign(n + 1, 0);
  for (const auto& e : edges) ++w.adjacency_begin[e[0] + 1], ++w.adjacency_begin[e[1] + 1];
  for (size_t v = 0; v < n; ++v) w.adjacency_begin[v + 1] += w.adjacency_begin[v];
  w.adjacency.resize(w.adjacency_begin[n]);
  std::vector<uint32_t> fill(w.adjacency_begin.begin(), w.adjacency_begin.end() - 1);
  for (const auto& e : edges) w.adjacency[fill[e[0]]++] = e[1], w.adjacency[fill[e[1]]++] = e[0];
  // Each triangle goes to the part most of its corners are in (the first corner's where all differ).
  std::array<std::vector<Tri>, kBodyPartCount> part_triangles;
  for (size_t t = 0; t < mesh.triangles.size(); ++t) {
    const Tri& tri = mesh.triangles[t];
    const uint8_t a = w.part[tri[0]], b = w.part[tri[1]], c = w.part[tri[2]];
    const uint8_t p = (b == c && b != a) ? b : a;
    w.parts[p].triangle.push_back(static_cast<uint32_t>(t));
    part_triangles[p].push_back(tri);
  }
  for (size_t p = 0; p < kBodyPartCount; ++p) {
    if (part_triangles[p].empty()) continue;
    w.parts[p].surface = std::make_unique<BodySurface>(mesh.positions, part_triangles[p]);
    w.parts[p].tree = std::make_unique<TriangleBvh>(*w.parts[p].surface, /*refit=*/true);
  }
  w.index.assign(n, -1);
}

SkinLayer::~SkinLayer() = default;
SkinLayer::SkinLayer(SkinLayer&&) noexcept = default;
SkinLayer& SkinLayer::operator=(SkinLayer&&) noexcept = default;

const SkinLayerOptions& SkinLayer::options() const { return impl_->options; }
void SkinLayer::set_gap(float gap) { impl_->options.gap = std::max(0.0f, gap); }

SkinContactStats SkinLayer::inside(std::span<const Vec3f> positions, float tolerance) {
  Impl& w = *impl_;
  if (positions.size() != w.bind.size()) throw std::invalid_argument("skin layer: the pose's vertex count differs from the body's");
  w.pose(positions);
  w.find(positions, false, true, [&](double distance) { return distance < -static_cast<double>(tolerance); }, w.seen,
         w.seen_used);
  SkinContactStats s;
  for (size_t v = 0; v < positions.size(); ++v) {
    double deepest = 0;
    for (size_t q = 0; q < kBodyPartCount; ++q)
      if (w.seen_used[v * kBodyPartCount + q]) deepest = std::max(deepest, -w.seen[v * kBodyPartCount + q].distance);
    if (deepest > 0) {
      ++s.vertices_inside;
      s.max_depth_m = std::max(s.max_depth_m, static_cast<float>(deepest));
    }
  }
  return s;
}

SkinContactStats SkinLayer::solve(std::span<const Vec3f> reference, std::span<Vec3f> out) {
  Impl& w = *impl_;
  const size_t n = w.bind.size();
  if (reference.size() != n || out.size() != n) throw std::invalid_argument("skin layer: the pose's vertex count differs from the body's");
  SkinContactStats s;
  const double gap = static_cast<double>(w.options.gap);
  if (out.data() != reference.data()) std::copy(reference.begin(), reference.end(), out.begin());
  std::vector<Vec3d> u(n, Vec3d::Zero());
  // The contacts of the last call (the previous frame) carried over, against the same triangle:
  // where skinning drives a part into another over several frames, the pair keeps the side it met
  // on, which a nearest point found afresh deep inside a thin part (a hand) would not.
  if (w.slot_used.size() == n * kBodyPartCount)
    for (size_t k = 0; k < w.slot.size(); ++k) {
      if (!w.slot_used[k]) continue;
      Candidate& c = w.slot[k];
      const Vec3f& a = reference[c.corner[0]];
      const Vec3f& b = reference[c.corner[1]];
      const Vec3f& d = reference[c.corner[2]];
      const collision::TrianglePoint at = collision::closest_on_triangle(reference[c.vertex], a, b, d);
      Vec3d normal = (b - a).cross(d - a).cast<double>();
      if (normal.norm() <= 0) {
        w.slot_used[k] = 0;
        continue;
      }
      normal.normalize();
      if (normal.dot(c.normal) < 0) normal = -normal;
      c.normal = normal;
      c.weight = {1.0 - static_cast<double>(at.b1) - static_cast<double>(at.b2), static_cast<double>(at.b1), static_cast<double>(at.b2)};
      c.distance = normal.dot((reference[c.vertex] - at.point).cast<double>());
      c.base = 0;
      if (c.distance >= gap + kCandidateMargin) w.slot_used[k] = 0;
    }
  for (int round = 0; round < kRounds; ++round) {
    // Contacts that are closed or near, found on the skin as the last round left it (the reference
    // first), linearised there; a vertex's contact with a part found again replaces the older one.
    w.pose(out);
    w.find(out, true, false, [&](double distance) { return distance < gap + kCandidateMargin; }, w.slot, w.slot_used);
    bool fresh_closed = false;
    w.candidates.clear();
    for (size_t k = 0; k < w.slot.size(); ++k) {
      if (!w.slot_used[k]) continue;
      Candidate& c = w.slot[k];
      if (std::isnan(c.base)) c.base = relative_move(c, u);
      w.candidates.push_back(c);
    }
    const size_t nc = w.candidates.size();
    w.closed.assign(nc, 0);
    for (size_t c = 0; c < nc; ++c) {
      w.closed[c] = gap_at(w.candidates[c], u, gap) < 0 ? 1 : 0;
      fresh_closed = fresh_closed || w.closed[c];
    }
    if (!fresh_closed) break;
    ++s.iterations;
    if (!w.solve_closed(gap, u, s)) break;
    for (size_t v = 0; v < n; ++v) out[v] = reference[v] + u[v].cast<float>();
  }
  s.contacts = 0;
  for (size_t c = 0; c < w.candidates.size(); ++c) s.contacts += gap_at(w.candidates[c], u, gap) < 1e-4 ? 1u : 0u;
  Vec3d net = Vec3d::Zero();
  for (size_t v = 0; v < n; ++v) {
    net += w.anchor[v] * u[v];
    s.anchor_force_n += w.anchor[v] * u[v].norm();
    const float move = static_cast<float>(u[v].norm());
    if (move <= kStill) {
      out[v] = reference[v];
      continue;
    }
    ++s.moved;
    s.max_move_m = std::max(s.max_move_m, move);
  }
  s.net_force_n = net.norm();
  return s;
}

bool SkinLayer::Impl::solve_closed(double gap, std::vector<Vec3d>& u, SkinContactStats& s) {
  const size_t nc = candidates.size();
  int rings = kRings;
  for (int it = 0; it < kMaxActiveSetIterations; ++it) {
    s.iterations += it > 0 ? 1 : 0;
    // The unknowns: the closed contacts' vertices and corners and `rings` of their neighbours.
    for (uint32_t v : active_vertices) index[v] = -1;
    active_vertices.clear();
    std::vector<uint32_t> frontier;
    const auto add = [&](uint32_t v) {
      if (index[v] >= 0) return;
      index[v] = static_cast<int>(active_vertices.size());
      active_vertices.push_back(v);
      frontier.push_back(v);
    };
    for (size_t c = 0; c < nc; ++c)
      if (closed[c]) {
        add(candidates[c].vertex);
        for (uint32_t v : candidates[c].corner) add(v);
      }
    for (int ring = 0; ring < rings; ++ring) {
      std::vector<uint32_t> current;
      current.swap(frontier);
      for (uint32_t v : current)
        for (uint32_t k = adjacency_begin[v]; k < adjacency_begin[v + 1]; ++k) add(adjacency[k]);
    }
    const size_t m = active_vertices.size();
    // The quadratic in u: anchors, membrane (a neighbour off the unknowns stays on its reference),
    // and the closed contacts' penalty k_c (distance - gap + J u - base)^2 / 2.
    std::vector<Eigen::Triplet<double>> triplets;
    Eigen::VectorXd rhs = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(3 * m));
    const double membrane = static_cast<double>(options.membrane);
    for (size_t a = 0; a < m; ++a) {
      const uint32_t v = active_vertices[a];
      double diagonal = anchor[v];
      for (uint32_t k = adjacency_begin[v]; k < adjacency_begin[v + 1]; ++k) {
        diagonal += membrane;
        const int b = index[adjacency[k]];
        if (b >= 0)
          for (int d = 0; d < 3; ++d) triplets.emplace_back(static_cast<int>(3 * a) + d, 3 * b + d, -membrane);
      }
      for (int d = 0; d < 3; ++d) triplets.emplace_back(static_cast<int>(3 * a) + d, static_cast<int>(3 * a) + d, diagonal);
    }
    for (size_t c = 0; c < nc; ++c) {
      if (!closed[c]) continue;
      const Candidate& cc = candidates[c];
      const double k = kContactFactor * anchor[cc.vertex];
      // J: +n on the vertex, -w_j n on each corner.
      const std::array<int, 4> at{index[cc.vertex], index[cc.corner[0]], index[cc.corner[1]], index[cc.corner[2]]};
      const std::array<double, 4> coef{1.0, -cc.weight[0], -cc.weight[1], -cc.weight[2]};
      const double g0 = cc.distance - gap - cc.base;
      for (size_t i = 0; i < 4; ++i) {
        for (int d = 0; d < 3; ++d) rhs[3 * at[i] + d] -= k * g0 * coef[i] * cc.normal[d];
        for (size_t j = 0; j < 4; ++j) {
          const double kij = k * coef[i] * coef[j];
          for (int d = 0; d < 3; ++d)
            for (int e = 0; e < 3; ++e) triplets.emplace_back(3 * at[i] + d, 3 * at[j] + e, kij * cc.normal[d] * cc.normal[e]);
        }
      }
    }
    Eigen::SparseMatrix<double> h(static_cast<Eigen::Index>(3 * m), static_cast<Eigen::Index>(3 * m));
    h.setFromTriplets(triplets.begin(), triplets.end());
    Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> ldlt(h);
    if (ldlt.info() != Eigen::Success) return false;
    const Eigen::VectorXd x = ldlt.solve(rhs);
    std::fill(u.begin(), u.end(), Vec3d::Zero());
    for (size_t a = 0; a < m; ++a) u[active_vertices[a]] = x.segment<3>(static_cast<Eigen::Index>(3 * a));
    double boundary = 0;
    for (uint32_t v : frontier) boundary = std::max(boundary, u[v].norm());
    if (boundary > kBoundaryMove && rings < kMaxRings) {
      rings = std::min(2 * rings, kMaxRings);
      --it;
      continue;
    }
    // The contacts closed at this rest: the set only grows (a contact closed once is held at the
    // gap), so the iterations end.
    bool grew = false;
    for (size_t c = 0; c < nc; ++c) {
      const Candidate& cc = candidates[c];
      if (!closed[c] && gap_at(cc, u, gap) < 0) {
        closed[c] = 1;
        grew = true;
      }
    }
    if (!grew) break;
  }
  return true;
}

}  // namespace drape
