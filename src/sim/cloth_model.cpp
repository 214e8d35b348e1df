// Building cloth models: the grid of Vassilev & Spanlang sec. 2.1, triangle meshes (the pattern
// layer's garments), and compile(), which turns any ClothSpec into the immutable ClothModel the step
// reads: springs sorted by kind, damping from the fabric, per-particle incidence in a fixed order
// (the deterministic force gather) and a colouring of the strain-limited springs (race-free
// Gauss-Seidel passes).
#include <Eigen/Geometry>
#include <algorithm>
#include <bit>
#include <limits>
#include <cmath>
#include <map>
#include <numbers>
#include <stdexcept>
#include <string>
#include <utility>

#include "drape/cloth.hpp"
#include "drape/error.hpp"

namespace drape {

std::string_view to_string(SpringKind kind) {
  switch (kind) {
    case SpringKind::Structural: return "structural";
    case SpringKind::Shear: return "shear";
    case SpringKind::Flexion: return "flexion";
    case SpringKind::Seam: return "seam";
    case SpringKind::Count: break;
  }
  return "unknown";
}

float ClothModel::total_mass() const {
  double sum = 0;
  for (float m : mass) sum += m;
  return static_cast<float>(sum);
}

namespace {

// One free particle's own bounds on the step (infinite where it has no such springs): eq. 4,
// dt <= 0.4 pi sqrt(m / K), with K the sum of the stiffnesses of its springs (by Gershgorin the
// highest squared frequency is at most 2 K / m, and symplectic Euler is stable for dt < 2 / omega =
// sqrt(2 m / K), which 0.4 pi sqrt(m / K) respects: 1.257 < 1.414), and, so that explicit damping
// does not overshoot (c dt / m well below 1), dt <= 0.5 m / C with C the sum of its spring dampings.
// m is the inertial mass.
struct ParticleBound {
  double stiffness, damping;
  double step() const { return std::min(stiffness, damping); }
};
ParticleBound particle_bound(const ClothModel& model, size_t i) {
  double k_sum = 0, c_sum = 0;
  for (uint32_t e = model.incident_begin[i]; e < model.incident_begin[i + 1]; ++e) {
    k_sum += model.stiffness[model.incident_spring[e]];
    c_sum += model.damping[model.incident_spring[e]];
  }
  const double m = model.inertial_mass(i), none = std::numeric_limits<double>::infinity();
  return {k_sum > 0 ? 0.4 * std::numbers::pi * std::sqrt(m / k_sum) : none, c_sum > 0 ? 0.5 * m / c_sum : none};
}

}  // namespace

// The smallest particle bound; particles without springs (or pinned) do not count.
float ClothModel::stable_time_step() const {
  double best = std::numeric_limits<double>::infinity();
  for (size_t i = 0; i < mass.size(); ++i) {
    if (inverse_mass[i] == 0) continue;
    const ParticleBound bound = particle_bound(*this, i);
    if (std::isfinite(bound.stiffness)) best = std::min(best, bound.step());
  }
  return std::isfinite(best) ? static_cast<float>(best) : 1e-3f;
}

// Eq. 4 with K per particle its stiffness along its stiffest direction (DressOptions::
// directional_time_step). The spring energy sum_s k_s (u_s . (x_a - x_b))^2 / 2 is at most
// sum_i x_i^T D_i x_i with D_i = sum of k_s u_s u_s^T over i's springs ((p - q)^2 <= 2 p^2 + 2 q^2),
// so omega^2 <= max_i 2 lambda_max(D_i) / m_i, and 0.4 pi sqrt(m / lambda_max(D)) keeps eq. 4's
// margin under symplectic Euler's limit 2 / omega, as stable_time_step() does with
// K = trace(D) (~1.8x lambda_max for a grid particle, whose springs pull along two axes).
// Directions are taken on the flat pattern; a spring whose flat length is not its rest length
// (seams, elastic bands, springs between panels) counts whole in every direction.
float ClothModel::directional_stable_time_step() const {
  double best = std::numeric_limits<double>::infinity();
  for (size_t i = 0; i < particle_count(); ++i) {
    if (inverse_mass[i] == 0) continue;
    Eigen::Matrix2d k_plane = Eigen::Matrix2d::Zero(), c_plane = Eigen::Matrix2d::Zero();
    double k_iso = 0, c_iso = 0;
    for (uint32_t e = incident_begin[i]; e < incident_begin[i + 1]; ++e) {
      const uint32_t s = incident_spring[e];
      const Eigen::Vector2d d = (flat_position[spring_b[s]] - flat_position[spring_a[s]]).cast<double>();
      const double len = d.norm(), rest = rest_length[s];
      if (rest > 0 && std::abs(len - rest) <= 1e-3 * rest) {
        const Eigen::Matrix2d uu = d * d.transpose() / (len * len);
        k_plane += stiffness[s] * uu;
        c_plane += damping[s] * uu;
      } else {
        k_iso += stiffness[s];
        c_iso += damping[s];
      }
    }
    const auto largest = [](const Eigen::Matrix2d& a) {
      return 0.5 * a.trace() + std::hypot(0.5 * (a(0, 0) - a(1, 1)), a(0, 1));
    };
    const double k_max = largest(k_plane) + k_iso, c_max = largest(c_plane) + c_iso;
    if (k_max <= 0) continue;
    const double m = inertial_mass(i);
    double dt = 0.4 * std::numbers::pi * std::sqrt(m / k_max);
    if (c_max > 0) dt = std::min(dt, 0.5 * m / c_max);  // explicit damping: no overshoot
    best = std::min(best, dt);
  }
  return std::isfinite(best) ? static_cast<float>(best) : stable_time_step();
}

size_t scale_inertia(ClothModel& model, float ratio) {
  if (!(ratio > 0)) return 0;
  const size_t n = model.particle_count();
  std::vector<ParticleBound> bounds(n);
  std::vector<double> steps;  // of the free particles, for the median
  steps.reserve(n);
  for (size_t i = 0; i < n; ++i) {
    if (model.inverse_mass[i] == 0) continue;
    bounds[i] = particle_bound(model, i);
    steps.push_back(bounds[i].step());
  }
  if (steps.empty()) return 0;
  std::nth_element(steps.begin(), steps.begin() + static_cast<std::ptrdiff_t>(steps.size() / 2), steps.end());
  const double target = ratio * steps[steps.size() / 2];
  if (!std::isfinite(target)) return 0;
  if (model.inertia_scale.empty()) model.inertia_scale.assign(n, 1.0f);
  size_t scaled = 0;
  for (size_t i = 0; i < n; ++i) {
    const ParticleBound& b = bounds[i];
    if (model.inverse_mass[i] == 0 || b.step() >= target) continue;
    // The stiffness term grows as sqrt(scale), the damping term as scale.
    const double s = std::max({1.0, (target / b.stiffness) * (target / b.stiffness), target / b.damping});
    model.inertia_scale[i] = static_cast<float>(model.inertia_scale[i] * s);
    model.inverse_mass[i] = 1.0f / model.inertial_mass(i);
    ++scaled;
  }
  return scaled;
}

ClothModel compile(ClothSpec spec) {
  const size_t n = spec.positions.size();
  if (n == 0) throw std::invalid_argument("compile: a cloth needs particles");
  if (spec.mass.size() != n || spec.drag_area.size() != n || (!spec.pinned.empty() && spec.pinned.size() != n) ||
      (!spec.flat_positions.empty() && spec.flat_positions.size() != n))
    throw std::invalid_argument("compile: per-particle arrays differ in size");

  ClothModel m;
  m.fabric = spec.fabric;
  m.grid_nx = spec.grid_nx;
  m.grid_ny = spec.grid_ny;
  m.mass = std::move(spec.mass);
  m.drag_area = std::move(spec.drag_area);
  m.rest_position = std::move(spec.positions);
  m.triangles = std::move(spec.triangles);
  m.inverse_mass.resize(n);
  for (size_t i = 0; i < n; ++i) {
    if (!(m.mass[i] > 0) || !std::isfinite(m.mass[i])) throw std::invalid_argument("compile: particle mass must be > 0");
    const bool pinned = !spec.pinned.empty() && spec.pinned[i];
    m.inverse_mass[i] = pinned ? 0.0f : 1.0f / m.mass[i];
  }
  if (spec.flat_positions.empty()) {
    m.flat_position.reserve(n);
    for (const Vec3f& p : m.rest_position) m.flat_position.emplace_back(p.x(), p.z());
  } else {
    m.flat_position = std::move(spec.flat_positions);
  }

  // Bending stencils, their weights from the flat pattern.
  for (const ClothSpec::Bend& bd : spec.bends) {
    if (bd.a >= n || bd.m >= n || bd.b >= n || bd.a == bd.m || bd.m == bd.b || bd.a == bd.b)
      throw std::invalid_argument("compile: bending stencil with bad particle index");
    const float l1 = (m.flat_position[bd.m] - m.flat_position[bd.a]).norm();
    const float l2 = (m.flat_position[bd.b] - m.flat_position[bd.m]).norm();
    if (!(l1 > 0) || !(l2 > 0) || !(bd.stiffness >= 0)) throw std::invalid_argument("compile: bad bending stencil constants");
    m.bend_stencil.push_back({bd.a, bd.m, bd.b});
    m.bend_weight.push_back({1.0f / l1, -(1.0f / l1 + 1.0f / l2), 1.0f / l2});
    m.bend_stiffness.push_back(bd.stiffness);
  }

  // Springs sorted by kind (stable: within a kind the builder's order is kept).
  std::stable_sort(spec.springs.begin(), spec.springs.end(),
                   [](const ClothSpec::Spring& a, const ClothSpec::Spring& b) { return a.kind < b.kind; });
  const size_t s_count = spec.springs.size();
  m.spring_a.resize(s_count);
  m.spring_b.resize(s_count);
  m.rest_length.resize(s_count);
  m.stiffness.resize(s_count);
  m.damping.resize(s_count);
  for (SpringRange& r : m.kind_range) r = {0, 0};
  for (size_t s = 0; s < s_count; ++s) {
    const ClothSpec::Spring& sp = spec.springs[s];
    if (sp.a >= n || sp.b >= n || sp.a == sp.b) throw std::invalid_argument("compile: spring with bad particle index");
    if (!(sp.rest_length >= 0) || !(sp.stiffness >= 0)) throw std::invalid_argument("compile: bad spring constants");
    m.spring_a[s] = sp.a;
    m.spring_b[s] = sp.b;
    m.rest_length[s] = sp.rest_length;
    m.stiffness[s] = sp.stiffness;
    // Damping along the spring: a fraction of the critical damping of the pair's reduced mass.
    const float ma = m.mass[sp.a], mb = m.mass[sp.b];
    m.damping[s] = 2.0f * spec.fabric.damping_ratio * std::sqrt(sp.stiffness * ma * mb / (ma + mb));
    SpringRange& r = m.kind_range[static_cast<size_t>(sp.kind)];
    if (r.size() == 0) r.begin = static_cast<uint32_t>(s);
    r.end = static_cast<uint32_t>(s + 1);
  }
  // Empty kinds get an empty range at the position where they would start.
  uint32_t next = 0;
  for (SpringRange& r : m.kind_range) {
    if (r.size() == 0) r = {next, next};
    next = r.end;
  }

  // Incidence lists: for each particle its springs in increasing spring index.
  m.incident_begin.assign(n + 1, 0);
  for (size_t s = 0; s < s_count; ++s) {
    ++m.incident_begin[m.spring_a[s] + 1];
    ++m.incident_begin[m.spring_b[s] + 1];
  }
  for (size_t i = 0; i < n; ++i) m.incident_begin[i + 1] += m.incident_begin[i];
  m.incident_spring.resize(2 * s_count);
  m.incident_sign.resize(2 * s_count);
  std::vector<uint32_t> fill(m.incident_begin.begin(), m.incident_begin.end() - 1);
  for (size_t s = 0; s < s_count; ++s) {
    const uint32_t ea = fill[m.spring_a[s]]++, eb = fill[m.spring_b[s]]++;
    m.incident_spring[ea] = static_cast<uint32_t>(s);
    m.incident_sign[ea] = 1.0f;
    m.incident_spring[eb] = static_cast<uint32_t>(s);
    m.incident_sign[eb] = -1.0f;
  }

  // Greedy colouring of the strain-limited springs: a spring takes the lowest colour that neither
  // of its particles has yet, so the springs of one colour share no particle.
  struct Limited {
    uint32_t a, b, colour;
    float rest;
  };
  std::vector<Limited> limited;
  std::vector<uint64_t> used(n, 0);
  uint32_t colours = 0;
  for (size_t s = 0; s < s_count; ++s) {
    const size_t kind = static_cast<size_t>(spec.springs[s].kind);
    if (!(spec.limited_kinds & (1u << kind)) || m.rest_length[s] <= 0) continue;
    const uint32_t a = m.spring_a[s], b = m.spring_b[s];
    const uint64_t taken = used[a] | used[b];
    if (taken == ~uint64_t{0}) throw std::invalid_argument("compile: a particle has more than 64 limited springs");
    const uint32_t colour = static_cast<uint32_t>(std::countr_one(taken));
    used[a] |= uint64_t{1} << colour;
    used[b] |= uint64_t{1} << colour;
    colours = std::max(colours, colour + 1);
    limited.push_back({a, b, colour, m.rest_length[s]});
  }
  std::stable_sort(limited.begin(), limited.end(), [](const Limited& x, const Limited& y) { return x.colour < y.colour; });
  m.limit_colour_begin.assign(colours + 1, 0);
  for (const Limited& l : limited) {
    m.limit_a.push_back(l.a);
    m.limit_b.push_back(l.b);
    m.limit_rest.push_back(l.rest);
    ++m.limit_colour_begin[l.colour + 1];
  }
  for (uint32_t c = 0; c < colours; ++c) m.limit_colour_begin[c + 1] += m.limit_colour_begin[c];
  return m;
}

uint32_t append(ClothSpec& into, const ClothSpec& part) {
  const auto base = static_cast<uint32_t>(into.positions.size());
  if (!into.pinned.empty() || !part.pinned.empty()) {
    into.pinned.resize(base, 0);
    if (part.pinned.empty()) into.pinned.resize(base + part.positions.size(), 0);
    else into.pinned.insert(into.pinned.end(), part.pinned.begin(), part.pinned.end());
  }
  into.positions.insert(into.positions.end(), part.positions.begin(), part.positions.end());
  into.flat_positions.insert(into.flat_positions.end(), part.flat_positions.begin(), part.flat_positions.end());
  into.mass.insert(into.mass.end(), part.mass.begin(), part.mass.end());
  into.drag_area.insert(into.drag_area.end(), part.drag_area.begin(), part.drag_area.end());
  for (const Tri& t : part.triangles) into.triangles.push_back({base + t[0], base + t[1], base + t[2]});
  for (ClothSpec::Spring sp : part.springs) {
    sp.a += base;
    sp.b += base;
    into.springs.push_back(sp);
  }
  for (ClothSpec::Bend bd : part.bends) {
    bd.a += base;
    bd.m += base;
    bd.b += base;
    into.bends.push_back(bd);
  }
  into.grid_nx = into.grid_ny = 0;  // several pieces: not one grid's indexing
  return base;
}

ClothSpec grid_cloth_spec(const Fabric& fabric, const GridClothOptions& o) {
  if (o.nx < 3 || o.ny < 3) throw InputError("--n", "a grid cloth needs at least 3 x 3 vertices");
  if (!(o.width > 0) || !(o.height > 0)) throw InputError("--size", "cloth width and height must be positive");
  validate_fabric(fabric, "--fabric");
  const uint32_t nx = o.nx, ny = o.ny;
  const float hu = o.width / static_cast<float>(nx - 1), hv = o.height / static_cast<float>(ny - 1);
  const Vec3f u = o.u_axis.normalized(), v = o.v_axis.normalized();

  ClothSpec spec;
  spec.fabric = fabric;
  spec.grid_nx = nx;
  spec.grid_ny = ny;
  const size_t n = size_t{nx} * ny;
  spec.positions.reserve(n);
  spec.flat_positions.reserve(n);
  spec.mass.reserve(n);
  spec.drag_area.reserve(n);
  // Particles: each owns the part of the cloth nearer to it than to any other (corners a quarter cell).
  for (uint32_t iy = 0; iy < ny; ++iy)
    for (uint32_t ix = 0; ix < nx; ++ix) {
      const float fu = hu * static_cast<float>(ix), fv = hv * static_cast<float>(iy);
      spec.positions.push_back(o.origin + fu * u + fv * v);
      spec.flat_positions.emplace_back(fu, fv);
      const float wu = (ix == 0 || ix == nx - 1) ? 0.5f : 1.0f, wv = (iy == 0 || iy == ny - 1) ? 0.5f : 1.0f;
      const float area = wu * wv * hu * hv;
      spec.mass.push_back(fabric.areal_density * area);
      spec.drag_area.push_back(area);
    }
  for (uint32_t iy = 0; iy + 1 < ny; ++iy)
    for (uint32_t ix = 0; ix + 1 < nx; ++ix) {
      const uint32_t i = iy * nx + ix;
      spec.triangles.push_back({i, i + 1, i + nx + 1});
      spec.triangles.push_back({i, i + nx + 1, i + nx});
    }

  // Springs as sec. 2.1 lists them. k = stiffness * (width the spring stands for) / rest length.
  const float diag = std::sqrt(hu * hu + hv * hv);
  const auto add = [&](uint32_t a, uint32_t b, float rest, float k, SpringKind kind) {
    spec.springs.push_back({a, b, rest, k, kind});
  };
  for (uint32_t iy = 0; iy < ny; ++iy)
    for (uint32_t ix = 0; ix < nx; ++ix) {
      const uint32_t i = iy * nx + ix;
      if (ix + 1 < nx) add(i, i + 1, hu, fabric.stretch_weft * hv / hu, SpringKind::Structural);
      if (iy + 1 < ny) add(i, i + nx, hv, fabric.stretch_warp * hu / hv, SpringKind::Structural);
      if (ix + 1 < nx && iy + 1 < ny) {
        add(i, i + nx + 1, diag, fabric.shear, SpringKind::Shear);
        add(i + 1, i + nx, diag, fabric.shear, SpringKind::Shear);
      }
      if (ix + 2 < nx) add(i, i + 2, 2 * hu, fabric.bend * hv / (2 * hu), SpringKind::Flexion);
      if (iy + 2 < ny) add(i, i + 2 * nx, 2 * hv, fabric.bend * hu / (2 * hv), SpringKind::Flexion);
      // Bending stencils along the same lines: k = B width / spacing, a line on the cloth's edge
      // standing for half a row's width.
      const float row = (iy == 0 || iy + 1 == ny) ? 0.5f * hv : hv, column = (ix == 0 || ix + 1 == nx) ? 0.5f * hu : hu;
      if (ix + 2 < nx) spec.bends.push_back({i, i + 1, i + 2, fabric.bending_rigidity * row / hu});
      if (iy + 2 < ny) spec.bends.push_back({i, i + nx, i + 2 * nx, fabric.bending_rigidity * column / hv});
    }
  return spec;
}

ClothModel grid_cloth(const Fabric& fabric, const GridClothOptions& options) {
  return compile(grid_cloth_spec(fabric, options));
}

ClothSpec mesh_cloth_spec(const Mesh& mesh, const Fabric& fabric, const std::string& source) {
  const size_t n = mesh.positions.size();
  if (n == 0 || mesh.triangles.empty()) throw InputError(source, "the cloth mesh has no triangles");
  const bool flat = mesh.uvs.size() == n;
  validate_fabric(fabric, source);

  ClothSpec spec;
  spec.fabric = fabric;
  spec.positions = mesh.positions;
  spec.triangles = mesh.triangles;
  spec.flat_positions.reserve(n);
  for (size_t i = 0; i < n; ++i) {
    if (!mesh.positions[i].allFinite() || (flat && !mesh.uvs[i].allFinite()))
      throw InputError(source, "vertex " + std::to_string(i) + " has a non-finite coordinate");
    spec.flat_positions.push_back(flat ? mesh.uvs[i] : Vec2f(mesh.positions[i].x(), mesh.positions[i].z()));
  }
  // Rest geometry: the flat pattern where there is one (a garment placed around a body is curved
  // but its rest shape is the flat panel), else the mesh as given.
  const auto rest_point = [&](uint32_t i) -> Vec3f {
    return flat ? Vec3f(mesh.uvs[i].x(), mesh.uvs[i].y(), 0.0f) : mesh.positions[i];
  };

  // Triangle areas; a third of each goes to each corner (mass, drag) and to each edge (stiffness).
  std::vector<float> area_of_particle(n, 0.0f);
  std::map<std::pair<uint32_t, uint32_t>, std::pair<float, std::vector<uint32_t>>> edges;  // area share, opposite corners
  for (size_t t = 0; t < mesh.triangles.size(); ++t) {
    const Tri& tri = mesh.triangles[t];
    for (uint32_t c : tri)
      if (c >= n) throw InputError(source, "triangle " + std::to_string(t) + " refers to vertex " + std::to_string(c) + " of " + std::to_string(n));
    if (tri[0] == tri[1] || tri[1] == tri[2] || tri[0] == tri[2])
      throw InputError(source, "triangle " + std::to_string(t) + " repeats a vertex");
    const Vec3f p0 = rest_point(tri[0]), p1 = rest_point(tri[1]), p2 = rest_point(tri[2]);
    const float area = 0.5f * (p1 - p0).cross(p2 - p0).norm();
    if (!(area > 1e-12f)) throw InputError(source, "triangle " + std::to_string(t) + " has zero area");
    for (int k = 0; k < 3; ++k) {
      area_of_particle[tri[k]] += area / 3.0f;
      const uint32_t a = tri[k], b = tri[(k + 1) % 3], opposite = tri[(k + 2) % 3];
      auto& e = edges[{std::min(a, b), std::max(a, b)}];
      e.first += area / 3.0f;
      e.second.push_back(opposite);
    }
  }
  for (size_t i = 0; i < n; ++i) {
    if (area_of_particle[i] <= 0) throw InputError(source, "vertex " + std::to_string(i) + " belongs to no triangle");
    spec.mass.push_back(fabric.areal_density * area_of_particle[i]);
    spec.drag_area.push_back(area_of_particle[i]);
  }

  // k = E(direction) * A_edge / l0^2 * 8/3: on an equilateral mesh this gives exactly the membrane
  // stiffness E under uniform stretch (and within 10 % on a right-triangle grid). E blends warp
  // (flat y) and weft (flat x) by the edge's direction on the flat pattern.
  constexpr float kCalibration = 8.0f / 3.0f;
  const auto directional = [&](const Vec3f& d, float warp, float weft) {
    const float len2 = d.head<2>().squaredNorm();
    if (!flat || len2 <= 0) return 0.5f * (warp + weft);
    return (weft * d.x() * d.x() + warp * d.y() * d.y()) / len2;
  };
  for (const auto& [key, info] : edges) {
    const auto [a, b] = key;
    const Vec3f d = rest_point(b) - rest_point(a);
    const float rest = d.norm();
    const float k = directional(d, fabric.stretch_warp, fabric.stretch_weft) * info.first / (rest * rest) * kCalibration;
    spec.springs.push_back({a, b, rest, k, SpringKind::Structural});
    // Bending across an interior edge: a spring between the two vertices opposite it.
    if (info.second.size() == 2) {
      const uint32_t c = info.second[0], e = info.second[1];
      if (c == e) continue;
      const Vec3f dce = rest_point(e) - rest_point(c);
      const float rest_ce = dce.norm();
      if (rest_ce <= 0) continue;
      spec.springs.push_back({c, e, rest_ce, fabric.bend * info.first / (rest_ce * rest_ce) * kCalibration, SpringKind::Flexion});
    }
  }
  return spec;
}

ClothModel mesh_cloth(const Mesh& mesh, const Fabric& fabric, const std::string& source) {
  return compile(mesh_cloth_spec(mesh, fabric, source));
}

}  // namespace drape
