#pragma once
// The bodies of the API's requests, read into what the routes act on: POST /api/bodies (JSON
// measurements, or a multipart upload of a body file) and POST /api/tryons. Every byte a shopper
// sends in a request body is read here (and by the loaders body_from_upload calls); anything
// malformed is a RequestError with the status and the words the shopper reads. fuzz/fuzz_web.cpp
// fuzzes them.
#include <string>
#include <string_view>

#include "web/bodies.hpp"
#include "web/http.hpp"

namespace drape::web {

// POST /api/bodies as JSON: {"sex": "female"|"male" (default female), "measurements": {"height":
// 1.68, ...}} (metres, keys of measurement_table(); "chest" = bust). RequestError 400 naming the
// field for anything else: not a JSON object, an unknown sex or key, a value that is not a number
// or outside what a person can measure, a key given twice.
BodyRequest parse_body_request(std::string_view body);

// POST /api/bodies as multipart/form-data: the part "file" (its filename gives the format) and the
// optional fields "units" (mm|cm|dm|m) and "up" (y|z). RequestError 400 without a file.
Upload upload_from_form(const httplib::Request& request);

// POST /api/tryons: {"body": ID, "garment": NAME, "size": SIZE or "auto"}.
struct TryOnRequest {
  std::string body, garment, size;
};
// RequestError 400 for anything but a JSON object with those three strings, 404 for a body that
// cannot be an id (the catalogue and the bodies are the service's to check).
TryOnRequest parse_tryon_request(std::string_view body);

// What the server answers a refused request with: {"error": message}. A message quotes what the
// shopper sent (a field, a token of the file); bytes of it that are not UTF-8 are replaced, so
// that every message can be sent.
std::string error_answer(std::string_view message);

}  // namespace drape::web
