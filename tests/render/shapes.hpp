#pragma once
// Analytic test shapes for the render tests.
#include <cmath>
#include <numbers>

#include "drape/mesh.hpp"

namespace drape {

// A UV sphere of radius r centred at c, counter-clockwise seen from outside.
inline Mesh uv_sphere(float r, Vec3f c, int slices, int stacks) {
  Mesh m;
  const float pi = std::numbers::pi_v<float>;
  m.positions.push_back(c + Vec3f(0, r, 0));
  for (int i = 1; i < stacks; ++i) {
    const float theta = pi * static_cast<float>(i) / static_cast<float>(stacks);
    for (int j = 0; j < slices; ++j) {
      const float phi = 2 * pi * static_cast<float>(j) / static_cast<float>(slices);
      m.positions.push_back(c + r * Vec3f(std::sin(theta) * std::sin(phi), std::cos(theta), std::sin(theta) * std::cos(phi)));
    }
  }
  m.positions.push_back(c + Vec3f(0, -r, 0));
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
