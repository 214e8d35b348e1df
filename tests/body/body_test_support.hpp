#pragma once
// Helpers shared by the body tests.
#include "drape/mesh.hpp"

namespace drape::test {

// The volume a closed mesh encloses, positive where its triangles face outwards.
inline double signed_volume(const Mesh& m) {
  double v = 0;
  for (const Tri& t : m.triangles)
    v += m.positions[t[0]].cast<double>().dot(m.positions[t[1]].cast<double>().cross(m.positions[t[2]].cast<double>())) / 6.0;
  return v;
}

}  // namespace drape::test
