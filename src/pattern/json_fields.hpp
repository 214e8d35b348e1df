#pragma once
// Typed access to JSON fields with errors that name the file and the element (InputError).
#include <fmt/format.h>

#include <nlohmann/json.hpp>
#include <string>

#include "drape/error.hpp"
#include "drape/garment.hpp"

namespace drape::pattern {

using Json = nlohmann::ordered_json;

// Where in a file we are: the file name plus a path like "panel 'front' edge 2".
struct Where {
  const std::string& source;
  std::string element;

  Where at(const std::string& child) const { return {source, element.empty() ? child : element + " " + child}; }
  [[noreturn]] void fail(const std::string& what) const {
    throw InputError(source, element.empty() ? what : element + ": " + what);
  }
};

inline const Json& field(const Json& obj, const char* key, const Where& where) {
  if (!obj.is_object()) where.fail("expected an object");
  for (const auto& [name, value] : obj.get_ref<const Json::object_t&>())
    if (name == key) return value;
  where.fail(fmt::format("missing \"{}\"", key));
}

inline const Json* optional_field(const Json& obj, const char* key) {
  if (!obj.is_object()) return nullptr;
  const auto& members = obj.get_ref<const Json::object_t&>();
  for (const auto& [name, value] : members)
    if (name == key) return value.is_null() ? nullptr : &value;
  return nullptr;
}

inline double as_number(const Json& v, const Where& where) {
  if (!v.is_number()) where.fail("expected a number");
  const double d = v.get<double>();
  if (!std::isfinite(d)) where.fail("number is not finite");
  return d;
}

inline std::string as_string(const Json& v, const Where& where) {
  if (!v.is_string()) where.fail("expected a string");
  return v.get<std::string>();
}

inline bool as_bool(const Json& v, const Where& where) {
  if (v.is_boolean()) return v.get<bool>();
  if (v.is_number_integer()) return v.get<long long>() != 0;
  where.fail("expected true or false");
}

inline Vec2d as_vec2(const Json& v, const Where& where) {
  if (!v.is_array() || v.size() != 2) where.fail("expected [x, y]");
  return {as_number(v[0], where), as_number(v[1], where)};
}

inline Vec3d as_vec3(const Json& v, const Where& where) {
  if (!v.is_array() || v.size() != 3) where.fail("expected [x, y, z]");
  return {as_number(v[0], where), as_number(v[1], where), as_number(v[2], where)};
}

}  // namespace drape::pattern
