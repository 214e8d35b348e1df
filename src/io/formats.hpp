#pragma once
// Internal: one parser and one encoder per file format, all working on bytes in memory so that the
// fuzz targets (fuzz/) exercise exactly what `drape info` runs. read_scene (scene_io.cpp) does the file
// reading, format detection, validation and unit/axis conversion around them.
#include <span>
#include <string>
#include <string_view>
#include <utility>

#include "drape/io.hpp"

namespace drape::io {

// OBJ and PLY hold one mesh: a scene with that mesh on one root node.
inline Scene single_mesh_scene(Mesh mesh) {
  Scene scene;
  scene.meshes.push_back(std::move(mesh));
  scene.nodes.push_back(Node{});
  scene.nodes.back().mesh = 0;
  return scene;
}

// Each parser throws InputError(source, ...) on malformed input and fills the counts it alone knows
// (faces triangulated, faces with fewer than three corners) into `check`.
Scene parse_obj(std::string_view text, const std::string& source, MeshCheck& check);
Scene parse_ply(std::span<const unsigned char> bytes, const std::string& source, MeshCheck& check);
// `base_dir` is where external buffers of a .gltf are looked for (empty: external buffers are refused).
Scene parse_gltf(std::span<const unsigned char> bytes, bool binary, const std::string& source,
                 const std::string& base_dir, MeshCheck& check);

// Checks one parsed mesh (non-empty, finite, indices in range, attribute sizes) and drops degenerate
// triangles, counting them. `what` names the mesh in messages (e.g. "mesh 2 'shirt'").
void validate_mesh(Mesh& mesh, const std::string& source, const std::string& what, MeshCheck& check);

// Messages from libraries may span lines; the CLI contract is one line.
std::string one_line(std::string_view message);
// A token from a file, quoted into a message: non-printable bytes become '?', long ones are cut.
std::string printable(std::string_view token);
// "mesh 3" or "mesh 3 'shirt'": how messages name an indexed, optionally named glTF object.
std::string element_name(const char* kind, size_t index, const std::string& name);

}  // namespace drape::io
