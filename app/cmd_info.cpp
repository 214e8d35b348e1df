// `drape info FILE`: what a mesh file holds (counts, bounds, height, holes, skin, animation), as text or
// JSON. Loading validates the file: a malformed one is refused with exit status 2.
#include <fmt/format.h>

#include <memory>
#include <nlohmann/json.hpp>

#include "commands.hpp"
#include "drape/io.hpp"

namespace drape::app {
namespace {

struct InfoArgs {
  std::string file;
  bool json = false;
  LoadOptions load;
};

void run_info(const InfoArgs& args) {
  MeshCheck check;
  const Scene scene = read_scene(args.file, load_options(args.load.units, args.load.up), &check);
  const Bounds box = bounds(merge_scene(scene).positions);

  std::vector<std::string> mesh_nodes, all_nodes;
  for (const Node& node : scene.nodes) {
    all_nodes.push_back(node.name);
    if (node.mesh >= 0) mesh_nodes.push_back(node.name);
  }
  size_t morph_targets = 0;
  for (const Mesh& mesh : scene.meshes) morph_targets += mesh.morph_targets.size();
  const auto duration = [](const Animation& a) {
    float t = 0.0f;
    for (const AnimationChannel& c : a.channels)
      if (!c.times.empty()) t = std::max(t, c.times.back());
    return t;
  };

  if (args.json) {
    nlohmann::json j;
    j["file"] = args.file;
    j["units_in"] = args.load.units;
    j["up_in"] = args.load.up;
    j["vertices"] = check.vertices;
    j["triangles"] = check.triangles;
    j["bounds_m"] = {{"min", {box.min.x(), box.min.y(), box.min.z()}},
                     {"max", {box.max.x(), box.max.y(), box.max.z()}}};
    j["height_m"] = box.size().y();
    j["boundary_edges"] = check.boundary_edges;
    j["boundary_loops"] = check.boundary_loops;
    j["non_manifold_edges"] = check.non_manifold_edges;
    j["degenerate_faces_removed"] = check.degenerate_faces_removed;
    j["non_triangle_faces_triangulated"] = check.non_triangle_faces_triangulated;
    j["meshes"] = scene.meshes.size();
    j["mesh_nodes"] = mesh_nodes;
    j["nodes"] = all_nodes;
    j["skins"] = nlohmann::json::array();
    for (const Skin& s : scene.skins) j["skins"].push_back({{"name", s.name}, {"joints", s.joints.size()}});
    j["animations"] = nlohmann::json::array();
    for (const Animation& a : scene.animations)
      j["animations"].push_back(
          {{"name", a.name}, {"channels", a.channels.size()}, {"duration_s", duration(a)}});
    j["morph_targets"] = morph_targets;
    fmt::print("{}\n", j.dump(2));
    return;
  }
  fmt::print("file:                      {}\n", args.file);
  fmt::print("vertices:                  {}\n", check.vertices);
  fmt::print("triangles:                 {}\n", check.triangles);
  fmt::print("bounds min (m):            {:.4f} {:.4f} {:.4f}\n", box.min.x(), box.min.y(), box.min.z());
  fmt::print("bounds max (m):            {:.4f} {:.4f} {:.4f}\n", box.max.x(), box.max.y(), box.max.z());
  fmt::print("height (m):                {:.4f}\n", box.size().y());
  fmt::print("boundary loops:            {} ({} boundary edges)\n", check.boundary_loops,
             check.boundary_edges);
  fmt::print("non-manifold edges:        {}\n", check.non_manifold_edges);
  fmt::print("degenerate faces dropped:  {}\n", check.degenerate_faces_removed);
  fmt::print("faces triangulated:        {}\n", check.non_triangle_faces_triangulated);
  fmt::print("meshes:                    {} on nodes: {}\n", scene.meshes.size(),
             fmt::join(mesh_nodes, ", "));
  if (scene.skins.empty()) fmt::print("skin:                      none\n");
  for (const Skin& s : scene.skins)
    fmt::print("skin:                      '{}' with {} joints\n", s.name, s.joints.size());
  if (scene.animations.empty()) fmt::print("animations:                none\n");
  for (const Animation& a : scene.animations)
    fmt::print("animation:                 '{}', {} channels, {:.3f} s\n", a.name, a.channels.size(),
               duration(a));
  fmt::print("morph targets:             {}\n", morph_targets);
}

}  // namespace

void add_info_command(CLI::App& app) {
  auto args = std::make_shared<InfoArgs>();
  CLI::App* cmd = app.add_subcommand(
      "info",
      "Print counts, bounds, height, holes, non-manifold edges, skin and animation of a mesh file\n"
      "(.obj, .ply, .glb, .gltf). Lengths are reported in metres after --units/--up conversion.");
  cmd->add_option("FILE", args->file, "Mesh file")->required();
  cmd->add_flag("--json", args->json, "Print JSON instead of text");
  add_load_options(*cmd, args->load);
  cmd->callback([args] { run_info(*args); });
}

}  // namespace drape::app
