// The dressing pipeline (Vassilev & Spanlang sec. 6, docs/dressing.md): each garment in turn is
// meshed, placed, sewn and draped with the body and the garments already dressed as colliders.
#include <chrono>
#include <optional>

#include "dress/stages.hpp"
#include "dress/waistband.hpp"
#include "drape/error.hpp"
#include "drape/size_advice.hpp"

namespace drape {

DressedGarment prepare_garment(const Body& body, const Garment& garment, const Collider& body_collider,
                               const DressOptions& o) {
  return dressing::prepare_garment(body, garment, body_collider, o, dressing::PlacementUse::sewing);
}

DressedGarment dressing::prepare_garment(const Body& body, const Garment& garment, const Collider& body_collider,
                                         const DressOptions& o, PlacementUse use) {
  DressedGarment g;
  g.name = garment.name;
  g.size = garment.size;
  Fabric fabric = fabric_or_throw(o.fabric.empty() ? garment.fabric : o.fabric);
  if (o.thickness > 0) fabric.collision_thickness = o.thickness;
  if (o.friction >= 0) fabric.friction = o.friction;
  g.fabric = fabric.name;
  const GarmentMesh mesh = mesh_garment(garment, o.mesh);
  dressing::PlacedPanels placed = dressing::place_panels(body, garment, mesh, body_collider, fabric.collision_thickness, use);
  dressing::GarmentCloth cloth = dressing::garment_cloth_spec(garment, mesh, placed, fabric);
  dressing::gather_elastic_bands(body, garment, mesh, placed, cloth);
  g.model = compile(std::move(cloth.spec));
  g.state = initial_state(g.model);
  for (Vec3f& x : g.state.x) x += o.placement_offset;
  g.seam_pairs = std::move(cloth.seam_pairs);
  g.seam_of_pair = std::move(cloth.seam_of_pair);
  for (const SeamSpec& s : garment.seams) g.seam_names.push_back(s.name);
  g.panel_first_vertex = std::move(cloth.panel_first_vertex);
  for (const Panel& p : garment.panels) g.panel_names.push_back(p.name);
  g.placement = std::move(placed.info);
  g.initial_max_gap = seam_gap_stats(g.state.x, g.seam_pairs).max;
  return g;
}

void start_from_transfer(DressedGarment& g, const Body& body, const Collider& body_collider,
                         std::span<const std::shared_ptr<const GarmentTransfer>> transfers) {
  if (transfers.empty()) return;
  const uint64_t mesh = mesh_fingerprint(body.mesh);
  for (const auto& t : transfers) {
    if (!t || !t->matches(g.name, g.size, g.state.x.size(), mesh)) continue;
    g.state.x = transfer_positions(*t, body.mesh);
    // Where the new body is fuller, a particle kept at its offset from one triangle can end up in
    // the body through another (a hem between the legs, nearest one thigh, inside the other): each
    // particle within the cloth's thickness of the skin, or under it, goes out along the skin's
    // normal to the thickness, as placement leaves the panels.
    const float thickness = g.model.fabric.collision_thickness;
    std::vector<ContactSample> near(g.state.x.size());
    body_collider.query(g.state.x, 0.05f, near);
    for (size_t i = 0; i < near.size(); ++i)
      if (near[i].distance < thickness) g.state.x[i] += (thickness - near[i].distance) * near[i].normal;
    g.initial_max_gap = seam_gap_stats(g.state.x, g.seam_pairs).max;
    g.transferred = true;
    return;
  }
}

FitQuality measure_fit(const Body& body, std::span<const DressedGarment> garments) {
  FitQuality q;
  const InsideTest inside(body.mesh);
  std::vector<float> all_strain;
  double gap_sum = 0;
  size_t gap_pairs = 0;
  q.settled = !garments.empty();
  q.lowest_y = std::numeric_limits<float>::infinity();
  for (const DressedGarment& g : garments) {
    const GarmentMeasure m = measure_garment(g.model, g.state.x, inside);
    q.finite = q.finite && m.finite && g.status == StepStatus::Ok;
    q.max_strain = std::max(q.max_strain, m.strain.max);
    all_strain.insert(all_strain.end(), m.structural_strain.begin(), m.structural_strain.end());
    q.penetrating_vertices += m.penetration.penetrating;
    q.max_penetration_m = std::max(q.max_penetration_m, m.penetration.max_depth_m);
    q.vertices += g.state.x.size();
    const SeamGapStats gaps = seam_gap_stats(g.state.x, g.seam_pairs);
    q.max_seam_gap_m = std::max(q.max_seam_gap_m, gaps.max);
    gap_sum += static_cast<double>(gaps.mean) * static_cast<double>(gaps.pairs);
    gap_pairs += gaps.pairs;
    q.settled = q.settled && g.settled;
    q.residual = std::max(q.residual, g.residual);
    if (m.finite) {
      const SkinThroughStats skin = measure_skin_through(body.mesh, g.state.x, g.model.triangles);
      q.skin_through.body_vertices += skin.body_vertices;
      q.skin_through.max_depth_m = std::max(q.skin_through.max_depth_m, skin.max_depth_m);
    }
    q.lowest_y = std::min(q.lowest_y, m.lowest_y);
    q.drop_m = std::max(q.drop_m, g.drop_m());
  }
  if (!all_strain.empty()) {
    const size_t k = std::min(all_strain.size() - 1, static_cast<size_t>(0.99 * static_cast<double>(all_strain.size())));
    std::nth_element(all_strain.begin(), all_strain.begin() + static_cast<std::ptrdiff_t>(k), all_strain.end());
    q.p99_strain = all_strain[k];
  }
  q.mean_seam_gap_m = gap_pairs ? static_cast<float>(gap_sum / static_cast<double>(gap_pairs)) : 0.0f;
  q.penetration_fraction = q.vertices ? static_cast<double>(q.penetrating_vertices) / static_cast<double>(q.vertices) : 0.0;
  if (!q.finite) q.settled = false;
  return q;
}

DressResult dress(const Body& body, const std::vector<GarmentRequest>& requests, const DressOptions& o,
                  const DressProgressCallback& progress) {
  DressResult result;
  const auto clock = [] { return std::chrono::steady_clock::now(); };
  const auto since = [&](auto t) { return std::chrono::duration<double>(clock() - t).count(); };

  // Sizes resolved (the body's size where none is asked for) and validated up front, so bad input
  // stops the run before anything is simulated.
  std::vector<Garment> garments;
  std::vector<std::string> size_reasons;
  for (const GarmentRequest& r : requests) {
    const SizeChoice choice = r.size.empty() ? choose_size(r.spec, body.measurements) : SizeChoice{r.size, "asked for"};
    garments.push_back(garment_in_size(r.spec, choice.size));
    size_reasons.push_back(choice.reason);
  }

  auto t0 = clock();
  // The implicit solver asks for few contacts: the candidate grid would cost more than it saves.
  BodyColliderOptions collider_options;
  collider_options.candidate_grid = o.solver != Solver::Implicit;
  std::unique_ptr<BodyCollider> body_collider = make_body_collider(body.mesh, o.collision, collider_options);
  std::vector<std::unique_ptr<Collider>> layers;
  std::vector<Collider*> colliders{body_collider.get()};
  result.setup_seconds += since(t0);

  std::vector<size_t> beneath;  // per garment: the colliders it was dressed on (body, then layers)
  std::optional<FitQuality> single_fit;  // one garment whose transferred start was checked
  for (size_t i = 0; i < garments.size(); ++i) {
    beneath.push_back(colliders.size());
    t0 = clock();
    DressedGarment g = prepare_garment(body, garments[i], *body_collider, o);
    g.size_reason = size_reasons[i];
    if (o.solver == Solver::Implicit) start_from_transfer(g, body, *body_collider, o.transfers);
    result.setup_seconds += since(t0);
    if (o.coarse_edge > 1.25 * o.mesh.edge_length && !g.transferred) {
      dressing::dress_coarse_first(g, body, garments[i], *body_collider, colliders, o, progress, i, garments.size());
      result.setup_seconds += g.coarse.setup_seconds;
      result.simulation.iterations += g.coarse.iterations;
      result.simulation.wall_seconds += g.coarse.wall_seconds;
    }
    if (o.solver == Solver::Implicit) {
      sew_and_drape_implicit(g, colliders, o, progress, i, garments.size());
      // A transferred start that does not end within the gates is dressed again from its
      // placement: a body fuller at the waist than the one the garment was dressed on holds a
      // band where it sat there, stretched and pressed into the skin, where one placed anew slides
      // to where the body's girth matches it.
      std::optional<FitQuality> checked;
      if (g.transferred) checked = measure_fit(body, std::span(&g, 1));
      if (checked && !all_passed(evaluate_gates(*checked, g.model.fabric.strain_threshold, o.gates))) {
        const double tried = g.sewing_seconds + g.drape_seconds;
        const uint64_t iterations = g.state.iterations;
        t0 = clock();
        DressedGarment placed = prepare_garment(body, garments[i], *body_collider, o);
        placed.size_reason = g.size_reason;
        result.setup_seconds += since(t0);
        g = std::move(placed);
        sew_and_drape_implicit(g, colliders, o, progress, i, garments.size());
        g.transfer_failed = true;
        result.simulation.iterations += iterations;
        result.simulation.wall_seconds += tried;
      } else if (checked && garments.size() == 1) {
        single_fit = checked;  // the whole dressing's fit: measuring it again would cost as much
      }
    } else {
      sew_and_drape(g, colliders, o, progress, i, garments.size());
    }
    result.simulation.iterations += g.state.iterations;
    result.simulation.wall_seconds += g.sewing_seconds + g.drape_seconds;
    result.simulation.time_step_s = std::max(result.simulation.time_step_s, static_cast<double>(g.time_step));
    // The dressed garment is a solid for the next one (sec. 6).
    if (i + 1 < garments.size() && g.status == StepStatus::Ok) {
      t0 = clock();
      layers.push_back(garment_collider(g));
      colliders.push_back(layers.back().get());
      result.setup_seconds += since(t0);
    }
    result.garments.push_back(std::move(g));
  }
  const auto& s = result.simulation;
  result.simulation.seconds_per_iteration = s.iterations ? s.wall_seconds / static_cast<double>(s.iterations) : 0.0;

  if (o.soft_body && o.solver == Solver::Implicit && o.simulate) {
    // Body and cloth in rounds: the cloth's pressure presses the soft regions in, the garments
    // settle again on the body as it gave way, until the body stops moving.
    t0 = clock();
    const SoftBody soft = make_soft_body(body, o.soft);
    SoftBodySolver soft_solver(soft);
    SoftBodyResult sb{body, {}, 0, 0.0f, 0.0};
    for (int round = 0; round < o.soft_body_rounds; ++round) {
      const FitAnalysis fit = analyse_dress_fit(sb.body, result, garments);
      const SoftSolve solved = soft_solver.solve(fit.pressure.force, sb.body.mesh.positions);
      sb.last_move_m = 0;
      for (size_t v = 0; v < solved.positions.size(); ++v)
        sb.last_move_m = std::max(sb.last_move_m, (solved.positions[v] - sb.body.mesh.positions[v]).norm());
      sb.body.mesh.positions = solved.positions;
      sb.body.mesh.normals = vertex_normals(sb.body.mesh.positions, sb.body.mesh.triangles);
      sb.regions = solved.regions;
      ++sb.rounds;
      if (sb.last_move_m < o.soft_body_settled_m) break;
      body_collider = make_body_collider(sb.body.mesh, o.collision, collider_options);
      colliders[0] = body_collider.get();
      for (size_t i = 0; i < result.garments.size(); ++i) {
        DressedGarment& g = result.garments[i];
        if (g.status != StepStatus::Ok) continue;
        // The garment goes on from where it lies; where it was placed and how long it has taken so
        // far still count.
        const float placed_y = g.placed_centre_y;
        const double sewing = g.sewing_seconds, draping = g.drape_seconds;
        const uint64_t before = g.state.iterations;
        sew_and_drape_implicit(g, std::span<Collider* const>(colliders.data(), beneath[i]), o, progress, i, garments.size());
        g.placed_centre_y = placed_y;
        result.simulation.iterations += g.state.iterations - before;
        result.simulation.wall_seconds += g.sewing_seconds + g.drape_seconds;
        g.sewing_seconds += sewing;
        g.drape_seconds += draping;
      }
    }
    sb.seconds = since(t0);
    result.soft_body = std::move(sb);
    result.simulation.seconds_per_iteration =
        s.iterations ? s.wall_seconds / static_cast<double>(s.iterations) : 0.0;
  }

  result.quality = single_fit && !result.soft_body
                       ? *single_fit
                       : measure_fit(result.soft_body ? result.soft_body->body : body, result.garments);
  for (DressedGarment& g : result.garments) g.self_intersections = self_intersections(g.model, g.state.x);
  float threshold = 0;
  for (const DressedGarment& g : result.garments) threshold = std::max(threshold, g.model.fabric.strain_threshold);
  result.gates = evaluate_gates(result.quality, threshold, o.gates);
  return result;
}

}  // namespace drape
