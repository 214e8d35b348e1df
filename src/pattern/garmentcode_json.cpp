// GarmentCode pattern specifications and the Korosteleva 2021 templates (see
// ../shared/data/patterns/FORMAT_NOTES.md sections 1-2). Both store panels as vertex lists with an
// ordered, directed edge loop, relative Bezier controls (t, s) or SVG-style circle arcs, a rigid 3D
// placement R(x, y, 0) + T (XYZ Euler in degrees) and whole-edge stitches. Lengths are in
// 1/units_in_meter metres. Loops keep their winding: it encodes the fabric's right side.
#include <fmt/format.h>

#include <algorithm>
#include <limits>
#include <cmath>

#include "pattern/garment_formats.hpp"
#include "pattern/json_fields.hpp"

namespace drape::pattern {
namespace {

// (t, s) of an absolute control point relative to the edge a -> b.
Vec2d relative_control(const Vec2d& c, const Vec2d& a, const Vec2d& b) {
  const Vec2d d = b - a, perp(-d.y(), d.x());
  const double dd = d.squaredNorm();
  if (dd <= 0) return Vec2d::Zero();
  return {(c - a).dot(d) / dd, (c - a).dot(perp) / dd};
}

// Placement hints guessed from the panel's name, label and 3D position (+X is the body's left).
PlacementHint guess_placement(const PanelSpec& panel, const Vec3d& centre, bool pelvis_origin) {
  PlacementHint h;
  std::string name = panel.name;
  std::transform(name.begin(), name.end(), name.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  const bool sleeve = name.find("sleeve") != std::string::npos || panel.label == "arm";
  const bool pants = name.find("pant") != std::string::npos ||
                     ((name.rfind("l", 0) == 0 || name.rfind("r", 0) == 0) &&
                      (name.find("front") == 1 || name.find("back") == 1));
  h.side = centre.z() >= 0 ? PanelSide::front : PanelSide::back;
  if (sleeve) {
    h.body_part = centre.x() >= 0 ? BodyRegion::left_arm : BodyRegion::right_arm;
    h.landmark = Landmark::shoulder;
  } else if (pants) {
    h.body_part = centre.x() >= 0 ? BodyRegion::left_leg : BodyRegion::right_leg;
    h.landmark = Landmark::waist;
  } else {
    const double height = centre.y() + (pelvis_origin ? 1.0 : 0.0);
    h.landmark = height > 1.2 ? Landmark::shoulder : height > 0.95 ? Landmark::waist : Landmark::hip;
  }
  // Anchor: the top centre of the panel's bounding box in its base size.
  Eigen::AlignedBox2d box;
  for (const Vec2d& p : panel.vertices[0]) box.extend(p);
  h.anchor = {box.center().x(), box.max().y()};
  h.clearance = 0.03;
  return h;
}

}  // namespace

GarmentSpec parse_garmentcode(const Json& root, const std::string& source) {
  const Where top{source, ""};
  const Json& pattern = field(root, "pattern", top);
  const Json& panels = field(pattern, "panels", top.at("pattern"));
  if (!panels.is_object() || panels.empty()) top.at("pattern.panels").fail("expected a non-empty object of panels");

  // Units and curve conventions.
  double units_in_meter = 100;
  bool absolute_controls = false;
  if (const Json* props = optional_field(root, "properties")) {
    if (const Json* u = optional_field(*props, "units_in_meter")) {
      units_in_meter = as_number(*u, top.at("properties.units_in_meter"));
      if (units_in_meter <= 0) top.at("properties.units_in_meter").fail("must be positive");
    }
    if (const Json* c = optional_field(*props, "curvature_coords"))
      absolute_controls = as_string(*c, top.at("properties.curvature_coords")) == "absolute";
  }
  const double scale = 1.0 / units_in_meter;

  // The 2021 templates use bare [t, s] curvature lists and carry template parameters.
  bool is_2021 = false;
  if (const Json* params = optional_field(root, "parameters")) is_2021 = params->is_object() && !params->empty();
  for (const auto& [name, p] : panels.items())
    if (const Json* edges = optional_field(p, "edges"))
      for (const Json& e : *edges)
        if (const Json* c = optional_field(e, "curvature")) is_2021 = is_2021 || c->is_array();

  GarmentSpec spec;
  spec.source = source;
  spec.format = is_2021 ? "garmentcode-2021" : "garmentcode";
  spec.name = std::filesystem::path(source).stem().string();
  spec.sizes = {"as drafted"};
  // Neither format names a fabric. GarmentCode's simulator drapes every pattern in one very soft,
  // stretchy material (default_sim_props.yaml: garment_edge_ke 1.0, "Very soft fabric") and its
  // patterns have little ease, so its specifications get the knit preset; the 2021 templates cotton.
  spec.fabric = is_2021 ? "cotton" : "jersey";

  // Panel order: panel_order where given, else file order.
  std::vector<std::string> order;
  if (const Json* po = optional_field(pattern, "panel_order")) {
    for (const Json& n : *po)
      if (n.is_string() && panels.contains(n.get<std::string>())) order.push_back(n.get<std::string>());
  }
  for (const auto& [name, p] : panels.items())
    if (std::find(order.begin(), order.end(), name) == order.end()) order.push_back(name);

  // Per panel: the loop's edges relative to original edge indices (identical: edge k stays edge k).
  for (const std::string& name : order) {
    const Json& p = panels[name];
    const Where wp = top.at(fmt::format("panel '{}'", name));
    PanelSpec panel;
    panel.name = name;
    if (const Json* l = optional_field(p, "label")) panel.label = l->is_string() ? l->get<std::string>() : "";
    const Json& vertices = field(p, "vertices", wp);
    const Json& edges = field(p, "edges", wp);
    if (!vertices.is_array() || !edges.is_array() || edges.size() < 2) wp.fail("expected vertex and edge lists (2 or more edges)");
    std::vector<Vec2d> vs;
    for (size_t i = 0; i < vertices.size(); ++i) vs.push_back(scale * as_vec2(vertices[i], wp.at(fmt::format("vertex {}", i))));

    std::vector<Vec2d> loop;
    for (size_t k = 0; k < edges.size(); ++k) {
      const Where we = wp.at(fmt::format("edge {}", k));
      const Json& ends = field(edges[k], "endpoints", we);
      if (!ends.is_array() || ends.size() != 2 || !ends[0].is_number_integer() || !ends[1].is_number_integer())
        we.at("endpoints").fail("expected [start, end] vertex indices");
      const long long i0 = ends[0].get<long long>(), i1 = ends[1].get<long long>();
      if (i0 < 0 || i1 < 0 || static_cast<size_t>(i0) >= vs.size() || static_cast<size_t>(i1) >= vs.size())
        we.at("endpoints").fail(fmt::format("vertex index out of range (panel has {} vertices)", vs.size()));
      // The loop must be closed and ordered: this edge's end is the next edge's start.
      const Json& next = field(edges[(k + 1) % edges.size()], "endpoints", we);
      if (!next.is_array() || next.size() != 2 || !next[0].is_number_integer() || next[0].get<long long>() != i1)
        we.fail("edges do not form a closed loop (this edge's end is not the next edge's start)");
      const Vec2d a = vs[static_cast<size_t>(i0)], b = vs[static_cast<size_t>(i1)];
      loop.push_back(a);

      EdgeSpec e;
      if (const Json* l = optional_field(edges[k], "label")) e.name = l->is_string() ? l->get<std::string>() : "";
      if (const Json* c = optional_field(edges[k], "curvature")) {
        const auto control = [&](const Json& ts, const Where& w) {
          const Vec2d v = as_vec2(ts, w);
          return absolute_controls ? relative_control(scale * v, a, b) : v;
        };
        if (c->is_array()) {  // 2021: one quadratic control [t, s]
          e.curve = EdgeCurve::quadratic;
          e.control[0] = control(*c, we.at("curvature"));
        } else {
          const std::string type = as_string(field(*c, "type", we.at("curvature")), we.at("curvature.type"));
          const Json& params = field(*c, "params", we.at("curvature"));
          if (!params.is_array()) we.at("curvature.params").fail("expected a list");
          if (type == "quadratic" || type == "cubic") {
            const size_t n = type == "quadratic" ? 1 : 2;
            if (params.size() != n) we.at("curvature.params").fail(fmt::format("a {} curve needs {} control point(s)", type, n));
            e.curve = n == 1 ? EdgeCurve::quadratic : EdgeCurve::cubic;
            for (size_t q = 0; q < n; ++q) e.control[q] = control(params[q], we.at("curvature.params"));
          } else if (type == "circle") {
            if (params.size() != 3) we.at("curvature.params").fail("a circle needs [radius, large_arc, right]");
            e.curve = EdgeCurve::arc;
            e.radius = scale * as_number(params[0], we.at("curvature.params"));
            e.large_arc = as_bool(params[1], we.at("curvature.params"));
            // boxmeshgen passes sweep = right; in the y-up panel plane that is counter-clockwise.
            e.counter_clockwise = as_bool(params[2], we.at("curvature.params"));
            if (e.radius <= 0) we.at("curvature.params").fail("circle radius must be positive");
          } else {
            we.at("curvature.type").fail(fmt::format("unknown curve type \"{}\"", type));
          }
        }
      }
      panel.edges.push_back(e);
    }
    panel.vertices = {loop};

    PanelTransform t;
    if (const Json* tr = optional_field(p, "translation")) t.translation = scale * as_vec3(*tr, wp.at("translation"));
    if (const Json* ro = optional_field(p, "rotation")) t.rotation_deg = as_vec3(*ro, wp.at("rotation"));
    t.pelvis_origin = is_2021;
    panel.transform = t;
    // The panel's centre in 3D for the placement guess.
    Eigen::AlignedBox2d box;
    for (const Vec2d& v : loop) box.extend(v);
    const Eigen::Matrix3d rot = (Eigen::AngleAxisd(t.rotation_deg.z() * M_PI / 180, Vec3d::UnitZ()) *
                                 Eigen::AngleAxisd(t.rotation_deg.y() * M_PI / 180, Vec3d::UnitY()) *
                                 Eigen::AngleAxisd(t.rotation_deg.x() * M_PI / 180, Vec3d::UnitX())).toRotationMatrix();
    const Vec3d centre = rot * Vec3d(box.center().x(), box.center().y(), 0) + t.translation;
    panel.placement = guess_placement(panel, centre, is_2021);
    spec.panels.push_back(std::move(panel));
  }

  // Stitches: whole edge to whole edge. Default orientation joins edge1.end to edge2.start
  // ("reversed"); a third element "right_wrong" joins start to start.
  if (const Json* stitches = optional_field(pattern, "stitches")) {
    if (!stitches->is_array()) top.at("pattern.stitches").fail("expected a list");
    for (size_t i = 0; i < stitches->size(); ++i) {
      const Json& s = (*stitches)[i];
      const Where ws = top.at(fmt::format("stitch {}", i));
      if (!s.is_array() || s.size() < 2) ws.fail("expected [{panel, edge}, {panel, edge}]");
      SeamSpec seam;
      seam.name = fmt::format("stitch {}", i);
      SeamSide* sides[2] = {&seam.a, &seam.b};
      for (size_t k = 0; k < 2; ++k) {
        const Where wk = ws.at(k == 0 ? "first" : "second");
        const std::string panel = as_string(field(s[k], "panel", wk), wk.at("panel"));
        const auto it = std::find(order.begin(), order.end(), panel);
        if (it == order.end()) wk.fail(fmt::format("panel '{}' does not exist", panel));
        const Json& edge = field(s[k], "edge", wk);
        const size_t pi = static_cast<size_t>(it - order.begin());
        if (!edge.is_number_integer() || edge.get<long long>() < 0 ||
            static_cast<size_t>(edge.get<long long>()) >= spec.panels[pi].edges.size())
          wk.at("edge").fail(fmt::format("edge does not exist (panel '{}' has {} edges)", panel, spec.panels[pi].edges.size()));
        sides[k]->panel = static_cast<uint32_t>(pi);
        sides[k]->first_edge = static_cast<uint32_t>(edge.get<long long>());
        sides[k]->edge_count = 1;
      }
      if (s.size() > 2 && s[2].is_string() && s[2].get<std::string>() == "right_wrong") seam.same_direction = true;
      spec.seams.push_back(seam);
    }
  }

  // GarmentCode's simulator attaches the edges labelled `lower_interface` (a skirt's waistband,
  // a dress's waist seam) to the body; drape has nothing that holds vertices in place, so they
  // become an elastic band (ElasticBand: a little smaller than the body's girth where it sits,
  // held up by its tension and friction).
  ElasticBand band;
  for (size_t p = 0; p < spec.panels.size(); ++p)
    for (size_t k = 0; k < spec.panels[p].edges.size(); ++k)
      if (spec.panels[p].edges[k].name == "lower_interface")
        band.edges.push_back({static_cast<uint32_t>(p), static_cast<uint32_t>(k), 1});
  // The 2021 templates label no edges. A bottom (every panel below kBottomTop of the pelvis
  // origin: skirts, trousers) has its waist where its unsewn edges reach the garment's top: those
  // are its band.
  if (is_2021) {
    constexpr double kBottomTop = 0.15, kAtTop = 0.02;  // metres
    std::vector<std::vector<double>> height(spec.panels.size());  // per panel, per loop vertex
    double garment_top = -std::numeric_limits<double>::max();
    for (size_t p = 0; p < spec.panels.size(); ++p) {
      const PanelTransform& t = *spec.panels[p].transform;
      const Eigen::Matrix3d rot = (Eigen::AngleAxisd(t.rotation_deg.z() * M_PI / 180, Vec3d::UnitZ()) *
                                   Eigen::AngleAxisd(t.rotation_deg.y() * M_PI / 180, Vec3d::UnitY()) *
                                   Eigen::AngleAxisd(t.rotation_deg.x() * M_PI / 180, Vec3d::UnitX())).toRotationMatrix();
      for (const Vec2d& v : spec.panels[p].vertices[0]) {
        height[p].push_back((rot * Vec3d(v.x(), v.y(), 0) + t.translation).y());
        garment_top = std::max(garment_top, height[p].back());
      }
    }
    std::vector<std::vector<bool>> sewn(spec.panels.size());
    for (size_t p = 0; p < spec.panels.size(); ++p) sewn[p].assign(spec.panels[p].edges.size(), false);
    for (const SeamSpec& seam : spec.seams) {
      sewn[seam.a.panel][seam.a.first_edge] = true;
      sewn[seam.b.panel][seam.b.first_edge] = true;
    }
    if (garment_top < kBottomTop && band.edges.empty())
      for (size_t p = 0; p < spec.panels.size(); ++p) {
        const size_t n = height[p].size();
        for (size_t k = 0; k < n; ++k)
          if (!sewn[p][k] && height[p][k] > garment_top - kAtTop && height[p][(k + 1) % n] > garment_top - kAtTop)
            band.edges.push_back({static_cast<uint32_t>(p), static_cast<uint32_t>(k), 1});
      }
  }
  if (!band.edges.empty()) spec.bands.push_back(std::move(band));
  return spec;
}

}  // namespace drape::pattern
