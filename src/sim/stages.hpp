#pragma once
// The stages of one cloth step (see step.cpp for their order). Each reads the model and settings and
// writes the state or the scratch; none allocates.
#include <cstdint>
#include <span>

#include "drape/cloth.hpp"

namespace drape::sim {

struct StepContext {
  const ClothModel& model;
  ClothState& state;
  StepScratch& scratch;
  const StepSettings& settings;
  float dt;
};

struct StrainLimitResult {
  uint32_t passes = 0;
  uint64_t corrections = 0;
  bool at_pass_limit = false;  // the last pass still corrected springs
};

// contacts.cpp: nearest surface per particle over all colliders; responses.
void update_colliders(std::span<Collider* const> colliders, double time);
void detect_contacts(const StepContext& c, std::span<Collider* const> colliders);
// StepSettings::face_clearance: contacts lowered where the body rises under the cloth's edges.
void lift_over_curvature(const StepContext& c, std::span<Collider* const> colliders);
uint64_t apply_contact_forces(const StepContext& c);
// changed (optional, per particle): set to `mark` where the response changed a position or velocity.
uint64_t respond_to_contacts(const StepContext& c, uint32_t* changed = nullptr, uint32_t mark = 0);

// forces.cpp: per-spring forces, then per-particle gather + external forces + velocity update.
void compute_spring_forces(const StepContext& c);
void integrate_velocities(const StepContext& c);

// strain_limit.cpp: velocity modification (sec. 3.3) and position modification (sec. 3.2).
// answer_contacts: run respond_to_contacts after every pass (velocity collision response).
StrainLimitResult limit_strain_velocity(const StepContext& c, bool answer_contacts);
// converge_passes: further passes over the springs still near the limit (StepSettings::converge_passes).
StrainLimitResult limit_strain_position(const StepContext& c, int max_passes, int converge_passes);

// integrate.cpp: positions (eq. 3, last line) and the health check.
void integrate_positions(const StepContext& c);
StepStatus check_health(const StepContext& c);

}  // namespace drape::sim
