#pragma once
// The default bodies as the build bakes them into the binary (src/default_bodies): the MakeHuman
// shape that measures as the average adult of each sex (solving for it is the slow part of making
// a body, ~1 s); building the body from the shape, analysing and rigging it run when a body is
// asked for. Format (native byte order: written and read by builds of the same machine):
// "DRAPEBB2", a uint32 body count, then per body uint32 sex (0 female, 1 male), float weight,
// height and scale, a uint32 count of measurement targets and their floats.
#include <span>
#include <string>
#include <vector>

#include "body/makehuman.hpp"

namespace drape::body {

std::string encode_baked_shapes(const std::vector<MhShape>& shapes);
// std::runtime_error when the bytes are not a well-formed bake or hold no body of this sex.
MhShape decode_baked_shape(std::span<const unsigned char> bytes, Sex sex);

}  // namespace drape::body
