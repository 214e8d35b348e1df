// Meshing: both meshers cover the outline's exact area, keep seam vertices matched (same count,
// same arc-length fractions, right orientation), and the grid mesher follows the grain line.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <set>

#include "drape/garment.hpp"
#include "support/test_support.hpp"

namespace drape {
namespace {

double mesh_area(const Mesh& m) {
  double a = 0;
  for (const Tri& t : m.triangles) {
    const Vec3f e1 = m.positions[t[1]] - m.positions[t[0]], e2 = m.positions[t[2]] - m.positions[t[0]];
    a += 0.5 * static_cast<double>(e1.x() * e2.y() - e1.y() * e2.x());
  }
  return a;
}

using test::sanitized;

// Arc-length fraction of a boundary vertex along its seam side.
double side_fraction(const Garment& g, const PanelMesh& pm, const SeamSide& side, uint32_t vertex, bool at_end) {
  const Panel& p = g.panels[side.panel];
  const Vec3f q3 = pm.mesh.positions[vertex];
  const Vec2d q(q3.x(), q3.y());
  double before = 0, best = 1e9, best_at = 0;
  for (uint32_t k = 0; k < side.edge_count; ++k) {
    const Curve& c = p.edges[(side.first_edge + k) % p.edges.size()];
    const double len = c.length();
    const std::vector<Vec2d> samples = c.sample_by_length(400);
    for (int i = 0; i <= 400; ++i) {
      const double d = (samples[static_cast<size_t>(i)] - q).norm();
      if (d < best - 1e-12) { best = d; best_at = before + len * i / 400.0; }
    }
    before += len;
  }
  EXPECT_LT(best, 1e-3) << "seam vertex not on its side";
  if (at_end && best_at < 1e-9) best_at = before;  // a closed side's end is its start
  return best_at / before;
}

void expect_good_mesh(const Garment& g, const MeshOptions& opt) {
  const GarmentMesh gm = mesh_garment(g, opt);
  ASSERT_EQ(gm.panels.size(), g.panels.size());
  for (size_t p = 0; p < g.panels.size(); ++p) {
    const PanelMesh& pm = gm.panels[p];
    const double exact = g.panels[p].signed_area();
    // Triangles wind like the outline, and cover its area (curves flattened at the edge length).
    EXPECT_NEAR(mesh_area(pm.mesh), exact, 0.015 * std::abs(exact)) << g.name << " " << g.panels[p].name;
    EXPECT_EQ(pm.mesh.uvs.size(), pm.mesh.positions.size());
    EXPECT_EQ(pm.flags.size(), pm.mesh.positions.size());
    for (size_t v = 0; v < pm.mesh.positions.size(); ++v) {
      EXPECT_EQ(pm.mesh.positions[v].z(), 0.0f);
      EXPECT_EQ(pm.mesh.uvs[v].x(), pm.mesh.positions[v].x());
    }
    for (uint32_t b : pm.boundary) EXPECT_TRUE(pm.flags[b] & kVertexBoundary);
  }
  // Seam pairs: per seam, the same fraction of each side's length, in the declared orientation.
  for (size_t s = 0; s < g.seams.size(); ++s) {
    const SeamSpec& seam = g.seams[s];
    std::vector<SeamVertexPair> pairs;
    for (const SeamVertexPair& sp : gm.seam_pairs)
      if (sp.seam == s) pairs.push_back(sp);
    ASSERT_GE(pairs.size(), 2u);
    const double la = g.seam_side_length(seam.a), lb = g.seam_side_length(seam.b);
    EXPECT_LE(la / static_cast<double>(pairs.size() - 1), opt.edge_length * 1.0001 + 1e-9);
    for (size_t k = 0; k < pairs.size(); ++k) {
      const SeamVertexPair& sp = pairs[k];
      EXPECT_TRUE(gm.panels[sp.panel_a].flags[sp.vertex_a] & kVertexSeam);
      EXPECT_TRUE(gm.panels[sp.panel_b].flags[sp.vertex_b] & kVertexSeam);
      const bool last = k + 1 == pairs.size();
      const double fa = side_fraction(g, gm.panels[sp.panel_a], seam.a, sp.vertex_a, last);
      const bool b_end = seam.same_direction ? last : k == 0;
      double fb = side_fraction(g, gm.panels[sp.panel_b], seam.b, sp.vertex_b, b_end);
      if (!seam.same_direction) fb = 1 - fb;
      // Equal fractions, up to the snapping of corners inside multi-edge sides (one step).
      const double slack = (seam.a.edge_count > 1 || seam.b.edge_count > 1 ? 1.0 : 0.02) / static_cast<double>(pairs.size() - 1);
      EXPECT_NEAR(fa, fb, slack + 1e-3) << g.name << " seam " << seam.name << " pair " << k;
      (void)la;
      (void)lb;
    }
  }
}

TEST(Mesh, EveryBuiltinInEverySizeMeshesWithMatchedSeams) {
  for (const BuiltinGarment& b : builtin_garments()) {
    const GarmentSpec spec = *builtin_garment(b.name);
    for (const std::string& size : spec.sizes) {
      SCOPED_TRACE(b.name + " size " + size);
      const Garment g = garment_in_size(spec, size);
      expect_good_mesh(g, {Mesher::grid, sanitized() ? 0.04 : 0.02});
      if (size == spec.sizes[spec.base_size]) expect_good_mesh(g, {Mesher::triangle, sanitized() ? 0.04 : 0.02});
    }
  }
}

TEST(Mesh, StraightEqualSeamsHaveEqualLengthSteps) {
  const GarmentSpec spec = parse_garment(R"({"drape_garment": 1, "name": "tube", "panels": [
      {"name": "front", "vertices": [[0, 0], [0.4, 0], [0.4, 0.6], [0, 0.6]]},
      {"name": "back", "vertices": [[0, 0], [0.4, 0], [0.4, 0.6], [0, 0.6]]}],
    "seams": [{"a": {"panel": "front", "edge": 3}, "b": {"panel": "back", "edge": 1}},
              {"a": {"panel": "front", "edge": 1}, "b": {"panel": "back", "edge": 3}, "direction": "same"}]})",
                                         "tube.json");
  const Garment g = garment_in_size(spec);
  const GarmentMesh gm = mesh_garment(g, {Mesher::grid, 0.025});
  std::vector<size_t> counts(2, 0);
  for (const SeamVertexPair& sp : gm.seam_pairs) {
    ++counts[sp.seam];
    const Vec3f a = gm.panels[sp.panel_a].mesh.positions[sp.vertex_a];
    const Vec3f b = gm.panels[sp.panel_b].mesh.positions[sp.vertex_b];
    // Reversed seam 0: front's left side going down meets back's right side going up -> same height.
    if (sp.seam == 0) {
      EXPECT_NEAR(a.y(), b.y(), 1e-6);
    } else {  // "same" on front edge 1 (upward) and back edge 3 (downward): mirrored heights
      EXPECT_NEAR(a.y(), 0.6f - b.y(), 1e-6);
    }
  }
  EXPECT_EQ(counts[0], 25u);  // 0.6 m / 0.025 m = 24 steps
  EXPECT_EQ(counts[1], 25u);
}

