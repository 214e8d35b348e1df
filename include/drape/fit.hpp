#pragma once
// How well a garment fits, measured honestly on the final state (DESIGN.md's report.json contract):
// structural strain, vertices inside the body (an exact inside test independent of the collision
// method), gaps between sewn vertex pairs, whether the cloth came to rest, and the quality gates a
// dressing must pass (docs/dressing.md). The report.json writer lives here too.
#include <array>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "drape/cloth.hpp"
#include "drape/collision.hpp"
#include "drape/mesh.hpp"

namespace drape {

// Distance between the two vertices of every sewn pair.
struct SeamGapStats {
  size_t pairs = 0;
  float max = 0;   // m
  float mean = 0;  // m
};
SeamGapStats seam_gap_stats(std::span<const Vec3f> x, std::span<const std::array<uint32_t, 2>> pairs);

// Vertices deeper inside the body than this count as penetrating. The body is a polygonal
// approximation and cloth vertices rest `collision_thickness` (4 mm) off it, so a vertex more than
// 1 mm inside is a real failure of the collision handling, not tessellation noise.
inline constexpr float kPenetrationTolerance = 0.001f;  // m

// Skin showing through the cloth. The collision keeps the cloth's vertices off the body, not the
// faces between them: over a tight, curved part (a shoulder under a sleeve cap) the skin between
// two vertices 2-4 cm apart can rise through the flat triangle they span. From every body vertex a
// ray goes into the body, against its normal, for `reach`; where it meets a garment triangle more
// than `tolerance` deep, the cloth passes under the skin there. Skin the garment does not cover
// (beyond a hem or a neckline) has no cloth under it and does not count. Reported, not gated.
inline constexpr float kSkinThroughTolerance = 0.001f;  // m
struct SkinThroughStats {
  size_t body_vertices = 0;  // body vertices with cloth more than the tolerance under them
  float max_depth_m = 0;     // deepest such cloth below the skin (0 when none)
};
SkinThroughStats measure_skin_through(const Mesh& body, std::span<const Vec3f> cloth, std::span<const Tri> triangles,
                                      float reach = 0.015f, float tolerance = kSkinThroughTolerance);

// DESIGN.md's `quality` object (over all garments), plus what the gates also need.
struct FitQuality {
  float max_strain = 0;  // structural (l - l0) / l0
  float p99_strain = 0;
  size_t penetrating_vertices = 0;
  double penetration_fraction = 0;
  float max_penetration_m = 0;
  float max_seam_gap_m = 0;
  float mean_seam_gap_m = 0;
  bool settled = false;
  float residual = 0;  // largest |net force| / (m g) over the garments' particles at the end
  // Not in `quality` but gated:
  bool finite = true;             // no NaN / explosion
  float lowest_y = 0;             // m, lowest garment vertex (the floor is y = 0)
  float drop_m = 0;               // how far a garment's centre of mass fell from where it was placed
  size_t vertices = 0;
  // Reported beside `quality`, not gated: measure_skin_through over every garment.
  SkinThroughStats skin_through;
};

// Strain and penetration of one garment's state (seam gaps and settling come from the sewing).
struct GarmentMeasure {
  StrainStats strain;
  std::vector<float> structural_strain;  // every structural spring's stretch (for the p99 over all)
  PenetrationStats penetration;
  float lowest_y = 0;
  bool finite = true;
};
GarmentMeasure measure_garment(const ClothModel& model, std::span<const Vec3f> x, const InsideTest& body);

// Thresholds of the quality gates (docs/dressing.md).
struct QualityGates {
  float max_seam_gap_m = 0.002f;          // every seam closed
  double max_penetration_fraction = 0.005;  // at most 0.5 % of the vertices inside the body
  float strain_margin = 0.01f;            // max strain <= fabric threshold + this
  float floor_y = 0.0f;                   // nothing below the floor
  float max_drop_m = 0.15f;               // the garment did not slide off the body
};

struct GateResult {
  std::string name;    // "seams_closed", "penetration", "strain", "settled", "finite", "above_floor", "stayed_on"
  bool passed = false;
  double value = 0;
  double limit = 0;
  std::string detail;  // one line for people
};
// Evaluates every gate; `strain_threshold` is the (largest) fabric threshold of the garments.
std::vector<GateResult> evaluate_gates(const FitQuality& quality, float strain_threshold,
                                       const QualityGates& gates = {});
bool all_passed(const std::vector<GateResult>& gates);

// report.json: DESIGN.md's `quality` (exactly its eight keys) and `simulation` objects, then the
// gates and whatever the caller adds (garments, body, profile) under `extra`'s keys.
struct SimulationSummary {
  uint64_t iterations = 0;
  double time_step_s = 0;
  double wall_seconds = 0;
  double seconds_per_iteration = 0;
};
std::string report_json(const FitQuality& quality, const SimulationSummary& simulation,
                        const std::vector<GateResult>& gates, const std::string& extra_json_object = "{}");

}  // namespace drape
