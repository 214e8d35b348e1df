// Fit maps (drape/fit_map.hpp): strain along the grain per triangle, contact forces from each
// particle's force balance at rest, pressure on the body, and cuts of the garment by a plane.
//
// The dressing's contact response acts on velocities (Vassilev & Spanlang eq. 5), so it leaves no
// force behind to read. At rest every particle's forces balance, and what the springs, the strain
// limit's tension and gravity leave unbalanced where the cloth touches the body is the body's push:
// f_contact = -(f_springs + f_limit + m g). Sewn pairs are held together by the step, not by their
// springs alone, so each pair is one node and its two particles' forces are summed before the
// body's share is read. The strain limit is a constraint with no force of its own in the state, so
// its tensions are solved for: those that best balance the nodes off the body. The push can only
// point out of the body, and friction can hold at most mu times the push; what is beyond that is
// the residual of a cloth not quite at rest, not contact.
#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

#include "drape/fit_map.hpp"
#include "geometry/disjoint_sets.hpp"
#include "geometry/vertex_grid.hpp"

namespace drape {

// Gauss-Seidel sweeps of the strain limit's tension (a long hanging chain of springs needs many).
constexpr int kTensionSweeps = 2000;

std::array<float, 3> directional_strain(const Vec2f& a, const Vec2f& b, const Vec2f& c, const Vec3f& pa,
                                        const Vec3f& pb, const Vec3f& pc, const Vec2f& warp) {
  Eigen::Matrix2f flat;
  flat.col(0) = b - a;
  flat.col(1) = c - a;
  const float det = flat.determinant();
  if (!(std::abs(det) > 1e-12f)) return {0.0f, 0.0f, 0.0f};
  Eigen::Matrix<float, 3, 2> edges;
  edges.col(0) = pb - pa;
  edges.col(1) = pc - pa;
  const Eigen::Matrix<float, 3, 2> F = edges * flat.inverse();
  const Vec2f w = warp.normalized();
  const Vec2f weft(w.y(), -w.x());
  const float s = std::sqrt(0.5f);
  const auto stretch = [&](const Vec2f& d) { return (F * d).norm() - 1.0f; };
  return {stretch(w), stretch(weft), std::max(stretch(s * (w + weft)), stretch(s * (w - weft)))};
}

DirectionalStrain triangle_strain(const ClothModel& model, std::span<const Vec3f> x, std::span<const Vec2f> warp) {
  const size_t n = model.triangles.size();
  DirectionalStrain out{std::vector<float>(n, 0.0f), std::vector<float>(n, 0.0f), std::vector<float>(n, 0.0f),
                        std::vector<uint8_t>(n, 1)};
  // Slivers: flat area under a quarter of the median.
  std::vector<float> area(n, 0.0f);
  for (size_t t = 0; t < n; ++t) {
    const Tri& tri = model.triangles[t];
    const Vec2f e1 = model.flat_position[tri[1]] - model.flat_position[tri[0]];
    const Vec2f e2 = model.flat_position[tri[2]] - model.flat_position[tri[0]];
    area[t] = 0.5f * std::abs(e1.x() * e2.y() - e1.y() * e2.x());
  }
  if (n > 0) {
    std::vector<float> sorted = area;
    std::nth_element(sorted.begin(), sorted.begin() + static_cast<std::ptrdiff_t>(n / 2), sorted.end());
    const float floor = 0.25f * sorted[n / 2];
    for (size_t t = 0; t < n; ++t) out.measured[t] = area[t] >= floor ? 1 : 0;
  }
  const auto count = static_cast<std::ptrdiff_t>(n);
#pragma omp parallel for schedule(static)
  for (std::ptrdiff_t k = 0; k < count; ++k) {
    const auto t = static_cast<size_t>(k);
    const Tri& tri = model.triangles[t];
    const Vec2f grain = warp.empty() ? Vec2f::UnitY() : warp[tri[0]];
    const auto s = directional_strain(model.flat_position[tri[0]], model.flat_position[tri[1]],
                                      model.flat_position[tri[2]], x[tri[0]], x[tri[1]], x[tri[2]], grain);
    out.warp[t] = s[0];
    out.weft[t] = s[1];
    out.bias[t] = s[2];
  }
  return out;
}

std::vector<float> strain_percent_of_limit(const ClothModel& model, const DirectionalStrain& strain, float limit) {
  std::vector<float> out(model.particle_count(), 0.0f);
  const float scale = limit > 0 ? 100.0f / limit : 0.0f;
  for (size_t t = 0; t < model.triangles.size(); ++t) {
    const float s = std::max(0.0f, strain.along_grain(t)) * scale;
    for (uint32_t v : model.triangles[t]) out[v] = std::max(out[v], s);
  }
  return out;
}

ContactForces contact_forces(const ClothModel& model, std::span<const Vec3f> x,
                             std::span<const std::array<uint32_t, 2>> seam_pairs, const Collider& body,
                             const Vec3f& gravity, float contact_distance) {
  const size_t n = model.particle_count();
  ContactForces out;
  out.force.assign(n, Vec3f::Zero());
  out.point.assign(n, Vec3f::Zero());
  out.distance.assign(n, std::numeric_limits<float>::infinity());
  out.footprint.assign(n, 0.0f);
  for (size_t i = 0; i < n && i < model.drag_area.size(); ++i) out.footprint[i] = std::sqrt(std::max(0.0f, model.drag_area[i]));

  std::vector<ContactSample> samples(n);
  body.query(x, 0.5f, samples);
  for (size_t i = 0; i < n; ++i) {
    out.distance[i] = samples[i].distance;
    out.point[i] = std::isfinite(samples[i].distance) ? Vec3f(x[i] - samples[i].distance * samples[i].normal) : x[i];
  }

  // Net force of springs and weight per particle (at rest: no velocity, so no damping).
  const std::vector<Vec3f> zero_velocity(n, Vec3f::Zero());
  std::vector<Vec3f> net = spring_forces_per_particle(model, x, zero_velocity);
  for (size_t i = 0; i < n; ++i) {
    net[i] += model.mass[i] * gravity;
    out.weight += static_cast<double>(model.mass[i]) * static_cast<double>(gravity.norm());
  }

  // Sewn pairs are one node; each node's body contact is read at its particle nearest the body.
  DisjointSets nodes(n);
  for (const auto& [a, b] : seam_pairs)
    if (a < n && b < n) nodes.unite(a, b);
  std::vector<Vec3f> node_net(n, Vec3f::Zero());
  std::vector<uint32_t> nearest(n, UINT32_MAX);
  for (size_t i = 0; i < n; ++i) {
    const uint32_t root = nodes.find(static_cast<uint32_t>(i));
    node_net[root] += net[i];
    if (nearest[root] == UINT32_MAX || out.distance[i] < out.distance[nearest[root]]) nearest[root] = static_cast<uint32_t>(i);
  }
  // Which nodes touch the body.
  std::vector<uint8_t> touching(n, 0);
  for (size_t root = 0; root < n; ++root)
    if (nearest[root] != UINT32_MAX && out.distance[nearest[root]] <= contact_distance) touching[root] = 1;

  // The strain limit's tension. A spring held at the fabric's limit pulls harder than its (soft)
  // stiffness says: the limit stands for the cloth's real, much stiffer fibres. Its tension is
  // unknown; it is found as the tensions t_s >= 0 of the springs at the limit that leave the least
  // force unbalanced: on a node off the body all of its net force, on a node on the body what the
  // body cannot take (a push out of it, with friction up to mu times the push: the distance of the
  // force to that cone). Projected Gauss-Seidel in a fixed order, from zero tension: the least
  // tension that holds the garment where it rests.
  const float mu = model.fabric.friction;
  const auto unbalanced = [&](size_t root) -> Vec3f {
    const Vec3f& f = node_net[root];
    if (!touching[root]) return f;
    // f + (the body's force nearest to -f): zero where the body can take all of it.
    const Vec3f& normal = samples[nearest[root]].normal;
    const Vec3f v = -f;
    const float vn = v.dot(normal);
    const Vec3f vt = v - vn * normal;
    const float t = vt.norm();
    Vec3f body_force = Vec3f::Zero();
    if (t <= mu * vn) body_force = v;
    else if (mu * t > -vn) {
      const float pn = (vn + mu * t) / (1 + mu * mu);
      body_force = pn * normal + (t > 0 ? Vec3f(mu * pn * vt / t) : Vec3f::Zero());
    }
    return f + body_force;
  };
  const float threshold = model.fabric.strain_threshold;
  struct Held {
    uint32_t a, b;
    Vec3f u;
    float tension;
  };
  std::vector<Held> held;
  const SpringRange structural = model.range(SpringKind::Structural);
  for (uint32_t s = structural.begin; s < structural.end; ++s) {
    const uint32_t a = nodes.find(model.spring_a[s]), b = nodes.find(model.spring_b[s]);
    if (a == b) continue;
    const Vec3f d = x[model.spring_b[s]] - x[model.spring_a[s]];
    const float length = d.norm();
    if (!(length >= (1.0f + 0.9f * threshold) * model.rest_length[s])) continue;
    held.push_back({a, b, d / length, 0.0f});
  }
  // Bottom first: a hanging strip passes its weight up through its springs in one sweep.
  std::stable_sort(held.begin(), held.end(), [&](const Held& p, const Held& q) {
    return std::min(x[p.a].y(), x[p.b].y()) < std::min(x[q.a].y(), x[q.b].y());
  });
  float largest_weight = 0;
  for (size_t i = 0; i < n; ++i) largest_weight = std::max(largest_weight, model.mass[i] * gravity.norm());
  const float tolerance = 1e-4f * largest_weight;
  for (int sweep = 0; sweep < kTensionSweeps && !held.empty(); ++sweep) {
    float change = 0;
    // Alternating direction (symmetric Gauss-Seidel).
    for (size_t k = 0; k < held.size(); ++k) {
      Held& h = held[sweep % 2 == 0 ? k : held.size() - 1 - k];
      // d/dt of 1/2 sum |unbalanced|^2 (the tension pulls a towards b: +t u on a, -t u on b); the
      // curvature is at most 1 per end.
      const float slope = unbalanced(h.a).dot(h.u) - unbalanced(h.b).dot(h.u);
      const float next = std::max(0.0f, h.tension - 0.5f * slope);
      const float d = next - h.tension;
      if (d == 0.0f) continue;
      node_net[h.a] += d * h.u;
      node_net[h.b] -= d * h.u;
      h.tension = next;
      change = std::max(change, std::abs(d));
    }
    if (change < tolerance) break;
  }
  for (size_t root = 0; root < n; ++root)
    if (nearest[root] != UINT32_MAX) out.unbalanced += unbalanced(root).norm();

  for (size_t root = 0; root < n; ++root) {
    if (!touching[root]) continue;
    const uint32_t i = nearest[root];
    const Vec3f normal = samples[i].normal;
    const Vec3f f = -node_net[root];
    const float push = f.dot(normal);
    if (!(push > 0)) continue;  // the body only pushes
    Vec3f tangential = f - push * normal;
    const float t = tangential.norm();
    if (t > mu * push) tangential *= mu * push / t;
    out.force[i] = push * normal + tangential;
    ++out.in_contact;
  }
  for (const Vec3f& f : out.force) out.total += f;
  return out;
}

PressureMap empty_pressure_map(const Mesh& body) {
  PressureMap map;
  const size_t n = body.positions.size();
  map.force.assign(n, Vec3f::Zero());
  map.area.assign(n, 0.0f);
  map.pressure.assign(n, 0.0f);
  for (const Tri& t : body.triangles) {
    const float a = 0.5f * (body.positions[t[1]] - body.positions[t[0]]).cross(body.positions[t[2]] - body.positions[t[0]]).norm();
    for (uint32_t v : t) map.area[v] += a / 3.0f;
  }
  return map;
}

void add_pressure(PressureMap& map, const Mesh& body, const ContactForces& contacts, float min_radius) {
  if (body.positions.empty()) return;
  float widest = min_radius;
  for (float r : contacts.footprint) widest = std::max(widest, 2.0f * r);
  const VertexGrid grid(body.positions, widest);
  std::vector<std::pair<uint32_t, float>> weights;
  for (size_t i = 0; i < contacts.force.size(); ++i) {
    const Vec3f& f = contacts.force[i];
    if (f.squaredNorm() == 0.0f) continue;
    const Vec3f& c = contacts.point[i];
    const float spread_radius = std::max(min_radius, i < contacts.footprint.size() ? 2.0f * contacts.footprint[i] : 0.0f);
    weights.clear();
    float sum = 0;
    grid.near(c, [&](uint32_t v) {
      const float d = (body.positions[v] - c).norm();
      if (d >= spread_radius) return;
      const float w = (1 - d / spread_radius) * (1 - d / spread_radius);
      weights.emplace_back(v, w);
      sum += w;
    });
    if (weights.empty()) {
      // No vertex that close (a coarse body): the nearest one takes it all.
      uint32_t best = 0;
      float best_d = std::numeric_limits<float>::infinity();
      for (size_t v = 0; v < body.positions.size(); ++v)
        if (const float d = (body.positions[v] - c).squaredNorm(); d < best_d) {
          best_d = d;
          best = static_cast<uint32_t>(v);
        }
      weights.emplace_back(best, 1.0f);
      sum = 1.0f;
    }
    // Visited in bucket order, which depends only on the body: the sum is the same on every run.
    for (const auto& [v, w] : weights) map.force[v] -= (w / sum) * f;
  }
  map.total = Vec3f::Zero();
  for (const Vec3f& f : map.force) map.total += f;
}

void finish_pressure(PressureMap& map, const Mesh& body) {
  const std::vector<Vec3f> computed =
      body.normals.size() == body.positions.size() ? std::vector<Vec3f>{} : vertex_normals(body.positions, body.triangles);
  const std::vector<Vec3f>& normals = computed.empty() ? body.normals : computed;
  for (size_t v = 0; v < map.force.size(); ++v) {
    const float push = -map.force[v].dot(normals[v]);
    map.pressure[v] = map.area[v] > 0 && push > 0 ? push / map.area[v] : 0.0f;
  }
}

GarmentCut cut_garment(const ClothModel& model, std::span<const Vec3f> x, const Vec3f& centre, const Vec3f& normal,
                       float reach, std::span<const uint8_t> selected) {
  GarmentCut cut;
  const Vec3f n = normal.normalized();
  for (size_t t = 0; t < model.triangles.size(); ++t) {
    if (!selected.empty() && !selected[t]) continue;
    const Tri& tri = model.triangles[t];
    const Vec3f centroid = (x[tri[0]] + x[tri[1]] + x[tri[2]]) / 3.0f;
    if ((centroid - centre).norm() > reach) continue;
    std::array<float, 3> s{};
    for (int k = 0; k < 3; ++k) s[static_cast<size_t>(k)] = (x[tri[static_cast<size_t>(k)]] - centre).dot(n);
    Vec3f p[2];
    Vec2f u[2];
    int found = 0;
    for (int k = 0; k < 3 && found < 2; ++k) {
      const auto a = static_cast<size_t>(k), b = static_cast<size_t>((k + 1) % 3);
      if ((s[a] >= 0) == (s[b] >= 0)) continue;
      const float f = s[a] / (s[a] - s[b]);
      p[found] = x[tri[a]] + f * (x[tri[b]] - x[tri[a]]);
      u[found] = model.flat_position[tri[a]] + f * (model.flat_position[tri[b]] - model.flat_position[tri[a]]);
      ++found;
    }
    if (found != 2) continue;
    cut.pattern_m += (u[1] - u[0]).norm();
    cut.draped_m += (p[1] - p[0]).norm();
    ++cut.segments;
    if ((p[0].x() >= 0) != (p[1].x() >= 0)) cut.crosses_midline = true;
  }
  return cut;
}

}  // namespace drape
