// One step of the cloth simulation: the whole algorithm in the order it runs. Each stage is a
// function in its own file (stages.hpp) and is timed into StepProfile.
//
//   update colliders      bodies move to t + dt (animation, soft tissue)
//   detect contacts       nearest surface of every particle (drape::Collider), lifted by the
//                         body's curvature under the cloth's edges            [face_clearance]
//   spring forces         eq. 2 + damping along each spring
//   integrate velocities  gather forces per particle, gravity, viscous damping, air drag; eq. 3
//   contact forces        sec. 5 force response (animated bodies)          [Force response]
//   respond to contacts   eq. 5 on velocities                              [Velocity response]
//   limit strain          velocity modification, sec. 3.3, each pass followed by
//                         the contact response (velocities only)          [Velocity limit]
//   integrate positions   eq. 3
//   limit strain          position modification, Provot / sec. 3.2         [Position limit, or
//                         position_passes after velocity modification]
//   check health          NaN / explosion: reported, sticky, never hidden
#include <chrono>
#include <limits>
#include <stdexcept>

#include "sim/parallel.hpp"
#include "sim/stages.hpp"

namespace drape {

std::string_view to_string(StepStatus status) {
  switch (status) {
    case StepStatus::Ok: return "ok";
    case StepStatus::NonFinite: return "non-finite positions or velocities (NaN/inf)";
    case StepStatus::Exploded: return "exploded (a particle exceeded the speed limit)";
  }
  return "unknown";
}

std::string_view to_string(StrainLimit limit) {
  switch (limit) {
    case StrainLimit::None: return "none";
    case StrainLimit::Position: return "position";
    case StrainLimit::Velocity: return "velocity";
  }
  return "unknown";
}

std::string_view StepProfile::name(Stage stage) {
  static constexpr std::string_view names[StageCount] = {
      "update_colliders",  "detect_contacts",       "spring_forces",       "integrate_velocities",
      "contact_forces",    "limit_strain_velocity", "respond_to_contacts", "integrate_positions",
      "limit_strain_position", "check_health"};
  return names[stage];
}

double StepProfile::total_seconds() const {
  double sum = 0;
  for (double s : seconds) sum += s;
  return sum;
}

StepSettings default_step_settings(const ClothModel& model) {
  StepSettings s;
  s.strain_threshold = model.fabric.strain_threshold;
  return s;
}

ClothState initial_state(const ClothModel& model) {
  ClothState s;
  s.x = model.rest_position;
  s.v.assign(model.particle_count(), Vec3f::Zero());
  return s;
}

StepScratch::StepScratch(const ClothModel& model, size_t colliders) { resize(model, colliders); }

void StepScratch::resize(const ClothModel& model, size_t colliders) {
  spring_force.assign(model.spring_count(), Vec3f::Zero());
  contact.assign(model.particle_count(), ContactSample{});
  contact_tmp.assign(colliders > 1 ? model.particle_count() : 0, ContactSample{});
  contact_plane.assign(model.particle_count(), std::numeric_limits<float>::infinity());
  const size_t blocks = sim::block_count(model.particle_count());
  block_energy.assign(blocks, 0.0);
  block_speed.assign(blocks, 0.0f);
  block_count.assign(blocks, 0u);
  active_spring.assign(model.limit_a.size(), 0u);
  limit_incident_begin.assign(model.particle_count() + 1, 0u);
  for (size_t s = 0; s < model.limit_a.size(); ++s) {
    ++limit_incident_begin[model.limit_a[s] + 1];
    ++limit_incident_begin[model.limit_b[s] + 1];
  }
  for (size_t i = 0; i < model.particle_count(); ++i) limit_incident_begin[i + 1] += limit_incident_begin[i];
  limit_incident.assign(2 * model.limit_a.size(), 0u);
  {
    std::vector<uint32_t> next(limit_incident_begin.begin(), limit_incident_begin.end() - 1);
    for (size_t s = 0; s < model.limit_a.size(); ++s) {
      limit_incident[next[model.limit_a[s]]++] = static_cast<uint32_t>(s);
      limit_incident[next[model.limit_b[s]]++] = static_cast<uint32_t>(s);
    }
  }
  near_limit_bits.assign((model.limit_a.size() + 63) / 64, 0u);
  const size_t edges = model.range(SpringKind::Structural).size() + model.range(SpringKind::Shear).size();
  face_lift.edge.assign(edges, 0u);
  face_lift.block_measured.assign(sim::block_count(edges), 0u);
  face_lift.midpoint.assign(edges, Vec3f::Zero());
  face_lift.contact.assign(edges, ContactSample{});
  face_lift.contact_tmp.assign(colliders > 1 ? edges : 0, ContactSample{});
  face_lift.need.assign(model.particle_count(), 0.0f);
  face_lift.lift.assign(model.particle_count(), 0.0f);
  const size_t rows = model.limit_a.size();
  projection.node.assign(model.particle_count(), 0u);
  projection.node_inverse_mass.assign(model.particle_count(), 0.0f);
  projection.merged.assign(model.particle_count(), 0u);
  projection.seam_row.assign(rows, 0u);
  projection.a.assign(rows, 0u);
  projection.b.assign(rows, 0u);
  projection.direction.assign(rows, Vec3f::Zero());
  for (auto* v : {&projection.rhs, &projection.lambda, &projection.residual, &projection.search, &projection.product,
                  &projection.diagonal})
    v->assign(rows, 0.0f);
  projection.gathered.assign(model.particle_count(), Vec3f::Zero());
  projection.saved.assign(model.particle_count(), Vec3f::Zero());
  converge_start.assign(model.particle_count(), Vec3f::Zero());
  step_start.assign(model.particle_count(), Vec3f::Zero());
  changed_in_pass.assign(model.particle_count(), 0u);
  max_colliders = colliders;
}

namespace {

// Adds the wall-clock time since the last mark to one stage of the profile (if there is one).
class StageClock {
 public:
  explicit StageClock(StepProfile* profile) : profile_(profile), last_(now()) {}
  void mark(StepProfile::Stage stage) {
    if (!profile_) return;
    const double t = now();
    profile_->seconds[stage] += t - last_;
    last_ = t;
  }

