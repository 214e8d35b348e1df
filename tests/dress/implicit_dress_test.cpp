// Dressing with the implicit solver (DressOptions::solver, drape/implicit.hpp): the garment ends in
// equilibrium (report.json's residual), every gate passes, and sizes that the explicit step leaves
// open or unsettled on the parametric generator's average bodies dress.
#include <gtest/gtest.h>

#include "dress/dress_support.hpp"
#include "drape/dress.hpp"

namespace drape {
namespace {

using test::cached_body;
using test::failed_gates;
using test::sanitized;

DressResult dress_implicit(const Body& body, const std::string& garment, const std::string& size) {
  DressOptions o;
  o.solver = Solver::Implicit;
  return dress(body, {{load_garment(garment), size}}, o);
}

void expect_in_equilibrium(const DressResult& r) {
  ASSERT_EQ(r.garments.size(), 1u);
  const DressedGarment& g = r.garments[0];
  EXPECT_EQ(g.status, StepStatus::Ok);
  EXPECT_TRUE(g.seams_closed);
  EXPECT_LE(r.quality.residual, 0.01f);
  EXPECT_TRUE(r.quality.settled);
  EXPECT_LE(r.quality.max_strain, g.model.fabric.strain_threshold + 0.01f);
  EXPECT_EQ(r.quality.penetrating_vertices, 0u);
  EXPECT_TRUE(r.passed()) << failed_gates(r);
  EXPECT_GT(g.implicit_profile.newton_iterations, 0u);
}

TEST(ImplicitDressing, DefaultShirtEndsInEquilibrium) {
  const DressResult r = dress_implicit(cached_body(Sex::Female), default_garment_name(), "");
  expect_in_equilibrium(r);
  // The report says which solver ran and carries the residual.
  const std::string report = dress_report_json(cached_body(Sex::Female), r, [] {
    DressOptions o;
    o.solver = Solver::Implicit;
    return o;
  }());
  EXPECT_NE(report.find("\"solver\": \"implicit\""), std::string::npos);
  EXPECT_NE(report.find("\"residual\""), std::string::npos);
}

// From 4000 particles the factorised matrix leaves out the self-contact pairs' blocks (the
// conjugate gradients' products take them): the dress at 1.6 cm cells (4198 particles), whose skirt
// folds against itself, dresses with its pattern analysed once, in equilibrium, passing every gate
// and with no edge through its own triangles.
TEST(ImplicitDressing, AGarmentOfOver4000ParticlesKeepsItsPatternThroughSelfContact) {
  DressOptions o;
  o.solver = Solver::Implicit;
  o.mesh.edge_length = 0.016;
  const DressResult r = dress(cached_body(Sex::Female), {{load_garment("dress"), ""}}, o);
  expect_in_equilibrium(r);
  const DressedGarment& g = r.garments[0];
  EXPECT_GE(g.model.particle_count(), 4000u);
  EXPECT_GT(g.implicit_profile.self_pairs_outside_pattern, 0u);
  EXPECT_EQ(g.implicit_profile.analyses, 1u);
  EXPECT_EQ(g.self_intersections, 0u);
}

// Sizes the explicit step does not dress on the parametric generator's average bodies (the default
// bodies when this was measured, test::generator_body): the shirt M on the male body (a shoulder
// corner 10-20 mm open) and the trousers S on the female body (an outseam's top corner 26 mm open).
struct ImplicitFit {
  const char* garment;
  const char* size;
  Sex sex;
};
class ImplicitBeyondExplicit : public ::testing::TestWithParam<ImplicitFit> {};
TEST_P(ImplicitBeyondExplicit, PassesTheGates) {
  if (sanitized()) GTEST_SKIP() << "sanitized build: only the default shirt";
  expect_in_equilibrium(dress_implicit(test::generator_body(GetParam().sex), GetParam().garment, GetParam().size));
}
INSTANTIATE_TEST_SUITE_P(Garments, ImplicitBeyondExplicit,
                         ::testing::Values(ImplicitFit{"shirt", "M", Sex::Male}, ImplicitFit{"trousers", "S", Sex::Female}),
                         [](const ::testing::TestParamInfo<ImplicitFit>& p) {
                           return std::string(p.param.garment) + "_" + p.param.size + "_" +
                                  (p.param.sex == Sex::Male ? "male" : "female");
                         });

}  // namespace
}  // namespace drape
