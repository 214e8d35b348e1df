#pragma once
// Elastic bands (drape::ElasticBand, docs/dressing.md "Elastic bands"): a waistband that holds a
// skirt or trousers up by its own tension, not by pinned vertices.
#include <vector>

#include "dress/stages.hpp"

namespace drape::dressing {

// What one band became on this body.
struct BandFit {
  double drafted_m = 0;        // the band edges' length in the pattern
  double body_waist_m = 0;     // the body's waist girth
  double relaxed_m = 0;        // the elastic's relaxed length: min(drafted, (1 + ease) x waist)
  double placed_height_m = 0;  // mean height of the band's edge after placement
  size_t springs = 0;          // elastic springs added
};

// Adds each band of `garment` to `cloth` (before it is compiled): an elastic ring of springs along
// the band's edges (and the edges sewn to them), relaxed at relaxed / drafted of their length, and
// the band's vertices' mass doubled (the fold). Bands no longer than relaxed are left as drafted.
std::vector<BandFit> gather_elastic_bands(const Body& body, const Garment& garment, const GarmentMesh& mesh,
                                          const PlacedPanels& placed, GarmentCloth& cloth);

}  // namespace drape::dressing
