#pragma once
// Shared by the animation tests: the default female body, whether the build is sanitized, and an
// animation's outputs written without a video, anim.glb checked by the Khronos validator and read back.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>

#include "drape/animate.hpp"
#include "drape/body.hpp"
#include "support/gltf_validator.hpp"
#include "support/test_support.hpp"

namespace drape::test {

inline const Body& female() {
  static const Body body = default_body(Sex::Female);
  return body;
}

// Writes dir's outputs and returns anim.glb's scene (EXPECTs it valid).
inline Scene written_animation(const std::filesystem::path& dir, const Body& body, const Motion& motion,
                               const AnimationResult& r, const AnimateOptions& o) {
  AnimationOutputOptions out;
  out.video = false;
  write_animation_outputs(dir, body, motion, r, o, out);
  EXPECT_TRUE(gltf_is_valid(dir / "anim.glb"));
  return read_scene(dir / "anim.glb");
}

}  // namespace drape::test