 private:
  static double now() {
    return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
  }
  StepProfile* profile_;
  double last_;
};

}  // namespace

StepStatus step(const ClothModel& model, ClothState& state, std::span<Collider* const> colliders,
                const StepSettings& settings, StepScratch& scratch, StepProfile* profile) {
  if (state.status != StepStatus::Ok) return state.status;
  if (state.x.size() != model.particle_count() || state.v.size() != model.particle_count() ||
      scratch.spring_force.size() != model.spring_count() || scratch.contact.size() != model.particle_count() ||
      scratch.changed_in_pass.size() != model.particle_count() ||
      scratch.contact_plane.size() != model.particle_count() ||
      scratch.converge_start.size() != model.particle_count() ||
      scratch.projection.gathered.size() != model.particle_count() ||
      scratch.projection.saved.size() != model.particle_count() ||
      scratch.projection.a.size() != model.limit_a.size() ||
      scratch.limit_incident.size() != 2 * model.limit_a.size() ||
      scratch.step_start.size() != model.particle_count() ||
      scratch.face_lift.lift.size() != model.particle_count() ||
      scratch.face_lift.edge.size() != model.range(SpringKind::Structural).size() + model.range(SpringKind::Shear).size() ||
      (colliders.size() > 1 && scratch.face_lift.contact_tmp.size() != scratch.face_lift.edge.size()) ||
      colliders.size() > std::max<size_t>(scratch.max_colliders, 1) ||
      (colliders.size() > 1 && scratch.contact_tmp.size() != model.particle_count()))
    throw std::invalid_argument("step: state or scratch was not made for this model and collider count");

  const float dt = settings.time_step > 0 ? settings.time_step : model.stable_time_step();
  const sim::StepContext c{model, state, scratch, settings, dt};
  StageClock clock(profile);
  uint64_t contacts = 0;
  sim::StrainLimitResult limited;

  sim::update_colliders(colliders, state.time + dt);
  clock.mark(StepProfile::UpdateColliders);
  sim::detect_contacts(c, colliders);
  sim::lift_over_curvature(c, colliders);
  clock.mark(StepProfile::DetectContacts);
  sim::compute_spring_forces(c);
  clock.mark(StepProfile::SpringForces);
  sim::integrate_velocities(c);
  clock.mark(StepProfile::IntegrateVelocities);
  if (settings.collision_response == CollisionResponse::Force) contacts = sim::apply_contact_forces(c);
  clock.mark(StepProfile::ContactForces);
  if (settings.collision_response == CollisionResponse::Velocity) contacts = sim::respond_to_contacts(c);
  clock.mark(StepProfile::RespondToContacts);
  if (settings.strain_limit == StrainLimit::Velocity) {
    limited = sim::limit_strain_velocity(c, settings.collision_response == CollisionResponse::Velocity);
    clock.mark(StepProfile::LimitStrainVelocity);
  }
  sim::integrate_positions(c);
  clock.mark(StepProfile::IntegratePositions);
  if (settings.strain_limit == StrainLimit::Position) {
    limited = sim::limit_strain_position(c, settings.strain_passes, settings.converge_passes);
  } else if (settings.strain_limit == StrainLimit::Velocity && settings.position_passes > 0) {
    // Clean-up of what the velocity passes left (springs already past the threshold stay there
    // under velocity modification alone): counted with the velocity passes.
    const sim::StrainLimitResult cleanup = sim::limit_strain_position(c, settings.position_passes, settings.converge_passes);
    limited.passes += cleanup.passes;
    limited.corrections += cleanup.corrections;
    limited.at_pass_limit = limited.at_pass_limit || cleanup.at_pass_limit;
  }
  clock.mark(StepProfile::LimitStrainPosition);
  state.status = sim::check_health(c);
  clock.mark(StepProfile::CheckHealth);

  state.time += dt;
  ++state.iterations;
  if (profile) {
    ++profile->steps;
    profile->contacts += contacts;
    profile->strain_passes += limited.passes;
    profile->strain_corrections += limited.corrections;
    profile->steps_at_pass_limit += limited.at_pass_limit ? 1u : 0u;
  }
  return state.status;
}

}  // namespace drape
