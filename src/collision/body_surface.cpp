// Body surface geometry for the collision layer; see body_surface.hpp.
#include "collision/body_surface.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <stdexcept>
#include <unordered_map>

namespace drape::collision {
namespace {

uint64_t edge_key(uint32_t a, uint32_t b) {
  if (a > b) std::swap(a, b);
  return (uint64_t{a} << 32) | b;
}

// Interior angle of triangle (a, b, c) at corner a.
float corner_angle(const Vec3f& a, const Vec3f& b, const Vec3f& c) {
  const Vec3f u = b - a, v = c - a;
  return std::atan2(u.cross(v).norm(), u.dot(v));
}

}  // namespace

BodySurface::BodySurface(std::span<const Vec3f> positions, std::span<const Tri> triangles)
    : triangles_(triangles.begin(), triangles.end()) {
  const size_t n = positions.size();
  for (const Tri& t : triangles_)
    for (uint32_t v : t)
      if (v >= n) throw std::invalid_argument("body mesh: triangle index out of range");

  // Weld vertices at bit-identical positions (split at UV or normal seams) so seams are not holes.
  canonical_.resize(n);
  std::unordered_map<std::string, uint32_t> first_at;
  first_at.reserve(n);
  for (uint32_t v = 0; v < n; ++v) {
    std::string key(sizeof(float) * 3, '\0');
    std::memcpy(key.data(), positions[v].data(), sizeof(float) * 3);
    canonical_[v] = first_at.emplace(std::move(key), v).first->second;
  }

  // Edge adjacency over welded vertices: an edge used by exactly two triangles is closed.
  std::unordered_map<uint64_t, std::array<int32_t, 3>> uses;  // first two triangles and the use count
  uses.reserve(triangles_.size() * 2);
  for (size_t t = 0; t < triangles_.size(); ++t)
    for (int k = 0; k < 3; ++k) {
      const uint64_t key = edge_key(canonical_[triangles_[t][k]], canonical_[triangles_[t][(k + 1) % 3]]);
      auto [it, fresh] = uses.try_emplace(key, std::array<int32_t, 3>{static_cast<int32_t>(t), -1, 0});
      if (!fresh && it->second[2] == 1) it->second[1] = static_cast<int32_t>(t);
      ++it->second[2];
    }
  edge_neighbor_.resize(triangles_.size());
  vertex_open_.assign(n, 0);
  for (size_t t = 0; t < triangles_.size(); ++t)
    for (int k = 0; k < 3; ++k) {
      const uint32_t a = canonical_[triangles_[t][k]], b = canonical_[triangles_[t][(k + 1) % 3]];
      const auto& use = uses.at(edge_key(a, b));
      if (use[2] == 2) {
        edge_neighbor_[t][k] = use[0] == static_cast<int32_t>(t) ? use[1] : use[0];
      } else {
        edge_neighbor_[t][k] = -1;
        vertex_open_[a] = vertex_open_[b] = 1;
        closed_ = false;
      }
    }

  face_normals_.resize(triangles_.size());
  edge_pseudo_normals_.resize(triangles_.size());
  if (!closed_) winding_ = WindingNumberTree(positions, triangles_);
  set_positions(positions, 0.0);
}

void BodySurface::set_positions(std::span<const Vec3f> positions, double t) {
  if (positions.size() != canonical_.size())
    throw std::invalid_argument("body pose: vertex count differs from the body mesh");
  if (has_pose_) {
    previous_.swap(positions_);
    positions_.assign(positions.begin(), positions.end());
    const double dt = t - time_;
    velocities_.resize(positions_.size());
    for (size_t v = 0; v < positions_.size(); ++v)
      velocities_[v] = dt > 0 ? Vec3f((positions_[v] - previous_[v]) / static_cast<float>(dt)) : Vec3f::Zero();
  } else {
    positions_.assign(positions.begin(), positions.end());
    velocities_.assign(positions_.size(), Vec3f::Zero());
  }
  time_ = t;
  has_pose_ = true;
  moving_ = std::any_of(velocities_.begin(), velocities_.end(), [](const Vec3f& v) { return v != Vec3f::Zero(); });

  // Face normals; smooth normals (area-weighted) and vertex pseudo-normals (angle-weighted, welded).
  smooth_normals_.assign(positions_.size(), Vec3f::Zero());
  vertex_pseudo_normals_.assign(positions_.size(), Vec3f::Zero());
  for (size_t f = 0; f < triangles_.size(); ++f) {
    const Tri& tri = triangles_[f];
    const Vec3f& a = positions_[tri[0]];
    const Vec3f& b = positions_[tri[1]];
    const Vec3f& c = positions_[tri[2]];
    const Vec3f area_vector = (b - a).cross(c - a);
    const float len = area_vector.norm();
    face_normals_[f] = len > 0 ? Vec3f(area_vector / len) : Vec3f::Zero();
    const float angles[3] = {corner_angle(a, b, c), corner_angle(b, c, a), corner_angle(c, a, b)};
    for (int k = 0; k < 3; ++k) {
      smooth_normals_[canonical_[tri[k]]] += area_vector;
      vertex_pseudo_normals_[canonical_[tri[k]]] += angles[k] * face_normals_[f];
    }
  }
  for (size_t v = 0; v < positions_.size(); ++v) {
    const uint32_t c = canonical_[v];
    smooth_normals_[v] = smooth_normals_[c].normalized();
    vertex_pseudo_normals_[v] = vertex_pseudo_normals_[c];
  }
  for (size_t f = 0; f < triangles_.size(); ++f)
    for (int k = 0; k < 3; ++k) {
      const int32_t other = edge_neighbor_[f][k];
      edge_pseudo_normals_[f][k] = face_normals_[f] + (other >= 0 ? face_normals_[static_cast<size_t>(other)] : Vec3f::Zero());
    }
  if (!closed_) winding_.refit(positions_);
}

Vec3f BodySurface::pseudo_normal(const SurfaceHit& hit, bool& open) const {
  const Tri& tri = triangles_[hit.triangle];
  auto vertex = [&](int k) {
    open = vertex_open_[canonical_[tri[k]]] != 0;
    return vertex_pseudo_normals_[tri[k]];
  };
  auto edge = [&](int k) {
    open = edge_neighbor_[hit.triangle][k] < 0;
    return edge_pseudo_normals_[hit.triangle][k];
  };
  open = false;
  switch (hit.where.feature) {
    case TriangleFeature::kVertex0: return vertex(0);
    case TriangleFeature::kVertex1: return vertex(1);
    case TriangleFeature::kVertex2: return vertex(2);
    case TriangleFeature::kEdge01: return edge(0);
    case TriangleFeature::kEdge12: return edge(1);
    case TriangleFeature::kEdge20: return edge(2);
    case TriangleFeature::kFace: break;
  }
  return face_normals_[hit.triangle];
}

void BodySurface::prefetch(const SurfaceHit& hit, int step) const {
  const uint32_t t = hit.triangle;
  const TriangleFeature feature = hit.where.feature;
  const bool on_vertex = feature == TriangleFeature::kVertex0 || feature == TriangleFeature::kVertex1 || feature == TriangleFeature::kVertex2;
  if (step == 0) {
    __builtin_prefetch(&triangles_[t]);
    if (feature == TriangleFeature::kFace) {
      __builtin_prefetch(&face_normals_[t]);
    } else if (!on_vertex) {
      __builtin_prefetch(&edge_pseudo_normals_[t]);
      __builtin_prefetch(&edge_neighbor_[t]);
    }
    return;
  }
  for (uint32_t v : triangles_[t]) {
    __builtin_prefetch(&smooth_normals_[v]);
    if (moving_) __builtin_prefetch(&velocities_[v]);
  }
  if (on_vertex) {
    const uint32_t v = triangles_[t][static_cast<size_t>(feature)];  // kVertexK == K
    __builtin_prefetch(&vertex_pseudo_normals_[v]);
    __builtin_prefetch(&canonical_[v]);
  }
}

float BodySurface::sign(const SurfaceHit& hit, const Vec3f& p) const {
  bool open = false;
  const Vec3f n = pseudo_normal(hit, open);
  if (open) return winding_.winding_number(p) > 0.5 ? -1.0f : 1.0f;
  return (p - hit.where.point).dot(n) < 0.0f ? -1.0f : 1.0f;
}

Vec3f BodySurface::smooth_normal(const SurfaceHit& hit) const {
  const Tri& tri = triangles_[hit.triangle];
  const float b1 = hit.where.b1, b2 = hit.where.b2;
  const Vec3f n = (1.0f - b1 - b2) * smooth_normals_[tri[0]] + b1 * smooth_normals_[tri[1]] + b2 * smooth_normals_[tri[2]];
  const float len = n.norm();
  return len > 0 ? Vec3f(n / len) : face_normals_[hit.triangle];
}

Vec3f BodySurface::velocity(const SurfaceHit& hit) const {
  const Tri& tri = triangles_[hit.triangle];
  const float b1 = hit.where.b1, b2 = hit.where.b2;
  return (1.0f - b1 - b2) * velocities_[tri[0]] + b1 * velocities_[tri[1]] + b2 * velocities_[tri[2]];
}

}  // namespace drape::collision
