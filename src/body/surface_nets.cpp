// Naive surface nets, hand-written: no Debian package polygonises an implicit function into a
// clean quad-dominant mesh (CGAL's surface mesher is Delaunay-based and far slower for this use).
// Why surface nets rather than marching cubes: one vertex per cell gives near-uniform quads (about
// half the triangles of marching cubes for the same detail) and needs no case tables; the rare
// non-manifold cell is detected and the caller shifts the grid.
#include "body/surface_nets.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <unordered_map>

namespace drape::body {

namespace {

constexpr std::array<std::array<int, 3>, 8> kCorner{{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0},
                                                  {0, 0, 1}, {1, 0, 1}, {0, 1, 1}, {1, 1, 1}}};
constexpr std::array<std::array<int, 2>, 12> kEdge{{{0, 1}, {2, 3}, {4, 5}, {6, 7}, {0, 2}, {1, 3},
                                                 {4, 6}, {5, 7}, {0, 4}, {1, 5}, {2, 6}, {3, 7}}};

// For each corner sign mask: are the inside corners connected along cube edges, and the outside ones?
std::array<bool, 256> single_sheet_table() {
  std::array<bool, 256> table{};
  for (int mask = 0; mask < 256; ++mask) {
    auto connected = [&](bool want_inside) {
      int seen = 0, first = -1, count = 0;
      for (int c = 0; c < 8; ++c)
        if (((mask >> c) & 1) == want_inside) {
          if (first < 0) first = c;
          ++count;
        }
      if (count == 0) return true;
      seen = 1 << first;
      for (bool grew = true; grew;) {
        grew = false;
        for (const auto& e : kEdge) {
          const bool a = (seen >> e[0]) & 1, b = (seen >> e[1]) & 1;
          const bool ea = ((mask >> e[0]) & 1) == want_inside, eb = ((mask >> e[1]) & 1) == want_inside;
          if (ea && eb && a != b) {
            seen |= (1 << e[0]) | (1 << e[1]);
            grew = true;
          }
        }
      }
      return __builtin_popcount(static_cast<unsigned>(seen)) == count;
    };
    table[static_cast<size_t>(mask)] = connected(true) && connected(false);
  }
  return table;
}

Vec3f gradient(const ScalarField& f, const Vec3f& p, float h) {
  const Vec3f dx(h, 0, 0), dy(0, h, 0), dz(0, 0, h);
  return Vec3f(f(p + dx) - f(p - dx), f(p + dy) - f(p - dy), f(p + dz) - f(p - dz)) / (2 * h);
}

void project(const ScalarField& f, Vec3f& p, int steps, float h, float max_move) {
  const Vec3f start = p;
  for (int i = 0; i < steps; ++i) {
    const float v = f(p);
    const Vec3f g = gradient(f, p, h);
    const float g2 = g.squaredNorm();
    if (g2 < 1e-12f) break;
    p -= (v / g2) * g;
  }
  // Never move a vertex out of its neighbourhood (keeps the mesh valid where the field is flat).
  const Vec3f d = p - start;
  if (d.norm() > max_move) p = start + d * (max_move / d.norm());
}

}  // namespace

