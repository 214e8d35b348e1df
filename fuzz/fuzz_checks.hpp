#pragma once
// What the fuzz targets check on every input, shared by the libFuzzer entry points (fuzz/fuzz_*.cpp)
// and the corpus replay in the tests (tests/fuzz_replay), so CI runs the same checks over every kept
// input in the release build without libFuzzer.
//
// Each check parses the input as a user's file; bad input must end in an InputError. Anything else is
// a finding: a sanitizer report, a crash, another exception escaping, or a Finding thrown when a
// property of what was read does not hold.
#include <cstdint>
#include <span>
#include <stdexcept>
#include <string>
#include <string_view>

#include "drape/io.hpp"

namespace drape::fuzz {

// A property that does not hold for an input that parsed.
class Finding : public std::logic_error {
 public:
  using std::logic_error::logic_error;
};

// Parses `bytes` as a mesh file. When it reads, the merged mesh is written as OBJ, PLY (three
// encodings) and the scene as GLB, and each must read back to the same mesh (same triangles, the
// same positions within float rounding). Returns whether the input was read.
bool check_mesh_file(std::span<const unsigned char> bytes, MeshFormat format, const std::string& source);

// Garment formats, as parse_garment detects them from the content.
enum class GarmentFormat { DrapeJson, GarmentCode, Dxf };

// True when `text` would be read as `format`; a target skips inputs of the other formats, so each
// target explores its own parser.
bool is_garment_format(std::string_view text, GarmentFormat format);

// Parses `text` as a garment file. When it parses (every size validated), each size must resolve
// again and mesh with the grid mesher, either to a consistent mesh (indices in range, seam pairs on
// existing vertices, finite positions) or to an InputError. Returns whether the input was read.
bool check_garment_file(std::string_view text, const std::string& source);

}  // namespace drape::fuzz
