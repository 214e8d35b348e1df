// `drape render FILE -o out.png`: a picture of any mesh file (OBJ, PLY, glTF/GLB) from several views.
// In a glTF scene the node called `body` is drawn in a skin tone and every other mesh node in its own
// fabric colour; an OBJ or PLY file is one mesh in a skin tone (per-vertex colours win where present).
#include <fmt/format.h>

#include <chrono>
#include <memory>
#include <stdexcept>

#include "commands.hpp"
#include "drape/error.hpp"
#include "drape/io.hpp"
#include "drape/render.hpp"

namespace drape::app {
namespace {

struct RenderArgs {
  std::string file;
  std::string output = "preview.png";
  std::string views = "front,side,back";
  int width = 1200, height = 600;
  int supersample = 3;
  std::string title;  // default: the file's name
  bool no_title = false, no_labels = false, no_shadow = false;
  LoadOptions load;
};

// The scene's meshes as render items: one per mesh node (merge_scene puts each node's triangles in
// a group named after it), so bodies and garments get their own colours.
std::vector<Mesh> split_by_node(const Scene& scene, const Mesh& merged) {
  if (scene.meshes.size() <= 1 || merged.group_names.size() <= 1 ||
      merged.triangle_groups.size() != merged.triangles.size())
    return {merged};
  std::vector<Mesh> parts(merged.group_names.size());
  for (size_t g = 0; g < parts.size(); ++g) {
    parts[g].name = merged.group_names[g];
    parts[g].positions = merged.positions;
    parts[g].normals = merged.normals;
    parts[g].colors = merged.colors;
  }
  for (size_t t = 0; t < merged.triangles.size(); ++t) parts[merged.triangle_groups[t]].triangles.push_back(merged.triangles[t]);
  std::erase_if(parts, [](const Mesh& m) { return m.triangles.empty(); });
  return parts;
}

void run_render(const RenderArgs& args) {
  const auto start = std::chrono::steady_clock::now();
  RenderOptions options;
  options.views = parse_views(args.views, "--views");
  options.width = args.width;
  options.height = args.height;
  options.supersample = args.supersample;
  options.view_labels = !args.no_labels;
  options.floor_shadow = !args.no_shadow;
  if (!args.no_title) options.title = args.title.empty() ? std::filesystem::path(args.file).filename().string() : args.title;

  const Scene scene = read_scene(args.file, load_options(args.load.units, args.load.up));
  const Mesh merged = merge_scene(scene);
  if (merged.triangles.empty()) throw InputError(args.file, "has no triangles to draw");
  const std::vector<Mesh> parts = split_by_node(scene, merged);

  std::vector<RenderItem> items;
  size_t garment_index = 0;
  for (const Mesh& part : parts)
    items.push_back(parts.size() == 1 || part.name == "body" ? body_item(part) : garment_item(part, garment_index++));
  Image picture;
  try {
    picture = render_views(items, options);
  } catch (const std::invalid_argument& e) {  // the file was fine: the options leave no room
    throw InputError("--width/--height/--views", e.what());
  }
  write_png(args.output, picture);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  fmt::print("wrote {} ({}x{}, {} views, {} triangles) in {:.2f} s\n", args.output, picture.width, picture.height,
             options.views.size(), merged.triangles.size(), seconds);
}

}  // namespace

void add_render_command(CLI::App& app) {
  auto args = std::make_shared<RenderArgs>();
  CLI::App* cmd = app.add_subcommand(
      "render", "Render a mesh file (.obj, .ply, .glb, .gltf) from several views into a PNG picture.\n"
                "In a glTF scene the node `body` is drawn in a skin tone, other mesh nodes in fabric colours.");
  cmd->add_option("FILE", args->file, "Mesh or scene file")->required();
  cmd->add_option("-o,--output", args->output, "PNG file to write")->capture_default_str();
  cmd->add_option("--views", args->views, "Comma-separated views: front, side, back, left, right")->capture_default_str();
  cmd->add_option("--width", args->width, "Picture width in pixels")->check(CLI::Range(64, 16384))->capture_default_str();
  cmd->add_option("--height", args->height, "Picture height in pixels")->check(CLI::Range(64, 16384))->capture_default_str();
  cmd->add_option("--supersample", args->supersample, "Anti-aliasing samples per pixel along each axis (1-8)")
      ->check(CLI::Range(1, 8))
      ->capture_default_str();
  cmd->add_option("--title", args->title, "Caption at the top left (default: the file name)");
  cmd->add_flag("--no-title", args->no_title, "No caption");
  cmd->add_flag("--no-labels", args->no_labels, "No view names under the views");
  cmd->add_flag("--no-shadow", args->no_shadow, "No floor shadow");
  add_load_options(*cmd, args->load);
  cmd->callback([args] { run_render(*args); });
}

}  // namespace drape::app