Mesh polygonise(const ScalarField& field, const Bounds& box, const PolygoniseOptions& options) {
  const float h = options.step;
  const Vec3f origin = box.min - Vec3f::Constant(2 * h);
  const Vec3f extent = box.size() + Vec3f::Constant(4 * h);
  const int nx = static_cast<int>(std::ceil(extent.x() / h)) + 1;
  const int ny = static_cast<int>(std::ceil(extent.y() / h)) + 1;
  const int nz = static_cast<int>(std::ceil(extent.z() / h)) + 1;
  auto index = [&](int i, int j, int k) { return (static_cast<size_t>(k) * ny + j) * nx + i; };
  auto point = [&](int i, int j, int k) { return Vec3f(origin + h * Vec3f(float(i), float(j), float(k))); };

  // Field samples on the grid (independent per point: parallel, deterministic).
  std::vector<float> value(static_cast<size_t>(nx) * ny * nz);
#pragma omp parallel for schedule(dynamic, 1)
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i) value[index(i, j, k)] = field(point(i, j, k));
  auto inside = [&](int i, int j, int k) { return value[index(i, j, k)] < 0.0f; };

  // A cell holds one sheet of surface (so one vertex keeps the mesh manifold) only when its inside
  // corners are connected along cube edges and so are its outside corners. Where the surface grazes
  // the grid (a saddle, a limb running along a grid diagonal) that fails; flipping the sign of the
  // corner nearest the surface (|value| tiny, a sub-millimetre change) restores it.
  const std::array<bool, 256> single_sheet = single_sheet_table();
  for (int pass = 0; pass < 16; ++pass) {
    bool changed = false;
    for (int k = 0; k + 1 < nz; ++k)
      for (int j = 0; j + 1 < ny; ++j)
        for (int i = 0; i + 1 < nx; ++i) {
          int mask = 0;
          for (int c = 0; c < 8; ++c)
            mask |= (value[index(i + kCorner[c][0], j + kCorner[c][1], k + kCorner[c][2])] < 0.0f) << c;
          if (single_sheet[static_cast<size_t>(mask)]) continue;
          size_t nearest = 0;
          float smallest = std::numeric_limits<float>::max();
          for (int c = 0; c < 8; ++c) {
            const size_t at = index(i + kCorner[c][0], j + kCorner[c][1], k + kCorner[c][2]);
            if (std::abs(value[at]) < smallest) {
              smallest = std::abs(value[at]);
              nearest = at;
            }
          }
          value[nearest] = value[nearest] < 0.0f ? 1e-7f : -1e-7f;
          changed = true;
        }
    if (!changed) break;
  }

  // One vertex per crossed cell: the mean of its edge crossings.
  Mesh mesh;
  std::unordered_map<size_t, uint32_t> vertex_of_cell;
  for (int k = 0; k + 1 < nz; ++k)
    for (int j = 0; j + 1 < ny; ++j)
      for (int i = 0; i + 1 < nx; ++i) {
        float v[8];
        int count = 0;
        for (int c = 0; c < 8; ++c) {
          v[c] = value[index(i + kCorner[c][0], j + kCorner[c][1], k + kCorner[c][2])];
          count += v[c] < 0.0f;
        }
        if (count == 0 || count == 8) continue;
        Vec3f sum = Vec3f::Zero();
        int n = 0;
        for (const auto& e : kEdge) {
          const float a = v[e[0]], b = v[e[1]];
          if ((a < 0.0f) == (b < 0.0f)) continue;
          const float t = a / (a - b);
          const Vec3f pa = point(i + kCorner[e[0]][0], j + kCorner[e[0]][1], k + kCorner[e[0]][2]);
          const Vec3f pb = point(i + kCorner[e[1]][0], j + kCorner[e[1]][1], k + kCorner[e[1]][2]);
          sum += pa + t * (pb - pa);
          ++n;
        }
        vertex_of_cell.emplace(index(i, j, k), static_cast<uint32_t>(mesh.positions.size()));
        mesh.positions.push_back(sum / static_cast<float>(n));
      }

  // One quad per crossed grid edge, joining the four cells around it; oriented so the normal points
  // from inside to outside.
  auto cell = [&](int i, int j, int k) { return vertex_of_cell.at(index(i, j, k)); };
  auto emit = [&](uint32_t a, uint32_t b, uint32_t c, uint32_t d, bool flip) {
    if (flip) std::swap(b, d);
    // Split along the shorter diagonal.
    const auto& p = mesh.positions;
    if ((p[a] - p[c]).squaredNorm() <= (p[b] - p[d]).squaredNorm()) {
      mesh.triangles.push_back({a, b, c});
      mesh.triangles.push_back({a, c, d});
    } else {
      mesh.triangles.push_back({a, b, d});
      mesh.triangles.push_back({b, c, d});
    }
  };
  for (int k = 1; k + 1 < nz; ++k)
    for (int j = 1; j + 1 < ny; ++j)
      for (int i = 1; i + 1 < nx; ++i) {
        const bool in = inside(i, j, k);
        // Edge along +x: cells (i, j-1..j, k-1..k).
        if (in != inside(i + 1, j, k))
          emit(cell(i, j - 1, k - 1), cell(i, j, k - 1), cell(i, j, k), cell(i, j - 1, k), !in);
        // Edge along +y: cells (i-1..i, j, k-1..k).
        if (in != inside(i, j + 1, k))
          emit(cell(i - 1, j, k - 1), cell(i - 1, j, k), cell(i, j, k), cell(i, j, k - 1), !in);
        // Edge along +z: cells (i-1..i, j-1..j, k).
        if (in != inside(i, j, k + 1))
          emit(cell(i - 1, j - 1, k), cell(i, j - 1, k), cell(i, j, k), cell(i - 1, j, k), !in);
      }
  if (!is_closed_manifold(mesh)) return {};

  // Put vertices on the surface, then even them out along it.
  const float fd_step = 0.25f * h;
  auto& pos = mesh.positions;
