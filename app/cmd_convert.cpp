// `drape convert IN OUT`: mesh files between OBJ, PLY and GLB/glTF, converted to metres and +Y up.
// The input is validated like `drape info` does; the output is written whole or not at all.
#include <fmt/format.h>

#include <memory>

#include "commands.hpp"
#include "drape/io.hpp"

namespace drape::app {
namespace {

struct ConvertArgs {
  std::string input, output;
  LoadOptions load;
};

void run_convert(const ConvertArgs& args) {
  mesh_format_of(args.output);  // refuse an unknown output format before reading anything
  MeshCheck check;
  const Scene scene = read_scene(args.input, load_options(args.load.units, args.load.up), &check);
  write_scene(args.output, scene);
  fmt::print("wrote {} ({} vertices, {} triangles)\n", args.output, check.vertices, check.triangles);
}

}  // namespace

void add_convert_command(CLI::App& app) {
  auto args = std::make_shared<ConvertArgs>();
  CLI::App* cmd = app.add_subcommand(
      "convert",
      "Convert a mesh between OBJ, PLY and GLB/glTF (formats by extension), to metres and +Y up.\n"
      "OBJ and PLY hold one mesh: a glTF scene is merged into one, without skin or animation.");
  cmd->add_option("IN", args->input, "Input mesh file")->required();
  cmd->add_option("OUT", args->output, "Output file (.obj, .ply, .glb or .gltf); written whole or not at all")
      ->required();
  add_load_options(*cmd, args->load);
  cmd->callback([args] { run_convert(*args); });
}

}  // namespace drape::app
