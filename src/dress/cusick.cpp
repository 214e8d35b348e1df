// The Cusick drape test as a scene (drape/cusick.hpp): the specimen is a one-panel garment (a disc
// of four arcs) meshed by the same grid mesher and made into cloth by the same stage as every
// garment, so the test sees the fabric exactly as a garment of it does. The middle is clamped: the
// particles over the support disc are pinned, as between the tester's two discs. Draping is the
// dressing stage of the chosen solver with no seams to sew.
#include "drape/cusick.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <numbers>

#include "drape/error.hpp"
#include "dress/stages.hpp"

namespace drape {
namespace {

constexpr float kSupportTop = 0.3f;     // m, height of the support disc's top
constexpr float kSupportHeight = 0.3f;  // m, the pillar under it
// The specimen starts flat this far above the support, just inside its contact layer (the layer is
// the fabric's collision thickness), so it rests on the support from the first step.
constexpr float kStartAboveSupport = 0.75f;  // x collision thickness

Panel disc_panel(double radius) {
  Panel p;
  p.name = "specimen";
  p.grain = Vec2d::UnitY();
  const double quarter = 0.5 * std::numbers::pi;
  for (int k = 0; k < 4; ++k) {
    Curve c;
    c.kind = EdgeCurve::arc;
    c.centre = Vec2d::Zero();
    c.radius = radius;
    c.start_angle = k * quarter;
    c.sweep = quarter;
    c.start = radius * Vec2d(std::cos(c.start_angle), std::sin(c.start_angle));
    c.end = radius * Vec2d(std::cos(c.start_angle + quarter), std::sin(c.start_angle + quarter));
    p.edges.push_back(c);
    p.edge_names.push_back("hem " + std::to_string(k + 1));
  }
  return p;
}

// Folds round the hem: maxima of the shadow's radius over the angle, after smoothing it over 20
// degrees (a node spans 40 or more), that stand out from the mean by at least 2 mm.
int count_nodes(const std::vector<double>& radius) {
  const int n = static_cast<int>(radius.size());
  if (n < 8) return 0;
  const int half = std::max(1, n / 36);
  std::vector<double> smooth(static_cast<size_t>(n));
  for (int i = 0; i < n; ++i) {
    double sum = 0;
    for (int k = -half; k <= half; ++k) sum += radius[static_cast<size_t>((i + k + n) % n)];
    smooth[static_cast<size_t>(i)] = sum / (2 * half + 1);
  }
  double mean = 0;
  for (double r : smooth) mean += r;
  mean /= n;
  // Count the crossings of the mean from below that are followed by a peak 1 mm above it.
  int nodes = 0;
  int start = 0;
  while (start < n && smooth[static_cast<size_t>(start)] >= mean) ++start;
  if (start == n) return 0;
  bool above = false;
  double peak = 0;
  for (int k = 1; k <= n; ++k) {
    const double r = smooth[static_cast<size_t>((start + k) % n)];
    if (!above && r >= mean) {
      above = true;
      peak = r;
    } else if (above && r >= mean) {
      peak = std::max(peak, r);
    } else if (above && r < mean) {
      above = false;
      if (peak - mean >= 2e-3) ++nodes;
    }
  }
  return nodes;
}

}  // namespace

std::vector<uint8_t> shadow_raster(std::span<const Vec3f> positions, std::span<const Tri> triangles, double x0, double z0,
                                   double cell, int nx, int nz) {
  std::vector<uint8_t> covered(static_cast<size_t>(std::max(nx, 0)) * static_cast<size_t>(std::max(nz, 0)), 0);
  if (!(cell > 0)) return covered;
  for (const Tri& t : triangles) {
    const Vec2d a(positions[t[0]].x(), positions[t[0]].z());
    const Vec2d b(positions[t[1]].x(), positions[t[1]].z());
    const Vec2d c(positions[t[2]].x(), positions[t[2]].z());
    const double area2 = (b - a).x() * (c - a).y() - (b - a).y() * (c - a).x();
    if (std::abs(area2) < 1e-18) continue;
    const int ix0 = std::max(0, static_cast<int>(std::floor((std::min({a.x(), b.x(), c.x()}) - x0) / cell - 0.5)));
    const int ix1 = std::min(nx - 1, static_cast<int>(std::ceil((std::max({a.x(), b.x(), c.x()}) - x0) / cell - 0.5)));
    const int iz0 = std::max(0, static_cast<int>(std::floor((std::min({a.y(), b.y(), c.y()}) - z0) / cell - 0.5)));
    const int iz1 = std::min(nz - 1, static_cast<int>(std::ceil((std::max({a.y(), b.y(), c.y()}) - z0) / cell - 0.5)));
    const double sign = area2 > 0 ? 1.0 : -1.0;
    const auto edge = [&](const Vec2d& p, const Vec2d& q, const Vec2d& r) {
      return sign * ((q - p).x() * (r - p).y() - (q - p).y() * (r - p).x());
    };
    for (int iz = iz0; iz <= iz1; ++iz)
      for (int ix = ix0; ix <= ix1; ++ix) {
        const Vec2d p(x0 + (ix + 0.5) * cell, z0 + (iz + 0.5) * cell);
        if (edge(a, b, p) >= 0 && edge(b, c, p) >= 0 && edge(c, a, p) >= 0)
          covered[static_cast<size_t>(iz) * static_cast<size_t>(nx) + static_cast<size_t>(ix)] = 1;
      }
  }
  return covered;
}

double shadow_area(std::span<const Vec3f> positions, std::span<const Tri> triangles, double cell) {
  if (positions.empty() || triangles.empty() || !(cell > 0)) return 0;
  double lo_x = positions[0].x(), hi_x = lo_x, lo_z = positions[0].z(), hi_z = lo_z;
  for (const Vec3f& p : positions) {
    lo_x = std::min(lo_x, static_cast<double>(p.x()));
    hi_x = std::max(hi_x, static_cast<double>(p.x()));
    lo_z = std::min(lo_z, static_cast<double>(p.z()));
    hi_z = std::max(hi_z, static_cast<double>(p.z()));
  }
  const int nx = static_cast<int>(std::ceil((hi_x - lo_x) / cell)) + 1;
  const int nz = static_cast<int>(std::ceil((hi_z - lo_z) / cell)) + 1;
  size_t count = 0;
  for (uint8_t c : shadow_raster(positions, triangles, lo_x, lo_z, cell, nx, nz)) count += c;
  return static_cast<double>(count) * cell * cell;
}

std::vector<double> shadow_radius_by_angle(std::span<const Vec3f> positions, int bins) {
  std::vector<double> radius(static_cast<size_t>(std::max(bins, 1)), 0.0);
  for (const Vec3f& p : positions) {
    const double r = std::hypot(static_cast<double>(p.x()), static_cast<double>(p.z()));
    double a = std::atan2(-static_cast<double>(p.z()), static_cast<double>(p.x()));
    if (a < 0) a += 2 * std::numbers::pi;
    const auto bin = std::min(radius.size() - 1, static_cast<size_t>(a / (2 * std::numbers::pi) * static_cast<double>(radius.size())));
    radius[bin] = std::max(radius[bin], r);
  }
  return radius;
}

CusickResult run_cusick(const CusickOptions& o, const DressProgressCallback& progress) {
  if (!(o.specimen_diameter >= 0.05 && o.specimen_diameter <= 1.0))
    throw InputError("cusick", "the specimen must be 0.05 to 1 m across");
  if (!(o.support_diameter >= 0.02 && o.support_diameter <= o.specimen_diameter - 0.02))
    throw InputError("cusick", "the support disc must be at least 0.02 m across and 0.02 m narrower than the specimen");
  if (!(o.edge_length >= o.specimen_diameter / 200 && o.edge_length <= o.specimen_diameter / 8))
    throw InputError("cusick", "the grid spacing must be 1/200 to 1/8 of the specimen's diameter");
  const Fabric fabric = o.fabric.name.empty() ? fabric_or_throw("cotton") : o.fabric;
  validate_fabric(fabric, "cusick");
  const double radius = 0.5 * o.specimen_diameter, support_radius = 0.5 * o.support_diameter;

  Garment garment;
  garment.name = "cusick specimen";
  garment.source = "cusick";
  garment.fabric = fabric.name;
  garment.panels.push_back(disc_panel(radius));
  MeshOptions mesh_options;
  mesh_options.mesher = Mesher::grid;
  mesh_options.edge_length = o.edge_length;
  const GarmentMesh mesh = mesh_garment(garment, mesh_options);

  // Flat over the support, the pattern's x along x and its y (the warp) along -z, right side up.
  CusickResult r;
  r.support_top = kSupportTop;
  r.support = std::make_unique<CylinderCollider>(Vec3f(0.0f, kSupportTop, 0.0f), static_cast<float>(support_radius), kSupportHeight);
  const float start_y = kSupportTop + kStartAboveSupport * fabric.collision_thickness;
  dressing::PlacedPanels placed;
  const Mesh& flat = mesh.panels[0].mesh;
  placed.positions.emplace_back();
  for (const Vec2f& uv : flat.uvs) placed.positions[0].push_back(Vec3f(uv.x(), start_y, -uv.y()));
  dressing::GarmentCloth cloth = dressing::garment_cloth_spec(garment, mesh, placed, fabric);
  cloth.spec.pinned.assign(cloth.spec.positions.size(), 0);
  for (size_t i = 0; i < flat.uvs.size(); ++i)
    cloth.spec.pinned[i] = flat.uvs[i].cast<double>().norm() <= support_radius ? 1 : 0;

  DressedGarment& g = r.specimen;
  g.name = garment.name;
  g.fabric = fabric.name;
  g.model = compile(std::move(cloth.spec));
  g.state = initial_state(g.model);
  g.panel_first_vertex = std::move(cloth.panel_first_vertex);
  g.panel_names = {"specimen"};
  g.seams_closed = true;

  DressOptions options;
  options.solver = o.solver;
  options.max_sewing_seconds = 0;
  options.max_drape_seconds = o.max_seconds;
  std::vector<Collider*> colliders{r.support.get()};
  const auto start = std::chrono::steady_clock::now();
  if (o.solver == Solver::Implicit) sew_and_drape_implicit(g, colliders, options, progress, 0, 1);
  else sew_and_drape(g, colliders, options, progress, 0, 1);
  r.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();

  // Areas: the specimen's own mesh (its outline is a polygon close to the circle), the support's
  // disc, and the draped shadow, which covers the support's disc too.
  for (const Tri& t : g.model.triangles) {
    const Vec2f a = g.model.flat_position[t[0]], b = g.model.flat_position[t[1]], c = g.model.flat_position[t[2]];
    r.specimen_area += 0.5 * std::abs(static_cast<double>((b - a).x() * (c - a).y() - (b - a).y() * (c - a).x()));
  }
  r.support_area = std::numbers::pi * support_radius * support_radius;
  r.shadow_area = shadow_area(g.state.x, g.model.triangles);
  r.drape_coefficient = (r.shadow_area - r.support_area) / (r.specimen_area - r.support_area);
  // The outline from points along every triangle edge (the hem's vertices alone leave sectors empty).
  std::vector<Vec3f> outline;
  for (const Tri& t : g.model.triangles)
    for (int e = 0; e < 3; ++e)
      for (int k = 0; k < 4; ++k)
        outline.push_back(g.state.x[t[static_cast<size_t>(e)]] + (0.25f * static_cast<float>(k)) *
                          (g.state.x[t[static_cast<size_t>((e + 1) % 3)]] - g.state.x[t[static_cast<size_t>(e)]]));
  r.nodes = count_nodes(shadow_radius_by_angle(outline, 180));
  return r;
}

}  // namespace drape
