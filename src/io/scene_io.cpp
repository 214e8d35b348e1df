// Reading and writing scenes by file: format detection, validation, unit/axis conversion, merging.
#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <fstream>
#include <iterator>

#include "drape/error.hpp"
#include "drape/files.hpp"
#include "drape/io.hpp"
#include "geometry/units.hpp"
#include "io/formats.hpp"

namespace drape {

LoadOptions load_options(std::string_view units, std::string_view up) {
  LoadOptions options;
  if (units == "mm")
    options.metres_per_unit = 0.001;
  else if (units == "cm")
    options.metres_per_unit = 0.01;
  else if (units == "dm")
    options.metres_per_unit = 0.1;
  else if (units == "m")
    options.metres_per_unit = 1.0;
  else
    throw InputError("--units", fmt::format("unknown unit '{}' (expected mm, cm, dm or m)", units));
  if (up == "y" || up == "Y")
    options.up = UpAxis::Y;
  else if (up == "z" || up == "Z")
    options.up = UpAxis::Z;
  else
    throw InputError("--up", fmt::format("unknown up axis '{}' (expected y or z)", up));
  return options;
}

MeshFormat mesh_format_of(const std::filesystem::path& path) {
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  if (ext == ".obj") return MeshFormat::Obj;
  if (ext == ".ply") return MeshFormat::Ply;
  if (ext == ".glb") return MeshFormat::Glb;
  if (ext == ".gltf") return MeshFormat::Gltf;
  throw InputError(path.string(),
                   fmt::format("unknown mesh format '{}' (expected .obj, .ply, .glb or .gltf)", ext));
}

namespace {

std::vector<unsigned char> read_file_bytes(const std::filesystem::path& path) {
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) throw InputError(path.string(), "no such file");
  if (!std::filesystem::is_regular_file(path, ec)) throw InputError(path.string(), "not a regular file");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path.string(), "cannot open for reading");
  std::vector<unsigned char> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (in.bad()) throw InputError(path.string(), "read error");
  return bytes;
}

// Magic bytes win over the extension: a GLB called .obj is still read as GLB.
MeshFormat sniff_format(std::span<const unsigned char> bytes, MeshFormat by_extension) {
  const std::string_view head(reinterpret_cast<const char*>(bytes.data()), std::min<size_t>(bytes.size(), 5));
  if (head.substr(0, 4) == "glTF") return MeshFormat::Glb;
  if (head.size() >= 4 && head.substr(0, 3) == "ply" && (head[3] == '\n' || head[3] == '\r'))
    return MeshFormat::Ply;
  return by_extension;
}

}  // namespace

Scene parse_scene(std::span<const unsigned char> bytes, MeshFormat format, const std::string& source,
                  const LoadOptions& options, MeshCheck* check_out) {
  if (bytes.empty()) throw InputError(source, "empty file");
  format = sniff_format(bytes, format);
  MeshCheck check;
  Scene scene;
  switch (format) {
    case MeshFormat::Obj:
      scene = io::parse_obj(std::string_view(reinterpret_cast<const char*>(bytes.data()), bytes.size()),
                            source, check);
      break;
    case MeshFormat::Ply:
      scene = io::parse_ply(bytes, source, check);
      break;
    case MeshFormat::Glb:
    case MeshFormat::Gltf: {
      const std::filesystem::path dir = std::filesystem::path(source).parent_path();
      scene =
          io::parse_gltf(bytes, format == MeshFormat::Glb, source, dir.empty() ? "." : dir.string(), check);
      break;
    }
  }
  if (scene.meshes.empty()) throw InputError(source, "no meshes");
  // Single-mesh formats are named after the file.
  if (format == MeshFormat::Obj || format == MeshFormat::Ply) {
    const std::string stem = std::filesystem::path(source).stem().string();
    scene.meshes[0].name = stem;
    scene.nodes[0].name = stem;
  }
  for (size_t m = 0; m < scene.meshes.size(); ++m) {
    const std::string what =
        scene.meshes.size() == 1 && (format == MeshFormat::Obj || format == MeshFormat::Ply)
            ? std::string("mesh")
            : io::element_name("mesh", m, scene.meshes[m].name);
    io::validate_mesh(scene.meshes[m], source, what, check);
  }
  if (options.metres_per_unit != 1.0 || options.up != UpAxis::Y) {
    const Eigen::Matrix3f axes =
        options.up == UpAxis::Z ? geometry::z_up_to_y_up() : Eigen::Matrix3f::Identity();
    geometry::change_frame(scene, static_cast<float>(options.metres_per_unit), axes);
  }
  if (check_out) *check_out = check;
  return scene;
}

Scene read_scene(const std::filesystem::path& path, const LoadOptions& options, MeshCheck* check) {
  const std::vector<unsigned char> bytes = read_file_bytes(path);
  // Magic bytes name the format where the file has them; otherwise the extension must.
  const MeshFormat format = sniff_format(bytes, MeshFormat::Obj) == sniff_format(bytes, MeshFormat::Gltf)
                                ? sniff_format(bytes, MeshFormat::Obj)
                                : mesh_format_of(path);
  return parse_scene(bytes, format, path.string(), options, check);
}

