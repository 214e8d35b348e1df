// UV ellipsoids for tests and benchmarks (drape/shapes.hpp).
#include "drape/shapes.hpp"

#include <cmath>
#include <numbers>
#include <stdexcept>

namespace drape {

Mesh uv_ellipsoid(const Vec3f& radii, const Vec3f& centre, int slices, int stacks) {
  if (slices < 3 || stacks < 2) throw std::invalid_argument("uv_ellipsoid: need at least 3 slices and 2 stacks");
  const float pi = std::numbers::pi_v<float>;
  Mesh m;
  m.positions.push_back(centre + Vec3f(0, radii.y(), 0));
  for (int i = 1; i < stacks; ++i) {
    const float theta = pi * static_cast<float>(i) / static_cast<float>(stacks);
    for (int j = 0; j < slices; ++j) {
      const float phi = 2 * pi * static_cast<float>(j) / static_cast<float>(slices);
      const Vec3f unit(std::sin(theta) * std::sin(phi), std::cos(theta), std::sin(theta) * std::cos(phi));
      m.positions.push_back(centre + unit.cwiseProduct(radii));
    }
  }
  m.positions.push_back(centre - Vec3f(0, radii.y(), 0));
  const auto ring = [&](int i, int j) { return static_cast<uint32_t>(1 + (i - 1) * slices + (j % slices)); };
  const auto bottom = static_cast<uint32_t>(m.positions.size() - 1);
  for (int j = 0; j < slices; ++j) {
    m.triangles.push_back({0, ring(1, j), ring(1, j + 1)});
    for (int i = 1; i + 1 < stacks; ++i) {
      m.triangles.push_back({ring(i, j), ring(i + 1, j), ring(i + 1, j + 1)});
      m.triangles.push_back({ring(i, j), ring(i + 1, j + 1), ring(i, j + 1)});
    }
    m.triangles.push_back({ring(stacks - 1, j), bottom, ring(stacks - 1, j + 1)});
  }
  m.normals = vertex_normals(m.positions, m.triangles);
  return m;
}

}  // namespace drape
