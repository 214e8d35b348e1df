#pragma once
// Fit maps and fit per body region (docs/fit.md), measured on a dressed garment's final state:
//
//   strain    per garment triangle along the warp (the panel's grain line), the weft and the bias,
//             from the triangle's deformation gradient between the flat pattern (TEXCOORD_0) and
//             3D; also as a percentage of the fabric's strain limit, as commercial fit maps show it;
//   contact   the force the body exerts on each cloth particle at rest: the particle's force
//             balance, -(spring forces + the strain limit's tension + weight), where it lies within
//             contact distance of the body (sewn pairs are one node: the seam holds them
//             together), split into a normal push and a friction part of at most mu times the
//             push; the tension of the springs held at the limit is solved for, as the tension
//             that best balances the cloth off the body;
//   pressure  those forces handed to the body's vertices (Newton's third law) and divided by each
//             vertex's area: N/m^2 on the skin;
//   ease      the garment-to-body distance per garment vertex, and per girth line the garment's
//             girth measured on the pattern (flat lengths of the garment cut by the body's line)
//             minus the body's girth.
//
// Everything here reads plain data (a cloth model, positions, a body mesh and its landmarks); the
// dressing and the size advice (drape/size_advice.hpp) fill it from a dressed garment.
#include <array>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "drape/body.hpp"
#include "drape/cloth.hpp"
#include "drape/collider.hpp"
#include "drape/mesh.hpp"

