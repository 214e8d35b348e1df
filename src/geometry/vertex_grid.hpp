#pragma once
// Points bucketed on a uniform grid of cells `cell` wide, for queries within one cell: near(q)
// visits every point in q's cell and the 26 around it (all those within `cell` of q, and some
// farther), in an order that depends only on the points.
#include <cmath>
#include <cstdint>
#include <span>
#include <unordered_map>
#include <vector>

#include "drape/mesh.hpp"

namespace drape {

struct VertexGrid {
  float cell;
  std::unordered_map<uint64_t, std::vector<uint32_t>> buckets;
  static uint64_t key(int i, int j, int k) {
    return (static_cast<uint64_t>(static_cast<uint32_t>(i) & 0x1fffff) << 42) |
           (static_cast<uint64_t>(static_cast<uint32_t>(j) & 0x1fffff) << 21) | (static_cast<uint32_t>(k) & 0x1fffff);
  }
  int index(float v) const { return static_cast<int>(std::floor(v / cell)); }
  VertexGrid(std::span<const Vec3f> p, float c) : cell(c) {
    for (size_t v = 0; v < p.size(); ++v) buckets[key(index(p[v].x()), index(p[v].y()), index(p[v].z()))].push_back(static_cast<uint32_t>(v));
  }
  template <class F>
  void near(const Vec3f& q, F&& visit) const {
    const int i = index(q.x()), j = index(q.y()), k = index(q.z());
    for (int di = -1; di <= 1; ++di)
      for (int dj = -1; dj <= 1; ++dj)
        for (int dk = -1; dk <= 1; ++dk)
          if (auto it = buckets.find(key(i + di, j + dj, k + dk)); it != buckets.end())
            for (uint32_t v : it->second) visit(v);
  }
};

}  // namespace drape
