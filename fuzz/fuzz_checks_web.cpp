// The request checks behind fuzz_web (see fuzz_checks.hpp).
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <nlohmann/json.hpp>

#include "drape/web.hpp"
#include "fuzz_checks.hpp"
#include "web/ids.hpp"
#include "web/request_error.hpp"
#include "web/requests.hpp"

namespace drape::fuzz {
namespace {

using nlohmann::json;

// Splits off the text up to the next newline; false (and `text` left as it was) when there is none.
bool take_line(std::string_view& text, std::string_view& line) {
  const size_t end = text.find('\n');
  if (end == std::string_view::npos) return false;
  line = text.substr(0, end);
  text.remove_prefix(end + 1);
  return true;
}

// A request that parsed holds what its JSON says: every measurement a key of the table (chest read
// as bust) with the value given, nothing more.
void expect_body_request(const web::BodyRequest& request, std::string_view body) {
  const json j = json::parse(body.begin(), body.end(), nullptr, false);
  const auto m = j.find("measurements");
  const size_t given = m == j.end() ? 0 : m->size();
  if (request.measurements.size() != given)
    throw Finding(fmt::format("{} measurements given, {} read", given, request.measurements.size()));
  if (given == 0) return;
  const auto& table = measurement_table();
  for (const auto& [key, value] : m->items()) {
    const std::string name = key == "chest" ? "bust" : key;
    const auto it = request.measurements.find(name);
    if (it == request.measurements.end() ||
        std::none_of(table.begin(), table.end(),
                     [&](const MeasurementInfo& info) { return info.key == name; }))
      throw Finding(fmt::format("measurement '{}' read as another", key));
    const double want = value.get<double>();
    if (!(std::abs(it->second - want) <= 1e-6 * std::abs(want)))
      throw Finding(fmt::format("measurement '{}': {} given, {} read", key, want, it->second));
  }
}

void expect_tryon_request(const web::TryOnRequest& request, std::string_view body) {
  const json j = json::parse(body.begin(), body.end(), nullptr, false);
  if (!web::is_id(request.body) || request.body != j["body"] || request.garment != j["garment"] ||
      request.size != j["size"])
    throw Finding("the try-on request read is not the one given");
}

// A body made from an upload is a rigged mesh: finite positions, one skin entry per vertex, every
// joint index in the skeleton.
void expect_uploaded_body(const Body& body) {
  const Mesh& mesh = body.mesh;
  if (mesh.positions.empty() || mesh.triangles.empty()) throw Finding("an uploaded body without a mesh");
  for (const Vec3f& p : mesh.positions)
    if (!p.allFinite()) throw Finding("an uploaded body with a non-finite vertex");
  if (body.skeleton.empty() || mesh.joints.size() != mesh.positions.size() ||
      mesh.weights.size() != mesh.positions.size())
    throw Finding("an uploaded body that is not rigged");
  for (const auto& joints : mesh.joints)
    for (const uint16_t j : joints)
      if (j >= body.skeleton.joints.size()) throw Finding(fmt::format("skin joint {} out of range", j));
}

}  // namespace

std::optional<bool> check_web_request(std::string_view input) {
  std::string_view route;
  if (!take_line(input, route)) return std::nullopt;
  try {
    if (route == "bodies") {
      expect_body_request(web::parse_body_request(input), input);
    } else if (route == "tryons") {
      expect_tryon_request(web::parse_tryon_request(input), input);
    } else if (route == "upload") {
      // Lines: the file part's filename, then the units and up fields; each absent line leaves its
      // part out of the form.
      httplib::Request request;
      std::string_view filename, units, up;
      const bool has_file = take_line(input, filename);
      const bool has_units = has_file && take_line(input, units);
      const bool has_up = has_units && take_line(input, up);
      if (has_file)
        request.files.emplace("file",
                              httplib::MultipartFormData{"file", std::string(input), std::string(filename),
                                                         "application/octet-stream"});
      if (has_units)
        request.files.emplace("units", httplib::MultipartFormData{"units", std::string(units), "", ""});
      if (has_up) request.files.emplace("up", httplib::MultipartFormData{"up", std::string(up), "", ""});
      expect_uploaded_body(
          web::body_from_upload(web::upload_from_form(request), ServeOptions{}.max_upload_triangles));
    } else {
      return std::nullopt;
    }
  } catch (const web::RequestError& e) {
    if (e.status() < 400 || e.status() > 499)
      throw Finding(fmt::format("refused with status {}: {}", e.status(), e.what()));
    if (std::string_view(e.what()).empty())
      throw Finding(fmt::format("refused with status {} and no words", e.status()));
    // The server answers {"error": message}: it must read back as such.
    std::string answer;
    try {
      answer = web::error_answer(e.what());
    } catch (const json::exception&) {
      throw Finding(fmt::format("refused with a message the answer cannot hold: {}", e.what()));
    }
    const json back = json::parse(answer, nullptr, false);
    if (!back.is_object() || !back.contains("error") || !back["error"].is_string())
      throw Finding(fmt::format("the answer to a refused request is not {{\"error\": ...}}: {}", answer));
    return false;
  }
  return true;
}

}  // namespace drape::fuzz
