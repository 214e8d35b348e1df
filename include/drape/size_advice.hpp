#pragma once
// Which size to buy (docs/fit.md): every size of a garment dressed on the body (two at a time, one
// per core), each judged by the quality gates and the fit per region (drape/fit_map.hpp), and one
// recommended with reasons a shopper reads. Also the fit of any dressing (`drape dress`), and the
// pictures: fitmap.png, sizes.png and fit.glb.
#include <filesystem>
#include <functional>
#include <span>
#include <string>
#include <vector>

#include "drape/dress.hpp"
#include "drape/fit_map.hpp"
#include "drape/render.hpp"

namespace drape {

// What the fit maps need from a dressed garment; `garment` is the size it was made in (its panels'
// grain lines and which panels are sleeves). The result points into `dressed`.
FitGarment fit_garment(const DressedGarment& dressed, const Garment& garment);
// The fit of a dressing: `garments[i]` is the size result.garments[i] was made in.
FitAnalysis analyse_dress_fit(const Body& body, const DressResult& result, std::span<const Garment> garments);
// A report.json text with `fit` (fit_json) added.
std::string report_with_fit(const std::string& report_json, const FitAnalysis& fit);

// ---- A size chart from the pattern ------------------------------------------------------------

// One girth of a garment at one of its own lines, measured on the flat pattern.
struct PatternGirth {
  std::string key;    // the chart key it sizes: "bust", "waist" or "hips"
  std::string line;   // where: "2.5 cm below the armhole", "its widest, 12 cm below its top"
  float girth_m = 0;  // the garment's girth there
  float ease_m = 0;   // the wearing ease it is drafted with there (intended_ease)
  float body_m() const { return girth_m - ease_m; }  // the body girth it is cut for
};
struct PatternSize {
  std::string size;
  std::vector<PatternGirth> girths;
};

// Wearing ease by chart key where a garment gives none: bust 8 cm, waist 3 cm, hips 5 cm.
const SizeMeasurements& default_intended_ease();
// The garment's intended ease at `key` (its own, else the default; 0 for other keys).
double intended_ease(const GarmentSpec& spec, std::string_view key);

// A garment's girths at its own lines (docs/fit.md), on `placed`, the size `garment` as placement
// put it round `body` (prepare_garment, seams still open):
//   a top (it reaches above the body's bust): the chest 2.5 cm below its underarm (the top of its
//     side seams), its waist where it is shaped (narrowest 14-26 cm below the underarm, 4 cm
//     narrower than chest and hips), its hips 38 cm below the underarm;
//   a bottom: its waist at its top edge, its hips its widest within 20 cm of the top and above its
//     crotch (left out where it is flared: more than 1.6 times its waist).
std::vector<PatternGirth> pattern_girths(const Body& body, const DressedGarment& placed, const Garment& garment,
                                         const GarmentSpec& spec);
// Every size of `spec` placed on `body` and measured.
std::vector<PatternSize> measure_pattern(const Body& body, const GarmentSpec& spec, const DressOptions& options);
// The size chart the measurements make: per size, each girth less its intended ease.
std::vector<SizeMeasurements> chart_from_pattern(std::span<const PatternSize> sizes);

// One size tried on.
struct SizeTrial {
  std::string size;
  Garment garment;   // the size's pattern
  DressResult result;
  FitAnalysis fit;
  // Measured on the pattern before draping: the panels placed round the body, cut at its girth
  // lines; lengths as placed (pattern_measurements).
  std::vector<RegionFit> pattern;
  // The girths at the garment's own lines and the body each is cut for (pattern_girths); the size
  // chart when the garment has none.
  std::vector<PatternGirth> pattern_girths;
  bool closes = false;    // every seam closed (and the simulation stayed finite)
  bool stays_on = false;  // the garment did not slide off
  double chart_distance = -1;  // RMS relative distance of the body to the size's chart entry (-1: none)
  std::string verdict;    // one line: "fits", "tight at the hips", "does not close: ...", ...
};

struct SizeAdvice {
  std::string garment;
  std::vector<SizeTrial> sizes;   // smallest to largest (the garment file's order)
  size_t recommended = 0;         // index into sizes; sizes.size() when none closes and stays on
  std::string chart_size;         // the size chart's choice for the body (empty: no chart)
  bool chart_from_pattern = false;  // the garment has no chart: it was made from its pattern
  std::string rule;               // which rule chose the recommendation
  std::vector<std::string> reasons;  // lines for the shopper: the recommended size first
  bool has_recommendation() const { return recommended < sizes.size(); }
};

// Dresses `spec` in every size on `body` with `options` and recommends one (docs/fit.md):
//   1. a size that does not close (a seam open, or the simulation went non-finite) or slides off
//      is never recommended;
//   2. among the rest, sizes that pass every quality gate come first;
//   3. among those, the size the garment's size chart gives the body (the chart entry nearest the
//      body: the size whose ease on this body is nearest the ease its pattern was drafted with);
//      a garment without a chart gets one made from its pattern (chart_from_pattern); where that
//      has no girth either, the smallest size not tight anywhere (the largest when all are tight).
// `progress` (may be empty) is called after each size with the number done; sizes run in
// parallel, two at a time (one with a single OpenMP thread), and the result does not depend on
// the thread count.
SizeAdvice advise_size(const Body& body, const GarmentSpec& spec, const DressOptions& options,
                       const std::function<void(size_t done, size_t total)>& progress = {});

// report.json of `drape fit` (recommended_size, sizes smallest to largest with verdicts and gates).
std::string size_advice_json(const Body& body, const SizeAdvice& advice);

// Pictures: the fit map of one dressing (front, side, back: garments by strain as a percentage of
// the limit; then by ease, their distance to the skin; below, the body by pressure), the sizes
// side by side labelled with their verdicts, and the fit map as a glTF scene with vertex colours.
Image fit_map_picture(const Body& body, const DressResult& result, const FitAnalysis& fit, const std::string& title);
Image sizes_picture(const Body& body, const SizeAdvice& advice);
Scene fit_scene(const Body& body, const DressResult& result, const FitAnalysis& fit);
// The colour scales used by the pictures and fit.glb.
Legend strain_legend();
Legend pressure_legend(const FitAnalysis& fit);

// Writes DIR/report.json, fitmap.png (the recommended size, else the chart's), sizes.png and
// fit.glb, each atomically; everything is encoded before the first file is written.
void write_fit_outputs(const std::filesystem::path& dir, const Body& body, const SizeAdvice& advice);

}  // namespace drape
