#pragma once
// Exact closest-point queries near a static body in O(1) cells: a uniform grid around the surface
// where every cell within `band` of it lists the body triangles that can be nearest to some point
// of the cell, sorted by their distance to the cell centre. The paper's object-space method and
// most cloth systems of its time (sec. 1: "voxel or octree subdivision") cut space the same way.
//
// Why a list per cell and not only a tree: a tree query must descend from the root, and near a
// curved surface the boxes of many leaves overlap the query sphere (Embree's rtcPointQuery measured
// about 580 ns per cloth vertex on the 47.5k-triangle mean body, the hand-made box BVH 1.1 us). A
// cell's list answers with about 3 point-triangle tests.
//
// Correctness: for a point p in a cell with centre c and half diagonal r, U (the largest distance
// from a corner of the cell to the centre's nearest triangle) bounds d(p, body) from above. A
// triangle T, with q its point nearest c and u = (c - q) / |c - q|, lies behind the plane through q
// across u (T is convex), so d(p, T) >= d(c, T) + (p - c) . u >= d(c, T) - h(u), h(u) the cell's
// half extent along u. The list keeps every T with d(c, T) - h(u) <= U: the nearest triangle of
// any p of the cell is among them. A scan in order of d(c, T) skips T when d(c, T) + (p - c) . u
// reaches the best distance so far and stops once d(c, T) - |p - c| does (no later one can be
// nearer). Cells beyond the band store no list: a point there is at least band - r from the body.
#include <cstdint>
#include <functional>
#include <vector>

#include "collision/body_surface.hpp"

namespace drape::collision {

class TriangleBvh;

class CandidateGrid {
 public:
  // Built over the surface's current pose, with the BVH (same pose) answering the build's searches.
  // `wanted` (optional): only cells whose box it accepts get a list; the others, where a caller
  // never asks (the image collider asks only over its hidden pixels), hold a kTruncated entry at
  // distance 0, so a query there goes to the tree: answers stay exact wherever they are asked.
  using CellFilter = std::function<bool(const Bounds& cell)>;
  CandidateGrid(const TriangleBvh& bvh, float cell, float band, const CellFilter& wanted = {});

  enum class Answer : uint8_t { kFound, kNone, kUnknown, kTruncatedFound, kTruncatedNone };
  // kFound: hit is the exact nearest point, within radius. kNone: nothing lies within radius.
  // kUnknown: p lies outside the listed cells and the radius reaches beyond them: ask the tree.
  // kTruncated*: the scan reached the end of a shortened list (see kMaxList) before it could stop:
  // hit is the best so far (kTruncatedFound) or there is none; the tree must look for a nearer one.
  Answer closest(const Vec3f& p, float radius, SurfaceHit& hit) const { return closest_in(cell_of(p), p, radius, hit); }

  // The same in steps, for a batch of queries: the grid is tens of MB, so one query is a chain of
  // cache misses (the cell's offsets, its list, its triangles). A batch finds every point's cell,
  // then prefetches the offsets of all, the lists of all, the triangles of all, and only then
  // answers them, so the misses of many points overlap. Each step reads only what the one before
  // fetched. Results are those of closest().
  static constexpr size_t npos = ~size_t{0};
  size_t cell_of(const Vec3f& p) const;  // npos outside the grid
  void prefetch_offsets(size_t cell) const {
    if (cell != npos) __builtin_prefetch(&first_[cell]);
  }
  void prefetch_list(size_t cell) const;
  void prefetch_triangles(size_t cell) const;
  Answer closest_in(size_t cell, const Vec3f& p, float radius, SurfaceHit& hit) const;

  float band() const { return band_; }
  size_t memory_bytes() const {
    return first_.size() * sizeof(uint32_t) + candidates_.size() * sizeof(Candidate) + records_.size() * sizeof(Record);
  }
  double mean_list_length() const;
  size_t listed_cells() const;  // cells with a list of their own (not left out by the filter)

 private:
  // A copy of one triangle's corners next to its id, in Morton order of the centroids: a cell's
  // candidates lie in neighbouring cache lines instead of 4 scattered reads each (index triple and
  // three vertices); one cache line per record.
  struct alignas(64) Record {
    Vec3f a, b, c;
    uint32_t triangle;
  };
  // 8 bytes per list entry (the lists are most of the grid's memory).
  struct Candidate {
    uint16_t record_low;  // index into records_ (24 bits); kTruncated: the list goes on beyond this entry
    uint8_t record_high;
    // Unit direction from the triangle's point nearest the centre to the centre (zero when the
    // triangle passes through it), times 127, rounded. The triangle is convex, so it lies behind the
    // plane through that point across this direction: d(p, T) >= d(centre, T) + (p - centre) . away
    // (less |p - centre| kAwayError for the rounding).
    int8_t away[3];
    uint16_t distance;  // d(centre, T) in distance_unit_, rounded down; of the first left out for kTruncated
    uint32_t record() const { return record_low | (uint32_t{record_high} << 16); }
  };
  static constexpr float kAwayError = 0.007f;  // >= |u - rounded u| = sqrt(3) / 254
  static constexpr uint32_t kTruncated = 0xffffff;

  // Lists are cut after this many triangles (a scan stops after about 7 on a body), ending in a
  // kTruncated entry: it keeps the grid small enough to stay in cache.
  static constexpr uint32_t kMaxList = 64;

  const BodySurface& surface_;
  float cell_, band_, half_diagonal_, distance_unit_;
  Vec3f origin_ = Vec3f::Zero();
  uint32_t dims_[3] = {0, 0, 0};
  std::vector<uint32_t> first_;  // per cell + 1: the cell's candidates are [first_[c], first_[c + 1])
  std::vector<Candidate> candidates_;
  std::vector<Record> records_;
  std::vector<uint32_t> record_of_;  // triangle -> its record
};

}  // namespace drape::collision
