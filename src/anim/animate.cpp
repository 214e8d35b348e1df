// The dressed body in motion: dress on the bind pose, retarget, then per frame skin the body, let
// its collider follow the skin (every solver step: positions interpolated between the frames, the
// surface velocity their difference), step the cloth with the implicit solver (implicit Euler,
// contacts found anew every step because the collider moves) and measure the frame.
//
// Why the implicit solver: a frame of 1/30 s is a few implicit steps, where the explicit step's
// stability bound (eq. 4) asks for about fifty, and every step must rebuild the body collider
// (refit its tree to the skinned mesh). The body is the collider of every garment, and each garment
// of the garments beneath it, as in dressing (sec. 6): each step the garments step innermost first,
// and an outer one meets the inner ones where they have just gone, with their velocity.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <optional>

#include <Eigen/LU>

#include "anim/motion_internal.hpp"
#include "drape/animate.hpp"
#include "drape/error.hpp"
#include "drape/fit_map.hpp"
#include "geometry/vertex_grid.hpp"

namespace drape {
namespace {

using Clock = std::chrono::steady_clock;
constexpr int kMaxStepsPerFrame = 32;

// How far the body moves near a garment over a frame: the 95th percentile of the travel of the
// body's vertices that `grid` (the body at the frame's start, kNearCloth cells) finds round the
// garment's particles. Parts away from the cloth (a walk's hands swinging below a shirt's short
// sleeves, its feet under a skirt) do not ask for more steps. The travel is the vertices' own, not
// against the cloth's: a step's Newton iterations start where the cloth was, with contacts found
// against where the body will be (measured against the garment's mean motion instead, the run took
// 3 steps a frame and left the shirt behind, a third of it inside the body). `near` and `moved`
// are scratch, one entry per body vertex.
constexpr float kNearCloth = 0.05f;  // m
float travel_near(const VertexGrid& grid, std::span<const Vec3f> from, std::span<const Vec3f> to, const ClothState& cloth,
                  std::vector<uint8_t>& near, std::vector<float>& moved) {
  std::fill(near.begin(), near.end(), uint8_t{0});
  for (const Vec3f& p : cloth.x) grid.near(p, [&](uint32_t v) { near[v] = 1; });
  size_t count = 0;
  for (size_t v = 0; v < from.size(); ++v)
    if (near[v]) moved[count++] = (to[v] - from[v]).norm();
  if (count == 0) return 0.0f;
  const size_t p95 = std::min(count - 1, static_cast<size_t>(0.95 * static_cast<double>(count)));
  std::nth_element(moved.begin(), moved.begin() + static_cast<long>(p95), moved.begin() + static_cast<long>(count));
  return moved[p95];
}

double seconds_since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

float centre_height(std::span<const Vec3f> x) {
  double y = 0;
  for (const Vec3f& p : x) y += p.y();
  return x.empty() ? 0.0f : static_cast<float>(y / static_cast<double>(x.size()));
}

// A mesh with the body's triangles at the given positions.
Mesh posed_mesh(const Body& body, std::span<const Vec3f> x) {
  Mesh m;
  m.positions.assign(x.begin(), x.end());
  m.triangles = body.mesh.triangles;
  return m;
}

// The body's collider, shared by the garments: brought to a time once, however many garments step
// to it (a second update to the same time would give the skin no velocity).
class SharedBodyCollider : public Collider {
 public:
  explicit SharedBodyCollider(BodyCollider& body) : body_(body) {}
  std::string_view name() const override { return body_.name(); }
  void update(double t) override {
    if (t == time_) return;
    body_.update(t);
    time_ = t;
    rebuild_seconds += body_.build_stats().build_seconds;
  }
  void query(std::span<const Vec3f> points, float radius, std::span<ContactSample> out) const override {
    body_.query(points, radius, out);
  }
  double rebuild_seconds = 0;

