// Measurements of a cloth state: strain statistics, energy, the per-particle spring force (for the
// physics-invariant tests), a determinism hash and the output mesh.
#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>

#include "drape/cloth.hpp"
#include "sim/kernels.hpp"

namespace drape {

StrainStats strain_stats(const ClothModel& model, std::span<const Vec3f> x, SpringKind kind) {
  const SpringRange r = model.range(kind);
  StrainStats s;
  if (r.size() == 0) return s;
  std::vector<float> strain;
  strain.reserve(r.size());
  double sum_abs = 0, sum_len = 0, sum_rest = 0;
  for (uint32_t k = r.begin; k < r.end; ++k) {
    const float rest = model.rest_length[k];
    if (rest <= 0) continue;
    const float len = (x[model.spring_b[k]] - x[model.spring_a[k]]).norm();
    const float e = (len - rest) / rest;
    strain.push_back(e);
    sum_abs += std::abs(e);
    sum_len += len;
    sum_rest += rest;
  }
  if (strain.empty()) return s;
  s.max = *std::max_element(strain.begin(), strain.end());
  s.min = *std::min_element(strain.begin(), strain.end());
  s.mean_abs = static_cast<float>(sum_abs / static_cast<double>(strain.size()));
  s.global = static_cast<float>((sum_len - sum_rest) / sum_rest);
  const size_t rank = std::min(strain.size() - 1, static_cast<size_t>(std::ceil(0.99 * static_cast<double>(strain.size()))) - 1);
  std::nth_element(strain.begin(), strain.begin() + static_cast<std::ptrdiff_t>(rank), strain.end());
  s.p99 = strain[rank];
  return s;
}

std::vector<float> particle_strain(const ClothModel& model, std::span<const Vec3f> x, SpringKind kind) {
  std::vector<float> out(model.particle_count(), 0.0f);
  const SpringRange r = model.range(kind);
  for (uint32_t k = r.begin; k < r.end; ++k) {
    const float rest = model.rest_length[k];
    if (rest <= 0) continue;
    const float e = ((x[model.spring_b[k]] - x[model.spring_a[k]]).norm() - rest) / rest;
    out[model.spring_a[k]] = std::max(out[model.spring_a[k]], e);
    out[model.spring_b[k]] = std::max(out[model.spring_b[k]], e);
  }
  return out;
}

ClothEnergy cloth_energy(const ClothModel& model, const ClothState& state, const Vec3f& gravity) {
  ClothEnergy e;
  for (size_t i = 0; i < model.particle_count(); ++i) {
    e.kinetic += 0.5 * model.mass[i] * state.v[i].squaredNorm();
    e.gravitational -= static_cast<double>(model.mass[i]) * gravity.dot(state.x[i]);
  }
  for (size_t s = 0; s < model.spring_count(); ++s) {
    const double stretch = (state.x[model.spring_b[s]] - state.x[model.spring_a[s]]).norm() - model.rest_length[s];
    e.elastic += 0.5 * model.stiffness[s] * stretch * stretch;
  }
  return e;
}

std::vector<Vec3f> spring_forces_per_particle(const ClothModel& model, std::span<const Vec3f> x,
                                              std::span<const Vec3f> v) {
  std::vector<Vec3f> f(model.particle_count(), Vec3f::Zero());
  for (size_t s = 0; s < model.spring_count(); ++s) {
    const uint32_t a = model.spring_a[s], b = model.spring_b[s];
    const Vec3f fa = sim::spring_force(x[a], x[b], v[a], v[b], model.rest_length[s], model.stiffness[s], model.damping[s]);
    f[a] += fa;
    f[b] -= fa;
  }
  return f;
}

uint64_t state_hash(const ClothState& state) {
  uint64_t h = 1469598103934665603ull;
  const auto mix = [&](const std::vector<Vec3f>& values) {
    for (const Vec3f& p : values)
      for (int k = 0; k < 3; ++k) {
        const uint32_t bits = std::bit_cast<uint32_t>(p[k]);
        for (int byte = 0; byte < 4; ++byte) h = (h ^ ((bits >> (8 * byte)) & 0xffu)) * 1099511628211ull;
      }
  };
  mix(state.x);
  mix(state.v);
  return h;
}

Mesh cloth_mesh(const ClothModel& model, const ClothState& state, std::string name) {
  Mesh mesh;
  mesh.name = std::move(name);
  mesh.positions = state.x;
  mesh.triangles = model.triangles;
  mesh.uvs = model.flat_position;
  mesh.normals = vertex_normals(mesh.positions, mesh.triangles);
  return mesh;
}

}  // namespace drape
