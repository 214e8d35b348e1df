#include "commands.hpp"
namespace drape::app {
void add_info_command(CLI::App& app) { app.add_subcommand("info", "Print counts, bounds, height and topology of a mesh file"); }
void add_convert_command(CLI::App& app) { app.add_subcommand("convert", "Convert between OBJ, PLY and GLB"); }
}