#pragma omp parallel for schedule(static)
  for (size_t v = 0; v < pos.size(); ++v) project(field, pos[v], options.projection_steps, fd_step, h);
  if (options.relax_iterations > 0) {
    std::vector<std::vector<uint32_t>> neighbours(pos.size());
    for (const Tri& t : mesh.triangles)
      for (int e = 0; e < 3; ++e) neighbours[t[e]].push_back(t[(e + 1) % 3]);
    for (int it = 0; it < options.relax_iterations; ++it) {
      const std::vector<Vec3f> normals = vertex_normals(pos, mesh.triangles);
      std::vector<Vec3f> next(pos.size());
#pragma omp parallel for schedule(static)
      for (size_t v = 0; v < pos.size(); ++v) {
        Vec3f c = Vec3f::Zero();
        for (uint32_t w : neighbours[v]) c += pos[w];
        c /= static_cast<float>(neighbours[v].size());
        Vec3f d = 0.5f * (c - pos[v]);
        d -= d.dot(normals[v]) * normals[v];
        Vec3f q = pos[v] + d;
        project(field, q, options.projection_steps, fd_step, h);
        next[v] = q;
      }
      pos.swap(next);
    }
  }
  mesh.normals = vertex_normals(pos, mesh.triangles);
  return mesh;
}

bool is_closed_manifold(const Mesh& mesh) {
  // Directed edges: each must appear once, and its reverse once.
  std::unordered_map<uint64_t, int> directed;
  directed.reserve(mesh.triangles.size() * 3);
  for (const Tri& t : mesh.triangles)
    for (int e = 0; e < 3; ++e) {
      const uint64_t key = (uint64_t{t[e]} << 32) | t[(e + 1) % 3];
      if (++directed[key] > 1) return false;
    }
  for (const auto& [key, n] : directed) {
    const uint64_t reverse = (key << 32) | (key >> 32);
    if (!directed.count(reverse)) return false;
  }
  // Single fan per vertex: the outgoing edges around a vertex form one cycle.
  std::vector<std::vector<std::pair<uint32_t, uint32_t>>> fan(mesh.positions.size());
  for (const Tri& t : mesh.triangles)
    for (int e = 0; e < 3; ++e) fan[t[e]].emplace_back(t[(e + 1) % 3], t[(e + 2) % 3]);
  for (const auto& f : fan) {
    if (f.empty()) continue;
    std::unordered_map<uint32_t, uint32_t> next;
    for (auto [a, b] : f) next[a] = b;
    size_t steps = 0;
    uint32_t at = f[0].first;
    do {
      at = next.at(at);
      ++steps;
    } while (at != f[0].first && steps <= f.size());
    if (steps != f.size()) return false;
  }
  return true;
}

}  // namespace drape::body
