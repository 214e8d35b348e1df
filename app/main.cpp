// drape: the command line. Each subcommand is in app/cmd_<name>.cpp; this file wires them up and
// turns errors into the exit statuses of DESIGN.md (2: bad input, one line naming the file).
#include <cstdio>
#include <exception>

#include "commands.hpp"
#include "drape/error.hpp"

int main(int argc, char** argv) {
  CLI::App app{"drape dresses virtual people: it sews 2D cutting patterns around a body, drapes them\n"
               "with a physically based cloth model and reports how they fit."};
  app.set_version_flag("--version", std::string("drape ") + DRAPE_VERSION);
  app.require_subcommand(1);
  app.fallthrough();

  drape::app::add_info_command(app);
  drape::app::add_convert_command(app);
  drape::app::add_render_command(app);
  drape::app::add_scene_command(app);
  drape::app::add_garment_command(app);
  drape::app::add_dress_command(app);
  drape::app::add_body_command(app);
  drape::app::add_measure_command(app);
  drape::app::add_animate_command(app);
  drape::app::add_fit_command(app);
  drape::app::add_serve_command(app);

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int code = app.exit(e);
    return code == 0 ? 0 : drape::kExitBadInput;
  } catch (const drape::InputError& e) {
    std::fprintf(stderr, "drape: %s\n", e.what());
    return drape::kExitBadInput;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "drape: error: %s\n", e.what());
    return drape::kExitFailure;
  }
  return drape::kExitOk;
}
