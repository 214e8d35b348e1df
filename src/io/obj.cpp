// Wavefront OBJ: read with tinyobjloader, written by hand (a few printf lines).
//
// tinyobjloader assembles faces, groups and attributes, but it reads a malformed number as 0, drops
// faces with fewer than three corners and only warns about out-of-range indices. A light scan first
// checks every v/vt/vn/f line (numbers present and finite, indices in range), so a bad file is refused
// with its line number instead of being silently "fixed".
#include <fmt/format.h>
#include <tiny_obj_loader.h>

#include <charconv>
#include <cmath>
#include <map>
#include <tuple>

#include "drape/error.hpp"
#include "geometry/topology.hpp"
#include "io/formats.hpp"

namespace drape::io {
namespace {

bool is_blank(char c) {
  return c == ' ' || c == '\t';
}

// Splits a line into whitespace-separated tokens, stopping at a comment.
std::vector<std::string_view> tokens_of(std::string_view line) {
  std::vector<std::string_view> out;
  size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && is_blank(line[i])) ++i;
    if (i >= line.size() || line[i] == '#') break;
    size_t j = i;
    while (j < line.size() && !is_blank(line[j])) ++j;
    out.push_back(line.substr(i, j - i));
    i = j;
  }
  return out;
}

bool parse_number(std::string_view s, double& value) {
  if (!s.empty() && s.front() == '+') s.remove_prefix(1);
  const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), value);
  return ec == std::errc() && end == s.data() + s.size();
}

bool parse_index(std::string_view s, long& value) {
  if (!s.empty() && s.front() == '+') s.remove_prefix(1);
  const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), value);
  return ec == std::errc() && end == s.data() + s.size() && value != 0;
}

// What the pre-scan learnt about the file.
struct ObjScan {
  size_t positions = 0, texcoords = 0, normals = 0;
  bool every_vertex_has_color = true;
  bool has_groups = false;
  size_t short_faces = 0;  // fewer than three corners
};

// Largest 1-based index used for one attribute, and where.
struct MaxIndex {
  long index = 0;
  size_t line = 0;
};

