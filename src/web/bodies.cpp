#include "web/bodies.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <span>

#include "drape/error.hpp"
#include "drape/io.hpp"
#include "web/request_error.hpp"

namespace drape::web {
namespace {

// The library names the CLI option ("--measurements: ..."); the shopper gave a field.
[[noreturn]] void rethrow_as(const InputError& e, const std::string& field) {
  std::string what = e.what();
  const std::string prefix = e.source() + ": ";
  if (what.starts_with(prefix)) what.erase(0, prefix.size());
  throw RequestError(400, field + ": " + what);
}

// An uploaded glTF may name external files for its buffers and images; the loader would read them
// from the server's disk. Only a self-contained GLB (data in its binary chunk or in data: URIs) is
// taken.
void refuse_external_files(const std::string& bytes, const std::string& source) {
  if (bytes.size() < 20 || bytes.compare(0, 4, "glTF") != 0) return;
  const auto u32 = [&](size_t at) {
    uint32_t v = 0;
    for (int i = 3; i >= 0; --i)
      v = (v << 8) | static_cast<unsigned char>(bytes[at + static_cast<size_t>(i)]);
    return v;
  };
  const size_t length = u32(12);
  if (length > bytes.size() - 20 || u32(16) != 0x4E4F534Au) return;  // the loader says what is wrong
  const nlohmann::json gltf = nlohmann::json::parse(
      bytes.begin() + 20, bytes.begin() + 20 + static_cast<long>(length), nullptr, false);
  if (!gltf.is_object()) return;
  for (const char* kind : {"buffers", "images"}) {
    const auto it = gltf.find(kind);
    if (it == gltf.end() || !it->is_array()) continue;
    for (const nlohmann::json& item : *it) {
      if (!item.is_object() || !item.contains("uri")) continue;
      const nlohmann::json& uri = item["uri"];
      if (!uri.is_string() || !uri.get<std::string>().starts_with("data:"))
        throw RequestError(400, source + ": refers to an external file for its " + std::string(kind) +
                                    "; upload a self-contained GLB");
    }
  }
}

}  // namespace

Body body_from_measurements(const BodyRequest& request) {
  if (request.measurements.empty()) return default_body(request.sex);
  try {
    return make_human_body(request.sex, request.measurements);
  } catch (const InputError& e) {
    rethrow_as(e, "measurements");
  }
}

Body body_from_upload(const Upload& upload, size_t max_triangles) {
  std::string ext = std::filesystem::path(upload.filename).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  MeshFormat format = MeshFormat::Obj;
  if (ext == ".ply")
    format = MeshFormat::Ply;
  else if (ext == ".glb")
    format = MeshFormat::Glb;
  else if (ext != ".obj")
    throw RequestError(400, "file: expected an OBJ, PLY or GLB file (.obj, .ply, .glb)");
  const std::string source = "upload" + ext;
  LoadOptions options;
  try {
    options = load_options(upload.units, upload.up);
  } catch (const InputError& e) {
    rethrow_as(e, e.source() == "--up" ? "up" : "units");
  }
  refuse_external_files(upload.bytes, source);
  try {
    MeshCheck check;
    const auto* data = reinterpret_cast<const unsigned char*>(upload.bytes.data());
    const Scene scene = parse_scene(std::span(data, upload.bytes.size()), format, source, options, &check);
    if (check.triangles > max_triangles)
      throw RequestError(
          413, fmt::format("{}: {} triangles; at most {} are taken", source, check.triangles, max_triangles));
    // As load_body does for a file, without the file: the skin of a rigged GLB is not kept (the
    // try-on dresses the standing body), so every upload is rigged from its landmarks alike.
    Body body;
    body.mesh = merge_scene(scene);
    body.mesh.name = "body";
    body.mesh.joints.clear();
    body.mesh.weights.clear();
    body.mesh.morph_targets.clear();
    body.mesh.morph_weights.clear();
    normalise_body_placement(body.mesh, source);
    analyse_body(body, source);
    rig_body(body);
    return body;
  } catch (const InputError& e) {
    std::string what = e.what();
    // Messages name the source we gave; anything else that looks like a path is not shown.
    if (!what.starts_with(source)) what = source + ": " + what;
    throw RequestError(400, what);
  }
}

nlohmann::json measurements_json(const Measurements& m) {
  nlohmann::json out = nlohmann::json::object();
  for (const MeasurementInfo& info : measurement_table())
    out[std::string(info.key)] = std::round(1e4 * static_cast<double>(m.*(info.field))) / 1e4;
  return out;
}

}  // namespace drape::web
