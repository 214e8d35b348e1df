// Cloth dropped onto real bodies (../shared/data; skipped when absent) through each collision
// method: after falling over the head and shoulders, no cloth vertex may be inside the body deeper
// than the collision thickness, judged by the independent inside test.
#include <gtest/gtest.h>

#include <cstdlib>

#include "drape/cloth.hpp"
#include "drape/collision.hpp"
#include "drape/fabric.hpp"
#include "drape/io.hpp"
#include "support/test_support.hpp"

namespace drape {
namespace {

void drop_cloth_on(const Mesh& body) {
  const bool sanitized = std::getenv("DRAPE_SANITIZED") != nullptr;
  const InsideTest truth(body);
  const Bounds box = bounds(body.positions);
  for (auto method : {CollisionMethod::image, CollisionMethod::bvh, CollisionMethod::sdf}) {
    BodyColliderOptions options;
    options.voxel_size = 0.005f;  // quicker field build; distances still within a voxel
    options.band = 0.01f;
    auto collider = make_body_collider(body, method, options);
    // A 0.5 m square held flat 3 cm above the top of the head, centred on it.
    GridClothOptions grid;
    grid.nx = grid.ny = sanitized ? 12 : 24;
    grid.width = grid.height = 0.5f;
    const Vec3f top(0.5f * (box.min.x() + box.max.x()), box.max.y() + 0.03f, 0.5f * (box.min.z() + box.max.z()));
    grid.origin = top - Vec3f(0.25f, 0.0f, 0.25f);
    const Fabric fabric;
    const ClothModel model = grid_cloth(fabric, grid);
    ClothState state = initial_state(model);
    const StepSettings settings = default_step_settings(model);
    StepScratch scratch(model);
    Collider* colliders[] = {collider.get()};
    const double dt = settings.time_step > 0 ? settings.time_step : model.stable_time_step();
    const int steps = static_cast<int>((sanitized ? 0.25 : 0.6) / dt);
    for (int i = 0; i < steps; ++i)
      ASSERT_EQ(step(model, state, colliders, settings, scratch), StepStatus::Ok) << to_string(method) << " step " << i;
    const auto stats = measure_penetration(truth, state.x, fabric.collision_thickness);
    EXPECT_EQ(stats.penetrating, 0u) << to_string(method) << ": deepest " << stats.max_depth_m << " m";
    // It did fall onto the body: some vertex lies on the skin (within a centimetre).
    float nearest = 1e9f;
    for (const Vec3f& x : state.x) nearest = std::min(nearest, truth.unsigned_distance(x));
    EXPECT_LT(nearest, 0.01f) << to_string(method);
  }
}

TEST(ClothDrop, OntoGarmentCodeMeanBody) {
  const auto path = DRAPE_REQUIRE_SHARED("bodies/garmentcode/mean_all.obj");
  drop_cloth_on(read_mesh(path));
}

TEST(ClothDrop, OntoMakeHumanBody) {
  const auto path = DRAPE_REQUIRE_SHARED("bodies/makehuman/derived/mh_female_average.obj");
  drop_cloth_on(read_mesh(path));
}

}  // namespace
}  // namespace drape
