#pragma once
// Runs the Khronos glTF validator (tools/gltf_validate.mjs, installed by `make deps`) on a file a test
// wrote. A missing node or validator is a failure, not a skip: `make test` always runs `make deps` first.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>

namespace drape::test {

struct GltfValidation {
  int errors = -1;  // -1: the validator did not run
  int warnings = -1;
  std::string report;  // the validator's JSON line, or why it did not run
};

GltfValidation validate_gltf(const std::filesystem::path& file);

// For EXPECT_TRUE / ASSERT_TRUE: success when the validator reports zero errors.
::testing::AssertionResult gltf_is_valid(const std::filesystem::path& file);

}  // namespace drape::test
