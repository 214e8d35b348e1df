#pragma once
// Readers of the garment file formats; each returns the common GarmentSpec (drape/garment.hpp).
#include <Eigen/Geometry>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <string_view>

#include "drape/error.hpp"
#include "drape/garment.hpp"

namespace drape::pattern {

// drape's own garment JSON (docs/garment-format.md). `base_dir` resolves a referenced DXF file.
GarmentSpec parse_drape_garment(const nlohmann::ordered_json& root, const std::string& source,
                                const std::filesystem::path& base_dir);

// GarmentCode specifications and the 2021 templates (FORMAT_NOTES.md sections 1 and 2).
GarmentSpec parse_garmentcode(const nlohmann::ordered_json& root, const std::string& source);

// AAMA/ASTM D6673 DXF. `units` overrides the header ("mm", "cm", "m", "in"; empty: the header's,
// with a plausibility check on piece sizes). `size` picks one size of a graded file (empty: the
// sample size).
struct DxfOptions {
  std::string units;
  std::string size;
};
GarmentSpec parse_dxf(std::string_view text, const std::string& source, const DxfOptions& options);

// Parses JSON text, reporting syntax errors with line and column. `allow_comments` strips // and
// /* */ comments first (the 2021 template documentation uses them).
nlohmann::ordered_json parse_json_text(std::string_view text, const std::string& source, bool allow_comments);

// Reads a whole file; InputError naming it when it cannot be read.
std::string read_text_file(const std::filesystem::path& path);

// Metres per unit for "mm", "cm", "m", "in"; 0 for an unknown name.
double metres_per_unit(std::string_view units);

}  // namespace drape::pattern

namespace drape::pattern {

// The concrete outline of one panel in one size (no validation beyond what building needs:
// an arc whose radius is shorter than half its chord is an InputError naming the edge).
Panel build_panel(const PanelSpec& spec, size_t size, const std::string& source);

}  // namespace drape::pattern
