#include "commands.hpp"

namespace drape::app {

void add_load_options(CLI::App& cmd, LoadOptions& opts) {
  cmd.add_option("--units", opts.units, "Length unit of the input file: mm, cm, dm or m")
      ->check(CLI::IsMember({"mm", "cm", "dm", "m"}))
      ->default_val("m");
  cmd.add_option("--up", opts.up, "Up axis of the input file: y or z (z-up files are rotated to y-up)")
      ->check(CLI::IsMember({"y", "z"}))
      ->default_val("y");
}

}  // namespace drape::app
