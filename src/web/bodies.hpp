#pragma once
// Bodies a shopper makes: from measurements (JSON) or from an uploaded scan (OBJ, PLY, GLB). Both
// go through the library's validated loaders and body makers; their errors come back as
// RequestError with the library's message, the upload named "upload.EXT", never a server path.
#include <cstddef>
#include <nlohmann/json.hpp>
#include <string>

#include "drape/body.hpp"

namespace drape::web {

// A body asked for by measurements (parse_body_request in web/requests.hpp reads it from JSON).
struct BodyRequest {
  Sex sex = Sex::Female;
  MeasurementRequest measurements;  // metres, keys of measurement_table(); none: the built-in body
};
// The body of that sex made to those measurements; RequestError 400 for a combination no human
// body has.
Body body_from_measurements(const BodyRequest& request);

struct Upload {
  std::string filename;  // the shopper's name for it: only its extension is used
  std::string bytes;
  std::string units = "m";  // mm|cm|dm|m
  std::string up = "y";     // y|z
};
// Throws RequestError 413 above `max_triangles`, 400 for anything the loaders refuse.
Body body_from_upload(const Upload& upload, size_t max_triangles);

// The body's tape measurements as JSON (every key of measurement_table(), metres).
nlohmann::json measurements_json(const Measurements& m);

}  // namespace drape::web
