// `drape measure BODY`: landmarks, tape measurements and body-part counts of a body file, as JSON.
// The body is normalised first (units/up from the options; facing, floor and centring found).
#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "commands.hpp"
#include "drape/body.hpp"
#include "drape/io.hpp"

namespace drape::app {
namespace {

struct MeasureArgs {
  std::string file;
  LoadOptions load;
};

nlohmann::json point(const Vec3f& p) { return {p.x(), p.y(), p.z()}; }

void run_measure(const MeasureArgs& args) {
  const Body body = load_body(args.file, load_options(args.load.units, args.load.up));
  nlohmann::json j;
  j["file"] = args.file;
  j["units"] = "m";
  j["frame"] = "+Y up, facing +Z, +X = body's left, feet on y = 0";
  j["vertices"] = body.mesh.vertex_count();
  j["rigged"] = !body.skeleton.empty();
  for (const auto& [name, p] : body.landmarks.named()) j["landmarks"][std::string(name)] = point(p);
  for (const auto& row : measurement_table()) j["measurements"][std::string(row.key)] = body.measurements.*row.field;
  std::array<size_t, kBodyPartCount> counts{};
  for (BodyPart part : body.parts) ++counts[static_cast<size_t>(part)];
  for (int i = 0; i < kBodyPartCount; ++i)
    j["part_vertices"][std::string(body_part_name(static_cast<BodyPart>(i)))] = counts[static_cast<size_t>(i)];
  fmt::print("{}\n", j.dump(2));
}

}  // namespace

void add_measure_command(CLI::App& app) {
  auto args = std::make_shared<MeasureArgs>();
  auto* cmd = app.add_subcommand("measure", "Landmarks and tape measurements of a standing body, as JSON (metres)");
  cmd->add_option("BODY", args->file, "Body file: OBJ, PLY (scans) or glTF/GLB")->required();
  add_load_options(*cmd, args->load);
  cmd->callback([args] { run_measure(*args); });
}

}  // namespace drape::app
