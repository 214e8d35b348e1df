// The step's pure kernels alone: one spring, one over-stretched spring, one colliding particle.
#include <gtest/gtest.h>

#include <cmath>

#include "sim/kernels.hpp"

namespace drape::sim {
namespace {

TEST(SpringForce, ZeroAtRestLengthAndNoRelativeMotion) {
  const Vec3f f = spring_force(Vec3f(0, 0, 0), Vec3f(0.1f, 0, 0), Vec3f(1, 2, 3), Vec3f(1, 2, 3), 0.1f, 50.0f, 0.3f);
  EXPECT_LT(f.norm(), 1e-6f);
}

TEST(SpringForce, PullsStretchedEndsTogetherAndPushesCompressedApart) {
  const Vec3f stretched = spring_force(Vec3f(0, 0, 0), Vec3f(0.2f, 0, 0), Vec3f::Zero(), Vec3f::Zero(), 0.1f, 50.0f, 0);
  EXPECT_NEAR(stretched.x(), 50.0f * 0.1f, 1e-5f);  // eq. 2: k (|d| - l0) along d, on end a towards b
  const Vec3f compressed = spring_force(Vec3f(0, 0, 0), Vec3f(0.05f, 0, 0), Vec3f::Zero(), Vec3f::Zero(), 0.1f, 50.0f, 0);
  EXPECT_NEAR(compressed.x(), -50.0f * 0.05f, 1e-5f);
}

TEST(SpringForce, DampsOnlyTheRelativeVelocityAlongTheSpring) {
  // Ends moving apart along the spring: damping pulls a towards b.
  const Vec3f along = spring_force(Vec3f(0, 0, 0), Vec3f(0.1f, 0, 0), Vec3f(-1, 0, 0), Vec3f(1, 0, 0), 0.1f, 0, 0.5f);
  EXPECT_NEAR(along.x(), 0.5f * 2.0f, 1e-5f);
  // Relative motion across the spring is not damped.
  const Vec3f across = spring_force(Vec3f(0, 0, 0), Vec3f(0.1f, 0, 0), Vec3f(0, -1, 0), Vec3f(0, 1, 0), 0.1f, 0, 0.5f);
  EXPECT_LT(across.norm(), 1e-6f);
}

TEST(SpringForce, ClosedSeamOfZeroLengthGivesZeroNotNaN) {
  const Vec3f f = spring_force(Vec3f(1, 1, 1), Vec3f(1, 1, 1), Vec3f::Zero(), Vec3f(0, 1, 0), 0.0f, 100.0f, 1.0f);
  EXPECT_TRUE(f.allFinite());
  EXPECT_LT(f.norm(), 1e-6f);
}

TEST(VelocityModification, OverStretchedSpringLosesItsStretchingComponents) {
  // Spring along x, 6 % over its rest length; a moves away from b (-x), b away from a (+x), both also move in y.
  Vec3f va(-1, 0.5f, 0), vb(2, -0.5f, 0);
  ASSERT_TRUE(limit_spring_velocity(Vec3f(0, 0, 0), Vec3f(0.106f, 0, 0), va, vb, 1, 1, 0.105f, 1e-3f, 1e-6f));
  EXPECT_NEAR(va.x(), 0, 1e-6f);
  EXPECT_NEAR(vb.x(), 0, 1e-6f);
  EXPECT_FLOAT_EQ(va.y(), 0.5f);  // components across the spring are kept (fig. 1: v1n, v2n)
  EXPECT_FLOAT_EQ(vb.y(), -0.5f);
}

TEST(VelocityModification, ShorteningAndSlackSpringsAreLeftAlone) {
  Vec3f va(1, 0, 0), vb(-1, 0, 0);  // over-long but shortening
  EXPECT_FALSE(limit_spring_velocity(Vec3f(0, 0, 0), Vec3f(0.2f, 0, 0), va, vb, 1, 1, 0.105f, 1e-3f, 1e-6f));
  EXPECT_EQ(va, Vec3f(1, 0, 0));
  Vec3f wa(-0.01f, 0, 0), wb(0.01f, 0, 0);  // slack, stretching slowly, stays below the limit this step
  EXPECT_FALSE(limit_spring_velocity(Vec3f(0, 0, 0), Vec3f(0.1f, 0, 0), wa, wb, 1, 1, 0.105f, 1e-3f, 1e-6f));
  EXPECT_EQ(wb, Vec3f(0.01f, 0, 0));
}

TEST(VelocityModification, SpringNearTheLimitEndsTheStepExactlyAtIt) {
  const float dt = 1e-3f;
  Vec3f va(0, 0, 0), vb(10, 0, 0);  // would grow by 1 cm in one step; 4 mm of room left
  limit_spring_velocity(Vec3f(0, 0, 0), Vec3f(0.101f, 0, 0), va, vb, 1, 1, 0.105f, dt, 1e-6f);
  EXPECT_NEAR(0.101f + dt * (vb.x() - va.x()), 0.105f, 1e-6f);
}

TEST(VelocityModification, PinnedEndKeepsItsVelocity) {
  Vec3f va(-1, 0, 0), vb(1, 0, 0);
  limit_spring_velocity(Vec3f(0, 0, 0), Vec3f(0.2f, 0, 0), va, vb, 0.0f, 1.0f, 0.105f, 1e-3f, 1e-6f);
  EXPECT_EQ(va, Vec3f(-1, 0, 0));
  EXPECT_NEAR(vb.x(), 0, 1e-6f);
}

TEST(VelocityModification, NeverSpeedsAParticleUp) {
  // Removing a component along the spring can only shorten each end's velocity (kinetic energy never grows).
  for (int k = 0; k < 200; ++k) {
    const float a = 0.37f * static_cast<float>(k), b = 1.3f * static_cast<float>(k);
    Vec3f va(std::sin(a), std::cos(b), std::sin(a + b)), vb(std::cos(a), std::sin(2 * b), std::cos(a - b));
    const Vec3f va0 = va, vb0 = vb;
    const Vec3f xb(0.1f + 0.01f * std::sin(b), 0.02f * std::cos(a), 0.01f);
    limit_spring_velocity(Vec3f::Zero(), xb, va, vb, 1.0f, 0.5f, 0.1f, 1e-3f, 1e-6f);
    EXPECT_LE(va.norm(), va0.norm() + 1e-6f);
    EXPECT_LE(vb.norm(), vb0.norm() + 1e-6f);
  }
}

TEST(PositionModification, MovesEndsBackToTheLimitByInverseMass) {
  Vec3f xa(0, 0, 0), xb(0.2f, 0, 0);
  ASSERT_TRUE(limit_spring_position(xa, xb, 1.0f, 3.0f, 0.1f, 1e-6f));
  EXPECT_NEAR((xb - xa).norm(), 0.1f, 1e-6f);
  EXPECT_NEAR(xa.x(), 0.025f, 1e-6f);  // the lighter end (larger inverse mass) moves three times as far
}

TEST(ContactVelocity, ApproachingParticleStopsAtTheThicknessAndKeepsSliding) {
  // Plane y = 0, thickness 1 cm, particle 1.1 cm above falling at 2 m/s with 1 m/s sideways.
  Vec3f x(0, 0.011f, 0), v(1, -2, 0);
  const float dt = 1e-3f;
  ASSERT_TRUE(respond_contact_velocity(x, v, 0.011f, Vec3f::UnitY(), Vec3f::Zero(), 0.01f, 0.3f, 0.0f, dt));
  EXPECT_GE(0.011f + dt * v.y(), 0.01f - 1e-6f);
  // Coulomb: the tangential speed drops by mu times the normal speed change (2 m/s).
  EXPECT_NEAR(v.x(), 1.0f - 0.3f * 2.0f, 1e-5f);
}

TEST(ContactVelocity, FrictionStopsSlowSlidingCompletelyNeverReverses) {
  Vec3f x(0, 0.01f, 0), v(0.1f, -2, 0);
  respond_contact_velocity(x, v, 0.01f, Vec3f::UnitY(), Vec3f::Zero(), 0.01f, 0.3f, 0.0f, 1e-3f);
  EXPECT_FLOAT_EQ(v.x(), 0.0f);
}

TEST(ContactVelocity, ReflectsWithRestitutionAndFollowsAMovingSurface) {
  Vec3f x(0, 0.01f, 0), v(0, -2, 0);
  respond_contact_velocity(x, v, 0.01f, Vec3f::UnitY(), Vec3f(0, 1, 0), 0.01f, 0.0f, 0.5f, 1e-3f);
  // Relative normal velocity -3 m/s reflected to +1.5 m/s on top of the surface's 1 m/s.
  EXPECT_NEAR(v.y(), 2.5f, 1e-5f);
}

TEST(ContactVelocity, ParticleInsideTheLayerIsPutBackOnIt) {
  Vec3f x(0, 0.002f, 0), v(0, 0, 0);
  ASSERT_TRUE(respond_contact_velocity(x, v, 0.002f, Vec3f::UnitY(), Vec3f::Zero(), 0.01f, 0.3f, 0.0f, 1e-3f));
  EXPECT_NEAR(x.y(), 0.01f, 1e-6f);
  EXPECT_GE(v.y(), 0.0f);
}

TEST(ContactVelocity, FarParticleIsUntouched) {
  Vec3f x(0, 0.5f, 0), v(0, -1, 0);
  EXPECT_FALSE(respond_contact_velocity(x, v, 0.5f, Vec3f::UnitY(), Vec3f::Zero(), 0.01f, 0.3f, 0.0f, 1e-3f));
  EXPECT_EQ(v, Vec3f(0, -1, 0));
}

TEST(ContactForce, PushesOutProportionallyToDepthAndOnlyInside) {
  Vec3f shallow(0, 0, 0), deep(0, 0, 0), outside(0, 0, 0);
  respond_contact_force(shallow, 0.009f, Vec3f::UnitY(), Vec3f::Zero(), 0.01f, 0.0f, 1e-3f);
  respond_contact_force(deep, 0.005f, Vec3f::UnitY(), Vec3f::Zero(), 0.01f, 0.0f, 1e-3f);
  EXPECT_FALSE(respond_contact_force(outside, 0.02f, Vec3f::UnitY(), Vec3f::Zero(), 0.01f, 0.0f, 1e-3f));
  EXPECT_GT(shallow.y(), 0);
  EXPECT_NEAR(deep.y(), 5 * shallow.y(), 1e-4f);
  EXPECT_EQ(outside, Vec3f::Zero());
}

// rise_exceeds: over a circular arc (radius R, the ends' normals theta apart) the surface rises
// R (1 - cos(theta / 2)) above the chord, which the test must not rule out; the bound it tests is the
// rise of a ridge halfway along the chord, R sin(theta / 2) tan(theta / 2). A symmetric ridge rises
// exactly that; concave and flat surfaces never exceed anything.
TEST(RiseExceeds, NeverRulesOutAnArcAndBoundsARidgeExactly) {
  constexpr float radius = 0.05f, height = 0.004f;  // particles 4 mm off a cylinder of 5 cm
  for (float theta : {0.1f, 0.5f, 1.0f, 2.0f}) {
    const Vec3f na(std::sin(-theta / 2), std::cos(theta / 2), 0), nb(std::sin(theta / 2), std::cos(theta / 2), 0);
    const auto exceeds = [&](float allowed) {
      return rise_exceeds((radius + height) * na, height, na, (radius + height) * nb, height, nb, allowed);
    };
    const float arc = radius * (1 - std::cos(theta / 2)), ridge = radius * std::sin(theta / 2) * std::tan(theta / 2);
    EXPECT_TRUE(exceeds(0.99f * arc)) << theta;
    EXPECT_TRUE(exceeds(0.99f * ridge)) << theta;
    EXPECT_FALSE(exceeds(1.01f * ridge)) << theta;
  }
  // A ridge: two planes meeting at the origin, normals 90 degrees apart; the body points 2 cm down
  // either slope, so the ridge line rises 2 cm / sqrt(2) above their chord.
  const Vec3f na = Vec3f(-1, 1, 0).normalized(), nb = Vec3f(1, 1, 0).normalized();
  const Vec3f pa = 0.02f * Vec3f(-1, -1, 0).normalized(), pb = 0.02f * Vec3f(1, -1, 0).normalized();
  const float rise = 0.02f / std::sqrt(2.0f);
  EXPECT_TRUE(rise_exceeds(pa + height * na, height, na, pb + height * nb, height, nb, 0.99f * rise));
  EXPECT_FALSE(rise_exceeds(pa + height * na, height, na, pb + height * nb, height, nb, 1.01f * rise));
  // The same ridge turned into a valley (normals towards each other), and a plane.
  EXPECT_FALSE(rise_exceeds(-pb + height * nb, height, nb, -pa + height * na, height, na, 0.0f));
  EXPECT_FALSE(rise_exceeds(Vec3f(0, height, 0), height, Vec3f::UnitY(), Vec3f(0.03f, height, 0), height, Vec3f::UnitY(), 0.0f));
}

}  // namespace
}  // namespace drape::sim
