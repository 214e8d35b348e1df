// A dressed garment carried onto another body of the same mesh; see drape/garment_transfer.hpp.
#include "drape/garment_transfer.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "collision/body_surface.hpp"
#include "collision/triangle_bvh.hpp"
#include "drape/dress.hpp"

namespace drape {
namespace {

// The frame a particle's offset is measured in: the triangle's first edge, the direction across it
// in the triangle's plane, and the triangle's normal (all unit). A degenerate triangle gives the
// world axes, which keeps the offset as it was.
std::array<Vec3f, 3> triangle_frame(const Vec3f& a, const Vec3f& b, const Vec3f& c) {
  const Vec3f e1 = b - a;
  const Vec3f n = e1.cross(c - a);
  if (e1.squaredNorm() < 1e-20f || n.squaredNorm() < 1e-20f) return {Vec3f::UnitX(), Vec3f::UnitY(), Vec3f::UnitZ()};
  const Vec3f u = e1.normalized(), w = n.normalized();
  return {u, w.cross(u), w};
}

}  // namespace

uint64_t mesh_fingerprint(const Mesh& mesh) {
  // FNV-1a over the vertex count and the triangles' corners: cheap, and any other mesh differs.
  uint64_t h = 1469598103934665603ull;
  const auto mix = [&h](uint64_t v) {
    for (int byte = 0; byte < 8; ++byte) {
      h ^= (v >> (8 * byte)) & 0xffu;
      h *= 1099511628211ull;
    }
  };
  mix(mesh.positions.size());
  for (const Tri& t : mesh.triangles) mix((uint64_t{t[0]} << 42) ^ (uint64_t{t[1]} << 21) ^ uint64_t{t[2]});
  return h;
}

bool GarmentTransfer::matches(std::string_view g, std::string_view s, size_t n, uint64_t body) const {
  return garment == g && size == s && particles == n && body_mesh == body;
}

GarmentTransfer make_garment_transfer(const Body& body, const DressedGarment& g) {
  GarmentTransfer t;
  t.garment = g.name;
  t.size = g.size;
  t.particles = g.state.x.size();
  t.body_mesh = mesh_fingerprint(body.mesh);
  t.body_measurements = body.measurements;
  t.triangle.resize(t.particles);
  t.where.resize(t.particles);
  const collision::BodySurface surface(body.mesh.positions, body.mesh.triangles);
  const collision::TriangleBvh bvh(surface, false);
  for (size_t i = 0; i < t.particles; ++i) {
    const Vec3f& p = g.state.x[i];
    collision::SurfaceHit hit;
    if (!bvh.closest(p, std::numeric_limits<float>::infinity(), hit))
      throw std::invalid_argument(fmt::format("garment transfer: no body triangle near particle {} of {}", i, g.name));
    const Tri& tri = body.mesh.triangles[hit.triangle];
    const auto frame = triangle_frame(body.mesh.positions[tri[0]], body.mesh.positions[tri[1]], body.mesh.positions[tri[2]]);
    const Vec3f d = p - hit.where.point;
    t.triangle[i] = hit.triangle;
    t.where[i] = {hit.where.b1, hit.where.b2, d.dot(frame[0]), d.dot(frame[1]), d.dot(frame[2])};
  }
  return t;
}

std::vector<Vec3f> transfer_positions(const GarmentTransfer& t, const Mesh& body) {
  if (mesh_fingerprint(body) != t.body_mesh)
    throw std::invalid_argument(fmt::format("garment transfer of {}: the body's mesh ({} vertices, {} triangles) is "
                                            "not the mesh the garment was dressed on",
                                            t.garment, body.positions.size(), body.triangles.size()));
  std::vector<Vec3f> x(t.particles);
  for (size_t i = 0; i < t.particles; ++i) {
    const Tri& tri = body.triangles[t.triangle[i]];
    const Vec3f &a = body.positions[tri[0]], &b = body.positions[tri[1]], &c = body.positions[tri[2]];
    const auto& w = t.where[i];
    const auto frame = triangle_frame(a, b, c);
    x[i] = (1 - w[0] - w[1]) * a + w[0] * b + w[1] * c + w[2] * frame[0] + w[3] * frame[1] + w[4] * frame[2];
  }
  return x;
}

std::vector<std::shared_ptr<const GarmentTransfer>> GarmentTransferStore::for_body(const std::string& garment,
                                                                                   const std::string& size,
                                                                                   const Body& body) const {
  std::vector<std::shared_ptr<const GarmentTransfer>> out;
  {
    const std::lock_guard lock(mutex_);
    const auto it = kept_.find(Key{garment, size, mesh_fingerprint(body.mesh)});
    if (it == kept_.end()) return out;
    out.assign(it->second.begin(), it->second.end());
  }
  const auto distance = [&body](const GarmentTransfer& t) {
    double sum = 0;
    for (float Measurements::*field : {&Measurements::height, &Measurements::bust, &Measurements::waist, &Measurements::hips}) {
      const double want = body.measurements.*field, had = t.body_measurements.*field;
      const double rel = want > 0 ? (had - want) / want : 0.0;
      sum += rel * rel;
    }
    return std::sqrt(sum / 4.0);
  };
  std::erase_if(out, [&](const auto& t) { return distance(*t) > max_difference_; });
  std::stable_sort(out.begin(), out.end(), [&](const auto& a, const auto& b) { return distance(*a) < distance(*b); });
  return out;
}

void GarmentTransferStore::add(std::shared_ptr<const GarmentTransfer> transfer) {
  if (!transfer || per_key_ == 0) return;
  const std::lock_guard lock(mutex_);
  auto& kept = kept_[Key{transfer->garment, transfer->size, transfer->body_mesh}];
  kept.push_front(std::move(transfer));
  while (kept.size() > per_key_) kept.pop_back();
}

size_t GarmentTransferStore::size() const {
  const std::lock_guard lock(mutex_);
  size_t n = 0;
  for (const auto& [key, kept] : kept_) n += kept.size();
  return n;
}

}  // namespace drape
