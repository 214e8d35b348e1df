// Stage 4: the meshed, placed panels of one garment as a single cloth model (paper sec. 2.1, 6.2).
//
// Grid panels keep the paper's rectangular topology: structural springs between lattice
// neighbours (and along the clipped boundary band), shear springs across cells, flexion springs two
// apart. Rest lengths come from the flat pattern, stiffness from the fabric as in grid_cloth_spec
// (k = membrane stiffness x width represented / rest length, warp and weft blended by direction).
// Triangle-mesher panels use the cloth core's mesh_cloth_spec. Seams become zero-length springs of
// SpringKind::Seam between the sewn vertex pairs; they are also velocity-limited (sec. 3.3 with a
// rest length of 0), so a seam, once pulled closer, never opens again.
#include <algorithm>
#include <climits>
#include <cmath>
#include <unordered_map>

#include "dress/stages.hpp"

namespace drape::dressing {
namespace {

// Membrane stiffness along a flat-pattern direction: weft along the lattice i axis, warp along j.
float directional_stiffness(const Fabric& f, const Vec2d& d, const GridTopology& g) {
  const double len2 = d.squaredNorm();
  if (len2 <= 0) return 0.5f * (f.stretch_warp + f.stretch_weft);
  const double cw = d.dot(g.weft), cv = d.dot(g.warp);
  return static_cast<float>((f.stretch_weft * cw * cw + f.stretch_warp * cv * cv) / len2);
}

// Appends one grid panel's particles and springs.
void append_grid_panel(ClothSpec& spec, const PanelMesh& panel, std::span<const Vec3f> placed, const Fabric& f,
                       uint32_t base) {
  const GridTopology& g = *panel.grid;
  const Mesh& m = panel.mesh;
  const auto flat = [&](uint32_t i) { return Vec2d(m.uvs[i].x(), m.uvs[i].y()); };
  const float h = static_cast<float>(g.spacing);
  const auto add = [&](uint32_t a, uint32_t b, float k, SpringKind kind) {
    const float rest = static_cast<float>((flat(b) - flat(a)).norm());
    if (rest > 0) spec.springs.push_back({base + a, base + b, rest, k, kind});
  };
  // Short boundary springs would get huge k = E h / l; the spring still stands for about one cell.
  for (const auto& [a, b] : g.structural) {
    const Vec2d d = flat(b) - flat(a);
    const float rest = static_cast<float>(d.norm());
    add(a, b, directional_stiffness(f, d, g) * h / std::max(rest, 0.5f * h), SpringKind::Structural);
  }
  for (const auto& [a, b] : g.shear) add(a, b, f.shear, SpringKind::Shear);
  for (const auto& [a, b] : g.flexion) add(a, b, 0.5f * f.bend, SpringKind::Flexion);
  // A bending stencil through each flexion spring's middle vertex, the lattice point between its
  // ends: k = B h / h for the lattice's spacing h across and along the line.
  std::unordered_map<int64_t, uint32_t> at_lattice;
  const auto key = [](int32_t i, int32_t j) { return (static_cast<int64_t>(i) << 32) ^ static_cast<int64_t>(static_cast<uint32_t>(j)); };
  for (size_t v = 0; v < g.lattice.size(); ++v)
    if (g.lattice[v][0] != INT32_MIN) at_lattice.emplace(key(g.lattice[v][0], g.lattice[v][1]), static_cast<uint32_t>(v));
  for (const auto& [a, b] : g.flexion) {
    const auto& la = g.lattice[a];
    const auto& lb = g.lattice[b];
    if (la[0] == INT32_MIN || lb[0] == INT32_MIN) continue;
    const auto middle = at_lattice.find(key((la[0] + lb[0]) / 2, (la[1] + lb[1]) / 2));
    if (middle == at_lattice.end()) continue;
    spec.bends.push_back({base + a, base + middle->second, base + b, f.bending_rigidity});
  }
  (void)placed;
}

}  // namespace

GarmentCloth garment_cloth_spec(const Garment& garment, const GarmentMesh& mesh, const PlacedPanels& placed,
                                const Fabric& fabric) {
  GarmentCloth out;
  ClothSpec& spec = out.spec;
  spec.fabric = fabric;
  for (size_t p = 0; p < mesh.panels.size(); ++p) {
    const PanelMesh& panel = mesh.panels[p];
    const auto base = static_cast<uint32_t>(spec.positions.size());
    out.panel_first_vertex.push_back(base);
    const std::vector<Vec3f>& x = placed.positions[p];
    if (panel.grid) {
      // Particles: a third of each adjacent flat triangle's area (mass, drag).
      const Mesh& m = panel.mesh;
      std::vector<float> area(m.positions.size(), 0.0f);
      for (const Tri& t : m.triangles) {
        const Vec2f a = m.uvs[t[0]], b = m.uvs[t[1]], c = m.uvs[t[2]];
        const float ar = 0.5f * std::abs((b - a).x() * (c - a).y() - (b - a).y() * (c - a).x());
        for (uint32_t k : t) area[k] += ar / 3.0f;
      }
      for (size_t i = 0; i < m.positions.size(); ++i) {
        spec.positions.push_back(x[i]);
        spec.flat_positions.push_back(m.uvs[i]);
        spec.mass.push_back(fabric.areal_density * std::max(area[i], 1e-8f));
        spec.drag_area.push_back(area[i]);
      }
      for (const Tri& t : m.triangles) spec.triangles.push_back({base + t[0], base + t[1], base + t[2]});
      append_grid_panel(spec, panel, x, fabric, base);
    } else {
      // Triangle mesher: the cloth core's mesh springs, built on the flat panel, moved to 3D.
      Mesh m = panel.mesh;
      ClothSpec ps = mesh_cloth_spec(m, fabric, garment.source + ": panel '" + garment.panels[p].name + "'");
      ps.positions.assign(x.begin(), x.begin() + static_cast<std::ptrdiff_t>(ps.positions.size()));
      append(spec, ps);
    }
  }
  out.panel_first_vertex.push_back(static_cast<uint32_t>(spec.positions.size()));

  // Seam springs: rest length 0. Their stiffness closes the whole garment at a rate of about
  // kSewingRate (rad/s): k = w^2 M / pairs, so the sewing time does not depend on the resolution.
  constexpr float kSewingRate = 60.0f;
  double total_mass = 0;
  for (float m : spec.mass) total_mass += m;
  // Pairs that share a vertex twice (corners where two seams meet) are kept once, with the seam
  // that listed them first.
  std::vector<std::array<uint32_t, 3>> pairs;  // a, b, seam
  for (const SeamVertexPair& pair : mesh.seam_pairs) {
    const uint32_t a = out.panel_first_vertex[pair.panel_a] + pair.vertex_a;
    const uint32_t b = out.panel_first_vertex[pair.panel_b] + pair.vertex_b;
    if (a != b) pairs.push_back({std::min(a, b), std::max(a, b), pair.seam});
  }
  std::sort(pairs.begin(), pairs.end());
  for (size_t i = 0; i < pairs.size(); ++i) {
    if (i > 0 && pairs[i][0] == pairs[i - 1][0] && pairs[i][1] == pairs[i - 1][1]) continue;
    out.seam_pairs.push_back({pairs[i][0], pairs[i][1]});
    out.seam_of_pair.push_back(pairs[i][2]);
  }
  const float k_seam = out.seam_pairs.empty() ? 0.0f
      : static_cast<float>(kSewingRate * kSewingRate * total_mass / static_cast<double>(out.seam_pairs.size()));
  // A pair of light vertices (an outline corner of the grid) gets at most sixteen times its own
  // pair's stiffness at that rate (k = 16 w^2 m_a m_b / (m_a + m_b), i.e. it closes at <= 4 w), so
  // it cannot outrun the step, yet it keeps up with its heavier neighbours.
  for (const auto& [a, b] : out.seam_pairs) {
    const double reduced = static_cast<double>(spec.mass[a]) * spec.mass[b] / (static_cast<double>(spec.mass[a]) + spec.mass[b]);
    const float k = std::min(k_seam, static_cast<float>(16.0 * kSewingRate * kSewingRate * reduced));
    spec.springs.push_back({a, b, 0.0f, k, SpringKind::Seam});
  }
  spec.limited_kinds = (1u << static_cast<unsigned>(SpringKind::Structural)) | (1u << static_cast<unsigned>(SpringKind::Seam));
  return out;
}

}  // namespace drape::dressing
