// One size of a garment: concrete curves from the graded vertices, and the validation a garment
// must pass before it is meshed (outlines simple, seams existing, unique and of matching length,
// panels sewn into one piece, fabrics known).
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <numeric>

#include "pattern/garment_formats.hpp"

namespace drape {
namespace pattern {
namespace {

Curve build_edge(const EdgeSpec& e, const Vec2d& a, const Vec2d& b, double base_chord, const std::string& where,
                 const std::string& source) {
  Curve c;
  c.kind = e.curve;
  c.start = a;
  c.end = b;
  const Vec2d d = b - a, perp(-d.y(), d.x());
  switch (e.curve) {
    case EdgeCurve::line:
      break;
    case EdgeCurve::quadratic:
    case EdgeCurve::cubic:
      for (size_t k = 0; k < 2; ++k) c.control[k] = a + e.control[k].x() * d + e.control[k].y() * perp;
      break;
    case EdgeCurve::arc: {
      const double chord = d.norm();
      if (chord <= 0) throw InputError(source, where + ": an arc needs distinct end points");
      // Grading scales the radius with the chord, keeping the arc's shape.
      c.radius = base_chord > 0 ? e.radius * chord / base_chord : e.radius;
      const double half = 0.5 * chord;
      if (c.radius < half * (1 - 1e-9))
        throw InputError(source, fmt::format("{}: arc radius {:.4g} m is shorter than half its chord ({:.4g} m)", where,
                                             c.radius, half));
      const double offset = std::sqrt(std::max(0.0, c.radius * c.radius - half * half));
      const Vec2d left = perp / chord;
      // Counter-clockwise about the centre means the centre is on the left of a short arc.
      const double sign = e.counter_clockwise != e.large_arc ? 1.0 : -1.0;
      c.centre = 0.5 * (a + b) + sign * offset * left;
      c.start_angle = std::atan2(a.y() - c.centre.y(), a.x() - c.centre.x());
      double sweep = std::atan2(b.y() - c.centre.y(), b.x() - c.centre.x()) - c.start_angle;
      constexpr double kTwoPi = 2 * std::numbers::pi;
      if (e.counter_clockwise) {
        while (sweep <= 0) sweep += kTwoPi;
        while (sweep > kTwoPi) sweep -= kTwoPi;
      } else {
        while (sweep >= 0) sweep -= kTwoPi;
        while (sweep < -kTwoPi) sweep += kTwoPi;
      }
      c.sweep = sweep;
      break;
    }
    case EdgeCurve::polyline:
      c.points.reserve(e.points.size() + 2);
      c.points.push_back(a);
      c.points.insert(c.points.end(), e.points.begin(), e.points.end());
      c.points.push_back(b);
      break;
  }
  return c;
}

// Closed polygon of the outline with the edge each segment belongs to.
struct TaggedPolygon {
  std::vector<Vec2d> points;
  std::vector<uint32_t> edge;  // segment i (points[i] -> points[i+1]) lies on this edge
};

TaggedPolygon tagged_polygon(const Panel& panel, double spacing) {
  TaggedPolygon out;
  for (size_t k = 0; k < panel.edges.size(); ++k) {
    const Curve& c = panel.edges[k];
    std::vector<Vec2d> pts;
    if (c.kind == EdgeCurve::line) pts = {c.start, c.end};
    else if (c.kind == EdgeCurve::polyline) pts = c.points;
    else pts = c.sample_by_length(static_cast<size_t>(std::max(4.0, std::ceil(c.length() / spacing))));
    for (size_t i = 0; i + 1 < pts.size(); ++i) {
      out.points.push_back(pts[i]);
      out.edge.push_back(static_cast<uint32_t>(k));
    }
  }
  return out;
}

double cross(const Vec2d& a, const Vec2d& b) { return a.x() * b.y() - a.y() * b.x(); }

// Proper or touching intersection of segments p0p1 and q0q1.
bool segments_intersect(const Vec2d& p0, const Vec2d& p1, const Vec2d& q0, const Vec2d& q1) {
  const double d1 = cross(p1 - p0, q0 - p0), d2 = cross(p1 - p0, q1 - p0);
  const double d3 = cross(q1 - q0, p0 - q0), d4 = cross(q1 - q0, p1 - q0);
  if (((d1 > 0 && d2 < 0) || (d1 < 0 && d2 > 0)) && ((d3 > 0 && d4 < 0) || (d3 < 0 && d4 > 0))) return true;
  const auto on_segment = [](const Vec2d& a, const Vec2d& b, const Vec2d& p) {
    return std::abs(cross(b - a, p - a)) <= 1e-14 && (p - a).dot(p - b) <= 0;
  };
  return on_segment(p0, p1, q0) || on_segment(p0, p1, q1) || on_segment(q0, q1, p0) || on_segment(q0, q1, p1);
}

// A garment panel measures at most this across; larger is a units mistake, and would be sampled
// and meshed into billions of points.
constexpr double kMaxPanelExtent = 10.0;  // metres

// The outline's extent from the points that bound it (Bezier curves lie in their control hull).
double outline_extent(const Panel& panel) {
  Eigen::AlignedBox2d box;
  for (const Curve& c : panel.edges) {
    box.extend(c.start);
    box.extend(c.end);
    if (c.kind == EdgeCurve::quadratic || c.kind == EdgeCurve::cubic)
      for (const Vec2d& p : c.control) box.extend(p);
    for (const Vec2d& p : c.points) box.extend(p);
    if (c.kind == EdgeCurve::arc) {
      box.extend(c.centre - Vec2d::Constant(c.radius));
      box.extend(c.centre + Vec2d::Constant(c.radius));
    }
  }
  return box.isEmpty() ? 0.0 : box.sizes().maxCoeff();
}

void check_outline(const Panel& panel, const std::string& source) {
  const std::string where = fmt::format("panel '{}'", panel.name);
  if (const double extent = outline_extent(panel); !(extent <= kMaxPanelExtent))
    throw InputError(source, fmt::format("{}: measures {:.3g} m across; a garment panel measures at most {} m "
                                         "(are the units right?)", where, extent, kMaxPanelExtent));
  for (size_t k = 0; k < panel.edges.size(); ++k)
    if (panel.edges[k].length() < 1e-6)
      throw InputError(source, fmt::format("{} edge {}: has zero length", where, k));

  // Self-intersection: every pair of non-adjacent segments of the flattened outline (bucketed by x).
  const TaggedPolygon poly = tagged_polygon(panel, std::min(0.005, panel.perimeter() / 200));
  const size_t n = poly.points.size();
  std::vector<size_t> order(n);
  std::iota(order.begin(), order.end(), 0);
  const auto lo = [&](size_t i) { return std::min(poly.points[i].x(), poly.points[(i + 1) % n].x()); };
  const auto hi = [&](size_t i) { return std::max(poly.points[i].x(), poly.points[(i + 1) % n].x()); };
  std::sort(order.begin(), order.end(), [&](size_t a, size_t b) { return lo(a) < lo(b); });
  for (size_t ia = 0; ia < n; ++ia) {
    const size_t i = order[ia];
    for (size_t ib = ia + 1; ib < n && lo(order[ib]) <= hi(i); ++ib) {
      const size_t j = order[ib];
      if ((i + 1) % n == j || (j + 1) % n == i || i == j) continue;  // neighbours share an end point
      if (segments_intersect(poly.points[i], poly.points[(i + 1) % n], poly.points[j], poly.points[(j + 1) % n])) {
        // Where the two segments cross (their supporting lines; the point of contact when parallel).
        const Vec2d p0 = poly.points[i], r = poly.points[(i + 1) % n] - p0;
        const Vec2d q0 = poly.points[j], q = poly.points[(j + 1) % n] - q0;
        const double denom = cross(r, q);
        const Vec2d at = std::abs(denom) > 1e-18 ? Vec2d(p0 + cross(q0 - p0, q) / denom * r) : q0;
        throw InputError(source, fmt::format("{}: outline intersects itself (edge {} crosses edge {} near ({:.3f}, {:.3f}) m)",
                                             where, poly.edge[std::min(i, j)], poly.edge[std::max(i, j)], at.x(), at.y()));
      }
    }
  }
  const double area = panel.signed_area();
  if (std::abs(area) < 1e-6) throw InputError(source, fmt::format("{}: outline encloses no area", where));
}

}  // namespace

Panel build_panel(const PanelSpec& spec, size_t size, const std::string& source) {
  Panel p;
  p.name = spec.name;
  p.grain = spec.grain;
  p.fabric = spec.fabric;
  p.placement = spec.placement;
  p.transform = spec.transform;
  p.label = spec.label;
  const auto& vs = spec.vertices.at(size);
  const auto& base = spec.vertices.front();
  const size_t n = vs.size();
  for (size_t k = 0; k < n; ++k) {
    const double base_chord = (base[(k + 1) % n] - base[k]).norm();
    p.edges.push_back(build_edge(spec.edges[k], vs[k], vs[(k + 1) % n], base_chord,
                                 fmt::format("panel '{}' edge {}", spec.name, k), source));
    p.edge_names.push_back(spec.edges[k].name);
  }
  return p;
}

}  // namespace pattern

const std::vector<std::string>& known_fabrics() {
  static const std::vector<std::string> kFabrics = {"cotton", "denim", "silk", "jersey", "wool"};
  return kFabrics;
}

// The body layer's measurement keys (drape/body.hpp, measurement_table) that a size chart may name;
// a dressing test checks that each is one of them.
const std::vector<std::string_view>& size_chart_keys() {
  static const std::vector<std::string_view> kKeys = {"height", "neck", "bust", "underbust", "waist", "hips",
                                                      "thigh", "upper_arm", "inseam", "shoulder_width"};
  return kKeys;
}

Garment garment_in_size(const GarmentSpec& spec, std::string_view size) {
  const std::string& source = spec.source;
  size_t index = spec.base_size;
  if (!size.empty()) {
    const auto it = std::find(spec.sizes.begin(), spec.sizes.end(), size);
    if (it == spec.sizes.end()) {
      std::string list;
      for (const auto& s : spec.sizes) list += (list.empty() ? "" : ", ") + s;
      throw InputError(source, fmt::format("garment '{}' has no size \"{}\" (sizes: {})", spec.name, size, list));
    }
    index = static_cast<size_t>(it - spec.sizes.begin());
  }
  const auto check_fabric = [&](const std::string& fabric, const std::string& where) {
    const auto& known = known_fabrics();
    if (std::find(known.begin(), known.end(), fabric) == known.end())
      throw InputError(source, fmt::format("{}unknown fabric \"{}\" (known: cotton, denim, silk, jersey, wool)", where, fabric));
  };
  check_fabric(spec.fabric, "");

  Garment g;
  g.name = spec.name;
  g.source = spec.source;
  g.size = spec.sizes.at(index);
  g.fabric = spec.fabric;
  g.layer = spec.layer;
  g.seams = spec.seams;
  g.bands = spec.bands;
  if (spec.panels.empty()) throw InputError(source, "garment has no panels");
  const std::string size_note = spec.sizes.size() > 1 ? fmt::format(" (size {})", g.size) : std::string();
  for (const PanelSpec& ps : spec.panels) {
    if (!ps.fabric.empty()) check_fabric(ps.fabric, fmt::format("panel '{}': ", ps.name));
    Panel p = pattern::build_panel(ps, index, source);
    if (p.fabric.empty()) p.fabric = spec.fabric;
    try {
      pattern::check_outline(p, source);
    } catch (const InputError& e) {
      throw InputError(source, std::string(e.what()).substr(source.size() + 2) + size_note);
    }
    g.panels.push_back(std::move(p));
  }

  // Seams: edges exist, each edge sewn at most once, lengths match within tolerance plus ease.
  std::vector<std::vector<int>> edge_seam(g.panels.size());
  for (size_t i = 0; i < g.panels.size(); ++i) edge_seam[i].assign(g.panels[i].edges.size(), -1);
  for (size_t s = 0; s < g.seams.size(); ++s) {
    const SeamSpec& seam = g.seams[s];
    for (const SeamSide* side : {&seam.a, &seam.b}) {
      const std::string where = fmt::format("seam '{}' side {}", seam.name, side == &seam.a ? "a" : "b");
      if (side->panel >= g.panels.size()) throw InputError(source, where + ": panel does not exist");
      const size_t n = g.panels[side->panel].edges.size();
      if (side->first_edge >= n || side->edge_count == 0 || side->edge_count > n)
        throw InputError(source, fmt::format("{}: edges {}..+{} do not exist in panel '{}'", where, side->first_edge,
                                             side->edge_count, g.panels[side->panel].name));
      for (uint32_t k = 0; k < side->edge_count; ++k) {
        const size_t e = (side->first_edge + k) % n;
        int& owner = edge_seam[side->panel][e];
        if (owner >= 0)
          throw InputError(source, fmt::format("{}: edge {} of panel '{}' is already sewn by seam '{}'", where, e,
                                               g.panels[side->panel].name, g.seams[static_cast<size_t>(owner)].name));
        owner = static_cast<int>(s);
      }
    }
    const double la = g.seam_side_length(seam.a), lb = g.seam_side_length(seam.b);
    const double shorter = std::min(la, lb);
    const double allowed = kSeamLengthTolerance + (kSeamLengthRelTolerance + seam.ease) * shorter;
    if (std::abs(la - lb) > allowed)
      throw InputError(source, fmt::format("seam '{}': sides differ in length by {:.1f} mm (panel '{}': {:.1f} mm, panel '{}': "
                                           "{:.1f} mm), more than the {:.1f} mm allowed{}; give \"ease\" for gathering",
                                           seam.name, 1000 * std::abs(la - lb), g.panels[seam.a.panel].name, 1000 * la,
                                           g.panels[seam.b.panel].name, 1000 * lb, 1000 * allowed, size_note));
  }

  // A garment of several panels is sewn into one piece: every panel seamed, all connected. Bare DXF
  // pieces are exempt: the format carries no seams by design (a companion file adds them).
  if (g.panels.size() > 1 && !(spec.format == "dxf" && g.seams.empty())) {
    std::vector<size_t> parent(g.panels.size());
    std::iota(parent.begin(), parent.end(), 0);
    const auto find = [&](size_t i) {
      while (parent[i] != i) i = parent[i] = parent[parent[i]];
      return i;
    };
    std::vector<bool> seamed(g.panels.size(), false);
    for (const SeamSpec& seam : g.seams) {
      seamed[seam.a.panel] = seamed[seam.b.panel] = true;
      parent[find(seam.a.panel)] = find(seam.b.panel);
    }
    for (size_t i = 0; i < g.panels.size(); ++i) {
      if (!seamed[i])
        throw InputError(source, fmt::format("panel '{}' has no seams; every panel of a garment must be sewn to another", g.panels[i].name));
      if (find(i) != find(0))
        throw InputError(source, fmt::format("panel '{}' is not sewn to panel '{}' through any chain of seams",
                                             g.panels[i].name, g.panels[0].name));
    }
  }
  return g;
}

}  // namespace drape
