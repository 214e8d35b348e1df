// The default bodies, baked into the binary when drape is built (tools/bake_default_bodies.cpp
// writes their MakeHuman shapes; .incbin puts the file in .rodata). The body is built from its
// shape, analysed and rigged on load, once per process and sex.
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
  // Built once per sex (thread-safe statics) and copied out: dressing tests and `drape fit` ask
  // for the same body many times.
  const auto build = [](Sex s) {
    const std::span<const unsigned char> bytes(drape_baked_bodies_begin, drape_baked_bodies_end);
    return body::mh_body(body::decode_baked_shape(bytes, s));
  };
  if (sex == Sex::Male) {
    static const Body male = build(Sex::Male);
    return male;
  }
  static const Body female = build(Sex::Female);
  return female;
}

}  // namespace drape
