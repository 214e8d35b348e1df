#pragma once
// Each `drape` subcommand lives in its own file app/cmd_<name>.cpp and registers itself here.
#include <CLI/CLI.hpp>

#include <string>

#include "drape/body.hpp"

namespace drape::app {

// Options every command that loads meshes shares (DESIGN.md: units and axes are never guessed).
struct LoadOptions {
  std::string units = "m";  // mm|cm|dm|m
  std::string up = "y";     // y|z
};
void add_load_options(CLI::App& cmd, LoadOptions& opts);

// The body a command dresses from its --body and --measurements: a built-in (female, male), one
// made from measurements for that sex, or a body file read with --units and --up.
Body load_command_body(const std::string& body, const std::string& measurements, const LoadOptions& load);

void add_info_command(CLI::App& app);
void add_convert_command(CLI::App& app);
void add_render_command(CLI::App& app);  // cmd_render.cpp: pictures of mesh files
void add_scene_command(CLI::App& app);  // cmd_scene.cpp: paper fig. 7 draping scenes
void add_garment_command(CLI::App& app);  // cmd_garment.cpp: `garments`, `garment check|mesh`
void add_dress_command(CLI::App& app);  // cmd_dress.cpp: dress a body in garments (paper sec. 6)
void add_body_command(CLI::App& app);     // cmd_body.cpp: a rigged body from measurements
void add_measure_command(CLI::App& app);  // cmd_measure.cpp: landmarks and measurements of a body
void add_animate_command(CLI::App& app);  // cmd_animate.cpp: a dressed body in motion
void add_fit_command(CLI::App& app);      // cmd_fit.cpp: every size tried on, fit maps, a size recommended
void add_serve_command(CLI::App& app);    // cmd_serve.cpp: the web try-on

}  // namespace drape::app
