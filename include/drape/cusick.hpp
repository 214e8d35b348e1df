#pragma once
// The Cusick drape test (BS 5058, ISO 9073-9), as a scene: a disc of fabric 30 cm across is clamped
// between two discs 18 cm across and hangs round them under its own weight. Its drape coefficient is
// the share of the ring outside the support that the draped fabric's shadow still covers,
//
//     DC = (A_shadow - A_support) / (A_specimen - A_support),
//
// 0 for a fabric that falls straight down, 1 for one that stays flat. It measures how a fabric's
// bending stiffness stands against its weight, the property that decides how a garment of it hangs,
// so each fabric preset is checked against the band published for its kind (docs/fabrics.md).
#include <memory>

#include "drape/analytic_colliders.hpp"
#include "drape/dress.hpp"
#include "drape/fabric.hpp"

namespace drape {

struct CusickOptions {
  Fabric fabric;                    // name empty: cotton
  double specimen_diameter = 0.30;  // m
  double support_diameter = 0.18;   // m
  double edge_length = 0.01;        // m, the specimen's grid spacing
  Solver solver = Solver::Implicit;
  double max_seconds = 12;          // explicit step: simulated seconds before giving up on settling
};

struct CusickResult {
  // The specimen as the dressing stages hold a garment: model, state, residual, settled, profiles.
  DressedGarment specimen;
  std::unique_ptr<CylinderCollider> support;  // top at y = support_top
  float support_top = 0;                      // m
  double specimen_area = 0, support_area = 0, shadow_area = 0;  // m^2 (the specimen: its mesh's area)
  double drape_coefficient = 0;                                  // fraction, see above
  int nodes = 0;             // folds round the hem (maxima of the shadow's radius over the angle)
  double wall_seconds = 0;   // simulation only
  bool passed() const { return specimen.status == StepStatus::Ok && specimen.settled; }
};

// Meshes the disc, clamps its middle over the support (pinned particles), lets it hang with the
// dressing stage of `solver` (draping and the settled test of docs/dressing.md, without seams) and
// measures its shadow. Throws InputError("cusick", ...) for diameters or spacing out of range.
CusickResult run_cusick(const CusickOptions& options, const DressProgressCallback& progress = {});

// The shadow the triangles cast straight down on a grid of nx x nz square cells of side `cell`,
// the first cell's corner at (x0, z0): 1 where a cell's centre lies in a projected triangle.
std::vector<uint8_t> shadow_raster(std::span<const Vec3f> positions, std::span<const Tri> triangles, double x0, double z0,
                                   double cell, int nx, int nz);

// Area (m^2) of the shadow the triangles cast straight down (the union of their projections on the
// horizontal plane), by rasterising it at `cell` metres.
double shadow_area(std::span<const Vec3f> positions, std::span<const Tri> triangles, double cell = 2.5e-4);

// The shadow's outline as the largest horizontal distance from the axis (x = z = 0) of the mesh's
// points in each of `bins` equal angle sectors (0 where a sector holds none).
std::vector<double> shadow_radius_by_angle(std::span<const Vec3f> positions, int bins = 360);

}  // namespace drape
