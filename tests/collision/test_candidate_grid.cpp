// The candidate grid (collision/candidate_grid.hpp) must give exactly the tree's answer: the same
// nearest distance for every point, inside or outside the band, for any query radius.
#include <gtest/gtest.h>

#include <cstdlib>
#include <initializer_list>
#include <memory>
#include <random>
#include <vector>

#include "collision/triangle_bvh.hpp"
#include "drape/io.hpp"
#include "support/test_support.hpp"

namespace drape::collision {
namespace {

// mean_all with its tree and full candidate grid (the test is skipped without ../shared/data).
class MeanAllGrid : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto path = DRAPE_REQUIRE_SHARED("bodies/garmentcode/mean_all.obj");
    body = read_mesh(path);
    surface = std::make_unique<BodySurface>(body.positions, body.triangles);
    bvh = std::make_unique<TriangleBvh>(*surface, /*refit=*/true);
    bvh->build_candidate_grid();
  }

  // `count` points near random vertices, off the skin along the normal by up to +-offset, jittered.
  std::vector<Vec3f> points_near_skin(unsigned seed, int count, float offset, float jitter) const {
    const auto normals = vertex_normals(body.positions, body.triangles);
    std::mt19937 rng(seed);
    std::uniform_int_distribution<size_t> vertex(0, body.positions.size() - 1);
    std::uniform_real_distribution<float> along(-offset, offset), shake(-jitter, jitter);
    std::vector<Vec3f> points;
    for (int i = 0; i < count; ++i) {
      const size_t v = vertex(rng);
      points.push_back(body.positions[v] + along(rng) * normals[v] + Vec3f(shake(rng), shake(rng), shake(rng)));
    }
    return points;
  }

  // Every point's answer through the grid equals the tree's, for each radius; returns how many found.
  int expect_answers_of_the_tree(const std::vector<Vec3f>& points, std::initializer_list<float> radii) const {
    int found = 0;
    for (const Vec3f& p : points)
      for (float radius : radii) {
        SurfaceHit grid_hit, tree_hit;
        const bool in_grid = bvh->closest(p, radius, grid_hit);
        EXPECT_EQ(in_grid, bvh->closest_in_tree(p, radius, tree_hit)) << "point " << p.transpose() << " radius " << radius;
        if (in_grid) {
          EXPECT_NEAR(grid_hit.distance, tree_hit.distance, 1e-6f) << "point " << p.transpose();
          ++found;
        }
      }
    return found;
  }

  Mesh body;
  std::unique_ptr<BodySurface> surface;
  std::unique_ptr<TriangleBvh> bvh;
};

TEST_F(MeanAllGrid, AnswersExactlyAsTheTree) {
  ASSERT_NE(bvh->candidate_grid(), nullptr);
  // Points up to 4 cm off the skin either way (beyond the 16 mm band too), near random vertices.
  const int count = std::getenv("DRAPE_SANITIZED") ? 2000 : 20000;
  const std::vector<Vec3f> points = points_near_skin(11, count, 0.04f, 0.005f);
  EXPECT_GT(expect_answers_of_the_tree(points, {0.005f, 0.02f, 0.1f}), count);  // most have the body within the larger radii
  // The batched query (staged prefetches over chunks of points) gives the same answers.
  for (float radius : {0.005f, 0.02f, 0.1f}) {
    std::vector<SurfaceHit> hits(points.size());
    std::vector<uint8_t> in_batch(points.size());
    bvh->closest_batch(points, radius, hits, in_batch);
    for (size_t i = 0; i < points.size(); ++i) {
      SurfaceHit single;
      const bool in_single = bvh->closest(points[i], radius, single);
      ASSERT_EQ(in_batch[i] != 0, in_single) << "point " << points[i].transpose() << " radius " << radius;
      if (in_single) {
        ASSERT_EQ(hits[i].distance, single.distance) << "point " << points[i].transpose();
      }
    }
  }
  // A moving body's update drops the grid (its lists hold for the old pose only).
  bvh->update();
  EXPECT_EQ(bvh->candidate_grid(), nullptr);
}

// A grid that lists only some cells (the image collider lists those above its hidden pixels) still
// answers exactly everywhere: a cell left out sends its queries to the tree.
TEST_F(MeanAllGrid, CellsLeftOutAskTheTree) {
  const size_t all_listed = bvh->candidate_grid()->listed_cells();
  // Only the body's left half (x > 0) and the cells above the waist.
  bvh->build_candidate_grid(TriangleBvh::kGridCell, TriangleBvh::kGridBand,
                            [](const Bounds& cell) { return cell.min.x() > 0.0f || cell.min.y() > 1.0f; });
  const size_t some_listed = bvh->candidate_grid()->listed_cells();
  EXPECT_GT(some_listed, all_listed / 5);
  EXPECT_LT(some_listed, all_listed * 4 / 5);
  const int count = std::getenv("DRAPE_SANITIZED") ? 1000 : 10000;
  EXPECT_GT(expect_answers_of_the_tree(points_near_skin(5, count, 0.03f, 0.0f), {0.005f, 0.02f}), count / 2);
}

}  // namespace
}  // namespace drape::collision
