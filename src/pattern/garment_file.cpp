// Reading garment files: format detection (drape JSON, GarmentCode, 2021 templates, DXF), JSON
// syntax errors with line numbers, validation of every size, and the built-in garments compiled
// into the binary (assets/garments/*.json, embedded by src/pattern/embed_garments.cmake).
#include <fmt/format.h>

#include <algorithm>
#include <fstream>
#include <sstream>

#include "pattern/embedded_garments.hpp"
#include "pattern/garment_formats.hpp"
#include "pattern/json_fields.hpp"

namespace drape {
namespace pattern {
namespace {

// One line: a message never spans lines (the CLI prints one line per error).
std::string one_line(std::string s) {
  std::replace(s.begin(), s.end(), '\n', ' ');
  std::replace(s.begin(), s.end(), '\r', ' ');
  return s;
}

// GarmentCode does not flag gathering: a stitch's length mismatch is its gathering. The importer
// records that mismatch as the seam's ease (still limited by kMaxSeamEase when validated).
void ease_from_mismatch(GarmentSpec& spec) {
  std::vector<Panel> panels;
  for (const PanelSpec& p : spec.panels) panels.push_back(build_panel(p, spec.base_size, spec.source));
  Garment g;
  g.panels = std::move(panels);
  for (SeamSpec& seam : spec.seams) {
    if (seam.a.panel >= g.panels.size() || seam.b.panel >= g.panels.size()) continue;
    const double la = g.seam_side_length(seam.a), lb = g.seam_side_length(seam.b);
    const double shorter = std::min(la, lb);
    if (shorter > 0) seam.ease = std::abs(la - lb) / shorter;
  }
}

}  // namespace

std::string read_text_file(const std::filesystem::path& path) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec))
    throw InputError(path.string(), std::filesystem::exists(path, ec) ? "not a regular file" : "no such file");
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  if (!in && !in.eof()) throw InputError(path.string(), "cannot be read");
  return s.str();
}

Json parse_json_text(std::string_view text, const std::string& source, bool allow_comments) {
  try {
    return Json::parse(text.begin(), text.end(), nullptr, true, allow_comments);
  } catch (const nlohmann::json::parse_error& e) {
    // nlohmann gives a byte offset; turn it into line and column.
    const size_t byte = std::min<size_t>(e.byte == 0 ? 0 : e.byte - 1, text.size());
    size_t line = 1, column = 1;
    for (size_t i = 0; i < byte; ++i) {
      if (text[i] == '\n') { ++line; column = 1; }
      else ++column;
    }
    std::string reason = e.what();
    if (const size_t colon = reason.find(": "); colon != std::string::npos && reason.find("column") < colon)
      reason = reason.substr(colon + 2);
    else if (const size_t br = reason.find("] "); br != std::string::npos)
      reason = reason.substr(br + 2);
    throw InputError(source, one_line(fmt::format("invalid JSON at line {}, column {}: {}", line, column, reason)));
  } catch (const nlohmann::json::out_of_range& e) {
    // A number too large for a double ("1e999"): nlohmann names the number, not where it is.
    std::string reason = e.what();
    if (const size_t br = reason.find("] "); br != std::string::npos) reason = reason.substr(br + 2);
    throw InputError(source, one_line(fmt::format("invalid JSON: {}", reason.substr(0, 120))));
  }
}

}  // namespace pattern

GarmentSpec parse_garment(std::string_view text, const std::string& source, const std::filesystem::path& base_dir) {
  using namespace pattern;
  size_t first = text.find_first_not_of(" \t\r\n");
  if (text.substr(0, 3) == "\xEF\xBB\xBF") first = text.find_first_not_of(" \t\r\n", 3);
  if (first == std::string_view::npos) throw InputError(source, "empty file");
  GarmentSpec spec;
  if (text[first] == '{' || text[first] == '/') {  // JSON, possibly opening with a // comment
    const Json root = parse_json_text(text, source, true);
    if (root.contains("drape_garment")) {
      spec = parse_drape_garment(root, source, base_dir);
    } else if (root.contains("pattern")) {
      spec = parse_garmentcode(root, source);
      ease_from_mismatch(spec);
    } else {
      throw InputError(source, "unknown garment format: expected a drape garment (\"drape_garment\": 1), "
                               "a GarmentCode specification (\"pattern\") or an AAMA/ASTM DXF file");
    }
  } else if (text[first] == '0' || text.substr(first, 7) == "SECTION") {
    spec = parse_dxf(text, source, {});
  } else {
    throw InputError(source, "not a garment file (neither JSON nor DXF)");
  }
  // Every size must be valid, not just the one asked for first.
  for (const std::string& size : spec.sizes) garment_in_size(spec, size);
  return spec;
}

GarmentSpec read_garment(const std::filesystem::path& path) {
  const std::string text = pattern::read_text_file(path);
  return parse_garment(text, path.string(), path.parent_path());
}

std::vector<BuiltinGarment> builtin_garments() {
  std::vector<BuiltinGarment> out;
  for (const auto& file : pattern::embedded_garments()) {
    const GarmentSpec spec = parse_garment(file.text, std::string(file.name), {});
    out.push_back({spec.name, spec.description, spec.sizes, spec.sizes.at(spec.base_size)});
  }
  return out;
}

const std::string& default_garment_name() {
  static const std::string kDefault = "shirt";
  return kDefault;
}

std::optional<GarmentSpec> builtin_garment(std::string_view name) {
  for (const auto& file : pattern::embedded_garments())
    if (std::filesystem::path(file.name).stem() == name) return parse_garment(file.text, std::string(file.name), {});
  return std::nullopt;
}

GarmentSpec load_garment(const std::string& name_or_path) {
  if (auto builtin = builtin_garment(name_or_path)) return *builtin;
  std::error_code ec;
  if (!std::filesystem::exists(name_or_path, ec)) {
    std::string names;
    for (const auto& file : pattern::embedded_garments())
      names += (names.empty() ? "" : ", ") + std::filesystem::path(file.name).stem().string();
    throw InputError(name_or_path, fmt::format("no such file or built-in garment (built-ins: {})", names));
  }
  return read_garment(name_or_path);
}

}  // namespace drape
