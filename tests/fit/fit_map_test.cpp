// Fit maps (drape/fit_map.hpp) on scenes whose answers are known: strain along the grain of a
// stretched triangle and cloth, the pressure under cloth lying flat (its weight per area), Newton's
// third law between the cloth's contact forces and the body's pressure, and girths of a tube.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "drape/analytic_colliders.hpp"
#include "drape/fit_map.hpp"

namespace drape {
namespace {

TEST(FitStrain, TriangleStretchedAlongTheWarp) {
  const Vec2f a(0, 0), b(0.02f, 0), c(0, 0.02f);
  // The grain along flat y; the triangle lies in the x-y plane, stretched 3 % along y.
  const auto s = directional_strain(a, b, c, Vec3f(0, 0, 0), Vec3f(0.02f, 0, 0), Vec3f(0, 0.0206f, 0), Vec2f::UnitY());
  EXPECT_NEAR(s[0], 0.03f, 1e-5f);   // warp
  EXPECT_NEAR(s[1], 0.0f, 1e-5f);    // weft
  EXPECT_NEAR(s[2], std::sqrt(0.5f * (1.03f * 1.03f + 1.0f)) - 1.0f, 1e-5f);  // bias: the diagonal
  // The grain turned by 90 degrees swaps warp and weft.
  const auto t = directional_strain(a, b, c, Vec3f(0, 0, 0), Vec3f(0.02f, 0, 0), Vec3f(0, 0.0206f, 0), Vec2f::UnitX());
  EXPECT_NEAR(t[0], 0.0f, 1e-5f);
  EXPECT_NEAR(t[1], 0.03f, 1e-5f);
  // A rigid rotation of the 3D triangle changes nothing.
  const Eigen::Matrix3f r = Eigen::AngleAxisf(0.7f, Vec3f(0.3f, 0.9f, -0.2f).normalized()).toRotationMatrix();
  const auto u = directional_strain(a, b, c, r * Vec3f(0, 0, 0), r * Vec3f(0.02f, 0, 0), r * Vec3f(0, 0.0206f, 0),
                                    Vec2f::UnitY());
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(u[static_cast<size_t>(k)], s[static_cast<size_t>(k)], 1e-5f);
}

TEST(FitStrain, ShearStretchesOnlyTheBias) {
  const Vec2f a(0, 0), b(0.02f, 0), c(0, 0.02f);
  // Shear: the warp fibre a-c turns by 0.1 rad towards the weft, keeping its length, as does the
  // weft fibre a-b; only the diagonals change length.
  const float angle = 0.1f;
  const Vec3f pc(0.02f * std::sin(angle), 0.02f * std::cos(angle), 0);
  const auto s = directional_strain(a, b, c, Vec3f(0, 0, 0), Vec3f(0.02f, 0, 0), pc, Vec2f::UnitY());
  EXPECT_NEAR(s[0], 0.0f, 1e-5f);
  EXPECT_NEAR(s[1], 0.0f, 1e-5f);
  EXPECT_GT(s[2], 0.04f);  // one diagonal lengthens by about sin(angle) / 2
}

ClothModel flat_cloth(float size, uint32_t n) {
  GridClothOptions o;
  o.nx = o.ny = n;
  o.width = o.height = size;
  o.origin = Vec3f(-0.5f * size, 0.0f, -0.5f * size);
  return grid_cloth(fabric_or_throw("cotton"), o);
}

TEST(FitStrain, ClothStretchedAcrossTheWeftIsAtItsShareOfTheLimit) {
  const ClothModel model = flat_cloth(0.4f, 21);
  std::vector<Vec3f> x = model.rest_position;
  for (Vec3f& p : x) p.x() *= 1.02f;  // the grid's u axis (flat x) is the weft
  // The grid's flat coordinates: which flat axis runs along 3D x?
  const Vec2f du = model.flat_position[1] - model.flat_position[0];
  const Vec2f weft_axis = du.normalized();
  const Vec2f warp(-weft_axis.y(), weft_axis.x());  // weft = warp turned by -90 degrees
  const std::vector<Vec2f> grain(model.particle_count(), warp);
  const DirectionalStrain s = triangle_strain(model, x, grain);
  ASSERT_EQ(s.warp.size(), model.triangles.size());
  for (size_t t = 0; t < s.warp.size(); ++t) {
    EXPECT_NEAR(s.weft[t], 0.02f, 1e-4f);
    EXPECT_NEAR(s.warp[t], 0.0f, 1e-4f);
  }
  const std::vector<float> percent = strain_percent_of_limit(model, s, model.fabric.strain_threshold);
  for (float p : percent) EXPECT_NEAR(p, 100.0f * 0.02f / model.fabric.strain_threshold, 0.01f);
}

// A flat body (a square of ground triangulated at `cells` x `cells`) at y = 0.
Mesh ground(float size, int cells) {
  Mesh m;
  for (int j = 0; j <= cells; ++j)
    for (int i = 0; i <= cells; ++i)
      m.positions.emplace_back(size * (static_cast<float>(i) / static_cast<float>(cells) - 0.5f), 0.0f,
                               size * (static_cast<float>(j) / static_cast<float>(cells) - 0.5f));
  const auto at = [&](int i, int j) { return static_cast<uint32_t>(j * (cells + 1) + i); };
  for (int j = 0; j < cells; ++j)
    for (int i = 0; i < cells; ++i) {
      // Counter-clockwise seen from above (+y).
      m.triangles.push_back({at(i, j), at(i, j + 1), at(i + 1, j)});
      m.triangles.push_back({at(i + 1, j), at(i, j + 1), at(i + 1, j + 1)});
    }
  m.normals.assign(m.positions.size(), Vec3f::UnitY());
  return m;
}

TEST(FitPressure, ClothLyingFlatPressesWithItsWeightPerArea) {
  // Cloth at rest (springs at their rest length) lying on the ground at its collision thickness:
  // the ground carries each particle's weight, so the pressure under it is areal density x g.
  const ClothModel model = flat_cloth(0.5f, 26);
  std::vector<Vec3f> x = model.rest_position;
  for (Vec3f& p : x) p.y() = model.fabric.collision_thickness;
  const PlaneCollider plane(Vec3f::Zero(), Vec3f::UnitY());
  const Vec3f gravity(0, -9.81f, 0);
  const ContactForces contacts = contact_forces(model, x, {}, plane, gravity, model.fabric.collision_thickness + 0.003f);
  EXPECT_EQ(contacts.in_contact, model.particle_count());
  const double weight = 9.81 * static_cast<double>(model.total_mass());
  EXPECT_NEAR(contacts.weight, weight, 1e-6 * weight);
  EXPECT_NEAR(contacts.total.y(), weight, 1e-4 * weight);
  EXPECT_NEAR(contacts.total.x(), 0.0, 1e-6 * weight);

  const Mesh body = ground(1.0f, 100);
  PressureMap map = empty_pressure_map(body);
  add_pressure(map, body, contacts);
  finish_pressure(map, body);
  // Newton's third law: the body gets what the cloth got, reversed.
  EXPECT_NEAR(map.total.y(), -contacts.total.y(), 1e-4 * weight);
  // The pressure integrated over the ground is the weight; in the middle it is rho g.
  double integral = 0;
  for (size_t v = 0; v < body.positions.size(); ++v) integral += static_cast<double>(map.pressure[v] * map.area[v]);
  EXPECT_NEAR(integral, weight, 1e-3 * weight);
  // Each particle's share is spread over the skin near it; on a body grid aligned with the cloth's
  // the shares alias by up to 10 % from vertex to vertex, and average out.
  const float expected = model.fabric.areal_density * 9.81f;
  double middle = 0;
  int count = 0;
  for (size_t v = 0; v < body.positions.size(); ++v) {
    const Vec3f& p = body.positions[v];
    if (std::abs(p.x()) < 0.15f && std::abs(p.z()) < 0.15f) {
      EXPECT_NEAR(map.pressure[v], expected, 0.15f * expected) << v;
      middle += static_cast<double>(map.pressure[v]);
      ++count;
    }
    if (std::abs(p.x()) > 0.3f || std::abs(p.z()) > 0.3f) {
      EXPECT_EQ(map.pressure[v], 0.0f);  // no cloth there
    }
  }
  EXPECT_NEAR(middle / count, expected, 0.02 * expected);
}

TEST(FitPressure, ClothHangingFreeHasNoContact) {
  const ClothModel model = flat_cloth(0.3f, 11);
  std::vector<Vec3f> x = model.rest_position;
  for (Vec3f& p : x) p.y() = 0.2f;  // 20 cm above the ground
  const PlaneCollider plane(Vec3f::Zero(), Vec3f::UnitY());
  const ContactForces contacts = contact_forces(model, x, {}, plane, Vec3f(0, -9.81f, 0), 0.007f);
  EXPECT_EQ(contacts.in_contact, 0u);
  EXPECT_EQ(contacts.total.norm(), 0.0f);
  for (float d : contacts.distance) EXPECT_NEAR(d, 0.2f, 1e-5f);  // the ease map: distance to the body
}

TEST(FitGirth, TubeCutAcrossMeasuresItsPatternAndDrapedGirth) {
  // A grid cloth rolled into a tube around the y axis, stretched 3 % round: its girth on the
  // pattern is the cloth's width, as draped 3 % more (less the chords' shortfall).
  const float width = 0.8f, height = 0.3f;
  GridClothOptions o;
  o.nx = 81;
  o.ny = 16;
  o.width = width;
  o.height = height;
  o.origin = Vec3f(0, 0, 0);
  o.u_axis = Vec3f::UnitX();
  o.v_axis = Vec3f::UnitY();
  const ClothModel model = grid_cloth(fabric_or_throw("cotton"), o);
  const float circumference = 1.03f * width;
  const float radius = circumference / (2 * std::numbers::pi_v<float>);
  std::vector<Vec3f> x(model.particle_count());
  for (size_t i = 0; i < x.size(); ++i) {
    const Vec3f& p = model.rest_position[i];
    const float angle = 1.03f * p.x() / radius;
    x[i] = Vec3f(radius * std::sin(angle), p.y(), radius * std::cos(angle));
  }
  const GarmentCut cut = cut_garment(model, x, Vec3f(0, 0.151f, 0), Vec3f::UnitY(), 0.5f);
  EXPECT_NEAR(cut.pattern_m, width, 1e-3f);
  EXPECT_NEAR(cut.draped_m, circumference, 2e-3f);
  EXPECT_TRUE(cut.crosses_midline);
  // Beyond its reach or above the tube: nothing.
  EXPECT_EQ(cut_garment(model, x, Vec3f(0, 0.5f, 0), Vec3f::UnitY(), 0.1f).segments, 0u);
}

}  // namespace
}  // namespace drape
