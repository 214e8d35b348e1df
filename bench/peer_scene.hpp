#pragma once
// What ../shared/peers' scenes (peers/README.md) give every engine, and drape's scene options for
// them: cotton's stiffness with its 5 % strain limit, the peers' mass, friction, margin and drag.
#include <cstdint>

#include "drape/cloth_scene.hpp"

namespace peer {

constexpr double kSimulatedSeconds = 2.0;
constexpr double kDensity = 0.2;   // kg/m^2
constexpr double kFriction = 0.3;
constexpr double kMargin = 0.01;   // m: drape's collision thickness
constexpr double kAirDrag = 1.0;   // 1/s

inline drape::ClothSceneOptions scene_options(drape::SceneObstacle obstacle, int n, drape::Solver solver) {
  drape::ClothSceneOptions options;
  options.solver = solver;
  options.obstacle = obstacle;
  options.n = static_cast<uint32_t>(n);
  options.fabric = drape::fabric_or_throw("cotton");
  options.fabric.areal_density = static_cast<float>(kDensity);
  options.fabric.friction = static_cast<float>(kFriction);
  options.fabric.collision_thickness = static_cast<float>(kMargin);
  options.fabric.air_damping = static_cast<float>(kAirDrag);
  options.fabric.air_drag = 0;
  options.strain_limit = drape::StrainLimit::Velocity;
  options.strain_threshold = 0.05f;
  return options;
}

}  // namespace peer
