// Body collision: each method against exact distances on analytic shapes, the independent inside
// test, holes, moving bodies.
#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <cmath>
#include <cstdlib>
#include <numbers>
#include <random>

#include "collision/shapes.hpp"
#include "drape/collision.hpp"
#include "support/test_support.hpp"

namespace drape {
namespace {

constexpr float kDegree = std::numbers::pi_v<float> / 180.0f;
const float kInfinity = std::numeric_limits<float>::infinity();

using test::sanitized;

// A narrower distance-field band than the default keeps the field builds quick in tests.
BodyColliderOptions test_options() {
  BodyColliderOptions options;
  options.band = 0.01f;
  return options;
}

float signed_volume(const Mesh& m) {
  float v = 0;
  for (const Tri& t : m.triangles) v += m.positions[t[0]].dot(m.positions[t[1]].cross(m.positions[t[2]])) / 6.0f;
  return v;
}

// Points in a shell of +-`shell` metres around a sphere, in random directions.
std::vector<Vec3f> shell_points(const Vec3f& centre, float radius, float shell, int count, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<float> normal;
  std::uniform_real_distribution<float> offset(-shell, shell);
  std::vector<Vec3f> points;
  for (int i = 0; i < count; ++i) {
    const Vec3f d = Vec3f(normal(rng), normal(rng), normal(rng)).normalized();
    points.push_back(centre + (radius + offset(rng)) * d);
  }
  return points;
}

struct MethodCase {
  CollisionMethod method;
  bool hidden_handling;
};

class SphereMethods : public ::testing::TestWithParam<MethodCase> {};

// Distance within one pixel / voxel of the exact sphere distance, normal within a few degrees.
TEST_P(SphereMethods, DistanceAndNormalMatchTheSphere) {
  const Vec3f centre(0.1f, 1.0f, -0.05f);
  const float radius = 0.12f;
  const Mesh sphere = test::icosphere(centre, radius, 5);
  ASSERT_GT(signed_volume(sphere), 0);
  BodyColliderOptions options = test_options();
  options.hidden_region_handling = GetParam().hidden_handling;
  const auto collider = make_body_collider(sphere, GetParam().method, options);
  const float cell = GetParam().method == CollisionMethod::image ? options.pixel_size
                     : GetParam().method == CollisionMethod::sdf ? options.voxel_size
                                                                 : 0.0f;
  const float sagitta = 0.0003f;  // the tessellation's largest gap to the true sphere (20k triangles)
  // The image maps know the surface where a Z ray meets it, so they are judged in a thinner shell
  // (cloth in contact), and their normals only where the surface faces the views.
  const bool image = GetParam().method == CollisionMethod::image;
  const auto points = shell_points(centre, radius, image ? 0.005f : 0.02f, sanitized() ? 500 : 4000, 7);
  std::vector<ContactSample> samples(points.size());
  collider->query(points, 0.05f, samples);
  int checked = 0;
  for (size_t i = 0; i < points.size(); ++i) {
    const Vec3f radial = (points[i] - centre).normalized();
    // The plain image method is not expected to know edge-on surfaces (that is its blind spot).
    if (image && !GetParam().hidden_handling && std::abs(radial.z()) < 0.5f) continue;
    const float exact = (points[i] - centre).norm() - radius;
    // Beyond the silhouette the plain maps see nothing: allowed for points outside the body.
    if (image && !GetParam().hidden_handling && !std::isfinite(samples[i].distance) && exact > 0) continue;
    ++checked;
    ASSERT_TRUE(std::isfinite(samples[i].distance)) << "point " << i << " exact " << exact;
    EXPECT_NEAR(samples[i].distance, exact, cell + sagitta) << "point " << i;
    if (!image || std::abs(radial.z()) > 0.7f) {
      EXPECT_GT(samples[i].normal.dot(radial), std::cos((image ? 5 : 3) * kDegree)) << "point " << i;
    }
    EXPECT_EQ(samples[i].velocity, Vec3f::Zero());
  }
  EXPECT_GT(checked, static_cast<int>(points.size()) / 3);
}

// Same on a capsule standing upright (a limb): the side walls are edge-on to the image views.
TEST_P(SphereMethods, DistanceAndNormalMatchTheCapsule) {
  const Vec3f centre(0.0f, 0.8f, 0.0f);
  const float radius = 0.08f, half_length = 0.2f;
  const Mesh body = test::capsule(centre, radius, half_length, 96, 24);
  ASSERT_GT(signed_volume(body), 0);
  BodyColliderOptions options = test_options();
  options.hidden_region_handling = GetParam().hidden_handling;
  const auto collider = make_body_collider(body, GetParam().method, options);
  const float cell = GetParam().method == CollisionMethod::image ? options.pixel_size
                     : GetParam().method == CollisionMethod::sdf ? options.voxel_size
                                                                 : 0.0f;
  const float sagitta = radius * (1 - std::cos(std::numbers::pi_v<float> / 96)) + 0.0002f;
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> u(-1, 1);
  int checked = 0;
  // Queries are cheap even under sanitizers: keep the full sample so enough points land near the surface.
  for (int i = 0; i < 3000; ++i) {
    const Vec3f p = centre + Vec3f(0.1f * u(rng), 0.3f * u(rng), 0.1f * u(rng));
    const float exact = test::capsule_distance(p, centre, radius, half_length);
    const bool image = GetParam().method == CollisionMethod::image;
    if (std::abs(exact) > (image ? 0.005f : 0.02f)) continue;
    Vec3f axis_point = centre;
    axis_point.y() += std::clamp(p.y() - centre.y(), -half_length, half_length);
    const Vec3f radial = (p - axis_point).normalized();
    if (image && !GetParam().hidden_handling && std::abs(radial.z()) < 0.5f) continue;
    ContactSample s;
    collider->query({&p, 1}, 0.05f, {&s, 1});
    if (image && !GetParam().hidden_handling && !std::isfinite(s.distance) && exact > 0) continue;
    ++checked;
    ASSERT_TRUE(std::isfinite(s.distance)) << "exact " << exact;
    EXPECT_NEAR(s.distance, exact, cell + sagitta);
    if (!image || std::abs(radial.z()) > 0.7f) {
      EXPECT_GT(s.normal.dot(radial), std::cos(5 * kDegree));
    }
  }
  EXPECT_GT(checked, 50);
}

INSTANTIATE_TEST_SUITE_P(Methods, SphereMethods,
                         ::testing::Values(MethodCase{CollisionMethod::bvh, true}, MethodCase{CollisionMethod::sdf, true},
                                           MethodCase{CollisionMethod::image, true},
                                           MethodCase{CollisionMethod::image, false}),
                         [](const auto& test_info) {
                           return std::string(to_string(test_info.param.method)) + (test_info.param.hidden_handling ? "" : "_plain");
                         });

// Nothing within the query radius: +inf, for every method.
TEST(BodyCollider, FarPointsReportInfinity) {
  const Mesh sphere = test::icosphere(Vec3f::Zero(), 0.2f, 3);
  for (auto method : {CollisionMethod::bvh, CollisionMethod::sdf, CollisionMethod::image}) {
    const auto collider = make_body_collider(sphere, method, test_options());
    const std::vector<Vec3f> points = {{0.0f, 0.0f, 0.5f}, {0.0f, 0.0f, 0.28f}, {3.0f, 0.0f, 0.0f}};
    std::vector<ContactSample> out(points.size());
    collider->query(points, 0.05f, out);
    for (const auto& s : out) EXPECT_EQ(s.distance, kInfinity) << to_string(method);
  }
}

TEST(BodyCollider, ParsesMethodNames) {
  EXPECT_EQ(parse_collision_method("image"), CollisionMethod::image);
  EXPECT_EQ(parse_collision_method("bvh"), CollisionMethod::bvh);
  EXPECT_EQ(parse_collision_method("sdf"), CollisionMethod::sdf);
  EXPECT_FALSE(parse_collision_method("ray"));
  EXPECT_THROW(make_body_collider(Mesh{}, CollisionMethod::bvh), std::invalid_argument);
}

// The inside test agrees with the analytic sphere and capsule away from the tessellation gap.
TEST(InsideTest, ExactOnKnownPoints) {
  const Vec3f centre(0.0f, 1.0f, 0.0f);
  const Mesh sphere = test::icosphere(centre, 0.3f, 4);
  const InsideTest test(sphere);
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> u(-0.5f, 0.5f);
  for (int i = 0; i < (sanitized() ? 500 : 5000); ++i) {
    const Vec3f p = centre + Vec3f(u(rng), u(rng), u(rng));
    const float exact = (p - centre).norm() - 0.3f;
    if (std::abs(exact) < 0.002f) continue;
    EXPECT_EQ(test.inside(p), exact < 0) << "exact distance " << exact;
    EXPECT_NEAR(test.unsigned_distance(p), std::abs(exact), 0.002f);
  }
  EXPECT_NEAR(test.winding_number(centre), 1.0, 0.02);
  EXPECT_NEAR(test.winding_number(centre + Vec3f(2, 0, 0)), 0.0, 1e-3);

  const Mesh body = test::capsule(centre, 0.1f, 0.3f, 48, 12);
  const std::vector<Vec3f> points = {centre, centre + Vec3f(0, 0.35f, 0), centre + Vec3f(0.09f, -0.29f, 0),
                                     centre + Vec3f(0.11f, 0, 0), centre + Vec3f(0, 0.45f, 0), centre + Vec3f(0, 0, -0.2f)};
  const auto stats = measure_penetration(body, points);
  EXPECT_EQ(stats.penetrating, 3u);
  EXPECT_DOUBLE_EQ(stats.fraction, 0.5);
  EXPECT_NEAR(stats.max_depth_m, 0.1f, 0.002f);
  EXPECT_EQ(measure_penetration(body, points, 0.05f).penetrating, 1u);  // only the centre is deeper than 5 cm
}

// A sphere with a few triangles removed (a scan with a hole) keeps the right sign, also in the hole.
TEST(Holes, SignStaysRightNearAHole) {
  const Vec3f centre(0.0f, 1.0f, 0.0f);
  const float radius = 0.2f;
  Mesh sphere = test::icosphere(centre, radius, 4);
  // Remove the triangles around the +z pole: a hole about 2-3 cm across.
  std::erase_if(sphere.triangles, [&](const Tri& t) {
    const Vec3f c = (sphere.positions[t[0]] + sphere.positions[t[1]] + sphere.positions[t[2]]) / 3.0f;
    return (c - centre).normalized().z() > 0.995f;
  });
  const InsideTest inside(sphere);
  std::vector<Vec3f> points;
  std::vector<bool> expect_inside;
  for (float offset : {-0.02f, -0.008f, 0.008f, 0.02f})
    for (float x : {0.0f, 0.004f, -0.006f}) {
      const Vec3f p = centre + Vec3f(x, 0.003f, radius + offset);
      points.push_back(p);
      expect_inside.push_back((p - centre).norm() < radius);
    }
  for (size_t i = 0; i < points.size(); ++i) EXPECT_EQ(inside.inside(points[i]), expect_inside[i]) << i;
  for (auto method : {CollisionMethod::bvh, CollisionMethod::sdf}) {
    const auto collider = make_body_collider(sphere, method, test_options());
    std::vector<ContactSample> out(points.size());
    collider->query(points, 0.1f, out);
    for (size_t i = 0; i < points.size(); ++i)
      EXPECT_EQ(out[i].distance < 0, expect_inside[i]) << to_string(method) << " point " << i << " d " << out[i].distance;
  }
}

// A body translated and rotated over time reports the rigid motion's velocity at the contact, and
// its distances follow the body.
TEST(MovingBody, ReportsSurfaceVelocity) {
  const Vec3f centre0(0.0f, 1.0f, 0.0f);
  const float radius = 0.15f;
  const Mesh sphere = test::icosphere(centre0, radius, 4);
  const Vec3f linear(0.3f, -0.1f, 0.2f);   // m/s
  const Vec3f angular(0.0f, 2.0f, 0.5f);   // rad/s, about the sphere's centre
  auto pose = [&](double t, std::span<Vec3f> out) {
    const Eigen::AngleAxisf rotation(static_cast<float>(t) * angular.norm(), angular.normalized());
    const Vec3f centre = centre0 + static_cast<float>(t) * linear;
    for (size_t v = 0; v < out.size(); ++v) out[v] = centre + rotation * (sphere.positions[v] - centre0);
  };
  const double dt = 1e-3, t1 = 0.1;
  const Vec3f centre1 = centre0 + static_cast<float>(t1) * linear;
  for (auto method : {CollisionMethod::bvh, CollisionMethod::sdf, CollisionMethod::image}) {
    auto collider = make_body_collider(sphere, method, test_options());
    collider->set_motion(pose);
    collider->update(t1 - dt);
    collider->update(t1);
    // Points just outside the moved sphere, in front (visible to the image maps) and to the side.
    for (const Vec3f& dir : {Vec3f(0, 0, 1), Vec3f(0.3f, 0.2f, 0.9f).normalized(), Vec3f(1, 0, 0), Vec3f(0, -0.5f, -0.8f).normalized()}) {
      const Vec3f p = centre1 + (radius + 0.004f) * dir;
      ContactSample s;
      collider->query({&p, 1}, 0.05f, {&s, 1});
      ASSERT_TRUE(std::isfinite(s.distance)) << to_string(method);
      EXPECT_NEAR(s.distance, 0.004f, 0.004f) << to_string(method);
      const Vec3f expected = linear + angular.cross(radius * dir);
      EXPECT_LT((s.velocity - expected).norm(), 0.02f * expected.norm())
          << to_string(method) << " got " << s.velocity.transpose() << " expected " << expected.transpose();
    }
  }
}

}  // namespace
}  // namespace drape
