// Stage 8: dressed.glb (node `body`, then one node per garment, TEXCOORD_0 = flat pattern metres),
// preview.png (front, side, back; second row: structural strain), report.json. Each written
// atomically; the directory gets all three or, on an error before writing, none.
#include <fmt/format.h>

#include <cmath>

#include <nlohmann/json.hpp>

#include "drape/dress.hpp"
#include "drape/files.hpp"
#include "drape/io.hpp"
#include "drape/render.hpp"

namespace drape {

Scene dressed_scene(const Body& body, const DressResult& result) {
  Scene scene = body_scene(body);
  std::vector<std::string> used{"body"};
  for (const DressedGarment& g : result.garments) {
    std::string name = g.name.empty() ? "garment" : g.name;
    for (int k = 2; std::find(used.begin(), used.end(), name) != used.end(); ++k) name = fmt::format("{}_{}", g.name, k);
    used.push_back(name);
    Mesh m = g.mesh();
    m.name = name;
    add_mesh_node(scene, std::move(m), name);
  }
  return scene;
}

std::string dress_report_json(const Body& body, const DressResult& r, const DressOptions& o) {
  nlohmann::ordered_json extra;
  nlohmann::ordered_json garments = nlohmann::ordered_json::array();
  for (const DressedGarment& g : r.garments) {
    const StrainStats st = strain_stats(g.model, g.state.x, SpringKind::Structural);
    const SeamGapStats gaps = seam_gap_stats(g.state.x, g.seam_pairs);
    nlohmann::ordered_json panels = nlohmann::ordered_json::array();
    for (const PanelPlacement& p : g.placement)
      panels.push_back({{"panel", p.panel}, {"region", p.region}, {"clearance_m", p.clearance},
                        {"vertices_touching_after_growing", p.vertices_touching}});
    nlohmann::ordered_json stages;
    for (int s = 0; s < StepProfile::StageCount; ++s)
      stages[std::string(StepProfile::name(static_cast<StepProfile::Stage>(s)))] = g.profile.seconds[static_cast<size_t>(s)];
    // Where the widest seam gap is, to find a seam that did not close.
    nlohmann::ordered_json worst = nullptr;
    float widest = -1;
    for (const auto& [a, b] : g.seam_pairs)
      if (const float gap = (g.state.x[a] - g.state.x[b]).norm(); gap > widest) {
        widest = gap;
        const Vec3f mid = 0.5f * (g.state.x[a] + g.state.x[b]);
        worst = {mid.x(), mid.y(), mid.z()};
      }
    const std::vector<float> seam_gap = g.seam_gaps();
    nlohmann::ordered_json seams = nlohmann::ordered_json::array();
    for (size_t i = 0; i < seam_gap.size(); ++i) seams.push_back({{"seam", g.seam_names[i]}, {"max_gap_m", seam_gap[i]}});
    nlohmann::ordered_json coarse = nullptr;  // started from the placement
    if (g.coarse.edge > 0)
      coarse = {{"edge_length_m", g.coarse.edge},
                {"vertices", g.coarse.vertices},
                {"iterations", g.coarse.iterations},
                {"wall_seconds", g.coarse.wall_seconds},
                {"status", std::string(to_string(g.coarse.status))},
                {"seams_closed", g.coarse.seams_closed},
                {"settled", g.coarse.settled},
                {"extrapolated_vertices", g.coarse.extrapolated},
                {"start_max_seam_gap_m", g.coarse.start_max_gap}};
    garments.push_back({{"name", g.name},
                        {"size", g.size},
                        {"size_reason", g.size_reason},
                        {"fabric", g.fabric},
                        {"contact_thickness_m", g.model.fabric.collision_thickness},
                        {"friction", g.model.fabric.friction},
                        {"vertices", g.model.particle_count()},
                        {"springs", g.model.spring_count()},
                        {"seam_pairs", g.seam_pairs.size()},
                        {"status", std::string(to_string(g.status))},
                        {"seams_closed", g.seams_closed},
                        {"settled", g.settled},
                        {"residual", g.residual},
                        {"newton_iterations", g.implicit_profile.newton_iterations},
                        {"factorizations", g.implicit_profile.factorizations},
                        {"triangular_solves", g.implicit_profile.triangular_solves},
                        {"pattern_analyses", g.implicit_profile.analyses},
                        {"initial_max_seam_gap_m", g.initial_max_gap},
                        {"max_seam_gap_m", gaps.max},
                        {"mean_seam_gap_m", gaps.mean},
                        {"widest_seam_gap_at", worst},
                        {"seams", seams},
                        {"max_strain", st.max},
                        {"p99_strain", st.p99},
                        {"coarse_start", coarse},
                        {"start", g.transferred ? "transferred" : g.transfer_failed ? "placed_after_transfer" : "placed"},
                        {"sewing_iterations", g.sewing_iterations},
                        {"sewing_stalled", g.sewing_stalled},
                        {"pulled_closed_pairs", g.pulled_closed},
                        {"sewn_max_strain", g.sewn_max_strain},
                        {"self_intersections", g.self_intersections},
                        {"relax_passes", g.relax_passes},
                        {"drape_iterations", g.drape_iterations},
                        {"sewing_wall_seconds", g.sewing_seconds},
                        {"drape_wall_seconds", g.drape_seconds},
                        {"simulated_seconds", g.state.time},
                        {"final_max_speed_m_per_s", g.state.max_speed},
                        {"final_rms_speed_m_per_s", std::sqrt(2.0 * g.state.kinetic_energy / g.model.total_mass())},
                        {"time_step_s", g.time_step},
                        {"mass_scaled_particles", g.mass_scaled},
                        // Gauss-Seidel passes per step (velocity, position and converge passes) and the
                        // steps whose last pass still corrected springs (the passes' cost: docs/cloth.md).
                        {"strain_passes_per_iteration", g.profile.steps ? double(g.profile.strain_passes) / double(g.profile.steps) : 0.0},
                        {"iterations_at_pass_limit", g.profile.steps_at_pass_limit},
                        {"centre_drop_m", g.drop_m()},
                        // The centre of mass's height where placement put the garment, when sewing
                        // ended and at the end: centre_drop_m is placed - final (0 if it rose).
                        {"centre_height_m", {{"placed", g.placed_centre_y}, {"sewn", g.sewn_centre_y}, {"final", g.final_centre_y}}},
                        {"strain_threshold", g.model.fabric.strain_threshold},
                        {"panels", panels},
                        {"stage_seconds", stages},
                        {"implicit_stage_seconds", {{"contacts", g.implicit_profile.contacts},
                                                    {"self_contacts", g.implicit_profile.self_contacts},
                                                    {"assemble", g.implicit_profile.assemble},
                                                    {"factorize", g.implicit_profile.factorize},
                                                    {"solve", g.implicit_profile.solve},
                                                    {"line_search", g.implicit_profile.line_search},
                                                    {"block_sweeps", g.implicit_profile.sweeps}}}});
  }
  extra["garments"] = garments;
  extra["body"] = {{"vertices", body.mesh.vertex_count()},
                   {"triangles", body.mesh.triangle_count()},
                   {"height_m", body.measurements.height}};
  extra["settings"] = {{"solver", std::string(to_string(o.solver))},
                       {"collision", std::string(to_string(o.collision))},
                       {"mesher", o.mesh.mesher == Mesher::grid ? "grid" : "triangle"},
                       {"edge_length_m", o.mesh.edge_length},
                       {"coarse_edge_length_m", o.coarse_edge},
                       {"seam_closed_m", o.seam_closed_m},
                       {"settle_distance_m", o.settle_distance_m},
                       {"settle_window_s", o.settle_window_s},
                       {"max_iterations", o.max_iterations},
                       {"mass_scaling", o.mass_scaling},
                       {"face_clearance_m", o.face_clearance},
                       {"penetration_tolerance_m", kPenetrationTolerance}};
  // Skin rising through the cloth between its vertices (drape/fit.hpp): reported, not gated.
  extra["skin_through_cloth"] = {{"body_vertices", r.quality.skin_through.body_vertices},
                                 {"max_depth_m", r.quality.skin_through.max_depth_m},
                                 {"tolerance_m", kSkinThroughTolerance}};
  extra["setup_seconds"] = r.setup_seconds;
  if (r.soft_body) {
    // The soft body (docs/soft-body.md): per region its volume change (a fraction of its tissue's
    // volume, area x depth) and how deep it was pressed in.
    nlohmann::ordered_json regions = nlohmann::ordered_json::array();
    for (const SoftRegionState& g : r.soft_body->regions)
      regions.push_back({{"name", g.name}, {"vertices", g.vertices}, {"volume_change", g.volume_change},
                         {"compression_m", g.compression_m}, {"bulge_m", g.bulge_m}});
    extra["soft_body"] = {{"regions", regions},
                          {"rounds", r.soft_body->rounds},
                          {"last_move_m", r.soft_body->last_move_m},
                          {"tissue_depth_m", o.soft.depth},
                          {"tissue_stiffness_pa_per_m", o.soft.tissue_stiffness},
                          {"individual_share", o.soft.individual},
                          {"seconds", r.soft_body->seconds}};
  }
  return report_json(r.quality, r.simulation, r.gates, extra.dump());
}

DressPreview dress_preview(const Body& given, const DressResult& result) {
  // A soft body is drawn as the garments left it.
  DressPreview p;
  p.body = result.soft_body ? result.soft_body->body.mesh : given.mesh;
  for (const DressedGarment& g : result.garments) {
    p.garments.push_back(g.mesh());
    p.strain.push_back(particle_strain(g.model, g.state.x));
    p.strain_threshold = g.model.fabric.strain_threshold;
  }
  return p;
}

std::vector<uint8_t> encode_preview_png(const DressPreview& p) {
  RenderOptions ro;
  ro.width = 1200;
  ro.height = 600;
  std::vector<RenderItem> items{body_item(p.body)};
  for (size_t i = 0; i < p.garments.size(); ++i) items.push_back(garment_item(p.garments[i], i));
  const Image shaded = render_views(items, ro);
  // Second row: structural strain (0 .. threshold + 1 %) on the same views.
  const float hi = p.strain_threshold + 0.01f;
  for (size_t i = 0; i < p.garments.size(); ++i) items[i + 1].vertex_colors = colorize(p.strain[i], ColorMap::kViridis, 0.0f, hi);
  RenderOptions so = ro;
  so.legend = Legend{"strain", ColorMap::kViridis, 0.0f, hi};
  const Image strain = render_views(items, so);
  Image both(shaded.width, shaded.height + strain.height);
  for (int y = 0; y < shaded.height; ++y)
    std::copy_n(shaded.pixel(0, y), 3 * static_cast<size_t>(shaded.width), both.pixel(0, y));
  for (int y = 0; y < strain.height; ++y)
    std::copy_n(strain.pixel(0, y), 3 * static_cast<size_t>(std::min(strain.width, both.width)), both.pixel(0, shaded.height + y));
  return encode_png(both);
}

void write_dress_outputs(const std::filesystem::path& dir, const Body& given, const DressResult& result,
                         const DressOptions& options, PreviewOutput preview) {
  // A soft body is drawn as the garments left it.
  const Body& body = result.soft_body ? result.soft_body->body : given;
  // Everything is encoded first, then written, so a failure while encoding leaves nothing behind.
  const std::vector<unsigned char> glb = encode_glb(dressed_scene(body, result));
  const std::vector<uint8_t> png =
      preview == PreviewOutput::Write ? encode_preview_png(dress_preview(given, result)) : std::vector<uint8_t>{};
  const std::string report = dress_report_json(given, result, options);

  write_file_atomic(dir / "dressed.glb", glb);
  if (preview == PreviewOutput::Write) write_file_atomic(dir / "preview.png", png);
  write_file_atomic(dir / "report.json", report);
}

}  // namespace drape
