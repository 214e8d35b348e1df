// Meshing a garment: the outlines are sampled first, seam by seam, so both sides of every seam get
// the same number of vertices at the same arc-length fractions (corners inside a multi-edge seam
// side are kept by moving the nearest sample onto them); unsewn edges are sampled at the edge
// length. The sampled outline is then filled by the grid or the triangle mesher.
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "drape/error.hpp"
#include "pattern/meshing.hpp"

namespace drape {
namespace pattern {
namespace {

// Samples along a seam side: count + 1 points, and for each of the side's edges the index of the
// sample at its start (the last entry is count).
struct SideSamples {
  std::vector<Vec2d> points;
  std::vector<size_t> corner;  // edge_count + 1 entries
};

SideSamples sample_side(const Panel& panel, const SeamSide& side, size_t count) {
  const size_t n = panel.edges.size();
  std::vector<const Curve*> edges;
  std::vector<double> start_len{0.0};
  for (uint32_t k = 0; k < side.edge_count; ++k) {
    edges.push_back(&panel.edges[(side.first_edge + k) % n]);
    start_len.push_back(start_len.back() + edges.back()->length());
  }
  const double total = start_len.back();
  SideSamples s;
  // Interior corners: the sample nearest to each corner's arc-length fraction, kept increasing.
  s.corner.push_back(0);
  for (size_t k = 1; k < edges.size(); ++k) {
    auto c = static_cast<size_t>(std::lround(start_len[k] / total * static_cast<double>(count)));
    c = std::clamp(c, s.corner.back() + 1, count - (edges.size() - k));
    s.corner.push_back(c);
  }
  s.corner.push_back(count);
  // Each edge gets its samples at equal arc length between its corners.
  for (size_t k = 0; k < edges.size(); ++k) {
    const size_t m = s.corner[k + 1] - s.corner[k];
    const std::vector<Vec2d> pts = edges[k]->sample_by_length(m);
    s.points.insert(s.points.end(), pts.begin(), pts.end() - 1);
  }
  s.points.push_back(edges.back()->end);
  return s;
}

// Samples per seam: enough for the longer side at the edge length, at least one per edge.
size_t seam_sample_count(const Garment& g, const SeamSpec& seam, double h) {
  const double longer = std::max(g.seam_side_length(seam.a), g.seam_side_length(seam.b));
  const size_t edges = std::max(seam.a.edge_count, seam.b.edge_count);
  return std::max<size_t>(edges, static_cast<size_t>(std::ceil(longer / h - 1e-9)));
}

}  // namespace
}  // namespace pattern

GarmentMesh mesh_garment(const Garment& garment, const MeshOptions& options) {
  using namespace pattern;
  const double h = options.edge_length;
  if (!(h > 0) || !std::isfinite(h)) throw std::invalid_argument("mesh_garment: edge length must be positive");

  // Which seam side covers each edge (seam index, 0 = side a / 1 = side b), -1 for unsewn edges.
  struct Owner {
    int seam = -1;
    int side = 0;
  };
  std::vector<std::vector<Owner>> owner(garment.panels.size());
  for (size_t p = 0; p < garment.panels.size(); ++p) owner[p].resize(garment.panels[p].edges.size());
  std::vector<std::array<SideSamples, 2>> sides(garment.seams.size());
  for (size_t s = 0; s < garment.seams.size(); ++s) {
    const SeamSpec& seam = garment.seams[s];
    const size_t count = seam_sample_count(garment, seam, h);
    for (int k = 0; k < 2; ++k) {
      const SeamSide& side = k == 0 ? seam.a : seam.b;
      const Panel& panel = garment.panels.at(side.panel);
      sides[s][static_cast<size_t>(k)] = sample_side(panel, side, count);
      for (uint32_t e = 0; e < side.edge_count; ++e)
        owner[side.panel][(side.first_edge + e) % panel.edges.size()] = {static_cast<int>(s), k};
    }
  }

  GarmentMesh out;
  // Boundary index of each edge's first point, per panel (to find seam vertices afterwards).
  std::vector<std::vector<uint32_t>> run_start(garment.panels.size());
  for (size_t p = 0; p < garment.panels.size(); ++p) {
    const Panel& panel = garment.panels[p];
    const size_t n = panel.edges.size();
    BoundaryLoop loop;
    run_start[p].resize(n);
    for (size_t e = 0; e < n; ++e) {
      run_start[p][e] = static_cast<uint32_t>(loop.points.size());
      const Owner o = owner[p][e];
      std::vector<Vec2d> run;
      if (o.seam >= 0) {
        const SeamSide& side = o.side == 0 ? garment.seams[static_cast<size_t>(o.seam)].a : garment.seams[static_cast<size_t>(o.seam)].b;
        const SideSamples& ss = sides[static_cast<size_t>(o.seam)][static_cast<size_t>(o.side)];
        const size_t k = (e + n - side.first_edge) % n;
        run.assign(ss.points.begin() + static_cast<std::ptrdiff_t>(ss.corner[k]),
                   ss.points.begin() + static_cast<std::ptrdiff_t>(ss.corner[k + 1]));
      } else {
        const Curve& c = panel.edges[e];
        const auto m = static_cast<size_t>(std::max(1.0, std::ceil(c.length() / h - 1e-9)));
        run = c.sample_by_length(m);
        run.pop_back();
      }
      const uint8_t kind = o.seam >= 0 ? kVertexSeam : kVertexHem;
      for (size_t i = 0; i < run.size(); ++i) {
        loop.points.push_back(run[i]);
        loop.edge.push_back(static_cast<uint32_t>(e));
        loop.flags.push_back(static_cast<uint8_t>(kVertexBoundary | kind | (i == 0 ? kVertexCorner : 0)));
      }
    }
    // A corner also ends the previous edge: it carries that edge's seam/hem flag too.
    for (size_t e = 0; e < n; ++e) {
      const size_t prev = (e + n - 1) % n;
      loop.flags[run_start[p][e]] |= owner[p][prev].seam >= 0 ? kVertexSeam : kVertexHem;
    }

    PanelMesh pm;
    PanelTriangulation tri;
    try {
      if (options.mesher == Mesher::grid) {
        GridTopology topo;
        tri = triangulate_grid(loop, panel.grain, h, topo);
        pm.grid = std::move(topo);
      } else {
        tri = triangulate_refined(loop, h);
      }
    } catch (const std::runtime_error& e) {
      throw InputError(garment.source, fmt::format("panel '{}': cannot be meshed: {}", panel.name, e.what()));
    }
    if (tri.triangles.empty())
      throw InputError(garment.source, fmt::format("panel '{}': meshing produced no triangles", panel.name));

    // Triangles wind like the outline, so their normal is the fabric's right side.
    if (panel.signed_area() < 0)
      for (Tri& t : tri.triangles) std::swap(t[1], t[2]);
    pm.mesh.name = panel.name;
    pm.mesh.triangles = std::move(tri.triangles);
    pm.mesh.positions.reserve(tri.points.size());
    pm.mesh.uvs.reserve(tri.points.size());
    for (const Vec2d& q : tri.points) {
      pm.mesh.positions.emplace_back(static_cast<float>(q.x()), static_cast<float>(q.y()), 0.0f);
      pm.mesh.uvs.emplace_back(static_cast<float>(q.x()), static_cast<float>(q.y()));
    }
    pm.flags.assign(tri.points.size(), 0);
    std::copy(loop.flags.begin(), loop.flags.end(), pm.flags.begin());
    pm.boundary.resize(loop.points.size());
    for (size_t i = 0; i < loop.points.size(); ++i) pm.boundary[i] = static_cast<uint32_t>(i);
    pm.boundary_edge = loop.edge;
    out.panels.push_back(std::move(pm));
  }

  // Seam vertex pairs: sample k of side a with sample k (same) or count - k (reversed) of side b.
  for (size_t s = 0; s < garment.seams.size(); ++s) {
    const SeamSpec& seam = garment.seams[s];
    const auto vertex = [&](const SeamSide& side, const SideSamples& ss, size_t k) {
      const size_t n = garment.panels[side.panel].edges.size();
      size_t j = 0;
      while (j + 1 < ss.corner.size() - 1 && ss.corner[j + 1] <= k) ++j;
      if (k == ss.corner.back()) return run_start[side.panel][(side.first_edge + side.edge_count) % n];
      return static_cast<uint32_t>(run_start[side.panel][(side.first_edge + j) % n] + (k - ss.corner[j]));
    };
    const SideSamples& sa = sides[s][0];
    const SideSamples& sb = sides[s][1];
    const size_t count = sa.corner.back();
    for (size_t k = 0; k <= count; ++k) {
      const size_t kb = seam.same_direction ? k : count - k;
      out.seam_pairs.push_back({static_cast<uint32_t>(s), seam.a.panel, vertex(seam.a, sa, k), seam.b.panel,
                                vertex(seam.b, sb, kb)});
    }
  }
  return out;
}

}  // namespace drape
