#pragma once
// A body that gives way under tight clothes: Vassilev's support springs (docs/soft-body.md,
// ../shared/papers/vassilev-deformable-body-support-springs.txt).
//
// The body's soft regions (belly, buttocks, thighs, bust, upper arms) are found from its landmarks
// and body parts; every other vertex (over bone: hip bones, shins, shoulders, collarbones, and the
// rest of the body) stays put. Each soft vertex hangs on a support spring from a point of an inner
// frame, `depth` straight in from it along its normal, and the surface is a membrane of springs
// along its edges. A region's springs act together (eq. 5 and 6):
//
//   l_tot = sum_i c_i l_i,    f_i = -c_i K (dl_tot + C dl_i) u_i,
//
// c_i = the vertex's area over the mean vertex area, u_i the spring's direction (the vertex's rest
// normal: the springs are perpendicular to the surface, and each one's length l_i is measured
// along it), K the collective stiffness and C in (0, 1) the share of each spring's own response:
// pressed in one place, a region bulges elsewhere and keeps its volume. Eq. 6 is the gradient of
//
//   E = K/2 (dl_tot^2 + C sum_i c_i dl_i^2),
//
// to which drape adds the tissue's resistance to sliding along the skin (the springs hold a vertex
// only along their direction). The body's rest under given forces is
// the minimum of E + membrane + sliding - forces . positions, found by Newton's method (each
// region's rank-one collective Hessian through Woodbury's identity on the sparse rest, factorised
// by Eigen's simplicial LDL^T).
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "drape/body.hpp"

namespace drape {

struct SoftBodyOptions {
  // Depth of the soft tissue over the frame (each support spring's rest length), m.
  float depth = 0.03f;
  // The tissue's stiffness under a flat press: pressure per metre of compression (Pa/m) of one
  // spring on its own (K C c_i = stiffness x the vertex's area). 1 kPa presses it in 1 cm: soft
  // tissue with a Young's modulus of about 3 kPa (fat; muscle at rest is a few times stiffer) over
  // the 3 cm depth.
  float tissue_stiffness = 1.0e5f;
  // C of eq. 6: the share of a spring's own response beside the region's collective one.
  float individual = 0.05f;
  // The tissue's resistance to sliding along the skin, as a share of its stiffness under a press
  // (the support springs hold a vertex only along the normal, the membrane only where stretched).
  float shear = 0.5f;
  // The membrane: springs along the surface's edges, as stiff as this (N/m) per metre of edge
  // length over the edge's rest length (a sheet's tension per unit strain).
  float membrane = 40.0f;
};

struct SoftRegion {
  std::string name;                // belly, buttocks, left_thigh, right_thigh, bust, left_upper_arm, right_upper_arm
  std::vector<uint32_t> vertices;  // body vertices
};

struct SoftBody {
  std::vector<SoftRegion> regions;
  std::vector<int> region_of;      // per body vertex: index into regions, -1 where it stays put
  std::vector<Vec3f> rest;         // the body's positions
  std::vector<Vec3f> frame;        // per body vertex: the inner frame point (soft vertices)
  std::vector<float> weight;       // per body vertex: c_i
  std::vector<float> area;         // per body vertex: a third of its triangles' area, m^2
  std::vector<std::array<uint32_t, 2>> edges;  // membrane springs with at least one soft end
  std::vector<float> edge_rest;
  SoftBodyOptions options;
  float collective = 0;            // K
  size_t soft_count() const;
};

// The soft regions of `body` (its landmarks and parts) with their springs.
SoftBody make_soft_body(const Body& body, const SoftBodyOptions& options = {});
// Any mesh with its soft regions given: `labels[v]` indexes `names` (-1: the vertex stays put).
SoftBody make_soft_body(const Mesh& mesh, std::span<const int> labels, const std::vector<std::string>& names,
                        const SoftBodyOptions& options = {});

struct SoftRegionState {
  std::string name;
  size_t vertices = 0;
  double volume_change = 0;  // fraction of the region's tissue volume (its area x depth)
  float compression_m = 0;   // the deepest a vertex was pressed in (along its rest normal)
  float bulge_m = 0;         // the farthest a vertex moved out
};

struct SoftSolve {
  std::vector<Vec3f> positions;  // every body vertex
  std::vector<SoftRegionState> regions;
  int newton_iterations = 0;
  int factorisations = 0;        // of the Hessian: kept across iterations while they converge fast
  double residual_n = 0;         // largest force left on a soft vertex, N
};

// The largest force left on a soft vertex at rest (N): 1e-5 N moves a vertex of the default body
// (a tissue stiffness of 10-20 N/m over its area) about a micrometre.
inline constexpr double kSoftBodyTolerance = 1e-5;

// The body at rest under `forces` (N per body vertex, e.g. the cloth's pressure), Newton's method
// from `start` (the rest shape when empty). Static vertices keep their rest positions.
SoftSolve solve_soft_body(const SoftBody& soft, std::span<const Vec3f> forces, std::span<const Vec3f> start = {});

// The same solve, again and again for one soft body (each frame of a motion, each round of a
// dressing): the Hessian's sparsity pattern is analysed once, and its last factorisation is kept
// from one solve to the next while Newton's steps on it go on converging (the body under a press
// that changes a little from frame to frame: a frame then costs a few triangular solves). `soft`
// must outlive the solver.
class SoftBodySolver {
 public:
  explicit SoftBodySolver(const SoftBody& soft);
  ~SoftBodySolver();
  SoftBodySolver(const SoftBodySolver&) = delete;
  SoftBodySolver& operator=(const SoftBodySolver&) = delete;
  // Newton's iterations end once no soft vertex is off balance by more than `tolerance` (N).
  SoftSolve solve(std::span<const Vec3f> forces, std::span<const Vec3f> start = {}, double tolerance = kSoftBodyTolerance);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// The regions' volume change and compression for `positions` (every body vertex).
std::vector<SoftRegionState> soft_region_states(const SoftBody& soft, std::span<const Vec3f> positions);

}  // namespace drape
