// AAMA/ASTM D6673 pattern DXF: each piece is a BLOCK whose layer-1 closed POLYLINE is the cut
// line, layer-2 POINTs mark turn points (corners), a layer-7 LINE the grain, and layer-1 TEXT
// carries "KEY: value" piece/style text (PIECE NAME, SIZE, UNITS: METRIC = mm, ENGLISH = inch).
//
// Hand-written group-code reader: DXF ASCII is a flat list of (code, value) line pairs, and the
// AAMA meaning lives in layers and text keys that no general DXF library interprets. Debian's
// libdxflib (the only candidate) is GPL-2 and callback-driven; reading the dozen entity kinds
// used here directly is shorter than adapting it and keeps drape's licence free.
//
// Edges of a piece are the runs of the boundary between consecutive turn points: straight when
// the run has no interior vertex, else a polyline parametrised by arc length. Pieces are moved so
// their bounding box starts at (0, 0) and their loops run counter-clockwise (seen from the right
// side, as AAMA draws pieces).
#include <fmt/format.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <map>
#include <set>

#include "pattern/garment_formats.hpp"

namespace drape::pattern {
namespace {

struct GroupPair {
  int code = 0;
  std::string value;
  size_t line = 0;  // 1-based line of the code
};

std::string_view trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t' || s.front() == '\r')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t' || s.back() == '\r')) s.remove_suffix(1);
  return s;
}

std::vector<GroupPair> read_pairs(std::string_view text, const std::string& source) {
  std::vector<std::string_view> lines;
  size_t start = 0;
  while (start <= text.size()) {
    const size_t nl = text.find('\n', start);
    if (nl == std::string_view::npos) {
      if (start < text.size()) lines.push_back(text.substr(start));
      break;
    }
    lines.push_back(text.substr(start, nl - start));
    start = nl + 1;
  }
  std::vector<GroupPair> pairs;
  pairs.reserve(lines.size() / 2);
  for (size_t i = 0; i + 1 < lines.size(); i += 2) {
    const std::string_view code = trim(lines[i]);
    int c = 0;
    const auto [ptr, ec] = std::from_chars(code.data(), code.data() + code.size(), c);
    if (ec != std::errc() || ptr != code.data() + code.size())
      throw InputError(source, fmt::format("line {}: expected a DXF group code, found \"{}\"", i + 1, std::string(code.substr(0, 40))));
    pairs.push_back({c, std::string(trim(lines[i + 1])), i + 1});
  }
  if (lines.size() % 2 == 1 && !trim(lines.back()).empty())
    throw InputError(source, fmt::format("line {}: group code without a value (file truncated?)", lines.size()));
  return pairs;
}

double number(const GroupPair& p, const std::string& source) {
  double v = 0;
  const char* b = p.value.data();
  const auto [ptr, ec] = std::from_chars(b, b + p.value.size(), v);
  if (ec != std::errc() || ptr != b + p.value.size() || !std::isfinite(v))
    throw InputError(source, fmt::format("line {}: expected a number for group code {}, found \"{}\"", p.line + 1, p.code,
                                         p.value.substr(0, 40)));
  return v;
}

// Codes 60-99 are 16-bit integers; anything else there is an error, never an overflowing cast.
int integer(const GroupPair& p, const std::string& source) {
  const double v = number(p, source);
  if (v != std::floor(v) || std::abs(v) > 32767)
    throw InputError(source, fmt::format("line {}: expected a 16-bit integer for group code {}, found \"{}\"", p.line + 1,
                                         p.code, p.value.substr(0, 40)));
  return static_cast<int>(v);
}

// One entity: its type and its group codes until the next code 0.
struct Entity {
  std::string type;
  std::string layer;
  std::vector<const GroupPair*> groups;
  size_t line = 0;
  const GroupPair* get(int code) const {
    for (const GroupPair* g : groups)
      if (g->code == code) return g;
    return nullptr;
  }
};

struct Block {
  std::string name;
  std::vector<Entity> entities;
};

struct Piece {
  std::string name, size, block;
  std::vector<Vec2d> boundary;
  std::vector<Vec2d> turn_points;
  std::optional<Vec2d> grain;
  size_t line = 0;
};

