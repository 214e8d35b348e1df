// Support springs (drape/soft_body.hpp): the soft regions of the default body, its rest under no
// force, and the collective response that keeps a region's volume when it is pressed.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <set>

#include "drape/soft_body.hpp"

namespace drape {
namespace {

const Body& female() {
  static const Body body = default_body(Sex::Female);
  return body;
}

const SoftRegionState& state(const SoftSolve& solve, const std::string& name) {
  for (const SoftRegionState& s : solve.regions)
    if (s.name == name) return s;
  throw std::runtime_error("no region " + name);
}

// Inward forces on the belly's vertices in a 4 cm band round the waist, `total` newtons in all
// (a tight waistband), spread by area.
std::vector<Vec3f> waistband(const Body& body, const SoftBody& soft, float total) {
  std::vector<Vec3f> f(body.mesh.positions.size(), Vec3f::Zero());
  const float y = body.landmarks.waist.y();
  double area = 0;
  std::vector<uint32_t> pressed;
  for (const SoftRegion& r : soft.regions)
    if (r.name == "belly")
      for (uint32_t v : r.vertices)
        if (std::abs(body.mesh.positions[v].y() - y) < 0.02f) {
          pressed.push_back(v);
          area += soft.area[v];
        }
  for (uint32_t v : pressed) {
    const Vec3f inward = (soft.frame[v] - soft.rest[v]).normalized();
    f[v] = static_cast<float>(total * soft.area[v] / area) * inward;
  }
  return f;
}

TEST(SoftBody, RegionsAreTheSoftPartsAndBoneStaysPut) {
  const Body& body = female();
  const SoftBody soft = make_soft_body(body);
  std::set<std::string> names;
  for (const SoftRegion& r : soft.regions) {
    names.insert(r.name);
    EXPECT_GT(r.vertices.size(), 50u) << r.name;
  }
  for (const char* name : {"belly", "buttocks", "left_thigh", "right_thigh", "bust", "left_upper_arm", "right_upper_arm"})
    EXPECT_TRUE(names.count(name)) << name;
  // Over bone: the shins, the shoulders' tops, the head, the hips' sides stay put.
  const Landmarks& lm = body.landmarks;
  for (size_t v = 0; v < body.mesh.positions.size(); ++v) {
    const Vec3f& p = body.mesh.positions[v];
    if (p.y() < lm.left_knee.y() || p.y() > lm.neck.y() || (p - lm.left_shoulder).norm() < 0.05f) {
      EXPECT_EQ(soft.region_of[v], -1) << "vertex " << v << " at y " << p.y();
    }
  }
  EXPECT_LT(soft.soft_count(), body.mesh.positions.size() / 2);
}

TEST(SoftBody, RestsInItsOwnShapeUnderNoForce) {
  const SoftBody soft = make_soft_body(female());
  const SoftSolve s = solve_soft_body(soft, {});
  EXPECT_LT(s.residual_n, 1e-4);
  for (size_t v = 0; v < soft.rest.size(); ++v) ASSERT_LT((s.positions[v] - soft.rest[v]).norm(), 1e-5f) << v;
  for (const SoftRegionState& r : s.regions) EXPECT_NEAR(r.volume_change, 0.0, 1e-6) << r.name;
}

// A waistband pressing 20 N into the belly: the belly gives way under it and bulges elsewhere,
// keeping its volume within 3 % (eq. 6's collective response); the spring forces balance the
// band's at every vertex (the residual); regions away from it do not move.
TEST(SoftBody, PressedRegionKeepsItsVolume) {
  const Body& body = female();
  const SoftBody soft = make_soft_body(body);
  const std::vector<Vec3f> f = waistband(body, soft, 20.0f);
  const SoftSolve s = solve_soft_body(soft, f);
  EXPECT_LT(s.residual_n, 1e-3);
  const SoftRegionState& belly = state(s, "belly");
  EXPECT_GT(belly.compression_m, 0.003f);
  EXPECT_LT(belly.compression_m, soft.options.depth);
  EXPECT_GT(belly.bulge_m, 0.0005f);
  EXPECT_LT(std::abs(belly.volume_change), 0.03);
  // The band's pressed volume comes back as the bulge: what the region lost under the band is many
  // times its net change.
  double pressed = 0, volume = 0;
  for (const SoftRegion& r : soft.regions)
    if (r.name == "belly")
      for (uint32_t v : r.vertices) {
        volume += soft.area[v] * soft.options.depth;
        if (f[v].squaredNorm() > 0) pressed += soft.area[v] * (soft.rest[v] - s.positions[v]).dot((soft.rest[v] - soft.frame[v]).normalized());
      }
  EXPECT_GT(pressed / volume, 10 * std::abs(belly.volume_change));
  // Regions away from the belly do not move; the bust, which borders it, hardly.
  for (const SoftRegionState& r : s.regions) {
    if (r.name != "belly") {
      EXPECT_LT(r.compression_m + r.bulge_m, r.name == "bust" ? 0.1f * belly.compression_m : 1e-6f) << r.name;
    }
  }
  std::fprintf(stderr, "belly: pressed in %.2f mm, out %.2f mm, volume %+.4f %% (pressed volume %.3f %%), %d Newton iterations\n",
               1e3 * belly.compression_m, 1e3 * belly.bulge_m, 100 * belly.volume_change, 100 * pressed / volume, s.newton_iterations);
}

// A solver kept from frame to frame (a motion: the band tightening and loosening by 10 % a frame)
// comes to the same rest as a fresh solve of each frame, within the forces' tolerance, and after
// its first solve factorises less often than the fresh ones, which factorise at least once each.
TEST(SoftBody, SolverKeptFromFrameToFrameFindsTheSameRestWithFewerFactorisations) {
  const Body& body = female();
  const SoftBody soft = make_soft_body(body);
  const std::vector<Vec3f> band = waistband(body, soft, 20.0f);
  SoftBodySolver kept(soft);
  std::vector<Vec3f> at = kept.solve(band).positions;
  int kept_factorisations = 0, fresh_factorisations = 0;
  for (int frame = 0; frame < 6; ++frame) {
    std::vector<Vec3f> press = band;
    for (Vec3f& f : press) f *= frame % 2 == 0 ? 1.1f : 1.0f;
    const SoftSolve a = kept.solve(press, at);
    const SoftSolve b = solve_soft_body(soft, press, at);
    EXPECT_LT(a.residual_n, 1e-4) << "frame " << frame;
    EXPECT_LT(b.residual_n, 1e-4) << "frame " << frame;
    EXPECT_GE(b.factorisations, 1);
    kept_factorisations += a.factorisations;
    fresh_factorisations += b.factorisations;
    float apart = 0;
    for (size_t v = 0; v < at.size(); ++v) apart = std::max(apart, (a.positions[v] - b.positions[v]).norm());
    EXPECT_LT(apart, 1e-5f) << "frame " << frame;
    at = a.positions;
  }
  EXPECT_LT(kept_factorisations, fresh_factorisations);
  std::fprintf(stderr, "6 frames: %d factorisations kept from frame to frame, %d fresh\n", kept_factorisations,
               fresh_factorisations);
}

}  // namespace
}  // namespace drape
