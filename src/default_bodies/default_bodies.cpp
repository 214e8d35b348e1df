// The default bodies, baked into the binary when drape is built (tools/bake_default_bodies.cpp
// writes the generator's meshes; .incbin puts the file in .rodata: a C array literal of ~2 MB
// would cost the compiler far more). Analysis and rig run on load: they are cheap (~0.1 s) and
// keep the bake down to meshes.
#include <span>

#include "body/baked.hpp"
#include "drape/body.hpp"

#ifndef DRAPE_BAKED_BODIES
#error "DRAPE_BAKED_BODIES must name the baked bodies file (set by CMakeLists.txt)"
#endif

__asm__(".pushsection .rodata\n"
        ".balign 16\n"
        ".globl drape_baked_bodies_begin\n"
        ".hidden drape_baked_bodies_begin\n"
        "drape_baked_bodies_begin:\n"
        ".incbin \"" DRAPE_BAKED_BODIES "\"\n"
        ".globl drape_baked_bodies_end\n"
        ".hidden drape_baked_bodies_end\n"
        "drape_baked_bodies_end:\n"
        ".popsection\n");

extern "C" const unsigned char drape_baked_bodies_begin[];
extern "C" const unsigned char drape_baked_bodies_end[];

namespace drape {

Body default_body(Sex sex) {
  const std::span<const unsigned char> bytes(drape_baked_bodies_begin, drape_baked_bodies_end);
  return finish_generated_body(sex, body::decode_baked_body(bytes, sex));
}

}  // namespace drape