Mesh merge_scene(const Scene& scene) {
  // Each placement of a mesh: on its node(s), or once unplaced when no node uses it.
  struct Part {
    int mesh;
    Mat4f transform;
    std::string name;
  };
  std::vector<Part> parts;
  std::vector<bool> placed(scene.meshes.size(), false);
  for (size_t i = 0; i < scene.nodes.size(); ++i) {
    const Node& node = scene.nodes[i];
    if (node.mesh < 0 || static_cast<size_t>(node.mesh) >= scene.meshes.size()) continue;
    const Mesh& mesh = scene.meshes[static_cast<size_t>(node.mesh)];
    // A skinned mesh's vertices are already its bind pose (glTF ignores the node's transform).
    const bool skinned = node.skin >= 0 && !mesh.joints.empty();
    parts.push_back({node.mesh, skinned ? Mat4f::Identity() : scene.world_transform(static_cast<int>(i)),
                     node.name.empty() ? mesh.name : node.name});
    placed[static_cast<size_t>(node.mesh)] = true;
  }
  for (size_t m = 0; m < scene.meshes.size(); ++m)
    if (!placed[m]) parts.push_back({static_cast<int>(m), Mat4f::Identity(), scene.meshes[m].name});

  Mesh out;
  if (parts.empty()) return out;
  const auto all = [&](auto has) {
    return std::all_of(parts.begin(), parts.end(),
                       [&](const Part& p) { return has(scene.meshes[static_cast<size_t>(p.mesh)]); });
  };
  const bool normals = all([](const Mesh& m) { return !m.normals.empty(); });
  const bool uvs = all([](const Mesh& m) { return !m.uvs.empty(); });
  const bool colors = all([](const Mesh& m) { return !m.colors.empty(); });
  const bool single = parts.size() == 1;
  out.name = single ? parts[0].name : std::string("scene");

  for (const Part& part : parts) {
    const Mesh& mesh = scene.meshes[static_cast<size_t>(part.mesh)];
    const auto offset = static_cast<uint32_t>(out.positions.size());
    const Eigen::Matrix3f linear = part.transform.topLeftCorner<3, 3>();
    const Vec3f translation = part.transform.topRightCorner<3, 1>();
    const Eigen::Matrix3f normal_matrix = linear.inverse().transpose();
    const bool mirrored = linear.determinant() < 0.0f;
    for (const Vec3f& p : mesh.positions) out.positions.push_back(linear * p + translation);
    if (normals)
      for (const Vec3f& n : mesh.normals) {
        const Vec3f m = normal_matrix * n;
        out.normals.push_back(m.norm() > 0.0f ? Vec3f(m.normalized()) : n);
      }
    if (uvs) out.uvs.insert(out.uvs.end(), mesh.uvs.begin(), mesh.uvs.end());
    if (colors) out.colors.insert(out.colors.end(), mesh.colors.begin(), mesh.colors.end());
    for (const Tri& t : mesh.triangles)
      out.triangles.push_back(mirrored ? Tri{t[0] + offset, t[2] + offset, t[1] + offset}
                                       : Tri{t[0] + offset, t[1] + offset, t[2] + offset});
    if (single) {
      out.group_names = mesh.group_names;
      out.triangle_groups = mesh.triangle_groups;
      out.joints = mesh.joints;
      out.weights = mesh.weights;
      out.morph_targets = mesh.morph_targets;
      out.morph_weights = mesh.morph_weights;
    } else {
      out.triangle_groups.insert(out.triangle_groups.end(), mesh.triangles.size(),
                                 static_cast<uint32_t>(out.group_names.size()));
      out.group_names.push_back(part.name);
    }
  }
  return out;
}

int add_mesh_node(Scene& scene, Mesh mesh, std::string node_name) {
  Node node;
  node.name = std::move(node_name);
  node.mesh = static_cast<int>(scene.meshes.size());
  if (mesh.name.empty()) mesh.name = node.name;
  scene.meshes.push_back(std::move(mesh));
  scene.nodes.push_back(std::move(node));
  return static_cast<int>(scene.nodes.size()) - 1;
}

Mesh read_mesh(const std::filesystem::path& path, const LoadOptions& options, MeshCheck* check) {
  return merge_scene(read_scene(path, options, check));
}

void write_scene(const std::filesystem::path& path, const Scene& scene) {
  switch (mesh_format_of(path)) {
    case MeshFormat::Obj:
      write_file_atomic(path, encode_obj(merge_scene(scene)));
      break;
    case MeshFormat::Ply:
      write_file_atomic(path, encode_ply(merge_scene(scene)));
      break;
    case MeshFormat::Glb:
      write_file_atomic(path, encode_glb(scene));
      break;
    case MeshFormat::Gltf:
      write_file_atomic(path, encode_gltf(scene));
      break;
  }
}

void write_mesh(const std::filesystem::path& path, const Mesh& mesh) {
  Scene scene;
  add_mesh_node(scene, mesh, mesh.name.empty() ? std::string("mesh") : mesh.name);
  write_scene(path, scene);
}

}  // namespace drape
