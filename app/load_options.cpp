#include <filesystem>

#include "commands.hpp"
#include "drape/error.hpp"
#include "drape/io.hpp"

namespace drape::app {

void add_load_options(CLI::App& cmd, LoadOptions& opts) {
  cmd.add_option("--units", opts.units, "Length unit of the input file: mm, cm, dm or m")
      ->check(CLI::IsMember({"mm", "cm", "dm", "m"}))
      ->default_val("m");
  cmd.add_option("--up", opts.up, "Up axis of the input file: y or z (z-up files are rotated to y-up)")
      ->check(CLI::IsMember({"y", "z"}))
      ->default_val("y");
}

Body load_command_body(const std::string& body, const std::string& measurements, const LoadOptions& load) {
  if (!measurements.empty()) {
    if (body != "female" && body != "male")
      throw InputError("--measurements", "goes with --body female or male, not a body file");
    return make_human_body(body == "male" ? Sex::Male : Sex::Female, parse_measurements(measurements));
  }
  if (body == "female" || body == "male") return default_body(body == "male" ? Sex::Male : Sex::Female);
  if (!std::filesystem::exists(body)) throw InputError(body, "no such body file (or use --body female|male)");
  return load_body(body, drape::load_options(load.units, load.up));
}

}  // namespace drape::app
