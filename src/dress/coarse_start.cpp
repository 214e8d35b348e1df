// Coarse-to-fine dressing: a fine garment starts from the same garment dressed at a coarser grid.
//
// The explicit step is bounded by the grid spacing (eq. 4) and costs in proportion to the vertex
// count, so dressing a fine mesh from its placement costs (vertices x 1/spacing) x the simulated
// time to sew and settle: 16x the vertices took 8x the iterations at 18x the cost per iteration
// (README, Table 2). The shape a garment comes to rest in is set by the pattern, the body and the
// fabric, not by the resolution; so the garment is sewn and draped at a coarse spacing first, and
// every fine particle starts where its point of the flat pattern lies on the dressed coarse
// garment. The fine run then only has to close the seam pairs the coarse run left a few
// millimetres apart, take up the finer folds and settle.
//
// Point location is by hand (a bucket grid over each coarse panel's flat triangles): it is a few
// lines, runs once per garment, and no library here locates points in a 2D triangle soup.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <string_view>

#include "dress/stages.hpp"

namespace drape::dressing {
namespace {

// Barycentric coordinates of p in the flat triangle (a, b, c); false for a degenerate triangle.
bool barycentric(const Vec2f& p, const Vec2f& a, const Vec2f& b, const Vec2f& c, Vec3f& w) {
  const Vec2f e0 = b - a, e1 = c - a, d = p - a;
  const float det = e0.x() * e1.y() - e0.y() * e1.x();
  if (std::abs(det) <= 1e-14f) return false;
  const float u = (d.x() * e1.y() - d.y() * e1.x()) / det;
  const float v = (e0.x() * d.y() - e0.y() * d.x()) / det;
  w = Vec3f(1.0f - u - v, u, v);
  return true;
}

// How far outside the triangle barycentric coordinates put a point (0 inside), in units of the
// triangle: used to pick the nearest triangle for points outside every one.
float outside(const Vec3f& w) { return std::max({0.0f, -w.x(), -w.y(), -w.z()}); }

struct PanelLocator {
  Vec2f lo = Vec2f::Zero();
  float cell = 1;
  int nx = 0, ny = 0;
  std::vector<uint32_t> begin, tris;  // bucket b holds tris[begin[b], begin[b + 1])

