#pragma once
// Shared body of the fuzz targets: parse the input as `format`; malformed input must end in an
// InputError (anything else - a crash, a sanitizer report, another exception - is a finding). When the
// input parses, writing the scene back and parsing that must succeed too: the writers only produce
// what the readers accept.
#include <cstdint>
#include <cstdio>
#include <cstdlib>

#include "drape/error.hpp"
#include "drape/io.hpp"

namespace drape::fuzz {

inline int parse_and_round_trip(const uint8_t* data, size_t size, MeshFormat format, const char* name) {
  Scene scene;
  try {
    scene = parse_scene({data, size}, format, name);
  } catch (const InputError&) {
    return 0;
  }
  try {
    const Mesh merged = merge_scene(scene);
    const std::string obj = encode_obj(merged);
    parse_scene({reinterpret_cast<const unsigned char*>(obj.data()), obj.size()}, MeshFormat::Obj,
                "again.obj");
    parse_scene(encode_ply(merged), MeshFormat::Ply, "again.ply");
    parse_scene(encode_glb(scene), MeshFormat::Glb, "again.glb");
  } catch (const InputError& e) {
    std::fprintf(stderr, "round trip refused what was read: %s\n", e.what());
    std::abort();
  }
  return 0;
}

}  // namespace drape::fuzz