namespace drape {

// ---- Strain along the grain --------------------------------------------------------------------

// Stretch (|F d| - 1) of one triangle along the warp `warp` (unit, flat pattern), the weft (warp
// turned by -90 degrees) and the bias (the larger of the two 45-degree directions), where F maps
// the flat triangle (a, b, c) onto the 3D one (pa, pb, pc). Zeros for a degenerate flat triangle.
std::array<float, 3> directional_strain(const Vec2f& a, const Vec2f& b, const Vec2f& c, const Vec3f& pa,
                                        const Vec3f& pb, const Vec3f& pc, const Vec2f& warp);

struct DirectionalStrain {
  std::vector<float> warp, weft, bias;  // per triangle of the model
  // Per triangle: 0 for slivers (flat area under a quarter of the median triangle's, where a grid
  // panel is clipped to its outline), whose deformation gradient magnifies a millimetre's error
  // into tens of percent of strain; they count in no map or peak.
  std::vector<uint8_t> measured;
  // Per triangle: the larger of warp and weft, the directions the fabric's strain limit holds (the
  // bias is the cloth shearing, which woven cloth does easily; it is reported, not held to the limit).
  float along_grain(size_t t) const { return measured[t] ? std::max(warp[t], weft[t]) : 0.0f; }
};
// `warp` holds one unit grain direction per particle (each panel's grain line).
DirectionalStrain triangle_strain(const ClothModel& model, std::span<const Vec3f> x, std::span<const Vec2f> warp);

// Per particle: the largest stretch along the grain (warp or weft) of its triangles, as a percentage
// of `limit` (the fabric's strain threshold): 100 = at the limit. Compression counts as 0.
std::vector<float> strain_percent_of_limit(const ClothModel& model, const DirectionalStrain& strain, float limit);

// ---- Contact forces, pressure, ease --------------------------------------------------------------

struct ContactForces {
  std::vector<Vec3f> force;    // per particle: force of the body on it (N); zero where not in contact
  std::vector<Vec3f> point;    // per particle: nearest point on the body
  std::vector<float> footprint; // per particle: radius of the cloth it stands for (m): sqrt(its area)
  std::vector<float> distance; // per particle: signed distance to the body (m, > 0 outside): the ease map
  size_t in_contact = 0;
  Vec3f total = Vec3f::Zero();  // sum of `force`
  double weight = 0;            // N, the garment's weight (m g)
  double unbalanced = 0;        // N, sum over the nodes of the force neither the cloth nor the body balances
};
// `body` answers distances (an exact collider: make_body_collider(mesh, bvh)). A particle is in
// contact within `contact_distance` of the body (the fabric's collision thickness plus a margin).
ContactForces contact_forces(const ClothModel& model, std::span<const Vec3f> x,
                             std::span<const std::array<uint32_t, 2>> seam_pairs, const Collider& body,
                             const Vec3f& gravity, float contact_distance);

struct PressureMap {
  std::vector<Vec3f> force;     // per body vertex: force of the cloth on the body (N)
  std::vector<float> area;      // per body vertex: a third of its triangles' area (m^2)
  std::vector<float> pressure;  // per body vertex: the push into the body / area (N/m^2, >= 0)
  Vec3f total = Vec3f::Zero();  // sum of `force`
};
// Adds the reaction of `contacts` (minus each contact force) to the body's vertices: each particle's
// reaction is spread over the body vertices within r = max(min_radius, twice its footprint) of its
// contact point (weights (1 - d/r)^2, summing to one; the nearest vertex when none is that close),
// so the total is kept and neighbouring particles' shares overlap into an even map.
void add_pressure(PressureMap& map, const Mesh& body, const ContactForces& contacts, float min_radius = 0.015f);
PressureMap empty_pressure_map(const Mesh& body);
// Fills `pressure` from `force` (normal component into the body over the vertex's area).
void finish_pressure(PressureMap& map, const Mesh& body);

// ---- Girths and lengths --------------------------------------------------------------------------

// The garment cut by a plane: the cut's length on the flat pattern (the garment's girth there, as
// a tape would measure the sewn garment laid flat around) and in 3D (as draped). Only triangles with
// `selected[t]` (empty: all) whose centroid lies within `reach` of `centre` count.
struct GarmentCut {
  float pattern_m = 0;
  float draped_m = 0;
  size_t segments = 0;
  bool crosses_midline = false;  // a cut segment crosses x = 0 (a skirt at thigh height, not two legs)
};
GarmentCut cut_garment(const ClothModel& model, std::span<const Vec3f> x, const Vec3f& centre, const Vec3f& normal,
                       float reach, std::span<const uint8_t> selected = {});

// ---- Fit per region ------------------------------------------------------------------------------

// Per garment, what the fit needs besides the model and the state.
struct FitGarment {
  std::string name, size;
  const ClothModel* model = nullptr;
  std::span<const Vec3f> x;
  std::span<const std::array<uint32_t, 2>> seam_pairs;
  std::vector<Vec2f> warp;       // per particle: unit grain direction of its panel (flat pattern)
  std::vector<uint8_t> on_arm;   // per particle: 1 where its panel wraps an arm (a sleeve)
  std::vector<uint8_t> on_leg;   // per particle: 1 where its panel wraps the left leg, 2 the right (trousers)
};

enum class FitVerdict : uint8_t { tight, good, loose, short_, long_ };
std::string_view to_string(FitVerdict verdict);

struct RegionFit {
  std::string region;  // neck, shoulders, bust, waist, hips, thighs, upper_arm, sleeve_length, leg_length, garment_length
  FitVerdict verdict = FitVerdict::good;
  bool girth = false;           // a girth line (ease below) or a length / a zone
  float body_m = 0;             // body girth or length
  float garment_m = 0;          // garment girth on the pattern, or garment length as draped
  float draped_m = 0;           // girth: the cut's length as draped
  float ease_m = 0;             // girth: garment_m - body_m; lengths: garment_m - body_m
  float hoop_strain = 0;        // girth: draped / pattern - 1
  float open_seam_m = 0;        // girth: widest gap of a seam crossing the line (0: every seam closed)
  // 95th percentiles over the region's triangles (the very highest are single triangles at an
  // outline or an open seam): strain along the grain as % of the fabric's limit, and bias stretch.
  float peak_strain_percent = 0;
  float peak_bias_strain = 0;
  float peak_pressure_pa = 0;      // largest pressure on the body in the region (N/m^2)
  std::string reason;           // one line for shoppers
};

// Thresholds of the verdicts (docs/fit.md).
struct FitThresholds {
  // A girth line is tight when the pattern is smaller than the body there (negative ease: the
  // cloth must stretch to go round), loose when the ease is above this fraction of the body's girth
  // (bust/chest, waist, hips, thigh, upper arm). The cut's stretch as draped is reported, not
  // judged: the cloth lies its collision thickness off the skin, which alone stretches a snug cut
  // by 2 pi x 4 mm round, and soft simulation springs let a hanging garment's own weight pull it
  // to its strain limit.
  std::array<float, 5> loose_fraction{0.20f, 0.20f, 0.15f, 0.20f, 0.30f};
  // A seam that crosses a girth line (within `open_seam_band` of it) and stays open by more than
  // `open_seam_m` (the seams gate's limit) means the garment does not close round the body there:
  // tight, whatever the pattern's ease.
  float open_seam_m = 0.002f;
  float open_seam_band = 0.06f;
  // Neck and shoulders (no girth line): tight when at least this fraction of the zone's triangles
  // are stretched to `zone_limit_percent` of the limit or more (most of the zone held at the limit,
  // not only the cloth the garment hangs from).
  float zone_tight_fraction = 0.5f;
  float zone_limit_percent = 100.0f;
};

struct GarmentFit {
  std::string name, size;
  float strain_limit = 0;
  std::vector<RegionFit> regions;
  DirectionalStrain strain;             // per triangle
  std::vector<float> strain_percent;    // per particle (% of limit)
  ContactForces contacts;
  float peak_strain_percent = 0;
};

struct FitAnalysis {
  std::vector<GarmentFit> garments;
  PressureMap pressure;
  float peak_pressure_pa = 0;
  // Verdicts of every garment, by region, the worst first (tight, loose, short/long, good).
  std::vector<const RegionFit*> worst_first() const;
};

// Fit of garments on a body (innermost first). `body_collider` answers exact distances to the body.
FitAnalysis analyse_fit(const Body& body, std::span<const FitGarment> garments, const Collider& body_collider,
                        const FitThresholds& thresholds = {});

// The garment measured on its pattern before draping: `placed` is the garment as placement put it
// round the body (seams still open). Each girth line cuts the panels where they lie (ease =
// pattern girth - body girth, judged tight / good / loose as above; no peaks, no open-seam test:
// every seam is open before sewing), and the sleeve, leg and garment lengths are taken as placed.
std::vector<RegionFit> pattern_measurements(const Body& body, const FitGarment& placed,
                                            const FitThresholds& thresholds = {});

// report.json's `fit` object (per garment: regions with verdict, ease, peak strain and pressure;
// totals) and a table for the terminal.
std::string fit_json(const FitAnalysis& fit);
std::string fit_table(const FitAnalysis& fit);

}  // namespace drape
