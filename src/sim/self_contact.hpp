#pragma once
// Self-contact of a cloth: which particles are near a triangle of the same cloth that is not part of
// their own neighbourhood on the pattern, for the implicit solver's self-contact penalty
// (docs/cloth.md, "Self-contact").
//
// A pair is a particle p and a triangle T with the point of T nearest to p (barycentric weights w)
// and a unit normal n pointing from T to p's side; the solver keeps n . (x_p - sum_j w_j x_j), the
// gap, at least the cloth's contact thickness. Which side p is on is taken from the step's start
// (the cloth is taken to be free of self-intersection there), so an iterate that carried p through
// T is pushed back, not further through.
//
// Excluded: the triangles with a corner within `exclusion` of p along the sewn cloth (over its
// structural and shear springs at their rest lengths, and across seams): there the cloth is
// continuous, and the penalty would fight the springs and the seams.
#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "drape/cloth.hpp"

namespace drape::sim {

struct SelfPair {
  uint32_t particle = 0;
  uint32_t triangle = 0;
  std::array<double, 3> weight{};  // of the triangle's corners at the nearest point
  Vec3d normal = Vec3d::UnitY();   // from the triangle towards the particle's side
};

class SelfContactFinder {
 public:
  // The model's triangles and springs; `exclusion` in metres along the sewn cloth.
  SelfContactFinder(const ClothModel& model, double exclusion);

  // Every pair whose particle lies within `radius` of the triangle at `x` (at most kPerParticle
  // nearest per particle), sides from `x_start`, in particle order: the same list on any number of
  // threads. Free particles only (`free`), none that `tangled` marks (one per particle, or empty:
  // none), nor triangles with a corner it marks. With `mark_tangled`, `tangled` is first made
  // anew from `x` (see crossings()). Allocates only while the lists grow.
  void find(std::span<const Vec3d> x, std::span<const Vec3d> x_start, std::span<const uint8_t> free, double radius,
            std::vector<SelfPair>& pairs, std::vector<uint8_t>& tangled, bool mark_tangled);

  // How many (edge, triangle) pairs of the cloth at `x` cross, leaving out those the pairs exclude:
  // the cloth passing through itself. `tangled` (optional): 1 for the ends of each crossing edge and
  // the corners of each crossed triangle, 2 for the particles one edge from those, 0 elsewhere.
  size_t crossings(std::span<const Vec3d> x, std::vector<uint8_t>* tangled = nullptr);

  static constexpr size_t kPerParticle = 8;
  // The default exclusion: twice the mean structural rest length (at least 2 mm).
  static double default_exclusion(const ClothModel& model);

 private:
  const ClothModel& model_;
  // Per particle, the triangles it never pairs with (sorted), CSR.
  std::vector<uint32_t> excluded_begin_, excluded_;
  // Spatial hash of the triangles' boxes grown by the radius (rebuilt by each find()). Written by
  // hand: a uniform grid rebuilt in one pass over a few thousand moving triangles, which a tree
  // library (Embree's BVH of the body collider) would rebuild at more cost for the same answer.
  std::vector<uint32_t> bucket_begin_, bucket_fill_, bucket_triangle_;
  std::vector<std::array<int32_t, 6>> cell_box_;  // per triangle: min and max cell
  std::vector<Vec3d> centre_;                     // per triangle: centre of its bounding sphere
  std::vector<double> bound_;                     // and its radius
  std::vector<SelfPair> slot_;                    // kPerParticle per particle
  std::vector<std::array<uint32_t, 2>> edges_;    // the triangles' edges, each once (a < b)
  std::vector<uint32_t> edge_crossings_, edge_first_;  // per edge: triangles it crosses, the first of them
  double inv_cell_ = 1.0;
  void build_grid(std::span<const Vec3d> x, double radius);
  uint32_t bucket_of(const Vec3d& p) const;
  bool excluded(uint32_t particle, uint32_t triangle) const;
  bool listed(uint32_t triangle, const Vec3d& p) const;  // p's cell is in the triangle's box of cells
  double longest_edge(std::span<const Vec3d> x) const;
  size_t crossings_on_grid(std::span<const Vec3d> x, std::vector<uint8_t>* tangled);  // on the grid built at x
  std::vector<uint8_t> slot_count_;
};

}  // namespace drape::sim
