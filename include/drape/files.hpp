#pragma once
// Writing output files whole: a temporary file next to the target, then an atomic rename, so a
// failure never leaves half a file behind (DESIGN.md contract).
#include <filesystem>
#include <span>
#include <string_view>

namespace drape {

// Writes `bytes` to `path` atomically; creates missing parent directories. Throws std::runtime_error
// naming the path when the disk refuses.
void write_file_atomic(const std::filesystem::path& path, std::span<const unsigned char> bytes);
void write_file_atomic(const std::filesystem::path& path, std::string_view text);

}  // namespace drape
