// Elastic bands: a waistband holds a skirt or trousers up the way an elastic one does on a person,
// by being a little shorter relaxed than the wearer's waist. Stretched round the body it presses
// on the skin (tension / radius), so the fabric's Coulomb friction holds it, and to slide down over
// the wider hips it would have to stretch further. Nothing is pinned: the elastic is a ring of
// springs along the band's edge, relaxed shorter than the edge, pulling the fabric it is sewn to
// into gathers; the fabric keeps its own rest lengths, strain limit and strain measure.
//
// The elastic is not fabric: it stretches far beyond the fabric's strain threshold (placement
// starts the band a few centimetres off the body, where it is much longer than relaxed), so its
// springs are not strain-limited. SpringKind has no elastic kind; the springs are stored with the
// flexion springs, the unlimited kind that neither the strain limit (sec. 3.3) nor the structural
// strain measure reads.
//
// GarmentCode attaches its `lower_interface` edges to the body in its simulator (the importer
// turns them into a band); drape garment files declare bands with "bands" (docs/garment-format.md).
#include "dress/waistband.hpp"

#include <algorithm>
#include <cmath>
#include <set>
#include <utility>

namespace drape::dressing {
namespace {

constexpr SpringKind kElasticKind = SpringKind::Flexion;

using EdgeRef = std::pair<uint32_t, uint32_t>;  // panel, edge

void add_side(std::set<EdgeRef>& edges, const Garment& garment, const SeamSide& side) {
  const auto n = static_cast<uint32_t>(garment.panels.at(side.panel).edges.size());
  for (uint32_t i = 0; i < side.edge_count; ++i) edges.insert({side.panel, (side.first_edge + i) % n});
}

bool side_touches(const std::set<EdgeRef>& edges, const Garment& garment, const SeamSide& side) {
  const auto n = static_cast<uint32_t>(garment.panels.at(side.panel).edges.size());
  for (uint32_t i = 0; i < side.edge_count; ++i)
    if (edges.count({side.panel, (side.first_edge + i) % n})) return true;
  return false;
}

}  // namespace

std::vector<BandFit> gather_elastic_bands(const Body& body, const Garment& garment, const GarmentMesh& mesh,
                                          const PlacedPanels& placed, GarmentCloth& cloth) {
  std::vector<BandFit> fits;
  ClothSpec& spec = cloth.spec;
  std::vector<uint8_t> band_vertex(spec.positions.size(), 0);
  // Each vertex's seam partner (the first pair that lists it), kNone where it is not sewn.
  constexpr uint32_t kNone = ~uint32_t{0};
  std::vector<uint32_t> sewn_to(spec.positions.size(), kNone);
  for (const auto& [a, b] : cloth.seam_pairs) {
    if (sewn_to[a] == kNone) sewn_to[a] = b;
    if (sewn_to[b] == kNone) sewn_to[b] = a;
  }
  for (const ElasticBand& band : garment.bands) {
    BandFit& fit = fits.emplace_back();
    // The band's own edges, and the edges sewn to them (gathered with them, not counted twice).
    std::set<EdgeRef> own;
    for (const SeamSide& side : band.edges) add_side(own, garment, side);
    std::set<EdgeRef> gathered = own;
    for (const SeamSpec& seam : garment.seams) {
      if (side_touches(own, garment, seam.a)) add_side(gathered, garment, seam.b);
      if (side_touches(own, garment, seam.b)) add_side(gathered, garment, seam.a);
    }
    for (const auto& [p, e] : own) fit.drafted_m += garment.panels[p].edges[e].length();

    // Where placement put the band (reported), and its relaxed length against the body's waist.
    double y_sum = 0;
    size_t y_count = 0;
    for (size_t p = 0; p < mesh.panels.size(); ++p) {
      const PanelMesh& pm = mesh.panels[p];
      for (size_t i = 0; i < pm.boundary.size(); ++i)
        if (own.count({static_cast<uint32_t>(p), pm.boundary_edge[i]})) {
          y_sum += placed.positions[p][pm.boundary[i]].y();
          ++y_count;
        }
    }
    if (y_count == 0 || fit.drafted_m <= 0) continue;
    fit.placed_height_m = y_sum / static_cast<double>(y_count);
    fit.body_waist_m = body.measurements.waist;
    fit.relaxed_m = std::min(fit.drafted_m, (1.0 + band.ease) * fit.body_waist_m);
    // A band much shorter than the body is round is not a whole band round it: left as drafted.
    if (fit.drafted_m < 0.5 * fit.body_waist_m) fit.relaxed_m = fit.drafted_m;
    const double scale = fit.relaxed_m / fit.drafted_m;
    if (scale >= 1.0) continue;

    // The elastic: one spring along each band-edge segment (and each segment of an edge sewn to
    // one), relaxed at `scale` of its drafted length, as stiff as `stiffness` strips of the fabric
    // `width` wide (k = E w / l, E the fabric's mean membrane stiffness).
    const double membrane = 0.5 * (static_cast<double>(spec.fabric.stretch_warp) + spec.fabric.stretch_weft);
    for (size_t p = 0; p < mesh.panels.size(); ++p) {
      const PanelMesh& pm = mesh.panels[p];
      const uint32_t base = cloth.panel_first_vertex[p];
      const size_t nb = pm.boundary.size();
      for (size_t i = 0; i < nb; ++i) {
        if (!gathered.count({static_cast<uint32_t>(p), pm.boundary_edge[i]})) continue;
        const uint32_t a = base + pm.boundary[i], b_own = base + pm.boundary[(i + 1) % nb];
        const double len = (spec.flat_positions[b_own] - spec.flat_positions[a]).cast<double>().norm();
        if (len <= 0) continue;
        // Where the ring reaches a seam, its spring ends on the sewn vertex of the other panel,
        // so the elastic's tension runs on through the elastic, not through the corner pair's
        // seam spring, which is weak for light corners: a ring broken at a seam pulls the seam's
        // end apart (the flare skirt's corners 45-58 mm, the 2021 pants' outseams 51-55 mm).
        // Such a spring across a seam that starts open is softer by len / start, so it starts
        // with no more force than one stretched by its own length (at full stiffness a 12 cm gap
        // at the pants' outseams sent their corners past the speed limit in the first step).
        uint32_t b = b_own;
        double k = band.stiffness * membrane * band.width / std::max(len, band.width);
        if (sewn_to[b_own] != kNone && sewn_to[b_own] != a) {
          b = sewn_to[b_own];
          const double start = (spec.positions[b] - spec.positions[a]).norm();
          k *= len / std::max(start, len);
        }
        spec.springs.push_back({a, b, static_cast<float>(scale * len), static_cast<float>(k), kElasticKind});
        band_vertex[a] = band_vertex[b] = band_vertex[b_own] = 1;
        ++fit.springs;
      }
    }
  }
  // A band is folded over its elastic: twice the cloth's mass along it (which also keeps the
  // stable time step, eq. 4, where the elastic adds stiffness).
  for (size_t v = 0; v < band_vertex.size(); ++v)
    if (band_vertex[v]) spec.mass[v] *= 2.0f;
  return fits;
}

}  // namespace drape::dressing
