// The paper's rectangular-topology cloth mesh (Vassilev & Spanlang, sec. 2 and 6.2, fig. 5): mass
// points on a square lattice aligned with the grain line, clipped to the panel outline. Lattice
// points closer than 0.4 h to the outline are dropped, the sampled outline itself becomes the
// boundary (so seam vertices lie exactly on the pattern's edges), and the band between outline and
// lattice is filled by a constrained Delaunay triangulation. Springs follow the lattice: structural
// to the 4-neighbours, shear to the diagonals, flexion to the neighbours two apart.
#include <algorithm>
#include <cmath>
#include <limits>
#include <set>

#include "pattern/cdt.hpp"

namespace drape::pattern {

namespace {
constexpr double kMinBoundaryDistance = 0.4;  // in lattice spacings
constexpr int32_t kOffLattice = std::numeric_limits<int32_t>::min();
}  // namespace

PanelTriangulation triangulate_grid(const BoundaryLoop& boundary, const Vec2d& grain, double h, GridTopology& topo) {
  const Vec2d warp = grain.normalized();
  const Vec2d weft(warp.y(), -warp.x());
  const auto to_uv = [&](const Vec2d& p) { return Vec2d(p.dot(weft), p.dot(warp)); };

  // Lattice through the centre of the outline's (u, v) bounding box.
  Eigen::AlignedBox2d box;
  std::vector<Vec2d> uv;
  uv.reserve(boundary.points.size());
  for (const Vec2d& p : boundary.points) {
    uv.push_back(to_uv(p));
    box.extend(uv.back());
  }
  const Vec2d centre = box.center();
  const Vec2d first = centre - h * ((centre - box.min()) / h).array().ceil().matrix();
  const int ni = static_cast<int>(std::ceil((box.max().x() - first.x()) / h)) + 1;
  const int nj = static_cast<int>(std::ceil((box.max().y() - first.y()) / h)) + 1;

  topo.warp = warp;
  topo.weft = weft;
  topo.spacing = h;
  topo.origin = first.x() * weft + first.y() * warp;

  std::vector<Vec2d> points = boundary.points;
  topo.lattice.assign(points.size(), {kOffLattice, kOffLattice});
  std::vector<int64_t> index(static_cast<size_t>(ni) * static_cast<size_t>(nj), -1);
  const auto at = [&](int i, int j) -> int64_t {
    if (i < 0 || j < 0 || i >= ni || j >= nj) return -1;
    return index[static_cast<size_t>(j) * static_cast<size_t>(ni) + static_cast<size_t>(i)];
  };

  // Scanline per lattice row: inside where the row has crossed the outline an odd number of times.
  const SegmentGrid segments(boundary.points, h);
  std::vector<double> crossings;
  for (int j = 0; j < nj; ++j) {
    const double v = first.y() + j * h;
    crossings.clear();
    for (size_t s = 0; s < uv.size(); ++s) {
      const Vec2d& a = uv[s];
      const Vec2d& b = uv[(s + 1) % uv.size()];
      if ((a.y() <= v) != (b.y() <= v)) crossings.push_back(a.x() + (v - a.y()) / (b.y() - a.y()) * (b.x() - a.x()));
    }
    std::sort(crossings.begin(), crossings.end());
    for (size_t c = 0; c + 1 < crossings.size(); c += 2) {
      const int i0 = std::max(0, static_cast<int>(std::ceil((crossings[c] - first.x()) / h)));
      const int i1 = std::min(ni - 1, static_cast<int>(std::floor((crossings[c + 1] - first.x()) / h)));
      for (int i = i0; i <= i1; ++i) {
        const Vec2d p = (first.x() + i * h) * weft + v * warp;
        if (segments.distance(p, kMinBoundaryDistance * h) < kMinBoundaryDistance * h) continue;
        index[static_cast<size_t>(j) * static_cast<size_t>(ni) + static_cast<size_t>(i)] = static_cast<int64_t>(points.size());
        points.push_back(p);
        topo.lattice.push_back({i, j});
      }
    }
  }

  // Triangulate outline + lattice.
  Cdt cdt;
  insert_outline(cdt, boundary);
  for (size_t k = boundary.points.size(); k < points.size(); ++k) {
    const auto v = cdt.insert(Cdt::Point(points[k].x(), points[k].y()));
    v->info().value = static_cast<int64_t>(k);
  }
  mark_domain(cdt);
  PanelTriangulation tri = collect_triangulation(cdt, std::move(points));
  // Vertices the triangulation added (where two outline constraints cross) are off the lattice,
  // like the outline's own: every vertex has its lattice entry.
  topo.lattice.resize(tri.points.size(), {kOffLattice, kOffLattice});

  // Springs along the lattice (never across the outline, e.g. over a dart's gap).
  const auto link = [&](std::vector<std::array<uint32_t, 2>>& out, int64_t a, int64_t b) {
    if (a < 0 || b < 0) return false;
    if (segments.crosses(tri.points[static_cast<size_t>(a)], tri.points[static_cast<size_t>(b)])) return false;
    out.push_back({static_cast<uint32_t>(a), static_cast<uint32_t>(b)});
    return true;
  };
  std::vector<std::array<uint32_t, 2>> unused;
  for (int j = 0; j < nj; ++j) {
    for (int i = 0; i < ni; ++i) {
      const int64_t a = at(i, j);
      if (a < 0) continue;
      link(topo.structural, a, at(i + 1, j));
      link(topo.structural, a, at(i, j + 1));
      link(topo.shear, a, at(i + 1, j + 1));
      link(topo.shear, at(i + 1, j), at(i, j + 1));
      // Flexion: two apart with the middle present and both halves inside.
      for (const auto& [di, dj] : {std::pair{1, 0}, std::pair{0, 1}}) {
        const int64_t mid = at(i + di, j + dj), far = at(i + 2 * di, j + 2 * dj);
        if (mid >= 0 && far >= 0 && link(unused, a, mid) && link(unused, mid, far)) link(topo.flexion, a, far);
      }
    }
  }
  // Structural springs for the band: every triangle edge that touches an outline vertex.
  const auto boundary_count = static_cast<uint32_t>(boundary.points.size());
  std::set<std::pair<uint32_t, uint32_t>> band;
  for (const Tri& t : tri.triangles)
    for (int e = 0; e < 3; ++e) {
      const uint32_t a = t[static_cast<size_t>(e)], b = t[static_cast<size_t>((e + 1) % 3)];
      if (a < boundary_count || b < boundary_count) band.insert({std::min(a, b), std::max(a, b)});
    }
  for (const auto& [a, b] : band) topo.structural.push_back({a, b});
  return tri;
}

}  // namespace drape::pattern