ObjScan scan_obj(std::string_view text, const std::string& source) {
  if (text.find('\0') != std::string_view::npos)
    throw InputError(source, "binary data in an OBJ file (is it really OBJ?)");
  ObjScan scan;
  MaxIndex max_v, max_vt, max_vn;
  size_t line_number = 0;
  const auto fail = [&](const std::string& what) {
    throw InputError(source, fmt::format("line {}: {}", line_number, what));
  };
  // Numbers after the keyword: between `least` and `most` of them, all finite.
  const auto check_numbers = [&](const std::vector<std::string_view>& tok, size_t least, size_t most,
                                 const char* what) {
    const size_t n = tok.size() - 1;
    if (n < least || n > most)
      fail(fmt::format("{} has {} numbers, expected {}{}", what, n, least,
                       most > least ? fmt::format(" to {}", most) : std::string()));
    for (size_t i = 1; i < tok.size(); ++i) {
      double x = 0;
      if (!parse_number(tok[i], x)) fail(fmt::format("{}: '{}' is not a number", what, printable(tok[i])));
      if (!std::isfinite(x)) fail(fmt::format("{} has a non-finite value '{}'", what, printable(tok[i])));
    }
    return n;
  };
  // A face corner v, v/t, v//n or v/t/n; negative indices count back from the last definition.
  const auto check_corner = [&](std::string_view corner) {
    std::string_view parts[3];
    size_t part = 0, start = 0;
    for (size_t i = 0; i <= corner.size(); ++i)
      if (i == corner.size() || corner[i] == '/') {
        if (part >= 3) fail(fmt::format("face corner '{}' has more than three indices", printable(corner)));
        parts[part++] = corner.substr(start, i - start);
        start = i + 1;
      }
    const size_t counts[3] = {scan.positions, scan.texcoords, scan.normals};
    MaxIndex* maxima[3] = {&max_v, &max_vt, &max_vn};
    const char* names[3] = {"vertex", "texture coordinate", "normal"};
    for (size_t k = 0; k < part; ++k) {
      if (parts[k].empty() && k > 0) continue;  // v//n
      long index = 0;
      if (!parse_index(parts[k], index))
        fail(fmt::format("face corner '{}' has a bad {} index", printable(corner), names[k]));
      if (index < 0) {
        if (static_cast<size_t>(-index) > counts[k])
          fail(fmt::format("face corner '{}': relative {} index {} points before the first one",
                           printable(corner), names[k], index));
      } else if (index > maxima[k]->index) {
        *maxima[k] = {index, line_number};
      }
    }
  };

  // Lines end at \n, \r or \r\n, as tinyobjloader splits them: both must see the same lines, or the
  // scan would count vertices the loader never reads.
  size_t pos = 0;
  while (pos < text.size()) {
    size_t end = text.find_first_of("\r\n", pos);
    if (end == std::string_view::npos) end = text.size();
    const std::string_view line = text.substr(pos, end - pos);
    pos = end + (text.substr(end, 2) == "\r\n" ? 2 : 1);
    ++line_number;
    const auto tok = tokens_of(line);
    if (tok.empty()) continue;
    const std::string_view key = tok[0];
    if (key == "v") {
      const size_t n = check_numbers(tok, 3, 7, "vertex");
      if (n != 6 && n != 7) scan.every_vertex_has_color = false;
      ++scan.positions;
    } else if (key == "vt") {
      check_numbers(tok, 1, 3, "texture coordinate");
      ++scan.texcoords;
    } else if (key == "vn") {
      check_numbers(tok, 3, 3, "normal");
      ++scan.normals;
    } else if (key == "f") {
      if (tok.size() - 1 < 3) ++scan.short_faces;
      if (tok.size() - 1 > 255)
        fail(fmt::format("face has {} corners; at most 255 are supported", tok.size() - 1));
      for (size_t i = 1; i < tok.size(); ++i) check_corner(tok[i]);
    } else if (key == "g" || key == "o") {
      scan.has_groups = true;
    }
  }
  // Positive indices may point forward, so they are checked against the final counts.
  const std::tuple<MaxIndex, size_t, const char*> checks[3] = {{max_v, scan.positions, "vertex"},
                                                               {max_vt, scan.texcoords, "texture coordinate"},
                                                               {max_vn, scan.normals, "normal"}};
  for (const auto& [max, count, name] : checks)
    if (static_cast<size_t>(max.index) > count)
      throw InputError(source, fmt::format("line {}: {} index {} out of range (the file has {})", max.line,
                                           name, max.index, count));
  if (scan.every_vertex_has_color && scan.positions == 0) scan.every_vertex_has_color = false;
  return scan;
}

}  // namespace

