#include "drape/files.hpp"

#include <cstdio>
#include <stdexcept>
#include <string>
#include <unistd.h>

namespace drape {

void write_file_atomic(const std::filesystem::path& path, std::span<const unsigned char> bytes) {
  namespace fs = std::filesystem;
  if (path.has_parent_path()) fs::create_directories(path.parent_path());
  const fs::path tmp = path.string() + ".tmp" + std::to_string(::getpid());
  std::FILE* f = std::fopen(tmp.c_str(), "wb");
  if (!f) throw std::runtime_error(path.string() + ": cannot open for writing");
  const bool ok = std::fwrite(bytes.data(), 1, bytes.size(), f) == bytes.size() && std::fflush(f) == 0;
  if (std::fclose(f) != 0 || !ok) {
    fs::remove(tmp);
    throw std::runtime_error(path.string() + ": write failed (disk full?)");
  }
  fs::rename(tmp, path);
}

void write_file_atomic(const std::filesystem::path& path, std::string_view text) {
  write_file_atomic(path, std::span<const unsigned char>(reinterpret_cast<const unsigned char*>(text.data()),
                                                         text.size()));
}

}  // namespace drape
