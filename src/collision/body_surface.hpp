#pragma once
// The body as the collision layer sees it: current vertex positions of a fixed-topology triangle
// mesh, with what every method needs per pose: unit face normals, smooth (area-weighted) vertex
// normals for the response, angle-weighted vertex and edge pseudo-normals for the sign of the
// distance (Baerentzen & Aanaes 2005), and vertex velocities by finite difference between poses.
// Where the mesh is open (holes, non-manifold edges) the pseudo-normal sign is not defined and the
// generalized winding number decides instead.
#include <Eigen/Geometry>
#include <array>
#include <span>
#include <vector>

#include "collision/triangle_closest.hpp"
#include "collision/winding_number.hpp"
#include "drape/mesh.hpp"

namespace drape::collision {

// The nearest point of the body to a query point.
struct SurfaceHit {
  uint32_t triangle = 0;
  TrianglePoint where{};
  float distance = 0;  // unsigned
};

class BodySurface {
 public:
  BodySurface(std::span<const Vec3f> positions, std::span<const Tri> triangles);

  // A new pose at time t; velocities are (positions - previous) / (t - previous t), zero for the first pose.
  void set_positions(std::span<const Vec3f> positions, double t);

  size_t vertex_count() const { return positions_.size(); }
  size_t triangle_count() const { return triangles_.size(); }
  bool closed() const { return closed_; }
  double time() const { return time_; }
  std::span<const Vec3f> positions() const { return positions_; }
  std::span<const Tri> triangles() const { return triangles_; }
  std::span<const Vec3f> smooth_normals() const { return smooth_normals_; }
  std::span<const Vec3f> velocities() const { return velocities_; }
  const Tri& triangle(uint32_t t) const { return triangles_[t]; }
  const Vec3f& position(uint32_t v) const { return positions_[v]; }

  // Closest point on triangle t to p.
  SurfaceHit closest_on(uint32_t t, const Vec3f& p) const {
    const Tri& tri = triangles_[t];
    SurfaceHit hit;
    hit.triangle = t;
    hit.where = closest_on_triangle(p, positions_[tri[0]], positions_[tri[1]], positions_[tri[2]]);
    hit.distance = (hit.where.point - p).norm();
    return hit;
  }
  // +1 when p lies outside the body at its nearest point `hit`, -1 inside.
  float sign(const SurfaceHit& hit, const Vec3f& p) const;
  // Unit interpolated vertex normal at the hit (what a renderer's normal buffer holds).
  Vec3f smooth_normal(const SurfaceHit& hit) const;
  Vec3f velocity(const SurfaceHit& hit) const;
  // False while every vertex velocity is zero (a static body): velocity() is then zero everywhere.
  bool moving() const { return moving_; }

  // Prefetch what sign(), smooth_normal() and velocity() will read for `hit`, in two steps for a
  // batch of hits (step 0: the triangle's own entries; step 1: its vertices', which needs step 0's).
  void prefetch(const SurfaceHit& hit, int step) const;

 private:
  Vec3f pseudo_normal(const SurfaceHit& hit, bool& open) const;

  std::vector<Tri> triangles_;
  std::vector<Vec3f> positions_, previous_, velocities_;
  std::vector<Vec3f> face_normals_, smooth_normals_, vertex_pseudo_normals_;
  std::vector<std::array<Vec3f, 3>> edge_pseudo_normals_;  // per triangle, edge k joins corners k and k+1
  std::vector<std::array<int32_t, 3>> edge_neighbor_;      // triangle across edge k; -1 when open
  std::vector<uint32_t> canonical_;                        // vertex -> first vertex at the same position
  std::vector<uint8_t> vertex_open_;                       // by canonical vertex
  bool closed_ = true;
  double time_ = 0;
  bool has_pose_ = false;
  bool moving_ = false;
  WindingNumberTree winding_;  // built only for open meshes
};

}  // namespace drape::collision
