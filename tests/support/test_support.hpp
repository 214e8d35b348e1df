#pragma once
// Helpers shared by all test executables: where the real-data fixtures and the CLI are,
// and running the CLI as a user would.
#include <cstdlib>
#include <filesystem>
#include <string>

#include <nlohmann/json.hpp>

namespace drape::test {

// Whether the tests run under the sanitizers (DRAPE_SANITIZED, set by `make sanitize`): long scenes
// are cut short or skipped there.
inline bool sanitized() { return std::getenv("DRAPE_SANITIZED") != nullptr; }

// ../shared/data (absolute), or an empty path when it is absent (a user's fresh clone).
std::filesystem::path shared_data();
// Path of a file under ../shared/data, or an empty path when it (or ../shared/data) is missing.
std::filesystem::path shared_file(const std::string& rel);
// `auto p = DRAPE_REQUIRE_SHARED("bodies/...");` gives the path; the calling test is skipped with a
// message when it is missing. (Use it only as the initialiser of a declaration, as shown.)
#define DRAPE_REQUIRE_SHARED(rel)                                                              \
  ::drape::test::shared_file(rel);                                                             \
  if (::drape::test::shared_file(rel).empty())                                                 \
  GTEST_SKIP() << "shared test data not found: " << (rel) << " (needs ../shared/data)"

// A fresh empty directory under the system temp dir, unique per test.
std::filesystem::path temp_dir(const std::string& tag);

struct CommandResult {
  int exit_code = -1;
  std::string out;  // stdout
  std::string err;  // stderr
};
// Runs build/drape with the given argument string (shell-quoted by the caller).
CommandResult run_drape(const std::string& args);

// A JSON file (a command's report.json), parsed.
nlohmann::json read_json(const std::filesystem::path& path);

}  // namespace drape::test
