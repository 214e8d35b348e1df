#pragma once
// Generalized winding number of a triangle mesh (Jacobson, Kavan & Sorkine-Hornung 2013): the sum of
// the signed solid angles of all triangles over 4 pi. ~1 inside a closed surface, ~0 outside, and it
// degrades gracefully (stays near 1/2 only close to the hole) when the surface has small holes, which
// ray parity does not. Evaluated hierarchically (Barill et al. 2018, "Fast winding numbers"): a
// cluster of triangles far from the query (distance > kFarFactor x its radius) contributes its
// first-order dipole term; near clusters are summed exactly (Van Oosterom & Strackee 1983).
// Hand-written: no Debian package provides it (libigl is not packaged for Debian 12).
#include <Eigen/Geometry>
#include <span>
#include <vector>

#include "drape/mesh.hpp"

namespace drape::collision {

class WindingNumberTree {
 public:
  WindingNumberTree() = default;
  WindingNumberTree(std::span<const Vec3f> positions, std::span<const Tri> triangles);

  // Same topology, new vertex positions (a moving body): recomputes the cluster moments bottom-up.
  void refit(std::span<const Vec3f> positions);

  double winding_number(const Vec3f& q) const;
  bool empty() const { return nodes_.empty(); }

 private:
  struct Node {
    Vec3d center = Vec3d::Zero();       // area-weighted centroid of the cluster
    Vec3d area_normal = Vec3d::Zero();  // sum of the triangles' area vectors (dipole moment)
    double area = 0;
    double radius = 0;                  // bounding sphere radius around center
    uint32_t begin = 0, end = 0;        // triangle range in tris_
    int32_t left = -1, right = -1;      // children (higher indices than the parent); -1 for a leaf
  };
  uint32_t build(uint32_t begin, uint32_t end, std::vector<Vec3f>& centroids);
  void fit_node(Node& node) const;

  static constexpr double kFarFactor = 2.5;
  static constexpr uint32_t kLeafSize = 8;

  std::vector<Node> nodes_;
  std::vector<Tri> tris_;  // triangles reordered so that each node's are contiguous
  std::vector<Vec3f> positions_;
};

// Signed solid angle of triangle (a, b, c) seen from q; positive when q is behind a counter-clockwise face.
double solid_angle(const Vec3d& q, const Vec3d& a, const Vec3d& b, const Vec3d& c);

}  // namespace drape::collision