// Splits the pairs into BLOCKS (entities grouped per block) and the text of every TEXT entity.
void collect(const std::vector<GroupPair>& pairs, std::vector<Block>& blocks, std::vector<std::string>& texts,
             std::map<std::string, int>& header_ints, const std::string& source) {
  std::string section;
  Block* block = nullptr;
  std::string header_var;
  for (size_t i = 0; i < pairs.size(); ++i) {
    const GroupPair& p = pairs[i];
    if (p.code == 0 && p.value == "SECTION") {
      if (i + 1 >= pairs.size() || pairs[i + 1].code != 2) throw InputError(source, fmt::format("line {}: SECTION without a name", p.line));
      section = pairs[++i].value;
      continue;
    }
    if (p.code == 0 && p.value == "ENDSEC") { section.clear(); block = nullptr; continue; }
    if (section == "HEADER") {
      if (p.code == 9) header_var = p.value;
      else if (p.code == 70) header_ints[header_var] = integer(p, source);
      continue;
    }
    if (p.code != 0) continue;
    if (section == "BLOCKS" && p.value == "BLOCK") {
      blocks.push_back({});
      block = &blocks.back();
    }
    if (p.value == "ENDBLK") { block = nullptr; continue; }
    // An entity (or the BLOCK header itself): gather its codes.
    Entity e;
    e.type = p.value;
    e.line = p.line;
    size_t j = i + 1;
    for (; j < pairs.size() && pairs[j].code != 0; ++j) {
      e.groups.push_back(&pairs[j]);
      if (pairs[j].code == 8) e.layer = pairs[j].value;
    }
    i = j - 1;
    if (e.type == "BLOCK") {
      // A BLOCK outside the BLOCKS section starts no block.
      if (const GroupPair* n = e.get(2); n && block) block->name = n->value;
      continue;
    }
    if (e.type == "TEXT" || e.type == "MTEXT")
      if (const GroupPair* t = e.get(1)) texts.push_back(t->value);
    if (block) block->entities.push_back(std::move(e));
  }
}

std::string text_value(const std::string& text, const char* key) {
  const std::string k = std::string(key) + ":";
  if (text.rfind(k, 0) != 0) return {};
  return std::string(trim(std::string_view(text).substr(k.size())));
}

// Pieces of one block: the layer-1 closed boundary, turn points, grain and piece text.
std::optional<Piece> read_piece(const Block& block, const std::string& source) {
  Piece piece;
  piece.block = block.name;
  piece.name = block.name;
  bool in_boundary = false;
  for (size_t k = 0; k < block.entities.size(); ++k) {
    const Entity& e = block.entities[k];
    const auto xy = [&](int cx, int cy) -> std::optional<Vec2d> {
      const GroupPair* x = e.get(cx);
      const GroupPair* y = e.get(cy);
      if (!x || !y) return std::nullopt;
      return Vec2d(number(*x, source), number(*y, source));
    };
    if (e.type == "TEXT" && e.layer == "1") {
      if (const GroupPair* t = e.get(1)) {
        if (auto v = text_value(t->value, "PIECE NAME"); !v.empty()) piece.name = v;
        if (auto v = text_value(t->value, "SIZE"); !v.empty()) piece.size = v;
      }
    } else if (e.type == "POLYLINE") {
      in_boundary = e.layer == "1" && piece.boundary.empty();
      if (in_boundary) piece.line = e.line;
    } else if (e.type == "VERTEX") {
      if (in_boundary)
        if (auto p = xy(10, 20)) piece.boundary.push_back(*p);
    } else if (e.type == "SEQEND") {
      in_boundary = false;
    } else if (e.type == "LWPOLYLINE" && e.layer == "1" && piece.boundary.empty()) {
      piece.line = e.line;
      const GroupPair* x = nullptr;
      for (const GroupPair* g : e.groups) {
        if (g->code == 10) x = g;
        if (g->code == 20 && x) piece.boundary.emplace_back(number(*x, source), number(*g, source));
      }
    } else if (e.type == "POINT" && e.layer == "2") {
      if (auto p = xy(10, 20)) piece.turn_points.push_back(*p);
    } else if (e.type == "LINE" && e.layer == "7" && !piece.grain) {
      auto a = xy(10, 20), b = xy(11, 21);
      if (a && b && (*b - *a).norm() > 0) piece.grain = (*b - *a).normalized();
    }
  }
  if (piece.boundary.size() < 3) return std::nullopt;  // a block without a cut line is not a piece
  // Drop repeated points, including a closing copy of the first.
  std::vector<Vec2d> clean;
  for (const Vec2d& p : piece.boundary)
    if (clean.empty() || (p - clean.back()).norm() > 1e-9) clean.push_back(p);
  while (clean.size() > 1 && (clean.back() - clean.front()).norm() <= 1e-9) clean.pop_back();
  piece.boundary = std::move(clean);
  if (piece.boundary.size() < 3) throw InputError(source, fmt::format("line {}: piece '{}' boundary has fewer than 3 distinct points", piece.line, piece.name));
  return piece;
}

