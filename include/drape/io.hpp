#pragma once
// Mesh and scene files: OBJ, PLY (ascii and binary), glTF 2.0 / GLB.
//
// Everything read is converted on load to drape's frame (DESIGN.md): metres, +Y up, the body facing +Z.
// The caller says what the file uses (LoadOptions, from the CLI's --units and --up); nothing is guessed.
// Loaders validate: a file that is empty, truncated, has non-finite numbers or out-of-range indices is
// refused with an InputError naming the file (and the line or element where there is one).
// Non-triangle faces are triangulated and degenerate faces dropped, both counted in MeshCheck;
// holes (boundary loops) and non-manifold edges are counted and reported, never refused.
// Every writer writes atomically (write_file_atomic): a failure leaves nothing behind.
#include <cstddef>
#include <filesystem>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "drape/mesh.hpp"
#include "drape/scene.hpp"

namespace drape {

enum class UpAxis { Y, Z };

// How to read a file's lengths and axes. Z-up files are rotated (x, y, z) -> (x, z, -y): +Z becomes +Y,
// the frame stays right-handed, and a Z-up scan facing -Y ends up facing +Z.
struct LoadOptions {
  double metres_per_unit = 1.0;
  UpAxis up = UpAxis::Y;
};

// Parses the CLI spelling: units "mm" | "cm" | "dm" | "m", up "y" | "z". InputError("--units"/"--up") else.
LoadOptions load_options(std::string_view units, std::string_view up);

// What the loader found and did (all counts summed over the scene's meshes).
struct MeshCheck {
  size_t vertices = 0;
  size_t triangles = 0;                        // after triangulation and dropping degenerate faces
  size_t degenerate_faces_removed = 0;         // repeated corners, zero area, fewer than 3 corners
  size_t non_triangle_faces_triangulated = 0;  // quads and polygons split into triangles
  size_t boundary_edges = 0;                   // edges used by exactly one triangle
  size_t boundary_loops = 0;                   // closed chains of boundary edges (holes)
  size_t non_manifold_edges = 0;               // edges used by three or more triangles
};

// File formats by extension (.obj .ply .glb .gltf; case-insensitive). InputError for anything else.
enum class MeshFormat { Obj, Ply, Glb, Gltf };
MeshFormat mesh_format_of(const std::filesystem::path& path);

// Reads a whole scene: OBJ and PLY give one mesh on one node named after the file's stem; glTF keeps its
// nodes, hierarchy, skins, animations and morph targets. The format comes from the file's magic bytes
// where it has one (GLB, PLY), else from the extension. `check`, when given, receives what was found.
Scene read_scene(const std::filesystem::path& path, const LoadOptions& options = {},
                 MeshCheck* check = nullptr);

// Reads all meshes of a file merged into one, in world space (node transforms applied; skinned meshes
// in their bind pose). Vertex i of an OBJ/PLY file stays vertex i (OBJ vertices with several UVs or
// normals get extra copies appended after the file's vertices).
Mesh read_mesh(const std::filesystem::path& path, const LoadOptions& options = {},
               MeshCheck* check = nullptr);

// Same as read_scene, from bytes in memory; `source` names the input in error messages, `format` says
// how to parse (magic bytes still win). External glTF buffers are looked up next to `source`.
Scene parse_scene(std::span<const unsigned char> bytes, MeshFormat format, const std::string& source,
                  const LoadOptions& options = {}, MeshCheck* check = nullptr);

// All meshes of a scene merged in world space; one group per mesh, named after its node. Attributes are
// kept where every mesh has them; skin and morph data only when the scene holds a single mesh.
Mesh merge_scene(const Scene& scene);

// Appends `mesh` on a new root node called `node_name`; returns the node index. Bodies and garments are
// separate named nodes (`body`, then one per garment), per DESIGN.md.
int add_mesh_node(Scene& scene, Mesh mesh, std::string node_name);

// Writes by extension: .glb (binary glTF), .gltf (glTF with the buffer embedded), .obj, .ply (binary
// little endian). OBJ and PLY hold one mesh: the scene is merged (merge_scene) first. Atomic.
void write_scene(const std::filesystem::path& path, const Scene& scene);
// A single mesh, on one node named after mesh.name (or "mesh").
void write_mesh(const std::filesystem::path& path, const Mesh& mesh);

// Encoders, for tests and for callers that stream (e.g. the web service).
enum class PlyEncoding { Ascii, BinaryLittleEndian, BinaryBigEndian };
std::vector<unsigned char> encode_glb(const Scene& scene);
std::string encode_gltf(const Scene& scene);  // JSON with the buffer as a data: URI
std::string encode_obj(const Mesh& mesh);
std::vector<unsigned char> encode_ply(const Mesh& mesh,
                                      PlyEncoding encoding = PlyEncoding::BinaryLittleEndian);

}  // namespace drape
