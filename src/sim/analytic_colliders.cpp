// Analytic obstacles: exact signed distances and normals, plus display meshes.
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>

#include "drape/analytic_colliders.hpp"

namespace drape {

void AnalyticCollider::query(std::span<const Vec3f> points, float radius, std::span<ContactSample> out) const {
  for (size_t i = 0; i < points.size(); ++i) {
    Vec3f n;
    const float d = signed_distance(points[i], &n);
    out[i] = d <= radius ? ContactSample{d, n, velocity_} : ContactSample{std::numeric_limits<float>::infinity(), n, velocity_};
  }
}

PlaneCollider::PlaneCollider(const Vec3f& point, const Vec3f& normal, float display_size)
    : point_(point), normal_(normal.normalized()), display_size_(display_size) {
  if (!(normal.norm() > 0)) throw std::invalid_argument("PlaneCollider: zero normal");
}

float PlaneCollider::signed_distance(const Vec3f& p, Vec3f* normal) const {
  if (normal) *normal = normal_;
  return (p - point_ - offset_).dot(normal_);
}

Mesh PlaneCollider::mesh() const {
  const Vec3f t = (std::abs(normal_.x()) < 0.9f ? Vec3f::UnitX() : Vec3f::UnitY()).cross(normal_).normalized();
  const Vec3f s = normal_.cross(t);
  const float h = 0.5f * display_size_;
  Mesh m;
  m.name = "plane";
  const Vec3f c = point_ + offset_;
  m.positions = {c - h * t - h * s, c + h * t - h * s, c + h * t + h * s, c - h * t + h * s};
  m.triangles = {Tri{0, 2, 1}, Tri{0, 3, 2}};
  // Keep the winding counter-clockwise seen from the normal side.
  if ((m.positions[2] - m.positions[0]).cross(m.positions[1] - m.positions[0]).dot(normal_) < 0)
    for (Tri& tri : m.triangles) std::swap(tri[1], tri[2]);
  m.normals = vertex_normals(m.positions, m.triangles);
  return m;
}

SphereCollider::SphereCollider(const Vec3f& centre, float radius) : centre_(centre), radius_(radius) {
  if (!(radius > 0)) throw std::invalid_argument("SphereCollider: radius must be > 0");
}

float SphereCollider::signed_distance(const Vec3f& p, Vec3f* normal) const {
  const Vec3f d = p - centre_ - offset_;
  const float len = d.norm();
  if (normal) *normal = len > 0 ? Vec3f(d / len) : Vec3f::UnitY();
  return len - radius_;
}

Mesh SphereCollider::mesh() const {
  Mesh m;
  m.name = "sphere";
  const int rings = 48, segments = 96;
  const Vec3f c = centre_ + offset_;
  for (int r = 0; r <= rings; ++r) {
    const float theta = std::numbers::pi_v<float> * static_cast<float>(r) / rings;
    for (int s = 0; s <= segments; ++s) {
      const float phi = 2 * std::numbers::pi_v<float> * static_cast<float>(s) / segments;
      const Vec3f n(std::sin(theta) * std::cos(phi), std::cos(theta), -std::sin(theta) * std::sin(phi));
      m.positions.push_back(c + radius_ * n);
      m.normals.push_back(n);
    }
  }
  const uint32_t row = segments + 1;
  for (uint32_t r = 0; r < static_cast<uint32_t>(rings); ++r)
    for (uint32_t s = 0; s < static_cast<uint32_t>(segments); ++s) {
      const uint32_t i = r * row + s;
      if (r > 0) m.triangles.push_back({i, i + row, i + 1});
      if (r + 1 < static_cast<uint32_t>(rings)) m.triangles.push_back({i + 1, i + row, i + row + 1});
    }
  return m;
}

BoxCollider::BoxCollider(const Vec3f& centre, const Vec3f& half_extent) : centre_(centre), half_(half_extent) {
  if (!(half_extent.minCoeff() > 0)) throw std::invalid_argument("BoxCollider: half extents must be > 0");
}

// Outside: distance to the nearest point of the box, normal towards the point. Inside: distance to
// the nearest face (negative), that face's normal.
float BoxCollider::signed_distance(const Vec3f& p, Vec3f* normal) const {
  const Vec3f local = p - centre_ - offset_;
  const Vec3f q = local.cwiseAbs() - half_;
  const Vec3f outside = q.cwiseMax(0.0f);
  const float out_len = outside.norm();
  if (out_len > 0) {
    if (normal) {
      Vec3f n = outside / out_len;
      for (int k = 0; k < 3; ++k) n[k] = std::copysign(n[k], local[k]);
      *normal = n;
    }
    return out_len;
  }
  int axis = 0;
  q.maxCoeff(&axis);
  if (normal) {
    *normal = Vec3f::Zero();
    (*normal)[axis] = local[axis] >= 0 ? 1.0f : -1.0f;
  }
  return q[axis];
}

Mesh BoxCollider::mesh() const {
  Mesh m;
  m.name = "box";
  const Vec3f c = centre_ + offset_;
  // Each face with its own four corners, so normals stay flat.
  for (int axis = 0; axis < 3; ++axis)
    for (int side = -1; side <= 1; side += 2) {
      Vec3f n = Vec3f::Zero();
      n[axis] = static_cast<float>(side);
      const int u = (axis + 1) % 3, v = (axis + 2) % 3;
      const uint32_t base = static_cast<uint32_t>(m.positions.size());
      const float corners[4][2] = {{-1, -1}, {1, -1}, {1, 1}, {-1, 1}};
      for (const auto& cc : corners) {
        Vec3f p = c;
        p[axis] += side * half_[axis];
        p[u] += cc[0] * half_[u];
        p[v] += cc[1] * half_[v];
        m.positions.push_back(p);
        m.normals.push_back(n);
      }
      if (side > 0) {
        m.triangles.push_back({base, base + 1, base + 2});
        m.triangles.push_back({base, base + 2, base + 3});
      } else {
        m.triangles.push_back({base, base + 2, base + 1});
        m.triangles.push_back({base, base + 3, base + 2});
      }
    }
  return m;
}

CapsuleCollider::CapsuleCollider(const Vec3f& a, const Vec3f& b, float radius) : a_(a), b_(b), radius_(radius) {
  if (!(radius > 0)) throw std::invalid_argument("CapsuleCollider: radius must be > 0");
}

float CapsuleCollider::signed_distance(const Vec3f& p, Vec3f* normal) const {
  const Vec3f a = a_ + offset_, ab = b_ - a_;
  const float len2 = ab.squaredNorm();
  const float t = len2 > 0 ? std::clamp((p - a).dot(ab) / len2, 0.0f, 1.0f) : 0.0f;
  const Vec3f d = p - (a + t * ab);
  const float len = d.norm();
  if (normal) {
    Vec3f fallback = ab.unitOrthogonal();
    *normal = len > 0 ? Vec3f(d / len) : fallback;
  }
  return len - radius_;
}

Mesh CapsuleCollider::mesh() const {
  // A cylinder between two hemispheres: latitude rings of a sphere split at the equator.
  Mesh m;
  m.name = "capsule";
  const Vec3f a = a_ + offset_, b = b_ + offset_;
  Vec3f axis = b - a;
  const float length = axis.norm();
  axis = length > 0 ? Vec3f(axis / length) : Vec3f::UnitY();
  const Vec3f e1 = axis.unitOrthogonal(), e2 = axis.cross(e1);
  const int rings = 24, segments = 48;  // rings per hemisphere
  for (int r = 0; r <= 2 * rings + 1; ++r) {
    const bool top = r > rings;
    const int rr = top ? r - 1 : r;
    const float theta = std::numbers::pi_v<float> * static_cast<float>(rr) / (2 * rings);  // 0 at the b pole
    const Vec3f centre = top ? a : b;
    for (int s = 0; s <= segments; ++s) {
      const float phi = 2 * std::numbers::pi_v<float> * static_cast<float>(s) / segments;
      const Vec3f n = std::cos(theta) * axis + std::sin(theta) * (std::cos(phi) * e1 + std::sin(phi) * e2);
      m.positions.push_back(centre + radius_ * n);
      m.normals.push_back(n);
    }
  }
  const uint32_t row = segments + 1, rows = 2 * rings + 2;
  for (uint32_t r = 0; r + 1 < rows; ++r)
    for (uint32_t s = 0; s < static_cast<uint32_t>(segments); ++s) {
      const uint32_t i = r * row + s;
      m.triangles.push_back({i, i + row, i + 1});
      m.triangles.push_back({i + 1, i + row, i + row + 1});
    }
  // Drop degenerate triangles at the poles.
  std::erase_if(m.triangles, [&](const Tri& t) {
    return (m.positions[t[1]] - m.positions[t[0]]).cross(m.positions[t[2]] - m.positions[t[0]]).squaredNorm() < 1e-16f;
  });
  return m;
}

CylinderCollider::CylinderCollider(const Vec3f& top_centre, float radius, float height)
    : top_(top_centre), radius_(radius), height_(height) {
  if (!(radius > 0) || !(height > 0)) throw std::invalid_argument("CylinderCollider: radius and height must be > 0");
}

// In the (radial, axial) half-plane the cylinder is a rectangle: the box's distance in 2D.
float CylinderCollider::signed_distance(const Vec3f& p, Vec3f* normal) const {
  const Vec3f local = p - top_ - offset_;
  const Vec2f radial(local.x(), local.z());
  const float r = radial.norm();
  const Vec2f out_dir = r > 0 ? Vec2f(radial / r) : Vec2f(1.0f, 0.0f);
  const float half = 0.5f * height_;
  const float axial = local.y() + half;  // from the middle of the cylinder
  const Vec2f q(r - radius_, std::abs(axial) - half);
  const float up = axial >= 0 ? 1.0f : -1.0f;
  const Vec2f outside = q.cwiseMax(0.0f);
  const float out_len = outside.norm();
  if (out_len > 0) {
    if (normal) {
      const Vec2f n = outside / out_len;
      *normal = Vec3f(n.x() * out_dir.x(), n.y() * up, n.x() * out_dir.y());
    }
    return out_len;
  }
  const bool side = q.x() > q.y();
  if (normal) *normal = side ? Vec3f(out_dir.x(), 0.0f, out_dir.y()) : Vec3f(0.0f, up, 0.0f);
  return side ? q.x() : q.y();
}

Mesh CylinderCollider::mesh() const {
  Mesh m;
  m.name = "cylinder";
  const Vec3f top = top_ + offset_, bottom = top - Vec3f(0.0f, height_, 0.0f);
  const int segments = 96;
  const auto ring = [&](const Vec3f& centre, bool side, float ny) {
    for (int s = 0; s <= segments; ++s) {
      const float phi = 2 * std::numbers::pi_v<float> * static_cast<float>(s) / segments;
      const Vec3f radial(std::cos(phi), 0.0f, -std::sin(phi));
      m.positions.push_back(centre + radius_ * radial);
      m.normals.push_back(side ? radial : Vec3f(0.0f, ny, 0.0f));
    }
  };
  const uint32_t row = segments + 1;
  // The side: two rings with radial normals; counter-clockwise seen from outside.
  ring(bottom, true, 0.0f);
  ring(top, true, 0.0f);
  for (uint32_t s = 0; s < static_cast<uint32_t>(segments); ++s) {
    m.triangles.push_back({s, s + 1, s + row});
    m.triangles.push_back({s + 1, s + row + 1, s + row});
  }
  // The ends: a fan each, facing up and down.
  for (int end = 0; end < 2; ++end) {
    const bool upper = end == 0;
    const Vec3f centre = upper ? top : bottom;
    const uint32_t hub = static_cast<uint32_t>(m.positions.size());
    m.positions.push_back(centre);
    m.normals.push_back(Vec3f(0.0f, upper ? 1.0f : -1.0f, 0.0f));
    ring(centre, false, upper ? 1.0f : -1.0f);
    for (uint32_t s = 0; s < static_cast<uint32_t>(segments); ++s) {
      if (upper) m.triangles.push_back({hub, hub + 1 + s, hub + 2 + s});
      else m.triangles.push_back({hub, hub + 2 + s, hub + 1 + s});
    }
  }
  return m;
}

}  // namespace drape