 private:
  BodyCollider& body_;
  double time_ = std::numeric_limits<double>::quiet_NaN();
};

// The rotation that takes a vertex's frame in the bind pose (normal n0, the direction e0 to a
// neighbour) to its frame in a pose (n1, e1).
Eigen::Matrix3f vertex_rotation(const Vec3f& n0, const Vec3f& e0, const Vec3f& n1, const Vec3f& e1) {
  const auto frame = [](const Vec3f& n, const Vec3f& e) {
    const Vec3f t = (e - e.dot(n) * n).normalized();
    Eigen::Matrix3f m;
    m.col(0) = n;
    m.col(1) = t;
    m.col(2) = n.cross(t);
    return m;
  };
  return frame(n1, e1) * frame(n0, e0).transpose();
}

// The soft body in motion (AnimatedSoftBody): the bind pose as it gave way, skinned each frame,
// and the body's rest under the cloth's reaction after each frame.
class MovingSoftBody {
 public:
  MovingSoftBody(const MovingSoftBody&) = delete;
  MovingSoftBody& operator=(const MovingSoftBody&) = delete;
  MovingSoftBody(const Body& body, const SoftBodyResult& dressed, const SoftBodyOptions& options)
      : bind_(body), soft_(make_soft_body(body, options)), solver_(soft_), displaced_(dressed.body) {
    for (size_t v = 0; v < soft_.region_of.size(); ++v)
      if (soft_.region_of[v] >= 0) out.vertices.push_back(static_cast<uint32_t>(v));
    neighbour_.assign(body.mesh.vertex_count(), 0);
    for (const Tri& t : body.mesh.triangles)
      for (int k = 0; k < 3; ++k) neighbour_[t[static_cast<size_t>(k)]] = t[static_cast<size_t>((k + 1) % 3)];
    out.worst = dressed.regions;
    rest_force_.assign(body.mesh.vertex_count(), Vec3f::Zero());
  }

  // The body of a frame: the bind pose as it gave way, skinned to `pose`; its displacement kept.
  void skin(const PoseView& pose, Skinning method, std::span<Vec3f> out_positions) {
    skin_mesh(displaced_, pose, method, out_positions);
    std::vector<Vec3f>& d = out.displacement.emplace_back(out.vertices.size());
    for (size_t k = 0; k < out.vertices.size(); ++k)
      d[k] = displaced_.mesh.positions[out.vertices[k]] - bind_.mesh.positions[out.vertices[k]];
  }

  // After a frame on the body at `posed`: the cloth's contact forces on it (their reaction, spread
  // over the skin), turned into the bind pose, and the body's rest under them from where it was.
  void give_way(std::span<const Vec3f> posed, std::span<const std::unique_ptr<ImplicitSolver>> solvers,
                std::span<const DressedGarment> garments) {
    const auto t0 = Clock::now();
    const Mesh mesh = posed_mesh(bind_, posed);
    PressureMap map;
    map.force.assign(posed.size(), Vec3f::Zero());
    for (size_t g = 0; g < solvers.size(); ++g) {
      const ClothModel& model = garments[g].model;
      ContactForces contacts;
      contacts.force.resize(model.particle_count());
      contacts.point.resize(model.particle_count());
      contacts.footprint.resize(model.particle_count());
      solvers[g]->contact_forces(contacts.force, contacts.point);
      const float density = std::max(1e-6f, model.fabric.areal_density);
      for (size_t i = 0; i < contacts.footprint.size(); ++i) contacts.footprint[i] = std::sqrt(model.mass[i] / density);
      add_pressure(map, mesh, contacts);
    }
    const std::vector<Vec3f> bind_normals = vertex_normals(displaced_.mesh.positions, bind_.mesh.triangles);
    const std::vector<Vec3f> posed_normals = vertex_normals(mesh.positions, mesh.triangles);
    for (const uint32_t v : out.vertices) {
      const uint32_t u = neighbour_[v];
      const Eigen::Matrix3f rotation =
          vertex_rotation(bind_normals[v], displaced_.mesh.positions[u] - displaced_.mesh.positions[v], posed_normals[v],
                          posed[u] - posed[v]);
      rest_force_[v] = rotation.transpose() * map.force[v];
    }
    // Each frame's body is solved to 0.1 mN a vertex (about 10 micrometres on the default body's
    // tissue) where dressing asks for 0.01 mN: it answers the cloth one frame late in any case. The
    // shirt's walk: 26 ms a frame for the body against 54 (docs/soft-body.md).
    constexpr double kFrameTolerance = 1e-4;  // N
    const SoftSolve solved = solver_.solve(rest_force_, displaced_.mesh.positions, kFrameTolerance);
    displaced_.mesh.positions = solved.positions;
    out.newton_iterations += solved.newton_iterations;
    for (size_t k = 0; k < solved.regions.size() && k < out.worst.size(); ++k) {
      SoftRegionState& w = out.worst[k];
      const SoftRegionState& now = solved.regions[k];
      if (std::abs(now.volume_change) > std::abs(w.volume_change)) w.volume_change = now.volume_change;
      w.compression_m = std::max(w.compression_m, now.compression_m);
      w.bulge_m = std::max(w.bulge_m, now.bulge_m);
    }
    out.seconds += seconds_since(t0);
  }

