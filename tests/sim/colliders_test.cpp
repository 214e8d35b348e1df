// Analytic obstacles: exact distances and normals, outward-facing display meshes, batched queries.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <limits>
#include <memory>

#include "drape/analytic_colliders.hpp"

namespace drape {
namespace {

TEST(AnalyticColliders, SignedDistancesAndNormals) {
  Vec3f n;
  SphereCollider sphere(Vec3f(0, 1, 0), 0.5f);
  EXPECT_NEAR(sphere.signed_distance(Vec3f(0, 2, 0), &n), 0.5f, 1e-6f);
  EXPECT_EQ(n, Vec3f(0, 1, 0));
  EXPECT_NEAR(sphere.signed_distance(Vec3f(0.25f, 1, 0), &n), -0.25f, 1e-6f);

  BoxCollider box(Vec3f::Zero(), Vec3f(1, 0.5f, 2));
  EXPECT_NEAR(box.signed_distance(Vec3f(0, 1, 0), &n), 0.5f, 1e-6f);
  EXPECT_EQ(n, Vec3f(0, 1, 0));
  EXPECT_NEAR(box.signed_distance(Vec3f(2, 1.5f, 0), &n), std::sqrt(2.0f), 1e-6f);  // off an edge
  EXPECT_NEAR(box.signed_distance(Vec3f(0.9f, 0, 0), &n), -0.1f, 1e-6f);
  EXPECT_EQ(n, Vec3f(1, 0, 0));

  CapsuleCollider capsule(Vec3f(0, 0, 0), Vec3f(0, 1, 0), 0.1f);
  EXPECT_NEAR(capsule.signed_distance(Vec3f(0.3f, 0.5f, 0), &n), 0.2f, 1e-6f);
  EXPECT_NEAR(capsule.signed_distance(Vec3f(0, 1.3f, 0), &n), 0.2f, 1e-6f);
  EXPECT_EQ(n, Vec3f(0, 1, 0));

  PlaneCollider plane(Vec3f(0, 1, 0), Vec3f(0, 2, 0));
  EXPECT_NEAR(plane.signed_distance(Vec3f(5, 0.5f, 3), &n), -0.5f, 1e-6f);
}

TEST(AnalyticColliders, MovingColliderAndBatchedQuery) {
  SphereCollider sphere(Vec3f::Zero(), 0.3f);
  sphere.set_velocity(Vec3f(1, 0, 0));
  sphere.update(0.5);
  const Vec3f points[] = {Vec3f(0.5f, 0.4f, 0), Vec3f(3, 0, 0)};
  ContactSample out[2];
  sphere.query(points, 0.2f, out);
  EXPECT_NEAR(out[0].distance, 0.1f, 1e-6f);
  EXPECT_EQ(out[0].velocity, Vec3f(1, 0, 0));
  EXPECT_EQ(out[1].distance, std::numeric_limits<float>::infinity());  // beyond the query radius
}

TEST(AnalyticColliders, DisplayMeshesFaceOutwardAndLieOnTheSurface) {
  std::vector<std::unique_ptr<AnalyticCollider>> all;
  all.push_back(std::make_unique<SphereCollider>(Vec3f(0, 1, 0), 0.4f));
  all.push_back(std::make_unique<BoxCollider>(Vec3f(0, 1, 0), Vec3f(0.3f, 0.1f, 0.2f)));
  all.push_back(std::make_unique<CapsuleCollider>(Vec3f(0, 0, 0), Vec3f(0.2f, 1, 0), 0.1f));
  all.push_back(std::make_unique<PlaneCollider>(Vec3f(0, 0, 0), Vec3f(0, 1, 0)));
  for (const auto& c : all) {
    const Mesh m = c->mesh();
    ASSERT_FALSE(m.triangles.empty()) << c->name();
    for (const Vec3f& p : m.positions) EXPECT_NEAR(c->signed_distance(p, nullptr), 0.0f, 1e-5f) << c->name();
    for (const Tri& t : m.triangles) {
      const Vec3f a = m.positions[t[0]], b = m.positions[t[1]], d = m.positions[t[2]];
      const Vec3f face = (b - a).cross(d - a);
      Vec3f n;
      c->signed_distance((a + b + d) / 3.0f, &n);
      EXPECT_GT(face.dot(n), 0.0f) << c->name();
    }
  }
}

}  // namespace
}  // namespace drape