Scene parse_obj(std::string_view text, const std::string& source, MeshCheck& check) {
  const ObjScan scan = scan_obj(text, source);
  check.degenerate_faces_removed += scan.short_faces;

  tinyobj::ObjReaderConfig config;
  config.triangulate = false;  // done below, so non-triangle faces are counted and split well
  config.vertex_color = scan.every_vertex_has_color;
  tinyobj::ObjReader reader;
  if (!reader.ParseFromString(std::string(text), std::string(), config))
    throw InputError(source, one_line(reader.Error().empty() ? "not a valid OBJ file" : reader.Error()));
  const tinyobj::attrib_t& attrib = reader.GetAttrib();

  Mesh mesh;
  const size_t file_vertices = attrib.vertices.size() / 3;
  mesh.positions.resize(file_vertices);
  for (size_t i = 0; i < file_vertices; ++i)
    mesh.positions[i] = {attrib.vertices[3 * i], attrib.vertices[3 * i + 1], attrib.vertices[3 * i + 2]};
  std::vector<Vec3f> colors;
  if (scan.every_vertex_has_color && attrib.colors.size() == 3 * file_vertices)
    for (size_t i = 0; i < file_vertices; ++i)
      colors.emplace_back(attrib.colors[3 * i], attrib.colors[3 * i + 1], attrib.colors[3 * i + 2]);

  // Output vertices: vertex i of the file keeps index i with the first (uv, normal) it is used with;
  // other combinations get copies appended after the file's vertices.
  constexpr int kUnset = -2;
  std::vector<std::pair<int, int>> slot(file_vertices, {kUnset, kUnset});
  std::map<std::tuple<int, int, int>, uint32_t> copies;
  std::vector<int> source_vertex;  // file vertex of each appended copy
  std::vector<std::pair<int, int>> copy_attributes;
  bool any_uv = false, every_normal = true;
  // The scan checked every index; the loader's are checked again before use, so a file the two read
  // differently is refused instead of indexing past the arrays.
  const size_t file_texcoords = attrib.texcoords.size() / 2, file_normals = attrib.normals.size() / 3;
  const auto vertex_of = [&](const tinyobj::index_t& idx) -> uint32_t {
    if (idx.vertex_index < 0 || static_cast<size_t>(idx.vertex_index) >= file_vertices ||
        idx.texcoord_index < -1 || (idx.texcoord_index >= 0 && static_cast<size_t>(idx.texcoord_index) >= file_texcoords) ||
        idx.normal_index < -1 || (idx.normal_index >= 0 && static_cast<size_t>(idx.normal_index) >= file_normals))
      throw InputError(source, fmt::format("face index out of range (the file has {} vertices, {} texture "
                                           "coordinates, {} normals)", file_vertices, file_texcoords, file_normals));
    const auto v = static_cast<size_t>(idx.vertex_index);
    any_uv |= idx.texcoord_index >= 0;
    every_normal &= idx.normal_index >= 0;
    const std::pair<int, int> attributes{idx.texcoord_index, idx.normal_index};
    if (slot[v].first == kUnset) slot[v] = attributes;
    if (slot[v] == attributes) return static_cast<uint32_t>(v);
    const auto [it, inserted] =
        copies.try_emplace({idx.vertex_index, idx.texcoord_index, idx.normal_index},
                           static_cast<uint32_t>(file_vertices + source_vertex.size()));
    if (inserted) {
      source_vertex.push_back(idx.vertex_index);
      copy_attributes.push_back(attributes);
    }
    return it->second;
  };

  // Faces, triangulated, with their group.
  std::map<std::string, uint32_t> group_index;
  std::vector<uint32_t> corners;
  for (const tinyobj::shape_t& shape : reader.GetShapes()) {
    const auto [group, inserted] =
        group_index.try_emplace(shape.name, static_cast<uint32_t>(mesh.group_names.size()));
    if (inserted) mesh.group_names.push_back(shape.name);
    size_t offset = 0;
    for (const unsigned char face_size : shape.mesh.num_face_vertices) {
      corners.clear();
      for (size_t k = 0; k < face_size; ++k) corners.push_back(vertex_of(shape.mesh.indices[offset + k]));
      offset += face_size;
      if (face_size > 3) ++check.non_triangle_faces_triangulated;
      // Corners were checked in range by the scan; copies share their file vertex's position.
      const size_t before = mesh.triangles.size();
      std::vector<Vec3f>& p = mesh.positions;
      for (size_t k = p.size(); k < file_vertices + source_vertex.size(); ++k)
        p.push_back(p[static_cast<size_t>(source_vertex[k - file_vertices])]);
      geometry::triangulate_polygon(p, corners, mesh.triangles);
      mesh.triangle_groups.insert(mesh.triangle_groups.end(), mesh.triangles.size() - before, group->second);
    }
  }
  for (size_t k = mesh.positions.size(); k < file_vertices + source_vertex.size(); ++k)
    mesh.positions.push_back(mesh.positions[static_cast<size_t>(source_vertex[k - file_vertices])]);
  if (!scan.has_groups) {
    mesh.group_names.clear();
    mesh.triangle_groups.clear();
  }

  // Attributes of every output vertex.
  const size_t n = mesh.positions.size();
  const auto attributes_of = [&](size_t i) {
    return i < file_vertices ? slot[i] : copy_attributes[i - file_vertices];
  };
  if (any_uv) {
    mesh.uvs.assign(n, Vec2f::Zero());
    for (size_t i = 0; i < n; ++i)
      if (const int t = attributes_of(i).first; t >= 0)
        mesh.uvs[i] = {attrib.texcoords[2 * static_cast<size_t>(t)],
                       attrib.texcoords[2 * static_cast<size_t>(t) + 1]};
  }
  if (every_normal && !mesh.triangles.empty()) {
    mesh.normals.assign(n, Vec3f::UnitY());  // unreferenced vertices
    for (size_t i = 0; i < n; ++i)
      if (const int k = attributes_of(i).second; k >= 0) {
        const auto s = 3 * static_cast<size_t>(k);
        const Vec3f normal(attrib.normals[s], attrib.normals[s + 1], attrib.normals[s + 2]);
        if (normal.norm() > 0.0f) mesh.normals[i] = normal.normalized();
      }
  }
  if (!colors.empty()) {
    mesh.colors.resize(n);
    for (size_t i = 0; i < n; ++i) {
      const size_t v = i < file_vertices ? i : static_cast<size_t>(source_vertex[i - file_vertices]);
      mesh.colors[i] = {colors[v].x(), colors[v].y(), colors[v].z(), 1.0f};
    }
  }

  return single_mesh_scene(std::move(mesh));
}

}  // namespace drape::io

