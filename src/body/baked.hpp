#pragma once
// The default bodies' meshes as the build bakes them into the binary (src/default_bodies): the
// generator's output, before analysis and rig, which are cheap and run when a body is asked for.
// Format (native byte order: written and read by builds of the same machine): "DRAPEBB1", a
// uint32 body count, then per body uint32 sex (0 female, 1 male), vertex count and triangle count,
// float positions[3 n], float normals[3 n], uint32 triangles[3 t].
#include <span>
#include <string>
#include <vector>

#include "drape/body.hpp"

namespace drape::body {

struct BakedBody {
  Sex sex = Sex::Female;
  Mesh mesh;  // positions, normals, triangles
};

std::string encode_baked_bodies(const std::vector<BakedBody>& bodies);
// std::runtime_error when the bytes are not a well-formed bake or hold no body of this sex.
Mesh decode_baked_body(std::span<const unsigned char> bytes, Sex sex);

}  // namespace drape::body