TEST(Mesh, GridFollowsTheGrainLine) {
  const double angle = 30.0 * 3.14159265358979 / 180.0;
  const std::string grain = "[" + std::to_string(std::sin(angle)) + ", " + std::to_string(std::cos(angle)) + "]";
  const GarmentSpec spec = parse_garment(R"({"drape_garment": 1, "name": "bias", "panels": [
      {"name": "p", "grain": )" + grain + R"(, "vertices": [[0, 0], [0.5, 0], [0.5, 0.4], [0.2, 0.55], [0, 0.4]],
       "edges": [{}, {}, {"curve": "quadratic", "control": [[0.5, 0.1]]}, {}, {}]}]})",
                                         "bias.json");
  const Garment g = garment_in_size(spec);
  const double h = 0.02;
  const GarmentMesh gm = mesh_garment(g, {Mesher::grid, h});
  const PanelMesh& pm = gm.panels[0];
  ASSERT_TRUE(pm.grid.has_value());
  const GridTopology& grid = *pm.grid;
  EXPECT_NEAR(grid.warp.dot(Vec2d(std::sin(angle), std::cos(angle))), 1.0, 1e-6);
  ASSERT_GT(grid.shear.size(), 100u);
  ASSERT_GT(grid.flexion.size(), 100u);
  size_t lattice_springs = 0;
  for (const auto& [a, b] : grid.structural) {
    const bool on_lattice = grid.lattice[a][0] != INT32_MIN && grid.lattice[b][0] != INT32_MIN;
    if (!on_lattice) continue;
    ++lattice_springs;
    const Vec3f d3 = pm.mesh.positions[b] - pm.mesh.positions[a];
    const Vec2d d(d3.x(), d3.y());
    EXPECT_NEAR(d.norm(), h, 1e-5);
    // Along the warp or along the weft, nothing else.
    EXPECT_NEAR(std::abs(d.normalized().dot(grid.warp)) + std::abs(d.normalized().dot(grid.weft)), 1.0, 1e-4);
  }
  EXPECT_GT(lattice_springs, 500u);
  for (const auto& [a, b] : grid.shear) {
    const Vec3f d = pm.mesh.positions[b] - pm.mesh.positions[a];
    EXPECT_NEAR(d.norm(), h * std::sqrt(2.0), 1e-5);
  }
  for (const auto& [a, b] : grid.flexion) EXPECT_NEAR((pm.mesh.positions[b] - pm.mesh.positions[a]).norm(), 2 * h, 1e-5);
  // Most vertices are lattice vertices (the rectangular topology), the rest on the outline.
  size_t lattice = 0;
  for (const auto& l : grid.lattice) lattice += l[0] != INT32_MIN;
  EXPECT_EQ(lattice + pm.boundary.size(), pm.mesh.positions.size());
  EXPECT_GT(lattice, 3 * pm.boundary.size());
}