namespace drape {

// Writes v (with colour when present), vt, vn, groups and faces; vertex i is written as v/vt/vn i+1.
std::string encode_obj(const Mesh& mesh) {
  std::string out = "# written by drape " DRAPE_VERSION "\n";
  fmt::memory_buffer buf;
  const bool colors = mesh.colors.size() == mesh.positions.size() && !mesh.colors.empty();
  for (size_t i = 0; i < mesh.positions.size(); ++i) {
    const Vec3f& p = mesh.positions[i];
    if (colors)
      fmt::format_to(std::back_inserter(buf), "v {} {} {} {} {} {}\n", p.x(), p.y(), p.z(),
                     mesh.colors[i].x(), mesh.colors[i].y(), mesh.colors[i].z());
    else
      fmt::format_to(std::back_inserter(buf), "v {} {} {}\n", p.x(), p.y(), p.z());
  }
  const bool uvs = mesh.uvs.size() == mesh.positions.size() && !mesh.uvs.empty();
  const bool normals = mesh.normals.size() == mesh.positions.size() && !mesh.normals.empty();
  for (const Vec2f& t : mesh.uvs) fmt::format_to(std::back_inserter(buf), "vt {} {}\n", t.x(), t.y());
  for (const Vec3f& nrm : mesh.normals)
    fmt::format_to(std::back_inserter(buf), "vn {} {} {}\n", nrm.x(), nrm.y(), nrm.z());

  const bool groups = !mesh.group_names.empty() && mesh.triangle_groups.size() == mesh.triangles.size();
  size_t current_group = SIZE_MAX;
  for (size_t f = 0; f < mesh.triangles.size(); ++f) {
    if (groups && mesh.triangle_groups[f] != current_group) {
      current_group = mesh.triangle_groups[f];
      const std::string& name = mesh.group_names.at(current_group);
      fmt::format_to(std::back_inserter(buf), "g {}\n", name.empty() ? "default" : name);
    }
    buf.push_back('f');
    for (uint32_t v : mesh.triangles[f]) {
      const uint32_t i = v + 1;
      if (uvs && normals)
        fmt::format_to(std::back_inserter(buf), " {}/{}/{}", i, i, i);
      else if (uvs)
        fmt::format_to(std::back_inserter(buf), " {}/{}", i, i);
      else if (normals)
        fmt::format_to(std::back_inserter(buf), " {}//{}", i, i);
      else
        fmt::format_to(std::back_inserter(buf), " {}", i);
    }
    buf.push_back('\n');
  }
  out.append(buf.data(), buf.size());
  return out;
}

}  // namespace drape
