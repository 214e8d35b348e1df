// The checks behind every fuzz target (see fuzz_checks.hpp).
#include "fuzz_checks.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <vector>

#include "drape/error.hpp"
#include "drape/garment.hpp"

namespace drape::fuzz {
namespace {

std::span<const unsigned char> bytes_of(const std::string& s) {
  return {reinterpret_cast<const unsigned char*>(s.data()), s.size()};
}

// The mesh read back from `encoded` must be `expected`: same vertex count and triangles, positions
// equal within float rounding of the text formats and of re-normalised node rotations.
void expect_same_mesh(const Mesh& expected, std::span<const unsigned char> encoded, MeshFormat format,
                      const char* what) {
  Scene again;
  try {
    again = parse_scene(encoded, format, what);
  } catch (const InputError& e) {
    throw Finding(fmt::format("{}: the reader refuses what the writer wrote: {}", what, e.what()));
  }
  const Mesh got = merge_scene(again);
  if (got.positions.size() != expected.positions.size())
    throw Finding(fmt::format("{}: {} vertices read back, {} written", what, got.positions.size(),
                              expected.positions.size()));
  if (got.triangles != expected.triangles)
    throw Finding(fmt::format("{}: {} triangles read back differ from the {} written", what,
                              got.triangles.size(), expected.triangles.size()));
  float scale = 1.0f;
  for (const Vec3f& p : expected.positions) scale = std::max(scale, p.cwiseAbs().maxCoeff());
  for (size_t i = 0; i < got.positions.size(); ++i)
    if (!((got.positions[i] - expected.positions[i]).cwiseAbs().maxCoeff() <= 1e-5f * scale))
      throw Finding(fmt::format("{}: vertex {} moved from ({}, {}, {}) to ({}, {}, {})", what, i,
                                expected.positions[i].x(), expected.positions[i].y(), expected.positions[i].z(),
                                got.positions[i].x(), got.positions[i].y(), got.positions[i].z()));
}

// The panels' extent, from every point that shapes an outline.
double garment_extent(const Garment& garment) {
  Eigen::AlignedBox2d box;
  for (const Panel& panel : garment.panels)
    for (const Curve& c : panel.edges) {
      box.extend(c.start);
      box.extend(c.end);
      for (const Vec2d& p : c.control) box.extend(p);
      for (const Vec2d& p : c.points) box.extend(p);
      if (c.kind == EdgeCurve::arc) {
        box.extend(c.centre - Vec2d::Constant(c.radius));
        box.extend(c.centre + Vec2d::Constant(c.radius));
      }
    }
  return box.isEmpty() ? 0.0 : box.sizes().maxCoeff();
}

// A mesh of `garment` must be consistent: every index in range, every position finite.
void expect_consistent(const Garment& garment, const GarmentMesh& mesh, const std::string& what) {
  const auto fail = [&](const std::string& why) { throw Finding(what + ": " + why); };
  if (mesh.panels.size() != garment.panels.size()) fail("one panel mesh per panel expected");
  for (size_t p = 0; p < mesh.panels.size(); ++p) {
    const PanelMesh& pm = mesh.panels[p];
    const size_t n = pm.mesh.positions.size();
    const auto in_range = [n](uint32_t v) { return v < n; };
    if (pm.mesh.triangles.empty()) fail(fmt::format("panel {} has no triangles", p));
    for (const Tri& t : pm.mesh.triangles)
      if (!std::all_of(t.begin(), t.end(), in_range)) fail(fmt::format("panel {}: triangle index out of range", p));
    for (const Vec3f& x : pm.mesh.positions)
      if (!x.allFinite()) fail(fmt::format("panel {}: non-finite vertex", p));
    if (pm.flags.size() != n) fail(fmt::format("panel {}: {} flags for {} vertices", p, pm.flags.size(), n));
    if (!pm.mesh.uvs.empty() && pm.mesh.uvs.size() != n) fail(fmt::format("panel {}: uv count", p));
    if (pm.boundary_edge.size() != pm.boundary.size()) fail(fmt::format("panel {}: boundary edge count", p));
    if (!std::all_of(pm.boundary.begin(), pm.boundary.end(), in_range))
      fail(fmt::format("panel {}: boundary vertex out of range", p));
    for (uint32_t e : pm.boundary_edge)
      if (e >= garment.panels[p].edges.size()) fail(fmt::format("panel {}: boundary edge {} out of range", p, e));
    if (pm.grid) {
      if (pm.grid->lattice.size() != n) fail(fmt::format("panel {}: lattice size", p));
      for (const auto* springs : {&pm.grid->structural, &pm.grid->shear, &pm.grid->flexion})
        for (const auto& s : *springs)
          if (!in_range(s[0]) || !in_range(s[1])) fail(fmt::format("panel {}: spring index out of range", p));
    }
  }
  for (const SeamVertexPair& pair : mesh.seam_pairs) {
    if (pair.seam >= garment.seams.size() || pair.panel_a >= mesh.panels.size() ||
        pair.panel_b >= mesh.panels.size() ||
        pair.vertex_a >= mesh.panels[pair.panel_a].mesh.positions.size() ||
        pair.vertex_b >= mesh.panels[pair.panel_b].mesh.positions.size())
      fail("seam pair out of range");
  }
}

bool starts_as_json(std::string_view text) {
  size_t first = text.find_first_not_of(" \t\r\n");
  if (text.substr(0, 3) == "\xEF\xBB\xBF") first = text.find_first_not_of(" \t\r\n", 3);
  return first != std::string_view::npos && (text[first] == '{' || text[first] == '/');
}

}  // namespace

bool check_mesh_file(std::span<const unsigned char> bytes, MeshFormat format, const std::string& source) {
  Scene scene;
  try {
    scene = parse_scene(bytes, format, source);
  } catch (const InputError&) {
    return false;
  }
  const Mesh merged = merge_scene(scene);
  expect_same_mesh(merged, bytes_of(encode_obj(merged)), MeshFormat::Obj, "written.obj");
  expect_same_mesh(merged, encode_ply(merged, PlyEncoding::BinaryLittleEndian), MeshFormat::Ply, "written.ply");
  expect_same_mesh(merged, encode_ply(merged, PlyEncoding::BinaryBigEndian), MeshFormat::Ply, "written_be.ply");
  expect_same_mesh(merged, encode_ply(merged, PlyEncoding::Ascii), MeshFormat::Ply, "written_ascii.ply");
  expect_same_mesh(merged, encode_glb(scene), MeshFormat::Glb, "written.glb");
  return true;
}

bool is_garment_format(std::string_view text, GarmentFormat format) {
  const bool json = starts_as_json(text);
  const bool drape = text.find("\"drape_garment\"") != std::string_view::npos;
  switch (format) {
    case GarmentFormat::DrapeJson: return json && drape;
    case GarmentFormat::GarmentCode: return json && !drape && text.find("\"pattern\"") != std::string_view::npos;
    case GarmentFormat::Dxf: return !json;
  }
  return false;
}

bool check_garment_file(std::string_view text, const std::string& source) {
  GarmentSpec spec;
  try {
    // No folder next to the input: a referenced DXF file is never found.
    spec = parse_garment(text, source, std::filesystem::path("/nonexistent-garment-folder"));
  } catch (const InputError&) {
    return false;
  }
  for (const std::string& size : spec.sizes) {
    Garment garment;
    try {
      garment = garment_in_size(spec, size);
    } catch (const InputError& e) {
      throw Finding(fmt::format("size '{}' validated when read, refused now: {}", size, e.what()));
    }
    // A grid of at most about 32 x 32 cells per panel: meshing is checked, not timed.
    MeshOptions options;
    options.edge_length = std::max(0.01, garment_extent(garment) / 32.0);
    try {
      expect_consistent(garment, mesh_garment(garment, options), fmt::format("size '{}'", size));
    } catch (const InputError&) {
      // An outline too narrow for the edge length is the user's to fix, and said so.
    }
  }
  return true;
}

}  // namespace drape::fuzz