TEST(Mesh, TriangleMesherHitsTheTargetEdgeLength) {
  const GarmentSpec spec = parse_garment(R"({"drape_garment": 1, "name": "disc", "panels": [
      {"name": "p", "vertices": [[0.3, 0], [-0.3, 0]],
       "edges": [{"curve": "arc", "radius": 0.3}, {"curve": "arc", "radius": 0.3}]}]})",
                                         "disc.json");
  const Garment g = garment_in_size(spec);
  for (double h : {0.01, 0.02, 0.04}) {
    const GarmentMesh gm = mesh_garment(g, {Mesher::triangle, h});
    const Mesh& m = gm.panels[0].mesh;
    std::set<std::pair<uint32_t, uint32_t>> edges;
    for (const Tri& t : m.triangles)
      for (int e = 0; e < 3; ++e) edges.insert(std::minmax(t[e], t[(e + 1) % 3]));
    double sum = 0, longest = 0;
    for (const auto& [a, b] : edges) {
      const double l = (m.positions[a] - m.positions[b]).norm();
      sum += l;
      longest = std::max(longest, l);
    }
    const double mean = sum / static_cast<double>(edges.size());
    EXPECT_NEAR(mean, h, 0.15 * h) << "h = " << h;
    EXPECT_LT(longest, 1.5 * h) << "h = " << h;
    EXPECT_NEAR(mesh_area(m), 3.14159265358979 * 0.09, 0.01 * 3.14159265358979 * 0.09);
  }
}

}  // namespace
}  // namespace drape
