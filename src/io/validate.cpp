#include <fmt/format.h>

#include <cmath>

#include "drape/error.hpp"
#include "geometry/topology.hpp"
#include "io/formats.hpp"

namespace drape::io {

std::string one_line(std::string_view message) {
  std::string out;
  for (char c : message) {
    if (c == '\n' || c == '\r') {
      if (!out.empty() && out.back() != ' ') out += "; ";
    } else {
      const auto u = static_cast<unsigned char>(c);
      if (u >= 0x20) out += u < 0x7f ? c : '?';
    }
  }
  while (!out.empty() && (out.back() == ' ' || out.back() == ';' || out.back() == '.')) out.pop_back();
  return out.empty() ? std::string("unknown error") : out;
}

std::string printable(std::string_view token) {
  constexpr size_t kMax = 40;
  std::string out;
  for (char c : token.substr(0, kMax)) {
    const auto u = static_cast<unsigned char>(c);
    out += u >= 0x20 && u < 0x7f ? c : '?';
  }
  if (token.size() > kMax) out += "...";
  return out;
}

std::string element_name(const char* kind, size_t index, const std::string& name) {
  return name.empty() ? fmt::format("{} {}", kind, index)
                      : fmt::format("{} {} '{}'", kind, index, printable(name));
}

namespace {

template <class Vec>
bool all_finite(const Vec& v) {
  return v.array().isFinite().all();
}

// Throws naming the first non-finite entry of an attribute array.
template <class Vec>
void require_finite(const std::vector<Vec>& values, const std::string& source, const std::string& what,
                    const char* attribute) {
  for (size_t i = 0; i < values.size(); ++i)
    if (!all_finite(values[i]))
      throw InputError(source, fmt::format("{}: vertex {} has a non-finite {}", what, i, attribute));
}

}  // namespace

void validate_mesh(Mesh& mesh, const std::string& source, const std::string& what, MeshCheck& check) {
  const size_t n = mesh.positions.size();
  if (n == 0) throw InputError(source, what + " has no vertices");
  const auto require_size = [&](size_t size, const char* attribute) {
    if (size != 0 && size != n)
      throw InputError(source, fmt::format("{} has {} {} for {} vertices", what, size, attribute, n));
  };
  require_size(mesh.normals.size(), "normals");
  require_size(mesh.uvs.size(), "texture coordinates");
  require_size(mesh.colors.size(), "colours");
  require_size(mesh.joints.size(), "joint sets");
  require_size(mesh.weights.size(), "weight sets");
  require_finite(mesh.positions, source, what, "position");
  require_finite(mesh.normals, source, what, "normal");
  require_finite(mesh.uvs, source, what, "texture coordinate");
  require_finite(mesh.colors, source, what, "colour");
  require_finite(mesh.weights, source, what, "skin weight");
  for (const MorphTarget& target : mesh.morph_targets) {
    require_size(target.position_deltas.size(), "morph position deltas");
    require_size(target.normal_deltas.size(), "morph normal deltas");
    require_finite(target.position_deltas, source, what + " morph target '" + target.name + "'",
                   "position delta");
    require_finite(target.normal_deltas, source, what + " morph target '" + target.name + "'",
                   "normal delta");
  }
  for (size_t f = 0; f < mesh.triangles.size(); ++f)
    for (uint32_t v : mesh.triangles[f])
      if (v >= n)
        throw InputError(source, fmt::format("{}: triangle {} uses vertex {} but there are only {} vertices",
                                             what, f, v, n));
  if (mesh.triangles.empty()) throw InputError(source, what + " has no faces");

  // Drop degenerate triangles (and their group entries), counting them.
  const bool grouped = mesh.triangle_groups.size() == mesh.triangles.size();
  size_t kept = 0;
  for (size_t f = 0; f < mesh.triangles.size(); ++f) {
    if (geometry::is_degenerate(mesh.positions, mesh.triangles[f])) continue;
    mesh.triangles[kept] = mesh.triangles[f];
    if (grouped) mesh.triangle_groups[kept] = mesh.triangle_groups[f];
    ++kept;
  }
  check.degenerate_faces_removed += mesh.triangles.size() - kept;
  if (kept == 0)
    throw InputError(source, fmt::format("{}: all {} faces are degenerate", what, mesh.triangles.size()));
  mesh.triangles.resize(kept);
  if (grouped) mesh.triangle_groups.resize(kept);
  if (!grouped && !mesh.triangle_groups.empty()) mesh.triangle_groups.clear();

  const geometry::EdgeTopology topo = geometry::edge_topology(mesh.positions, mesh.triangles);
  check.vertices += n;
  check.triangles += kept;
  check.boundary_edges += topo.boundary_edges;
  check.boundary_loops += topo.boundary_loops;
  check.non_manifold_edges += topo.non_manifold_edges;
}

}  // namespace drape::io
