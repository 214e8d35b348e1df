#include "support/gltf_validator.hpp"

#include <sys/wait.h>

#include <array>
#include <cstdio>
#include <nlohmann/json.hpp>

namespace drape::test {

GltfValidation validate_gltf(const std::filesystem::path& file) {
  GltfValidation result;
  const std::filesystem::path script =
      std::filesystem::path(DRAPE_SOURCE_DIR) / "tools" / "gltf_validate.mjs";
  const std::string cmd = "node \"" + script.string() + "\" \"" + file.string() + "\" 2>&1";
  std::FILE* pipe = ::popen(cmd.c_str(), "r");
  if (!pipe) {
    result.report = "cannot run node";
    return result;
  }
  std::array<char, 4096> buf{};
  std::string out;
  while (std::fgets(buf.data(), static_cast<int>(buf.size()), pipe)) out += buf.data();
  const int status = ::pclose(pipe);
  result.report = out;
  const int code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  if (code != 0 && code != 1) return result;  // the validator did not run (see report)
  const auto json = nlohmann::json::parse(out, nullptr, false);
  if (json.is_discarded() || !json.contains("errors")) return result;
  result.errors = json["errors"].get<int>();
  result.warnings = json["warnings"].get<int>();
  return result;
}

::testing::AssertionResult gltf_is_valid(const std::filesystem::path& file) {
  const GltfValidation v = validate_gltf(file);
  if (v.errors == 0) return ::testing::AssertionSuccess();
  if (v.errors < 0)
    return ::testing::AssertionFailure()
           << "glTF validator did not run on " << file << " (run `make deps`): " << v.report;
  return ::testing::AssertionFailure() << file << ": " << v.errors << " validator errors: " << v.report;
}

}  // namespace drape::test