PanelSpec piece_to_panel(const Piece& piece, double scale) {
  std::vector<Vec2d> pts = piece.boundary;
  // Counter-clockwise loops (AAMA draws pieces from the right side).
  double twice_area = 0;
  for (size_t i = 0; i < pts.size(); ++i) {
    const Vec2d& a = pts[i];
    const Vec2d& b = pts[(i + 1) % pts.size()];
    twice_area += a.x() * b.y() - b.x() * a.y();
  }
  if (twice_area < 0) std::reverse(pts.begin(), pts.end());
  Eigen::AlignedBox2d box;
  for (const Vec2d& p : pts) box.extend(p);
  const double extent = box.diagonal().norm();

  // Corners: boundary vertices where a layer-2 turn point lies.
  std::vector<size_t> corners;
  for (size_t i = 0; i < pts.size(); ++i)
    for (const Vec2d& t : piece.turn_points)
      if ((t - pts[i]).norm() <= 1e-6 * extent + 1e-6) {
        corners.push_back(i);
        break;
      }
  if (corners.size() < 2) {
    // No usable turn points: the first vertex and the one farthest from it.
    size_t far = 0;
    for (size_t i = 0; i < pts.size(); ++i)
      if ((pts[i] - pts[0]).norm() > (pts[far] - pts[0]).norm()) far = i;
    corners = {0, far};
  }

  PanelSpec panel;
  panel.name = piece.name;
  panel.label = piece.block;
  std::vector<Vec2d> vertices;
  const Vec2d origin = box.min();
  for (size_t c = 0; c < corners.size(); ++c) {
    const size_t i0 = corners[c], i1 = corners[(c + 1) % corners.size()];
    vertices.push_back(scale * (pts[i0] - origin));
    EdgeSpec e;
    for (size_t i = (i0 + 1) % pts.size(); i != i1; i = (i + 1) % pts.size()) e.points.push_back(scale * (pts[i] - origin));
    e.curve = e.points.empty() ? EdgeCurve::line : EdgeCurve::polyline;
    panel.edges.push_back(std::move(e));
  }
  panel.vertices = {vertices};
  if (piece.grain) panel.grain = *piece.grain;
  return panel;
}

}  // namespace

double metres_per_unit(std::string_view units) {
  if (units == "mm") return 0.001;
  if (units == "cm") return 0.01;
  if (units == "m") return 1.0;
  if (units == "in" || units == "inch") return 0.0254;
  return 0;
}

GarmentSpec parse_dxf(std::string_view text, const std::string& source, const DxfOptions& options) {
  const std::vector<GroupPair> pairs = read_pairs(text, source);
  if (pairs.empty() || pairs.front().code != 0 || pairs.front().value != "SECTION")
    throw InputError(source, "not a DXF file (it does not start with a SECTION)");
  std::vector<Block> blocks;
  std::vector<std::string> texts;
  std::map<std::string, int> header;
  collect(pairs, blocks, texts, header, source);

  // Units: the companion's override, else the style text, else $INSUNITS.
  std::string units = options.units, units_from = "the companion file";
  std::string sample_size;
  for (const std::string& t : texts) {
    if (auto v = text_value(t, "SAMPLE SIZE"); !v.empty()) sample_size = v;
    if (units.empty()) {
      const std::string v = text_value(t, "UNITS");
      if (v == "METRIC") units = "mm";
      if (v == "ENGLISH") units = "in";
      if (!units.empty()) units_from = fmt::format("its header (UNITS: {})", v);
    }
  }
  if (units.empty() && header.count("$INSUNITS")) {
    const std::map<int, std::string> codes{{1, "in"}, {4, "mm"}, {5, "cm"}, {6, "m"}};
    if (auto it = codes.find(header["$INSUNITS"]); it != codes.end()) {
      units = it->second;
      units_from = "its header ($INSUNITS)";
    }
  }
  if (units.empty())
    throw InputError(source, "no units in the file (no UNITS text or $INSUNITS); name them in a companion garment file (\"units\": \"mm\")");
  const double scale = metres_per_unit(units);

  // Pieces of the chosen size.
  std::vector<Piece> pieces;
  for (const Block& b : blocks)
    if (auto p = read_piece(b, source)) pieces.push_back(std::move(*p));
  if (pieces.empty()) throw InputError(source, "no pattern pieces (no BLOCK with a closed boundary POLYLINE on layer 1)");
  std::string size = options.size;
  if (size.empty()) size = !sample_size.empty() ? sample_size : pieces.front().size;
  std::set<std::string> sizes_seen;
  for (const Piece& p : pieces) sizes_seen.insert(p.size);
  if (!options.size.empty() && !sizes_seen.count(size))
    throw InputError(source, fmt::format("no pieces of size \"{}\"", size));

  GarmentSpec spec;
  spec.source = source;
  spec.format = "dxf";
  spec.name = std::filesystem::path(source).stem().string();
  spec.sizes = {size.empty() ? std::string("as drafted") : size};
  std::map<std::string, int> name_count;
  double largest = 0;
  for (const Piece& p : pieces) {
    if (!p.size.empty() && !size.empty() && p.size != size) continue;
    PanelSpec panel = piece_to_panel(p, scale);
    if (++name_count[panel.name] > 1) panel.name += fmt::format("_{}", name_count[panel.name]);
    Eigen::AlignedBox2d box;
    for (const Vec2d& v : panel.vertices[0]) box.extend(v);
    for (const EdgeSpec& e : panel.edges)
      for (const Vec2d& v : e.points) box.extend(v);
    largest = std::max(largest, box.sizes().maxCoeff());
    spec.panels.push_back(std::move(panel));
  }
  // Units taken from the file are checked: a garment piece measures between 15 cm and 2.5 m.
  if (options.units.empty() && (largest < 0.15 || largest > 2.5))
    throw InputError(source, fmt::format("the largest piece measures {:.3g} m in the units of {}; the units look wrong, "
                                         "name them in a companion garment file (\"units\": \"mm\"|\"cm\"|\"m\"|\"in\")",
                                         largest, units_from));
  return spec;
}

}  // namespace drape::pattern
