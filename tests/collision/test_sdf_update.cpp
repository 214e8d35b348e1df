// The distance field's incremental update for a moving body: two spheres, one of them moving. Only
// the bricks near the moving sphere are sampled again, and afterwards the field agrees with the
// exact distance around both spheres (within a voxel, as a freshly built field does).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <random>

#include "drape/collision.hpp"
#include "shapes.hpp"

namespace drape {
namespace {

TEST(SdfUpdate, ReSamplesOnlyNearTheMovedPartAndStaysExact) {
  const Vec3f still_centre(-0.3f, 1.0f, 0.0f), moving_centre(0.3f, 1.0f, 0.0f);
  const float radius = 0.12f;
  Mesh body = test::icosphere(still_centre, radius, 3);
  const Mesh other = test::icosphere(moving_centre, radius, 3);
  const auto offset = static_cast<uint32_t>(body.positions.size());
  body.positions.insert(body.positions.end(), other.positions.begin(), other.positions.end());
  for (const Tri& t : other.triangles) body.triangles.push_back({t[0] + offset, t[1] + offset, t[2] + offset});

  BodyColliderOptions options;
  options.voxel_size = 0.004f;
  options.band = 0.012f;
  const auto sdf = make_body_collider(body, CollisionMethod::sdf, options);
  auto exact = make_body_collider(body, CollisionMethod::bvh, options);
  std::vector<Vec3f> pose = body.positions;
  const Vec3f step(0.0f, 0.002f, 0.001f);  // per update: half a voxel
  const int frames = std::getenv("DRAPE_SANITIZED") ? 2 : 5;
  for (int frame = 1; frame <= frames; ++frame) {
    for (size_t v = offset; v < pose.size(); ++v) pose[v] += step;
    sdf->set_surface(pose, 0.01 * frame);
    exact->set_surface(pose, 0.01 * frame);
    // Only the moving sphere's neighbourhood was sampled again: well under the whole field.
    EXPECT_GT(sdf->build_stats().rebuilt_fraction, 0.0) << "frame " << frame;
    EXPECT_LT(sdf->build_stats().rebuilt_fraction, 0.7) << "frame " << frame;
  }
  // Around both spheres, points within the band: the field's distance within a voxel of the exact one.
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> unit(-1.0f, 1.0f), shell(-0.008f, 0.008f);
  const Vec3f moved_centre = moving_centre + static_cast<float>(frames) * step;
  std::vector<Vec3f> points;
  for (const Vec3f& centre : {still_centre, moved_centre})
    for (int i = 0; i < 400; ++i) {
      const Vec3f dir = Vec3f(unit(rng), unit(rng), unit(rng)).normalized();
      points.push_back(centre + (radius + shell(rng)) * dir);
    }
  std::vector<ContactSample> field(points.size()), truth(points.size());
  sdf->query(points, 0.05f, field);
  exact->query(points, 0.05f, truth);
  for (size_t i = 0; i < points.size(); ++i) {
    ASSERT_TRUE(std::isfinite(field[i].distance) && std::isfinite(truth[i].distance)) << i;
    EXPECT_NEAR(field[i].distance, truth[i].distance, options.voxel_size) << "point " << points[i].transpose();
  }
}

}  // namespace
}  // namespace drape