  AnimatedSoftBody out;

 private:
  const Body& bind_;
  SoftBody soft_;
  SoftBodySolver solver_;          // on soft_, its factorisation kept from frame to frame
  Body displaced_;                 // the bind pose as the body gave way
  std::vector<uint32_t> neighbour_;  // per vertex: one it shares a triangle with
  std::vector<Vec3f> rest_force_;  // per vertex: the cloth's force turned into the bind pose
};

}  // namespace

double AnimationResult::frames_per_wall_second() const {
  const size_t simulated = frames.size() > 1 ? frames.size() - 1 : 0;
  return simulation_seconds > 0 ? static_cast<double>(simulated) / simulation_seconds : 0.0;
}

std::vector<std::vector<Vec3f>> skinned_frames(const Body& body, const BodyAnimation& a, Skinning method) {
  std::vector<std::vector<Vec3f>> out(a.frame_count, std::vector<Vec3f>(body.mesh.vertex_count()));
  for (size_t f = 0; f < a.frame_count; ++f) skin_mesh(body, a.pose(f), method, out[f]);
  return out;
}

void add_body_displacement(const AnimationResult& r, size_t f, std::span<Vec3f> bind) {
  if (r.soft_body && f < r.soft_body->displacement.size())
    for (size_t k = 0; k < r.soft_body->vertices.size(); ++k) bind[r.soft_body->vertices[k]] += r.soft_body->displacement[f][k];
  if (r.skin_layer && f < r.skin_layer->displacement.size())
    for (size_t k = 0; k < r.skin_layer->vertices[f].size(); ++k) bind[r.skin_layer->vertices[f][k]] += r.skin_layer->displacement[f][k];
}

std::vector<std::vector<Vec3f>> animated_body_frames(const Body& body, const AnimationResult& r, Skinning method) {
  if (!r.soft_body && !r.skin_layer) return skinned_frames(body, r.body, method);
  Body displaced = body;
  std::vector<std::vector<Vec3f>> out(r.body.frame_count, std::vector<Vec3f>(body.mesh.vertex_count()));
  for (size_t f = 0; f < r.body.frame_count; ++f) {
    displaced.mesh.positions = body.mesh.positions;
    add_body_displacement(r, f, displaced.mesh.positions);
    skin_mesh(displaced, r.body.pose(f), method, out[f]);
  }
  return out;
}

AnimationResult animate(const Body& body, const std::vector<GarmentRequest>& garments, const Motion& motion,
                        const AnimateOptions& o, const AnimationProgressCallback& progress) {
  if (o.substeps < 1 || o.substeps > 64) throw std::invalid_argument("animate: substeps must be in [1, 64]");
  AnimationResult r;
  const auto report = [&](const char* phase, size_t frame, size_t frames) {
    if (progress) progress({phase, frame, frames});
  };

  // The motion first: a motion that does not fit the body is refused before the long dressing.
  auto start = Clock::now();
  report("retargeting", 0, 0);
  r.body = retarget(motion, body, o.retarget);
  r.retarget_seconds = seconds_since(start);
  start = Clock::now();
  report("dressing", 0, 0);
  r.dressed = dress(body, garments, o.dress, [&](const DressProgress&) { report("dressing", 0, 0); });
  r.dress_seconds = seconds_since(start);

  // The body's frames, skinned from the bind pose. A soft body: each frame skinned when it comes,
  // from the bind pose as it gave way (under the dressing's garments first, then after each frame
  // under the cloth's contact forces).
  std::optional<MovingSoftBody> soft;
  if (r.dressed.soft_body) soft.emplace(body, *r.dressed.soft_body, o.dress.soft);
  start = Clock::now();
  std::vector<std::vector<Vec3f>> skin;
  size_t skinned = 0;  // frames skinned so far: the collider never reads past them
  if (soft) {
    skin.assign(r.body.frame_count, std::vector<Vec3f>(body.mesh.vertex_count(), Vec3f::Zero()));
    soft->skin(r.body.pose(0), o.skinning, skin[0]);
    skinned = 1;
  } else {
    skin = skinned_frames(body, r.body, o.skinning);
    skinned = skin.size();
  }
  r.skinning_seconds = seconds_since(start);

  const size_t frames = r.body.frame_count;
  const double frame_time = r.body.frame_time;
  r.time_step = frame_time / o.substeps;
  const size_t ng = r.dressed.garments.size();
  r.positions.assign(ng, {});
  r.frames.resize(frames);

  // The skin layer: each frame's skin comes to rest on the skinned body, its parts kept apart by a
  // gap with room for a layer of every garment on either skin.
  std::optional<SkinLayer> skin_layer;
  if (o.skin_layer) {
    SkinLayerOptions so = o.skin;
    float thickness = 0;
    for (const DressedGarment& g : r.dressed.garments) thickness += g.model.fabric.collision_thickness;
    so.gap = std::max(so.gap, 2.0f * thickness);
    skin_layer.emplace(body, so);
    r.skin_layer.emplace();
    r.skin_layer->gap_m = so.gap;
    r.skin_layer->vertices.resize(frames);
    r.skin_layer->displacement.resize(frames);
  }
  std::vector<Vec3f> skinned_only;
  std::vector<Eigen::Matrix3f> linear;
  const auto lay_skin = [&](size_t f) {
    if (!skin_layer) return;
    AnimatedSkinLayer& k = *r.skin_layer;
    skinned_only = skin[f];
    const SkinContactStats before = skin_layer->inside(skinned_only);
    const auto t0 = Clock::now();
    const SkinContactStats st = skin_layer->solve(skinned_only, skin[f]);
    // The moves, turned into the bind pose.
    std::vector<uint32_t>& moved_vertices = k.vertices[f];
    for (size_t v = 0; v < skin[f].size(); ++v)
      if (skin[f][v] != skinned_only[v]) moved_vertices.push_back(static_cast<uint32_t>(v));
    linear.resize(moved_vertices.size());
    motion_detail::skinning_linear_parts(body, r.body.pose(f), o.skinning, moved_vertices, linear);
    k.displacement[f].resize(moved_vertices.size());
    for (size_t i = 0; i < moved_vertices.size(); ++i) {
      const uint32_t v = moved_vertices[i];
      const Eigen::FullPivLU<Eigen::Matrix3f> lu(linear[i]);
      const Vec3f move = skin[f][v] - skinned_only[v];
      k.displacement[f][i] = lu.isInvertible() ? Vec3f(lu.solve(move)) : move;
    }
    k.seconds += seconds_since(t0);
    const SkinContactStats after = skin_layer->inside(skin[f]);
    r.frames[f].skin_inside_skinned = before.vertices_inside;
    r.frames[f].skin_inside = after.vertices_inside;
    k.inside_skinned = std::max(k.inside_skinned, before.vertices_inside);
    k.depth_skinned_m = std::max(k.depth_skinned_m, before.max_depth_m);
    k.inside = std::max(k.inside, after.vertices_inside);
    k.depth_m = std::max(k.depth_m, after.max_depth_m);
    k.max_move_m = std::max(k.max_move_m, st.max_move_m);
    k.contacts = std::max(k.contacts, st.contacts);
  };
  for (size_t f = 0; f < skinned; ++f) lay_skin(f);

  // The body's collider, driven by the skinned frames.
  std::unique_ptr<BodyCollider> collider = make_body_collider(body.mesh, o.collision);
  // A soft body's frames are skinned as they come: a time at or past the last one skinned (the
  // collider is first brought to 0, a frame's last step ends on the frame) reads that frame alone.
  collider->set_motion([&skin, &skinned, frame_time](double t, std::span<Vec3f> x) {
    const double at = std::clamp(t / frame_time, 0.0, static_cast<double>(skinned - 1));
    const size_t f0 = static_cast<size_t>(std::floor(at));
    const size_t f1 = std::min(f0 + 1, skinned - 1);
    const float a = static_cast<float>(at - static_cast<double>(f0));
    for (size_t v = 0; v < x.size(); ++v) x[v] = (1 - a) * skin[f0][v] + a * skin[f1][v];
  });
  SharedBodyCollider shared(*collider);
  shared.update(0.0);

  std::vector<ClothState> states;
  states.reserve(r.dressed.garments.size());  // the layers' colliders read the states in place
  std::vector<std::unique_ptr<ImplicitSolver>> solvers;
  std::vector<ImplicitSettings> settings;
  std::vector<float> start_offset;  // garment centre above the hips in frame 0
  std::vector<std::string> joint_names;
  for (const Joint& j : body.skeleton.joints) joint_names.push_back(j.name);
  const size_t hips = static_cast<size_t>(find_joint_map(joint_names, "body").joint[0]);
  const auto hips_height = [&](size_t f) { return r.body.pose(f).position[hips].y(); };
  for (const DressedGarment& g : r.dressed.garments) {
    ClothState s = g.state;
    s.time = 0;
    std::fill(s.v.begin(), s.v.end(), Vec3f::Zero());
    states.push_back(std::move(s));
    solvers.push_back(std::make_unique<ImplicitSolver>(g.model, 1 + solvers.size()));
    ImplicitSettings is = default_implicit_settings(g.model);
    is.time_step = r.time_step;
    is.moving_colliders = true;
    is.quasi_static = false;
    // Dynamic steps (sweep_dynamic_steps): loose Newton directions, cheaper iterations whose errors
    // the next ones correct (the walk at 1.4x the frames per wall second with the same gates, the
    // run within its gates where exact directions let 1.8 % of the shirt into the body,
    // docs/animation.md); block sweeps between the Newton iterations, which settle locally what the
    // last factorisation's matrix did not know (springs crossing the strain barrier's start,
    // contacts met or left), over which a walk's iterations went back and forth; at most 6
    // iterations a step, ending once no particle is off balance by more than its weight.
    sweep_dynamic_steps(is);
    if (o.friction >= 0) is.friction = o.friction;
    // Static friction's range: 1 mm, where dressing holds the cloth within 0.1 mm. The body drags
    // the cloth by millimetres in a step, and Newton's iterates crossed a 0.1 mm range between
    // static and sliding friction at every iteration: the dress's walk, its steps solved to their
    // tolerance, took 1.6x the Newton iterations it takes without friction, at 1 mm 1.0x. Within
    // the cap, the four motions of docs/animation.md take 10-14 % fewer factorisations.
    is.friction_slip = 1e-3;
    // No self-contact in motion yet (docs/cloth.md, "Self-contact"): within a frame's few Newton
    // iterations its penalty took the shirt walking over the skirt past the strain gate, and cost
    // the walking shirt 15 % of its frames per wall second.
    settings.push_back(is);
    r.friction.push_back(is.friction);
    start_offset.push_back(centre_height(g.state.x) - hips_height(0));
  }
  // Per garment: the body, then the garments beneath it, following their particles.
  std::vector<std::unique_ptr<Collider>> layers;
  std::vector<std::vector<Collider*>> colliders(ng);
  for (size_t g = 0; g < ng; ++g) {
    colliders[g].push_back(&shared);
    for (size_t inner = 0; inner < g; ++inner) colliders[g].push_back(layers[inner].get());
    if (g + 1 < ng) {
      layers.push_back(moving_garment_collider(r.dressed.garments[g], states[g].x));
      layers.back()->update(0.0);
    }
  }

  const auto measure = [&](size_t f, bool settled, float residual, int newton) {
    const auto t0 = Clock::now();
    const InsideTest inside(posed_mesh(body, skin[f]));
    AnimationFrame& fr = r.frames[f];
    fr.time = static_cast<double>(f) * frame_time;
    fr.newton_iterations = newton;
    FitQuality& q = fr.quality;
    q.lowest_y = std::numeric_limits<float>::infinity();
    std::vector<float> all_strain;
    double gap_sum = 0;
    size_t pairs = 0;
    for (size_t g = 0; g < ng; ++g) {
      const DressedGarment& dg = r.dressed.garments[g];
      const ClothState& s = states[g];
      r.positions[g].push_back(s.x);
      const GarmentMeasure m = measure_garment(dg.model, s.x, inside);
      q.max_strain = std::max(q.max_strain, m.strain.max);
      all_strain.insert(all_strain.end(), m.structural_strain.begin(), m.structural_strain.end());
      q.penetrating_vertices += m.penetration.penetrating;
      q.max_penetration_m = std::max(q.max_penetration_m, m.penetration.max_depth_m);
      q.vertices += s.x.size();
      q.lowest_y = std::min(q.lowest_y, m.lowest_y);
      q.finite = q.finite && m.finite;
      const SeamGapStats gaps = seam_gap_stats(s.x, dg.seam_pairs);
      q.max_seam_gap_m = std::max(q.max_seam_gap_m, gaps.max);
      gap_sum += static_cast<double>(gaps.mean) * static_cast<double>(gaps.pairs);
      pairs += gaps.pairs;
      q.drop_m = std::max(q.drop_m, start_offset[g] - (centre_height(s.x) - hips_height(f)));
      for (size_t inner = 0; inner < g; ++inner)
        fr.vertices_through_layers += vertices_beneath(r.dressed.garments[inner], states[inner].x, s.x);
    }
    if (!all_strain.empty()) {
      const size_t k = std::min(all_strain.size() - 1, static_cast<size_t>(0.99 * static_cast<double>(all_strain.size())));
      std::nth_element(all_strain.begin(), all_strain.begin() + static_cast<long>(k), all_strain.end());
      q.p99_strain = all_strain[k];
    }
    q.penetration_fraction = q.vertices ? static_cast<double>(q.penetrating_vertices) / static_cast<double>(q.vertices) : 0;
    q.mean_seam_gap_m = pairs ? static_cast<float>(gap_sum / static_cast<double>(pairs)) : 0.0f;
    q.settled = settled;
    q.residual = residual;
    r.measure_seconds += seconds_since(t0);
  };
  measure(0, true, r.dressed.quality.residual, 0);

  // The skin layer of frames skinned before the loop counts with the skinning.
  r.simulation_seconds = r.skinning_seconds + (r.skin_layer && !soft ? r.skin_layer->seconds : 0.0);
  std::vector<float> moved(body.mesh.vertex_count());
  std::vector<uint8_t> near(body.mesh.vertex_count());
  std::vector<ClothState> start_of_frame(ng);
  const auto over_strain_gate = [&] {
    for (size_t g = 0; g < ng; ++g) {
      const ClothModel& model = r.dressed.garments[g].model;
      if (strain_stats(model, states[g].x).max > model.fabric.strain_threshold + o.gates.strain_margin) return true;
    }
    return false;
  };
  for (size_t f = 1; f < frames && r.status == StepStatus::Ok; ++f) {
    const auto frame_start = Clock::now();
    if (soft) {
      soft->skin(r.body.pose(f), o.skinning, skin[f]);
      skinned = f + 1;
      lay_skin(f);
    }
    // Steps this frame: the body's travel near the garments over the frame, cut into steps of at
    // most max_body_step. Over all the body's vertices (its hands and feet swing farthest), the
    // walk took 6.3 steps a frame at 1.5 cm a step where 4.9 near the garments (docs/animation.md).
    float travel = 0;
    const VertexGrid grid(skin[f - 1], kNearCloth);
    for (size_t g = 0; g < ng; ++g) travel = std::max(travel, travel_near(grid, skin[f - 1], skin[f], states[g], near, moved));
    int steps = std::clamp(static_cast<int>(std::ceil(travel / std::max(o.max_body_step, 1e-4f))), o.substeps, kMaxStepsPerFrame);
    bool converged = true;
    float residual = 0;
    int newton = 0;
    for (size_t g = 0; g < ng; ++g) start_of_frame[g] = states[g];  // copies into the capacity kept
    for (;;) {
      converged = true;
      residual = 0;
      for (int k = 0; k < steps && r.status == StepStatus::Ok; ++k)
        for (size_t g = 0; g < ng && r.status == StepStatus::Ok; ++g) {
          ImplicitStepStats stats;
          settings[g].time_step = frame_time / steps;
          r.status = solvers[g]->step(states[g], colliders[g], settings[g], &stats, &r.profile);
          converged = converged && stats.converged;
          newton += stats.newton_iterations;
          if (k + 1 == steps) residual = std::max(residual, stats.residual);
        }
      r.solver_steps += static_cast<uint64_t>(steps);
      // A frame whose steps end with a spring stretched past the strain gate is taken again from
      // its start in twice the steps. Its few Newton iterations a step leave what they did not
      // settle to the next step, and a fast limb can pull a sleeve past the barrier within one;
      // shorter steps move the body less in each, and the barrier's stiffness is met sooner.
      if (r.status != StepStatus::Ok || steps >= kMaxStepsPerFrame || !over_strain_gate()) break;
      for (size_t g = 0; g < ng; ++g) states[g] = start_of_frame[g];
      // The colliders back to the frame's start, so that the first step's surface velocity is
      // the body's over that step.
      shared.update(states[0].time);
      for (const std::unique_ptr<Collider>& layer : layers) layer->update(states[0].time);
      steps = std::min(2 * steps, kMaxStepsPerFrame);
      ++r.frames_retaken;
    }
    if (soft && r.status == StepStatus::Ok) soft->give_way(skin[f], solvers, r.dressed.garments);
    r.simulation_seconds += seconds_since(frame_start);
    measure(f, converged, residual, newton);
    report("simulating", f, frames - 1);
  }
  r.collider_seconds = shared.rebuild_seconds;
  if (soft) r.soft_body = std::move(soft->out);
  if (r.status != StepStatus::Ok) r.frames.resize(r.positions.empty() ? 0 : r.positions[0].size());

  // The worst of every key over the frames, and the frame that is worst overall.
  FitQuality& w = r.worst;
  w.lowest_y = std::numeric_limits<float>::infinity();
  w.settled = true;
  for (size_t f = 0; f < r.frames.size(); ++f) {
    const FitQuality& q = r.frames[f].quality;
    const FitQuality& b = r.frames[r.worst_frame].quality;
    if (q.penetrating_vertices > b.penetrating_vertices ||
        (q.penetrating_vertices == b.penetrating_vertices && q.max_strain > b.max_strain))
      r.worst_frame = f;
    w.max_strain = std::max(w.max_strain, q.max_strain);
    w.p99_strain = std::max(w.p99_strain, q.p99_strain);
    w.penetrating_vertices = std::max(w.penetrating_vertices, q.penetrating_vertices);
    w.penetration_fraction = std::max(w.penetration_fraction, q.penetration_fraction);
    w.max_penetration_m = std::max(w.max_penetration_m, q.max_penetration_m);
    w.max_seam_gap_m = std::max(w.max_seam_gap_m, q.max_seam_gap_m);
    w.mean_seam_gap_m = std::max(w.mean_seam_gap_m, q.mean_seam_gap_m);
    w.settled = w.settled && q.settled;
    w.residual = std::max(w.residual, q.residual);
    w.finite = w.finite && q.finite;
    w.lowest_y = std::min(w.lowest_y, q.lowest_y);
    w.drop_m = std::max(w.drop_m, q.drop_m);
    w.vertices = q.vertices;
  }
  w.finite = w.finite && r.status == StepStatus::Ok;
  float threshold = 0;
  for (const DressedGarment& g : r.dressed.garments) threshold = std::max(threshold, g.model.fabric.strain_threshold);
  // A moving garment is not at rest: the settled gate is left out (report.json keeps each frame's).
  for (GateResult& g : evaluate_gates(w, threshold, o.gates))
    if (g.name != "settled") r.gates.push_back(std::move(g));
  return r;
}

}  // namespace drape
