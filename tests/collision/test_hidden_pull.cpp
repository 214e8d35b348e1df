// A cloth strip pulled up into the armpit and between the legs of a real body (../shared/data,
// skipped when absent), through the image-space method with its hidden-region handling: it must stop
// at the skin, nothing inside the body and no segment through it, judged by the independent inside
// test (generalized winding number), never by the collider. The plain maps are run too and printed:
// on this A-pose the tops of both gaps face down and are seen edge-on, but their interpolated normals
// still point the strip back down, so the plain maps are right there as well (their failures are
// where layers hide each other: chin, hands, feet; see test_body_regions.cpp).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "drape/collision.hpp"
#include "drape/io.hpp"
#include "collision/image_pair.hpp"
#include "support/test_support.hpp"

namespace drape {
namespace {

constexpr float kThickness = 0.003f;  // the cloth's collision thickness (metres)

// The strip: a vertical line of particles 5 mm apart. It is pulled up in 2 mm steps; after each step
// every particle closer than the thickness to the body (or inside it) is put back on the thickness
// layer along the collider's normal, as the simulation's eq. 5 response does.
std::vector<Vec3f> pull_strip(const Collider& collider, Vec3f top, float pull) {
  std::vector<Vec3f> strip;
  for (int i = 0; i < 30; ++i) strip.push_back(top - Vec3f(0.0f, 0.005f * static_cast<float>(i), 0.0f));
  std::vector<ContactSample> contact(strip.size());
  for (float pulled = 0; pulled < pull; pulled += 0.002f) {
    for (Vec3f& x : strip) x.y() += 0.002f;
    collider.query(strip, 0.02f, contact);
    for (size_t i = 0; i < strip.size(); ++i)
      if (contact[i].distance < kThickness) strip[i] += (kThickness - contact[i].distance) * contact[i].normal;
  }
  return strip;
}

struct StripCheck {
  size_t inside_vertices = 0;   // deeper than 1 mm inside the body
  size_t crossing_segments = 0;  // segments between neighbours that pass through the body
};

StripCheck check(const InsideTest& truth, const std::vector<Vec3f>& strip) {
  StripCheck c;
  c.inside_vertices = measure_penetration(truth, strip, 0.001f).penetrating;
  for (size_t i = 0; i + 1 < strip.size(); ++i) {
    std::vector<Vec3f> samples;
    for (int k = 1; k < 10; ++k) samples.push_back(strip[i] + (static_cast<float>(k) / 10.0f) * (strip[i + 1] - strip[i]));
    c.crossing_segments += measure_penetration(truth, samples, 0.001f).penetrating > 0;
  }
  return c;
}

// The top of a gap: the lowest point inside the body on the vertical line through (x, z) above y0.
float gap_top(const InsideTest& truth, float x, float y0, float z) {
  for (float y = y0; y < y0 + 0.5f; y += 0.001f)
    if (truth.inside(Vec3f(x, y, z))) return y;
  return NAN;
}

// mean_all (GarmentCode, A-pose, 1.72 m, +X = the body's left, +Z front). The armpit: the outside
// run between the torso and the left arm along +x at chest height and the torso's mid-depth; the
// crotch: x = 0 at the legs' mid-depth.
TEST(HiddenRegions, StripPulledIntoArmpitAndCrotchIsCaught) {
  const auto path = DRAPE_REQUIRE_SHARED("bodies/garmentcode/mean_all.obj");
  const test::ImageCollidersWithTruth colliders(path);
  const Mesh& body = colliders.body;
  const InsideTest& truth = colliders.truth;
  const auto& plain = colliders.plain;
  const auto& handled = colliders.handled;

  float torso_z = 0, legs_z = 0;
  int torso_n = 0, legs_n = 0;
  for (const Vec3f& p : body.positions) {
    if (p.y() > 1.10f && p.y() < 1.20f && std::abs(p.x()) < 0.12f) torso_z += p.z(), ++torso_n;
    if (p.y() > 0.60f && p.y() < 0.70f) legs_z += p.z(), ++legs_n;
  }
  ASSERT_GT(torso_n, 0);
  ASSERT_GT(legs_n, 0);
  torso_z /= static_cast<float>(torso_n);
  legs_z /= static_cast<float>(legs_n);
  float gap_lo = NAN, gap_hi = NAN;
  bool seen_torso = false;
  for (float x = 0.0f; x < 0.5f; x += 0.001f) {
    const bool in = truth.inside(Vec3f(x, 1.15f, torso_z));
    if (in && std::isnan(gap_lo)) seen_torso = true;
    if (!in && seen_torso && std::isnan(gap_lo)) gap_lo = x;
    if (in && !std::isnan(gap_lo)) {
      gap_hi = x;
      break;
    }
  }
  ASSERT_FALSE(std::isnan(gap_hi)) << "no gap between arm and torso at chest height";

  struct Gap {
    const char* name;
    float x, y0, z;
  };
  for (const Gap& gap : {Gap{"armpit", 0.5f * (gap_lo + gap_hi), 1.15f, torso_z}, Gap{"crotch", 0.0f, 0.55f, legs_z}}) {
    const float top = gap_top(truth, gap.x, gap.y0, gap.z);
    ASSERT_FALSE(std::isnan(top)) << gap.name;
    // The strip starts 2 cm below the top of the gap and is pulled 6 cm up: 4 cm into the skin.
    const Vec3f start(gap.x, top - 0.02f, gap.z);
    ASSERT_FALSE(truth.inside(start)) << gap.name;
    const auto with = pull_strip(*handled, start, 0.06f);
    const auto without = pull_strip(*plain, start, 0.06f);
    const StripCheck h = check(truth, with), p = check(truth, without);
    std::printf("%-7s top of the gap y = %.3f: handled %zu vertices inside, %zu segments through the body; plain maps %zu, %zu\n",
                gap.name, top, h.inside_vertices, h.crossing_segments, p.inside_vertices, p.crossing_segments);
    // Caught: nothing inside, nothing through, and the strip's top rests on the skin (it was pulled
    // 4 cm past it) at least as high as the top of the gap was below it.
    EXPECT_EQ(h.inside_vertices, 0u) << gap.name;
    EXPECT_EQ(h.crossing_segments, 0u) << gap.name;
    EXPECT_LT(truth.unsigned_distance(with.front()), 0.01f) << gap.name;
    EXPECT_GT(with.front().y(), top - 0.01f) << gap.name;
  }
}

}  // namespace
}  // namespace drape
