#pragma once
// Internal stages of the dressing pipeline (src/dress), one per file.
#include <span>
#include <string>
#include <vector>

#include "drape/dress.hpp"

namespace drape::dressing {

// Stage 3 (placement.cpp): every panel's vertices rolled around its body region. positions[p][v]
// is panel p's vertex v in world space; info says where each panel went.
struct PlacedPanels {
  std::vector<std::vector<Vec3f>> positions;
  std::vector<PanelPlacement> info;
};
// What the panels are placed for: to be sewn (a layout whose seams close round the body), or to
// measure the pattern's lines on (pattern_chart.cpp: the heights as drafted, a file's own layout
// wherever it lies clear of the body).
enum class PlacementUse { sewing, measuring };
PlacedPanels place_panels(const Body& body, const Garment& garment, const GarmentMesh& mesh,
                          const Collider& body_collider, float collision_thickness,
                          PlacementUse use = PlacementUse::sewing);
// Imported panels that carry the file's 3D placement (placement_from_file.cpp): hints and panel
// orientation read from it, then rolled as above. place_panels calls it when every panel has one.
PlacedPanels place_panels_from_file(const Body& body, const Garment& garment, const GarmentMesh& mesh,
                                    const Collider& body_collider, float collision_thickness, PlacementUse use);
// prepare_garment (drape/dress.hpp) with the panels placed for `use`.
DressedGarment prepare_garment(const Body& body, const Garment& garment, const Collider& body_collider,
                               const DressOptions& options, PlacementUse use);

// Stage 4 (garment_model.cpp): one cloth spec for all panels (grid topology springs where the
// grid mesher made the panel, triangle-mesh springs otherwise) and zero-length seam springs.
struct GarmentCloth {
  ClothSpec spec;
  std::vector<std::array<uint32_t, 2>> seam_pairs;
  std::vector<uint32_t> seam_of_pair;  // per pair: the garment's seam index
  std::vector<uint32_t> panel_first_vertex;
};
GarmentCloth garment_cloth_spec(const Garment& garment, const GarmentMesh& mesh, const PlacedPanels& placed,
                                const Fabric& fabric);

// Coarse-to-fine (coarse_start.cpp): every fine particle placed where its flat-pattern point lies on
// the dressed coarse garment of the same pattern (barycentric in the coarse panel's flat triangle
// that holds it, or the nearest one), at rest. Panels are matched by index (`*_panels`: each panel's
// first particle, then the end). Returns how many fine particles lay outside every coarse triangle.
size_t start_from_coarse(ClothState& fine_state, const ClothModel& fine, std::span<const uint32_t> fine_panels,
                         const ClothModel& coarse, const ClothState& coarse_state, std::span<const uint32_t> coarse_panels);

// Coarse-to-fine (coarse_start.cpp, DressOptions::coarse_edge): `garment` meshed, placed, sewn and
// draped at the coarse spacing, then `fine` started from it (unless the coarse run failed: then
// `fine` keeps its placement); `fine.coarse` says how the coarse run went and what it cost.
void dress_coarse_first(DressedGarment& fine, const Body& body, const Garment& garment, const Collider& body_collider,
                        std::span<Collider* const> colliders, const DressOptions& options,
                        const DressProgressCallback& progress, size_t index, size_t count);

}  // namespace drape::dressing
