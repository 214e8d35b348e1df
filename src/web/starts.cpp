#include "web/starts.hpp"

#include <fmt/format.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>

#include "drape/files.hpp"

namespace drape::web {

std::filesystem::path start_file(const std::filesystem::path& data_dir, const std::string& garment,
                                 const std::string& size, const std::string& body_name) {
  std::string hex;
  for (const unsigned char c : size) hex += fmt::format("{:02x}", c);
  return data_dir / "starts" / fmt::format("{}-{}-{}.json", garment, hex, body_name);
}

void save_start(const std::filesystem::path& file, const GarmentTransfer* t, uint64_t body_mesh, double edge_m) {
  nlohmann::json j{{"format", "drape start"},
                   {"version", DRAPE_VERSION},
                   {"edge_m", edge_m},
                   {"body_mesh", body_mesh},
                   {"fits", t != nullptr}};
  if (t) {
    // Flat arrays, five numbers a particle for `where`.
    nlohmann::json triangle = nlohmann::json::array(), where = nlohmann::json::array();
    for (const uint32_t tri : t->triangle) triangle.push_back(tri);
    for (const auto& w : t->where)
      for (const float v : w) where.push_back(static_cast<double>(v));
    j["garment"] = t->garment;
    j["size"] = t->size;
    j["particles"] = t->particles;
    j["triangle"] = std::move(triangle);
    j["where"] = std::move(where);
  }
  std::filesystem::create_directories(file.parent_path());
  write_file_atomic(file, j.dump());
}

std::optional<KeptStart> load_start(const std::filesystem::path& file, const Body& body, double edge_m) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(file, ec)) return std::nullopt;
  const auto refuse = [&](const std::string& why) -> std::optional<KeptStart> {
    std::fprintf(stderr, "drape serve: %s: %s; dressing it again\n", file.string().c_str(), why.c_str());
    return std::nullopt;
  };
  std::ifstream in(file, std::ios::binary);
  const nlohmann::json j = nlohmann::json::parse(in, nullptr, false);
  if (!j.is_object() || j.value("format", "") != "drape start") return refuse("not a start drape saved by drape serve");
  // Another version may make the garment or the body anew: its starts are not trusted.
  if (j.value("version", "") != DRAPE_VERSION) return std::nullopt;
  if (!j.contains("edge_m") || !j["edge_m"].is_number() || j["edge_m"].get<double>() != edge_m) return std::nullopt;
  if (!j.contains("body_mesh") || !j["body_mesh"].is_number_unsigned() ||
      j["body_mesh"].get<uint64_t>() != mesh_fingerprint(body.mesh))
    return std::nullopt;
  if (!j.contains("fits") || !j["fits"].is_boolean()) return refuse("it says neither that the garment fits nor that it does not");
  if (!j["fits"].get<bool>()) return KeptStart{};
  try {
    GarmentTransfer t;
    t.garment = j.at("garment").get<std::string>();
    t.size = j.at("size").get<std::string>();
    t.particles = j.at("particles").get<size_t>();
    t.body_mesh = j.at("body_mesh").get<uint64_t>();
    t.body_measurements = body.measurements;
    t.triangle = j.at("triangle").get<std::vector<uint32_t>>();
    const std::vector<float> where = j.at("where").get<std::vector<float>>();
    if (t.particles == 0 || t.triangle.size() != t.particles || where.size() != 5 * t.particles)
      return refuse(fmt::format("{} particles, {} triangles and {} numbers of placement do not agree", t.particles,
                                t.triangle.size(), where.size()));
    t.where.resize(t.particles);
    for (size_t i = 0; i < t.particles; ++i)
      for (size_t k = 0; k < 5; ++k) t.where[i][k] = where[5 * i + k];
    for (size_t i = 0; i < t.particles; ++i) {
      if (t.triangle[i] >= body.mesh.triangles.size())
        return refuse(fmt::format("particle {} names body triangle {} of {}", i, t.triangle[i], body.mesh.triangles.size()));
      for (const float v : t.where[i])
        if (!std::isfinite(v)) return refuse(fmt::format("particle {} has a position that is not a number", i));
    }
    return KeptStart{true, std::move(t)};
  } catch (const nlohmann::json::exception& e) {
    return refuse(fmt::format("unreadable ({})", e.what()));
  }
}

}  // namespace drape::web
