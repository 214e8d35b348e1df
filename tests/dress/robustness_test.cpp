// Robustness: a garment in the size its chart gives a body passes every gate from starts a little
// different from the one the other tests dress from: the mesh's edge up to 10 % longer or shorter,
// the whole placement moved up to 1 cm in a random direction. A single failure fails the case.
// Two starts per case here; ten with --gtest_also_run_disabled_tests
// (`build/tests/test_dress --gtest_also_run_disabled_tests --gtest_filter='*PerturbedStart*'`;
// docs/dressing.md, "Status").
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <functional>
#include <ostream>
#include <random>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "drape/dress.hpp"
#include "dress/dress_support.hpp"
#include "support/test_support.hpp"

namespace drape {
namespace {

using test::cached_body;
using test::failed_gates;
using test::sanitized;

struct Start {
  double edge_scale = 1;      // of the default grid spacing
  Vec3f offset = Vec3f::Zero();  // m
};

// `count` starts drawn from a fixed seed: the edge scale uniform in [0.9, 1.1], the offset's
// direction uniform on the sphere and its length uniform in [0, 1 cm].
std::vector<Start> perturbed_starts(size_t count, uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> scale(0.9, 1.1);
  std::uniform_real_distribution<float> length(0.0f, 0.01f);
  std::normal_distribution<float> normal(0.0f, 1.0f);
  std::vector<Start> starts(count);
  for (Start& s : starts) {
    s.edge_scale = scale(rng);
    Vec3f d(normal(rng), normal(rng), normal(rng));
    while (d.norm() < 1e-3f) d = Vec3f(normal(rng), normal(rng), normal(rng));
    s.offset = d.normalized() * length(rng);
  }
  return starts;
}

struct Case {
  std::string garment;
  Sex sex;
};
void PrintTo(const Case& c, std::ostream* os) { *os << c.garment << (c.sex == Sex::Female ? " female" : " male"); }
std::string case_name(const ::testing::TestParamInfo<Case>& p) {
  return p.param.garment + (p.param.sex == Sex::Female ? "_female" : "_male");
}

void expect_every_start_passes(const Body& body, const std::string& garment, size_t count) {
  const GarmentSpec spec = load_garment(garment);
  const std::string size = choose_size(spec, body.measurements).size;
  const std::vector<Start> starts = perturbed_starts(count, 2026u + static_cast<uint32_t>(std::hash<std::string>{}(garment) % 1000u));
  for (size_t k = 0; k < starts.size(); ++k) {
    const Start& s = starts[k];
    SCOPED_TRACE(fmt::format("{} {} start {}: edge x{:.3f}, placement moved ({:.4f}, {:.4f}, {:.4f}) m", garment, size, k,
                             s.edge_scale, s.offset.x(), s.offset.y(), s.offset.z()));
    DressOptions o;
    o.mesh.edge_length = kPaperEdgeLength * s.edge_scale;
    o.placement_offset = s.offset;
    const DressResult r = dress(body, {{spec, size}}, o);
    EXPECT_TRUE(r.passed()) << failed_gates(r);
  }
}

class PerturbedStart : public ::testing::TestWithParam<Case> {};
TEST_P(PerturbedStart, PassesTheGates) {
  if (sanitized()) GTEST_SKIP() << "sanitized build: only the default shirt on the default body";
  expect_every_start_passes(cached_body(GetParam().sex), GetParam().garment, 2);
}
TEST_P(PerturbedStart, DISABLED_PassesTheGatesFromTenStarts) {
  expect_every_start_passes(cached_body(GetParam().sex), GetParam().garment, 10);
}
INSTANTIATE_TEST_SUITE_P(Garments, PerturbedStart,
                         ::testing::Values(Case{"shirt", Sex::Female}, Case{"skirt", Sex::Female},
                                           Case{"trousers", Sex::Female}, Case{"jeans", Sex::Female},
                                           Case{"dress", Sex::Female}, Case{"shirt", Sex::Male},
                                           Case{"skirt", Sex::Male}, Case{"trousers", Sex::Male},
                                           Case{"jeans", Sex::Male}, Case{"dress", Sex::Male}),
                         case_name);

// The same on the shared bodies (../shared/data; skipped where absent): GarmentCode's mean body and
// the MakeHuman-derived ones, each garment in the size its chart gives the body. Ten starts each,
// with --gtest_also_run_disabled_tests only (250 dressings).
struct SharedCase {
  std::string garment, body;
};
void PrintTo(const SharedCase& c, std::ostream* os) { *os << c.garment << " on " << c.body; }
class PerturbedStartSharedBody : public ::testing::TestWithParam<SharedCase> {};
TEST_P(PerturbedStartSharedBody, DISABLED_PassesTheGatesFromTenStarts) {
  const auto path = DRAPE_REQUIRE_SHARED("bodies/" + GetParam().body);
  expect_every_start_passes(load_body(path), GetParam().garment, 10);
}
std::vector<SharedCase> shared_cases() {
  std::vector<SharedCase> cases;
  for (const char* body : {"garmentcode/mean_all.obj", "makehuman/derived/mh_female_average.obj",
                           "makehuman/derived/mh_female_heavy.obj", "makehuman/derived/mh_male_average.obj",
                           "makehuman/derived/mh_male_thin.obj"})
    for (const char* garment : {"shirt", "skirt", "trousers", "jeans", "dress"}) cases.push_back({garment, body});
  return cases;
}
INSTANTIATE_TEST_SUITE_P(Bodies, PerturbedStartSharedBody, ::testing::ValuesIn(shared_cases()),
                         [](const ::testing::TestParamInfo<SharedCase>& p) {
                           return p.param.garment + "_" + std::filesystem::path(p.param.body).stem().string();
                         });

}  // namespace
}  // namespace drape
