#pragma once
// The built-in garment files, compiled into the binary at build time (embed_garments.cmake writes
// the definition from assets/garments/*.json), so `drape` finds them from any directory.
#include <span>
#include <string_view>

namespace drape::pattern {

struct EmbeddedFile {
  std::string_view name;  // file name, e.g. "shirt.json"
  std::string_view text;
};

std::span<const EmbeddedFile> embedded_garments();

}  // namespace drape::pattern