  int clamp_x(float x) const { return std::clamp(static_cast<int>(std::floor((x - lo.x()) / cell)), 0, nx - 1); }
  int clamp_y(float y) const { return std::clamp(static_cast<int>(std::floor((y - lo.y()) / cell)), 0, ny - 1); }
};

PanelLocator build_locator(const ClothModel& m, std::span<const uint32_t> panel_tris) {
  PanelLocator l;
  Vec2f lo = Vec2f::Constant(std::numeric_limits<float>::max()), hi = -lo;
  double edge = 0;
  for (uint32_t t : panel_tris)
    for (int k = 0; k < 3; ++k) {
      const Vec2f& p = m.flat_position[m.triangles[t][k]];
      lo = lo.cwiseMin(p);
      hi = hi.cwiseMax(p);
      edge += (m.flat_position[m.triangles[t][(k + 1) % 3]] - p).norm();
    }
  l.lo = lo;
  l.cell = std::max(1e-4f, static_cast<float>(2.0 * edge / std::max<double>(3.0 * panel_tris.size(), 1.0)));
  l.nx = std::max(1, static_cast<int>(std::ceil((hi.x() - lo.x()) / l.cell)) + 1);
  l.ny = std::max(1, static_cast<int>(std::ceil((hi.y() - lo.y()) / l.cell)) + 1);
  std::vector<uint32_t> count(static_cast<size_t>(l.nx) * l.ny + 1, 0);
  const auto each_bucket = [&](uint32_t t, auto&& f) {
    Vec2f tlo = m.flat_position[m.triangles[t][0]], thi = tlo;
    for (int k = 1; k < 3; ++k) {
      tlo = tlo.cwiseMin(m.flat_position[m.triangles[t][k]]);
      thi = thi.cwiseMax(m.flat_position[m.triangles[t][k]]);
    }
    for (int y = l.clamp_y(tlo.y()); y <= l.clamp_y(thi.y()); ++y)
      for (int x = l.clamp_x(tlo.x()); x <= l.clamp_x(thi.x()); ++x) f(static_cast<size_t>(y) * l.nx + x);
  };
  for (uint32_t t : panel_tris) each_bucket(t, [&](size_t b) { ++count[b + 1]; });
  for (size_t b = 1; b < count.size(); ++b) count[b] += count[b - 1];
  l.begin = count;
  l.tris.resize(count.back());
  for (uint32_t t : panel_tris) each_bucket(t, [&](size_t b) { l.tris[count[b]++] = t; });
  return l;
}

}  // namespace

size_t start_from_coarse(ClothState& fine_state, const ClothModel& fine, std::span<const uint32_t> fine_panels,
                         const ClothModel& coarse, const ClothState& coarse_state, std::span<const uint32_t> coarse_panels) {
  size_t extrapolated = 0;
  const size_t panels = std::min(fine_panels.size(), coarse_panels.size());
  for (size_t p = 0; p + 1 < panels; ++p) {
    // The coarse panel's triangles (every vertex in its particle range).
    std::vector<uint32_t> tris;
    for (uint32_t t = 0; t < coarse.triangles.size(); ++t) {
      const Tri& tri = coarse.triangles[t];
      if (tri[0] >= coarse_panels[p] && tri[0] < coarse_panels[p + 1]) tris.push_back(t);
    }
    if (tris.empty()) continue;
    const PanelLocator l = build_locator(coarse, tris);
    for (uint32_t i = fine_panels[p]; i < fine_panels[p + 1]; ++i) {
      const Vec2f& q = fine.flat_position[i];
      // The containing triangle, else the one the point is least outside of: first among the
      // point's bucket and its neighbours, then (points beyond the coarse outline) all of them.
      uint32_t best = tris.front();
      Vec3f best_w(1, 0, 0);
      float best_out = std::numeric_limits<float>::max();
      const auto consider = [&](uint32_t t) {
        Vec3f w;
        const Tri& tri = coarse.triangles[t];
        if (!barycentric(q, coarse.flat_position[tri[0]], coarse.flat_position[tri[1]], coarse.flat_position[tri[2]], w)) return;
        const float o = outside(w);
        if (o < best_out) best_out = o, best = t, best_w = w;
      };
      const int cx = l.clamp_x(q.x()), cy = l.clamp_y(q.y());
      for (int y = std::max(0, cy - 1); y <= std::min(l.ny - 1, cy + 1) && best_out > 0; ++y)
        for (int x = std::max(0, cx - 1); x <= std::min(l.nx - 1, cx + 1); ++x) {
          const size_t b = static_cast<size_t>(y) * l.nx + x;
          for (uint32_t k = l.begin[b]; k < l.begin[b + 1]; ++k) consider(l.tris[k]);
        }
      if (best_out > 1e-4f) {
        for (uint32_t t : tris) consider(t);
        if (best_out > 1e-4f) ++extrapolated;
      }
      // Past the coarse outline (a curve the coarse grid cut as a chord) the nearest triangle's
      // plane is extended: at most a fraction of a coarse cell.
      // Far outside (a region the coarse mesh does not cover) the point is held to the triangle.
      if (best_out > 0.25f) {
        best_w = best_w.cwiseMax(0.0f);
        best_w /= best_w.sum();
      }
      const Tri& tri = coarse.triangles[best];
      fine_state.x[i] = best_w.x() * coarse_state.x[tri[0]] + best_w.y() * coarse_state.x[tri[1]] + best_w.z() * coarse_state.x[tri[2]];
      fine_state.v[i] = Vec3f::Zero();
    }
  }
  return extrapolated;
}

void dress_coarse_first(DressedGarment& fine, const Body& body, const Garment& garment, const Collider& body_collider,
                        std::span<Collider* const> colliders, const DressOptions& options,
                        const DressProgressCallback& progress, size_t index, size_t count) {
  const auto t0 = std::chrono::steady_clock::now();
  DressOptions co = options;
  co.mesh.edge_length = options.coarse_edge;
  co.coarse_edge = 0;
  DressedGarment c = prepare_garment(body, garment, body_collider, co);
  DressedGarment::CoarseRun& run = fine.coarse;
  run.setup_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const DressProgressCallback coarse_progress = [&](const DressProgress& p) {
    if (!progress) return;
    DressProgress q = p;
    q.phase = std::string_view(p.phase) == "draping" ? "coarse draping" : "coarse sewing";
    progress(q);
  };
  sew_and_drape(c, colliders, co, coarse_progress, index, count);
  run.edge = options.coarse_edge;
  run.vertices = c.model.particle_count();
  run.iterations = c.state.iterations;
  run.wall_seconds = c.sewing_seconds + c.drape_seconds;
  run.seams_closed = c.seams_closed;
  run.settled = c.settled;
  run.status = c.status;
  // An exploded coarse run is no start: the fine garment starts from its placement.
  if (c.status == StepStatus::Ok)
    run.extrapolated = start_from_coarse(fine.state, fine.model, fine.panel_first_vertex, c.model, c.state, c.panel_first_vertex);
  run.start_max_gap = seam_gap_stats(fine.state.x, fine.seam_pairs).max;
}

}  // namespace drape::dressing
