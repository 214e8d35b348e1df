// drape's garment JSON (docs/garment-format.md): panels as closed outlines of lines, Bezier curves
// and arcs, graded to sizes by a grade-rule table (as AAMA grade rules are: a delta per point per
// size), seams as pairs of edge ranges, placement hints. A garment may instead take its panels from
// an AAMA/ASTM DXF file ("dxf": "pieces.dxf") and add the seams and hints the DXF cannot carry.
#include <fmt/format.h>

#include <algorithm>
#include <map>

#include "pattern/garment_formats.hpp"
#include "pattern/json_fields.hpp"

namespace drape::pattern {
namespace {

template <class E, size_t N>
E parse_enum(const Json& v, const std::array<std::pair<const char*, E>, N>& names, const Where& where) {
  const std::string s = as_string(v, where);
  std::string options;
  for (const auto& [name, value] : names) {
    if (s == name) return value;
    options += options.empty() ? name : std::string(", ") + name;
  }
  where.fail(fmt::format("unknown value \"{}\" (expected one of: {})", s, options));
}

constexpr std::array<std::pair<const char*, BodyRegion>, 5> kBodyParts{{{"torso", BodyRegion::torso},
    {"left_arm", BodyRegion::left_arm}, {"right_arm", BodyRegion::right_arm}, {"left_leg", BodyRegion::left_leg},
    {"right_leg", BodyRegion::right_leg}}};
constexpr std::array<std::pair<const char*, PanelSide>, 4> kSides{{{"front", PanelSide::front},
    {"back", PanelSide::back}, {"left", PanelSide::left}, {"right", PanelSide::right}}};
constexpr std::array<std::pair<const char*, Landmark>, 10> kLandmarks{{{"neck", Landmark::neck},
    {"shoulder", Landmark::shoulder}, {"bust", Landmark::bust}, {"waist", Landmark::waist}, {"hip", Landmark::hip},
    {"crotch", Landmark::crotch}, {"knee", Landmark::knee}, {"ankle", Landmark::ankle}, {"elbow", Landmark::elbow},
    {"wrist", Landmark::wrist}}};
constexpr std::array<std::pair<const char*, EdgeCurve>, 4> kCurves{{{"line", EdgeCurve::line},
    {"quadratic", EdgeCurve::quadratic}, {"cubic", EdgeCurve::cubic}, {"arc", EdgeCurve::arc}}};

// A grade rule: the displacement of a point in every size (metres), base size zero.
using GradeRule = std::vector<Vec2d>;

GradeRule parse_grade_rule(const Json& v, const GarmentSpec& spec, const Where& where) {
  GradeRule rule(spec.sizes.size(), Vec2d::Zero());
  if (v.is_array()) {  // inline step per size
    const Vec2d step = as_vec2(v, where);
    for (size_t k = 0; k < rule.size(); ++k)
      rule[k] = (static_cast<double>(k) - static_cast<double>(spec.base_size)) * step;
    return rule;
  }
  if (!v.is_object()) where.fail("expected a grade rule: {\"step\": [dx, dy]} or {\"deltas\": {size: [dx, dy]}}");
  if (const Json* step = optional_field(v, "step")) return parse_grade_rule(*step, spec, where.at("step"));
  const Json& deltas = field(v, "deltas", where);
  if (!deltas.is_object()) where.at("deltas").fail("expected an object of size: [dx, dy]");
  for (const auto& [size, delta] : deltas.items()) {
    const auto it = std::find(spec.sizes.begin(), spec.sizes.end(), size);
    if (it == spec.sizes.end()) where.at("deltas").fail(fmt::format("unknown size \"{}\"", size));
    rule[static_cast<size_t>(it - spec.sizes.begin())] = as_vec2(delta, where.at("deltas").at(size));
  }
  return rule;
}

// Vertices of a panel in every size, from base positions and grade rules or per-size outlines.
std::vector<std::vector<Vec2d>> parse_vertices(const Json& v, const GarmentSpec& spec,
                                               const std::map<std::string, GradeRule>& rules, const Where& where) {
  const size_t sizes = spec.sizes.size();
  std::vector<std::vector<Vec2d>> out(sizes);
  if (v.is_object()) {  // per-size outlines
    for (size_t k = 0; k < sizes; ++k) {
      const Where ws = where.at(fmt::format("size \"{}\"", spec.sizes[k]));
      const Json& list = field(v, spec.sizes[k].c_str(), where);
      if (!list.is_array()) ws.fail("expected a list of [x, y]");
      for (size_t i = 0; i < list.size(); ++i) out[k].push_back(as_vec2(list[i], ws.at(fmt::format("vertex {}", i))));
      if (out[k].size() != out[0].size())
        ws.fail(fmt::format("has {} vertices, size \"{}\" has {}", out[k].size(), spec.sizes[0], out[0].size()));
    }
    for (const auto& [size, unused] : v.items())
      if (std::find(spec.sizes.begin(), spec.sizes.end(), size) == spec.sizes.end())
        where.fail(fmt::format("unknown size \"{}\"", size));
    return out;
  }
  if (!v.is_array()) where.fail("expected a list of vertices or an object of per-size lists");
  for (size_t i = 0; i < v.size(); ++i) {
    const Where wv = where.at(fmt::format("{}", i));
    const Json& item = v[i];
    Vec2d base;
    GradeRule rule(sizes, Vec2d::Zero());
    if (item.is_array()) {
      base = as_vec2(item, wv);
    } else if (item.is_object()) {
      base = as_vec2(field(item, "at", wv), wv.at("at"));
      if (const Json* g = optional_field(item, "grade")) {
        if (g->is_string()) {
          const auto it = rules.find(g->get<std::string>());
          if (it == rules.end()) wv.fail(fmt::format("unknown grade rule \"{}\"", g->get<std::string>()));
          rule = it->second;
        } else {
          rule = parse_grade_rule(*g, spec, wv.at("grade"));
        }
      }
      bool mirror_x = false, mirror_y = false;
      if (const Json* m = optional_field(item, "mirror_x")) mirror_x = as_bool(*m, wv.at("mirror_x"));
      if (const Json* m = optional_field(item, "mirror_y")) mirror_y = as_bool(*m, wv.at("mirror_y"));
      for (Vec2d& d : rule) {
        if (mirror_x) d.x() = -d.x();
        if (mirror_y) d.y() = -d.y();
      }
    } else {
      wv.fail("expected [x, y] or {\"at\": [x, y], \"grade\": ...}");
    }
    for (size_t k = 0; k < sizes; ++k) out[k].push_back(base + rule[k]);
  }
  return out;
}

EdgeSpec parse_edge(const Json& v, const Where& where) {
  EdgeSpec e;
  if (!v.is_object()) where.fail("expected an object");
  if (const Json* n = optional_field(v, "name")) e.name = as_string(*n, where.at("name"));
  if (const Json* c = optional_field(v, "curve")) e.curve = parse_enum(*c, kCurves, where.at("curve"));
  const size_t controls = e.curve == EdgeCurve::quadratic ? 1 : e.curve == EdgeCurve::cubic ? 2 : 0;
  if (controls > 0) {
    const Json& list = field(v, "control", where);
    if (!list.is_array() || list.size() != controls)
      where.at("control").fail(fmt::format("a {} curve needs {} control point(s) [t, s]", to_string(e.curve), controls));
    for (size_t k = 0; k < controls; ++k) e.control[k] = as_vec2(list[k], where.at("control"));
  }
  if (e.curve == EdgeCurve::arc) {
    e.radius = as_number(field(v, "radius", where), where.at("radius"));
    if (e.radius <= 0) where.at("radius").fail("must be positive");
    if (const Json* l = optional_field(v, "large_arc")) e.large_arc = as_bool(*l, where.at("large_arc"));
    if (const Json* d = optional_field(v, "direction")) {
      const std::string dir = as_string(*d, where.at("direction"));
      if (dir != "ccw" && dir != "cw") where.at("direction").fail("expected \"ccw\" or \"cw\"");
      e.counter_clockwise = dir == "ccw";
    }
  }
  return e;
}

PlacementHint parse_placement(const Json& v, const Where& where) {
  PlacementHint h;
  if (!v.is_object()) where.fail("expected an object");
  h.body_part = parse_enum(field(v, "body_part", where), kBodyParts, where.at("body_part"));
  h.side = parse_enum(field(v, "side", where), kSides, where.at("side"));
  if (const Json* l = optional_field(v, "landmark")) h.landmark = parse_enum(*l, kLandmarks, where.at("landmark"));
  if (const Json* a = optional_field(v, "anchor")) h.anchor = as_vec2(*a, where.at("anchor"));
  if (const Json* c = optional_field(v, "clearance")) {
    h.clearance = as_number(*c, where.at("clearance"));
    if (h.clearance < 0 || h.clearance > 0.5) where.at("clearance").fail("must be between 0 and 0.5 m");
  }
  return h;
}

Vec2d parse_grain(const Json& v, const Where& where) {
  const Vec2d g = as_vec2(v, where);
  if (g.norm() < 1e-12) where.fail("grain direction is zero");
  return g.normalized();
}

// Index of an edge given by name or number.
uint32_t edge_index(const Json& v, const PanelSpec& panel, const Where& where) {
  if (v.is_number_integer()) {
    const long long i = v.get<long long>();
    if (i < 0 || static_cast<size_t>(i) >= panel.edges.size())
      where.fail(fmt::format("edge {} does not exist (panel '{}' has edges 0..{})", i, panel.name, panel.edges.size() - 1));
    return static_cast<uint32_t>(i);
  }
  const std::string name = as_string(v, where);
  for (size_t i = 0; i < panel.edges.size(); ++i)
    if (panel.edges[i].name == name) return static_cast<uint32_t>(i);
  where.fail(fmt::format("edge \"{}\" does not exist in panel '{}'", name, panel.name));
}

SeamSide parse_seam_side(const Json& v, const GarmentSpec& spec, const Where& where) {
  if (!v.is_object()) where.fail("expected {\"panel\": name, \"edge\": name or index}");
  const std::string panel = as_string(field(v, "panel", where), where.at("panel"));
  const auto it = std::find_if(spec.panels.begin(), spec.panels.end(), [&](const PanelSpec& p) { return p.name == panel; });
  if (it == spec.panels.end()) where.at("panel").fail(fmt::format("panel '{}' does not exist", panel));
  SeamSide side;
  side.panel = static_cast<uint32_t>(it - spec.panels.begin());
  const size_t n = it->edges.size();
  if (const Json* range = optional_field(v, "edges")) {
    // A range of consecutive edges, first to last in the outline's direction.
    if (!range->is_array() || range->size() != 2) where.at("edges").fail("expected [first, last]");
    side.first_edge = edge_index((*range)[0], *it, where.at("edges"));
    const uint32_t last = edge_index((*range)[1], *it, where.at("edges"));
    side.edge_count = static_cast<uint32_t>((last + n - side.first_edge) % n) + 1;
  } else {
    side.first_edge = edge_index(field(v, "edge", where), *it, where.at("edge"));
  }
  return side;
}

}  // namespace

GarmentSpec parse_drape_garment(const Json& root, const std::string& source, const std::filesystem::path& base_dir) {
  const Where top{source, ""};
  GarmentSpec spec;
  spec.source = source;
  spec.format = "drape";
  const Json& version = field(root, "drape_garment", top);
  if (!version.is_number_integer() || version.get<long long>() != 1)
    top.at("drape_garment").fail("unsupported version (this drape reads version 1)");
  spec.name = as_string(field(root, "name", top), top.at("name"));
  if (const Json* d = optional_field(root, "description")) spec.description = as_string(*d, top.at("description"));
  if (const Json* f = optional_field(root, "fabric")) spec.fabric = as_string(*f, top.at("fabric"));
  if (const Json* l = optional_field(root, "layer")) {
    if (!l->is_number_integer() || l->get<long long>() < 0 || l->get<long long>() > 16)
      top.at("layer").fail("expected an integer 0..16 (0 innermost)");
    spec.layer = static_cast<int>(l->get<long long>());
  }

  // Panels from a DXF file: the companion names pieces, seams and hints.
  if (const Json* dxf = optional_field(root, "dxf")) {
    const std::string rel = as_string(*dxf, top.at("dxf"));
    // The pieces lie beside the garment file: an uploaded file must not name any other file.
    const std::filesystem::path rel_path(rel);
    if (rel.empty() || rel_path.is_absolute() || rel_path.has_root_name() ||
        std::any_of(rel_path.begin(), rel_path.end(), [](const std::filesystem::path& part) { return part == ".."; }))
      top.at("dxf").fail("expected a file name relative to the garment file's folder, without '..'");
    DxfOptions options;
    if (const Json* u = optional_field(root, "units")) {
      options.units = as_string(*u, top.at("units"));
      if (metres_per_unit(options.units) <= 0) top.at("units").fail("expected mm, cm, m or in");
    }
    if (const Json* s = optional_field(root, "size")) options.size = as_string(*s, top.at("size"));
    const std::filesystem::path dxf_path = base_dir / rel;
    GarmentSpec pieces = parse_dxf(read_text_file(dxf_path), dxf_path.string(), options);
    spec.sizes = pieces.sizes;
    spec.base_size = 0;
    if (const Json* panels = optional_field(root, "panels")) {
      if (!panels->is_array()) top.at("panels").fail("expected a list");
      for (size_t i = 0; i < panels->size(); ++i) {
        const Json& p = (*panels)[i];
        const Where wp = top.at(fmt::format("panels[{}]", i));
        const std::string piece = as_string(field(p, "piece", wp), wp.at("piece"));
        const auto it = std::find_if(pieces.panels.begin(), pieces.panels.end(), [&](const PanelSpec& s) { return s.name == piece; });
        if (it == pieces.panels.end()) wp.at("piece").fail(fmt::format("no piece named '{}' in {}", piece, rel));
        PanelSpec panel = *it;
        if (const Json* n = optional_field(p, "name")) panel.name = as_string(*n, wp.at("name"));
        if (const Json* g = optional_field(p, "grain")) panel.grain = parse_grain(*g, wp.at("grain"));
        if (const Json* f = optional_field(p, "fabric")) panel.fabric = as_string(*f, wp.at("fabric"));
        if (const Json* h = optional_field(p, "placement")) panel.placement = parse_placement(*h, wp.at("placement"));
        spec.panels.push_back(std::move(panel));
      }
    } else {
      spec.panels = std::move(pieces.panels);
    }
  } else {
    // Sizes and the grade-rule table.
    if (const Json* sizes = optional_field(root, "sizes")) {
      if (!sizes->is_array() || sizes->empty()) top.at("sizes").fail("expected a non-empty list of size names");
      for (size_t i = 0; i < sizes->size(); ++i) {
        spec.sizes.push_back(as_string((*sizes)[i], top.at(fmt::format("sizes[{}]", i))));
        if (std::count(spec.sizes.begin(), spec.sizes.end(), spec.sizes.back()) > 1)
          top.at("sizes").fail(fmt::format("size \"{}\" is listed twice", spec.sizes.back()));
      }
    } else {
      spec.sizes = {"one size"};
    }
    spec.base_size = spec.sizes.size() / 2;
    if (const Json* b = optional_field(root, "base_size")) {
      const std::string base = as_string(*b, top.at("base_size"));
      const auto it = std::find(spec.sizes.begin(), spec.sizes.end(), base);
      if (it == spec.sizes.end()) top.at("base_size").fail(fmt::format("\"{}\" is not one of the sizes", base));
      spec.base_size = static_cast<size_t>(it - spec.sizes.begin());
    }
    std::map<std::string, GradeRule> rules;
    if (const Json* table = optional_field(root, "grade_rules")) {
      if (!table->is_object()) top.at("grade_rules").fail("expected an object of named rules");
      for (const auto& [name, rule] : table->items())
        rules[name] = parse_grade_rule(rule, spec, top.at(fmt::format("grade rule \"{}\"", name)));
    }

    const Json& panels = field(root, "panels", top);
    if (!panels.is_array() || panels.empty()) top.at("panels").fail("expected a non-empty list of panels");
    for (size_t i = 0; i < panels.size(); ++i) {
      const Json& p = panels[i];
      PanelSpec panel;
      panel.name = as_string(field(p, "name", top.at(fmt::format("panels[{}]", i))), top.at(fmt::format("panels[{}] name", i)));
      const Where wp = top.at(fmt::format("panel '{}'", panel.name));
      for (const PanelSpec& other : spec.panels)
        if (other.name == panel.name) wp.fail("panel name used twice");
      panel.vertices = parse_vertices(field(p, "vertices", wp), spec, rules, wp.at("vertex"));
      const size_t n = panel.vertices[0].size();
      if (n < 2) wp.fail("an outline needs at least 2 vertices");
      if (const Json* edges = optional_field(p, "edges")) {
        if (!edges->is_array() || edges->size() != n)
          wp.at("edges").fail(fmt::format("expected {} edges (edge i joins vertex i to vertex i+1), got {}", n,
                                          edges->is_array() ? edges->size() : 0));
        for (size_t e = 0; e < n; ++e) panel.edges.push_back(parse_edge((*edges)[e], wp.at(fmt::format("edge {}", e))));
      } else {
        panel.edges.resize(n);
      }
      for (size_t e = 0; e < n; ++e)
        for (size_t f = 0; f < e; ++f)
          if (!panel.edges[e].name.empty() && panel.edges[e].name == panel.edges[f].name)
            wp.at(fmt::format("edge {}", e)).fail(fmt::format("edge name \"{}\" used twice", panel.edges[e].name));
      if (const Json* g = optional_field(p, "grain")) panel.grain = parse_grain(*g, wp.at("grain"));
      if (const Json* f = optional_field(p, "fabric")) panel.fabric = as_string(*f, wp.at("fabric"));
      if (const Json* h = optional_field(p, "placement")) panel.placement = parse_placement(*h, wp.at("placement"));
      spec.panels.push_back(std::move(panel));
    }
  }

  // The size chart: the body measurements each size is drafted for.
  if (const Json* chart = optional_field(root, "size_chart")) {
    if (!chart->is_object()) top.at("size_chart").fail("expected an object of size: {measurement: metres}");
    spec.size_chart.assign(spec.sizes.size(), {});
    for (const auto& [size, entry] : chart->items()) {
      const Where ws = top.at("size_chart").at(fmt::format("size \"{}\"", size));
      const auto it = std::find(spec.sizes.begin(), spec.sizes.end(), size);
      if (it == spec.sizes.end()) ws.fail("is not one of the sizes");
      if (!entry.is_object() || entry.empty()) ws.fail("expected an object of measurement: metres");
      SizeMeasurements& m = spec.size_chart[static_cast<size_t>(it - spec.sizes.begin())];
      for (const auto& [key, value] : entry.items()) {
        const auto& keys = size_chart_keys();
        if (std::find(keys.begin(), keys.end(), key) == keys.end()) {
          std::string list;
          for (std::string_view k : keys) list += (list.empty() ? "" : ", ") + std::string(k);
          ws.at(key).fail(fmt::format("unknown measurement (expected one of: {})", list));
        }
        const double metres = as_number(value, ws.at(key));
        if (!(metres > 0.05 && metres < 3.0)) ws.at(key).fail("expected metres, between 0.05 and 3");
        m[key] = metres;
      }
    }
  }

  // The wearing ease the pattern is drafted with.
  if (const Json* ease = optional_field(root, "intended_ease")) {
    const Where we = top.at("intended_ease");
    if (!ease->is_object()) we.fail("expected an object of measurement: metres (bust, waist, hips)");
    for (const auto& [key, value] : ease->items()) {
      if (key != "bust" && key != "waist" && key != "hips") we.at(key).fail("unknown girth (expected one of: bust, waist, hips)");
      const double metres = as_number(value, we.at(key));
      if (!(metres >= -0.2 && metres <= 0.5)) we.at(key).fail("expected metres, between -0.2 and 0.5");
      spec.intended_ease[key] = metres;
    }
  }

  // Seams.
  if (const Json* seams = optional_field(root, "seams")) {
    if (!seams->is_array()) top.at("seams").fail("expected a list");
    for (size_t i = 0; i < seams->size(); ++i) {
      const Json& s = (*seams)[i];
      SeamSpec seam;
      seam.name = fmt::format("seam {}", i);
      if (const Json* n = optional_field(s, "name")) seam.name = as_string(*n, top.at(seam.name).at("name"));
      const Where ws = top.at(fmt::format("seam '{}'", seam.name));
      seam.a = parse_seam_side(field(s, "a", ws), spec, ws.at("a"));
      seam.b = parse_seam_side(field(s, "b", ws), spec, ws.at("b"));
      if (const Json* d = optional_field(s, "direction")) {
        const std::string dir = as_string(*d, ws.at("direction"));
        if (dir != "reversed" && dir != "same") ws.at("direction").fail("expected \"reversed\" or \"same\"");
        seam.same_direction = dir == "same";
      }
      if (const Json* e = optional_field(s, "ease")) {
        seam.ease = as_number(*e, ws.at("ease"));
        if (seam.ease < 0 || seam.ease > kMaxSeamEase)
          ws.at("ease").fail(fmt::format("must be between 0 and {} (a fraction of the shorter side)", kMaxSeamEase));
      }
      spec.seams.push_back(seam);
    }
  }

  // Elastic bands (a waistband): edges as seam sides, ease against the body's girth, width.
  if (const Json* bands = optional_field(root, "bands")) {
    if (!bands->is_array()) top.at("bands").fail("expected a list");
    for (size_t i = 0; i < bands->size(); ++i) {
      const Json& b = (*bands)[i];
      const Where wb = top.at(fmt::format("bands[{}]", i));
      const Json& edges = field(b, "edges", wb);
      if (!edges.is_array() || edges.empty()) wb.at("edges").fail("expected a list of {\"panel\", \"edge\"}");
      ElasticBand band;
      for (size_t k = 0; k < edges.size(); ++k)
        band.edges.push_back(parse_seam_side(edges[k], spec, wb.at(fmt::format("edges[{}]", k))));
      if (const Json* e = optional_field(b, "ease")) {
        band.ease = as_number(*e, wb.at("ease"));
        if (band.ease < -0.3 || band.ease > 0) wb.at("ease").fail("must be between -0.3 and 0 (a fraction of the body's girth)");
      }
      if (const Json* w = optional_field(b, "width")) {
        band.width = as_number(*w, wb.at("width"));
        if (band.width <= 0 || band.width > 0.2) wb.at("width").fail("must be between 0 and 0.2 m");
      }
      if (const Json* k = optional_field(b, "stiffness")) {
        band.stiffness = as_number(*k, wb.at("stiffness"));
        if (band.stiffness <= 0 || band.stiffness > 100) wb.at("stiffness").fail("must be between 0 and 100 (strips of the fabric)");
      }
      spec.bands.push_back(std::move(band));
    }
  }
  return spec;
}

}  // namespace drape::pattern
