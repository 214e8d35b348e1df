#include "support/test_support.hpp"

#include <array>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <sys/wait.h>
#include <unistd.h>

namespace drape::test {

std::filesystem::path shared_data() {
  std::filesystem::path p = DRAPE_SHARED_DATA;
  if (const char* env = std::getenv("DRAPE_SHARED_DATA")) p = env;
  return std::filesystem::exists(p) ? p : std::filesystem::path{};
}

std::filesystem::path shared_file(const std::string& rel) {
  const std::filesystem::path root = shared_data();
  if (root.empty() || !std::filesystem::exists(root / rel)) return {};
  return root / rel;
}

std::filesystem::path temp_dir(const std::string& tag) {
  auto base = std::filesystem::temp_directory_path() /
              ("drape_test_" + tag + "_" + std::to_string(::getpid()));
  std::filesystem::remove_all(base);
  std::filesystem::create_directories(base);
  return base;
}

static std::string slurp(const std::filesystem::path& p) {
  std::ifstream f(p, std::ios::binary);
  std::stringstream ss;
  ss << f.rdbuf();
  return ss.str();
}

nlohmann::json read_json(const std::filesystem::path& path) {
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  return nlohmann::json::parse(ss.str());
}

CommandResult run_drape(const std::string& args) {
  static int counter = 0;
  auto dir = std::filesystem::temp_directory_path() /
             ("drape_cmd_" + std::to_string(::getpid()) + "_" + std::to_string(counter++));
  std::filesystem::create_directories(dir);
  std::string cmd = std::string("\"") + DRAPE_BINARY + "\" " + args + " >\"" + (dir / "out").string() +
                    "\" 2>\"" + (dir / "err").string() + "\"";
  int status = std::system(cmd.c_str());
  CommandResult r;
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  r.out = slurp(dir / "out");
  r.err = slurp(dir / "err");
  std::filesystem::remove_all(dir);
  return r;
}

}  // namespace drape::test
