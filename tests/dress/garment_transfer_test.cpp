// Starting a dressing from the same garment dressed on another body of the same mesh
// (drape/garment_transfer.hpp): the transfer puts the garment back where it was on its own body,
// and a dressing started from it on a differently shaped body passes every gate there.
#include <gtest/gtest.h>

#include "dress/dress_support.hpp"
#include "drape/dress.hpp"
#include "drape/garment_transfer.hpp"

namespace drape {
namespace {

using test::cached_body;
using test::failed_gates;

const DressResult& dressed_default_shirt() {
  static const DressResult r = dress(cached_body(Sex::Female), {{load_garment("shirt"), "M"}}, DressOptions{});
  return r;
}

TEST(GarmentTransfer, OnItsOwnBodyPutsTheGarmentWhereItWas) {
  const Body& body = cached_body(Sex::Female);
  const DressedGarment& g = dressed_default_shirt().garments.at(0);
  const GarmentTransfer t = make_garment_transfer(body, g);
  EXPECT_TRUE(t.matches("shirt", "M", g.state.x.size(), mesh_fingerprint(body.mesh)));
  const std::vector<Vec3f> x = transfer_positions(t, body.mesh);
  ASSERT_EQ(x.size(), g.state.x.size());
  float worst = 0;
  for (size_t i = 0; i < x.size(); ++i) worst = std::max(worst, (x[i] - g.state.x[i]).norm());
  EXPECT_LT(worst, 1e-5f);
}

TEST(GarmentTransfer, RefusesABodyOfAnotherMesh) {
  const GarmentTransfer t = make_garment_transfer(cached_body(Sex::Female), dressed_default_shirt().garments.at(0));
  Mesh other = cached_body(Sex::Female).mesh;
  other.triangles.pop_back();
  EXPECT_NE(mesh_fingerprint(other), t.body_mesh);
  try {
    (void)transfer_positions(t, other);
    FAIL() << "no error";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("not the mesh the garment was dressed on"), std::string::npos) << e.what();
  }
}

// A shopper's body from measurements, fuller and taller than the default: the shirt started from
// the default body's drape closes, settles and passes every gate, as the one dressed from the flat
// pattern does, and with fewer Newton iterations (a quarter fewer and more built for the Intel
// Xeon; 123 against 159 built for the AMD EPYC).
TEST(GarmentTransfer, StartsTheSameGarmentOnAnotherBodyAndPassesTheGates) {
  if (test::sanitized()) GTEST_SKIP() << "sanitized build: only the default shirt";
  const Body& from = cached_body(Sex::Female);
  MeasurementRequest m = default_body_request(Sex::Female);
  m["height"] += 0.04f;
  m["bust"] += 0.04f;
  m["waist"] += 0.05f;
  m["hips"] += 0.03f;
  const Body to = make_human_body(Sex::Female, m);
  ASSERT_EQ(mesh_fingerprint(to.mesh), mesh_fingerprint(from.mesh));

  DressOptions o;
  o.transfers.push_back(std::make_shared<GarmentTransfer>(make_garment_transfer(from, dressed_default_shirt().garments.at(0))));
  const DressResult warm = dress(to, {{load_garment("shirt"), "M"}}, o);
  const DressResult cold = dress(to, {{load_garment("shirt"), "M"}}, DressOptions{});
  ASSERT_EQ(warm.garments.size(), 1u);
  EXPECT_TRUE(warm.garments[0].transferred);
  EXPECT_FALSE(cold.garments[0].transferred);
  EXPECT_TRUE(warm.passed()) << failed_gates(warm);
  EXPECT_TRUE(cold.passed()) << failed_gates(cold);
  EXPECT_LE(warm.quality.residual, 0.01f);
  const uint64_t warm_newton = warm.garments[0].implicit_profile.newton_iterations;
  const uint64_t cold_newton = cold.garments[0].implicit_profile.newton_iterations;
  std::printf("Newton iterations: transferred %llu, from the pattern %llu; simulation %.3f s against %.3f s\n",
              static_cast<unsigned long long>(warm_newton), static_cast<unsigned long long>(cold_newton),
              warm.simulation.wall_seconds, cold.simulation.wall_seconds);
  EXPECT_LT(5 * warm_newton, 4 * cold_newton);
}

// The jeans M dressed on the default body (waist 0.74 m) moved onto one with a 0.80 m waist and
// 1.04 m hips: the denim's band, stiff and tight, does not come to rest within the gates where the
// transfer puts it, where jeans placed anew slide to where the body's girth matches them. That start
// fails the gates, so the jeans are dressed again from their placement, and pass. (From the
// transferred start the jeans, the skirt and the trousers find a rest within the gates on waists
// up to 0.79 m since the contact stiffens past the skin; the jeans placed anew on 0.81 m and more
// fail too.)
TEST(GarmentTransfer, AStartThatFailsTheGatesIsDressedAgainFromThePlacement) {
  if (test::sanitized()) GTEST_SKIP() << "sanitized build: only the default shirt";
  const Body& from = cached_body(Sex::Female);
  const DressResult first = dress(from, {{load_garment("jeans"), "M"}}, DressOptions{});
  ASSERT_TRUE(first.passed()) << failed_gates(first);
  const Body to = make_human_body(Sex::Female, {{"waist", 0.80f}, {"hips", 1.04f}});
  DressOptions o;
  o.transfers.push_back(std::make_shared<GarmentTransfer>(make_garment_transfer(from, first.garments.at(0))));
  const DressResult r = dress(to, {{load_garment("jeans"), "M"}}, o);
  ASSERT_EQ(r.garments.size(), 1u);
  EXPECT_FALSE(r.garments[0].transferred);
  EXPECT_TRUE(r.garments[0].transfer_failed);
  EXPECT_TRUE(r.passed()) << failed_gates(r);
}

}  // namespace
}  // namespace drape
