#include <gtest/gtest.h>

#include "drape/mesh.hpp"

using namespace drape;

TEST(Mesh, VertexNormalsOfTetrahedronPointOutward) {
  std::vector<Vec3f> p{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  std::vector<Tri> t{{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}};
  const auto n = vertex_normals(p, t);
  const Vec3f c = bounds(p).center();
  for (size_t i = 0; i < p.size(); ++i) {
    EXPECT_NEAR(n[i].norm(), 1.0f, 1e-5f);
    EXPECT_GT(n[i].dot(p[i] - c), 0.0f) << "vertex " << i;
  }
}
