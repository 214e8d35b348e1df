#include "web/requests.hpp"

#include <fmt/format.h>

#include <nlohmann/json.hpp>

#include "drape/error.hpp"
#include "web/ids.hpp"
#include "web/request_error.hpp"

namespace drape::web {
namespace {

using nlohmann::json;

json parse_json(std::string_view body) {
  return json::parse(body.begin(), body.end(), nullptr, false);
}

}  // namespace

BodyRequest parse_body_request(std::string_view body) {
  const json request = parse_json(body);
  if (request.is_discarded())
    throw RequestError(
        400, "expected JSON {\"sex\": ..., \"measurements\": {...}} or a multipart upload of a body file");
  if (!request.is_object())
    throw RequestError(400, "expected a JSON object with \"sex\" and \"measurements\"");
  BodyRequest out;
  if (const auto it = request.find("sex"); it != request.end()) {
    if (!it->is_string() || (*it != "female" && *it != "male"))
      throw RequestError(400, "sex: expected \"female\" or \"male\"");
    out.sex = *it == "male" ? Sex::Male : Sex::Female;
  }
  const auto m = request.find("measurements");
  if (m == request.end() || (m->is_object() && m->empty())) return out;
  if (!m->is_object())
    throw RequestError(400, "measurements: expected an object of metres, e.g. {\"height\": 1.68}");
  // The library reads "key=value,...": a key holding ',' or '=' would read as other keys.
  std::string text;
  for (const auto& [key, value] : m->items()) {
    if (!value.is_number())
      throw RequestError(400, fmt::format("measurements: '{}' is not a number of metres", key));
    if (key.find_first_of(",=") != std::string::npos)
      throw RequestError(400, fmt::format("measurements: unknown measurement '{}'", key));
    text += fmt::format("{}{}={}", text.empty() ? "" : ",", key, value.get<double>());
  }
  try {
    out.measurements = parse_measurements(text);
  } catch (const InputError& e) {
    // The library names the CLI option ("--measurements: ..."); the shopper gave a field.
    std::string what = e.what();
    const std::string prefix = e.source() + ": ";
    if (what.starts_with(prefix)) what.erase(0, prefix.size());
    throw RequestError(400, "measurements: " + what);
  }
  return out;
}

Upload upload_from_form(const httplib::Request& request) {
  if (!request.has_file("file")) throw RequestError(400, "file: no file in the upload (field 'file')");
  Upload upload;
  const httplib::MultipartFormData file = request.get_file_value("file");
  upload.filename = file.filename;
  upload.bytes = file.content;
  if (request.has_file("units")) upload.units = request.get_file_value("units").content;
  if (request.has_file("up")) upload.up = request.get_file_value("up").content;
  return upload;
}

TryOnRequest parse_tryon_request(std::string_view body) {
  const json request = parse_json(body);
  if (request.is_discarded() || !request.is_object())
    throw RequestError(400, "expected JSON {\"body\": ID, \"garment\": NAME, \"size\": SIZE or \"auto\"}");
  for (const char* key : {"body", "garment", "size"})
    if (const auto it = request.find(key); it == request.end() || !it->is_string())
      throw RequestError(400, fmt::format("{}: missing (a string)", key));
  TryOnRequest out{request["body"], request["garment"], request["size"]};
  if (!is_id(out.body)) throw RequestError(404, "no such body (it may have expired or been deleted)");
  return out;
}

std::string error_answer(std::string_view message) {
  return json{{"error", message}}.dump(-1, ' ', false, json::error_handler_t::replace);
}

}  // namespace drape::web
