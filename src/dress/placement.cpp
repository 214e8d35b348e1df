// Stage 3: panels rolled around the body at a clearance (paper sec. 6.2: "they are positioned
// around the body"), so the garment starts near its place without touching the body.
//
// Torso panels lie on a lofted surface: at every height an ellipse around the body's cross-section
// (arms excluded; legs included, so a skirt clears both legs), pushed out by the clearance and
// enlarged where the panels are wider than the ellipse, so that the panels of one region never
// overlap. A panel's x coordinate is arc length along the ellipse from the centre line of its side
// (front at +Z, left at +X, back, right), its y coordinate is height, with the panel's anchor at the
// landmark's height. Rolling is isometric along each horizontal line.
// Arm and leg panels lie on circular cylinders around the limb axis (elbow->wrist for arms, hip->
// ankle for legs), radius from the limb's own vertices per station along the axis.
// The panel's right side (counter-clockwise loop, +z) faces away from the body: on a surface with
// outward normal n and "up" axis u, the panel's x axis runs along u x n.
// Afterwards every vertex is checked against the body collider; a region whose panels touch the
// body is placed again with 1 cm more clearance (up to 4 cm more), and vertices still inside are
// pushed out along the collider normal.
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <string>
#include <numbers>

#include "body/analysis.hpp"
#include "dress/stages.hpp"
#include "drape/error.hpp"

namespace drape::dressing {
namespace {

constexpr float kPi = std::numbers::pi_v<float>;
constexpr float kStation = 0.005f;  // m between stations along a region's axis
constexpr float kPanelGap = 0.02f;  // m of free arc left on each side of every panel
constexpr float kShoulderLift = 0.04f;  // m

bool is_limb(BodyRegion r) { return r != BodyRegion::torso; }

// The point of a landmark that a panel of region `r` is anchored to (left/right by the region).
Vec3f landmark_point(const Landmarks& l, Landmark which, BodyRegion r) {
  const bool right = r == BodyRegion::right_arm || r == BodyRegion::right_leg;
  const auto lr = [&](const Vec3f& left, const Vec3f& rt) -> Vec3f {
    if (r == BodyRegion::torso) return 0.5f * (left + rt);
    return right ? rt : left;
  };
  switch (which) {
    case Landmark::neck: return l.neck_base;
    case Landmark::shoulder: return lr(l.left_shoulder, l.right_shoulder);
    case Landmark::bust: return lr(l.left_bust, l.right_bust);
    case Landmark::waist: return l.waist;
    case Landmark::hip: return l.hip;
    case Landmark::crotch: return l.crotch;
    case Landmark::knee: return lr(l.left_knee, l.right_knee);
    case Landmark::ankle: return lr(l.left_ankle, l.right_ankle);
    case Landmark::elbow: return lr(l.left_elbow, l.right_elbow);
    case Landmark::wrist: return lr(l.left_wrist, l.right_wrist);
  }
  return l.waist;
}

// A region's axis: stations at t = (p - origin).up, t increasing towards the region's top.
struct Axis {
  Vec3f origin = Vec3f::Zero();
  Vec3f up = Vec3f::UnitY();
  Vec3f front = Vec3f::UnitZ();  // perpendicular to up, towards the body's front
};

Axis region_axis(const Body& body, BodyRegion r) {
  const Landmarks& l = body.landmarks;
  Axis a;
  if (r == BodyRegion::torso) return a;
  Vec3f top, bottom;
  if (r == BodyRegion::left_arm || r == BodyRegion::right_arm) {
    const bool left = r == BodyRegion::left_arm;
    top = left ? l.left_elbow : l.right_elbow;
    bottom = left ? l.left_wrist : l.right_wrist;
    // The upper arm from the elbow towards the shoulder joint (a little inside the acromion).
    const Vec3f shoulder = left ? l.left_shoulder : l.right_shoulder;
    const Vec3f armpit = left ? l.left_armpit : l.right_armpit;
    const Vec3f joint = 0.5f * (shoulder + armpit);
    const Vec3f dir = ((joint - top).normalized() + (top - bottom).normalized()).normalized();
    a.up = dir;
    a.origin = top;
  } else {
    const bool left = r == BodyRegion::left_leg;
    const BodyPart part = left ? BodyPart::LeftLeg : BodyPart::RightLeg;
    // Hip joint: the centre of the leg's vertices in a band just below the crotch.
    Vec3f sum = Vec3f::Zero();
    int count = 0;
    for (size_t i = 0; i < body.mesh.positions.size(); ++i) {
      const Vec3f& p = body.mesh.positions[i];
      if (body.parts[i] == part && p.y() < l.crotch.y() && p.y() > l.crotch.y() - 0.05f) {
        sum += p;
        ++count;
      }
    }
    top = count ? Vec3f(sum / static_cast<float>(count)) : Vec3f((left ? l.left_knee : l.right_knee) + Vec3f(0, 0.4f, 0));
    bottom = left ? l.left_ankle : l.right_ankle;
    a.up = (top - bottom).normalized();
    a.origin = bottom;
  }
  a.front = (Vec3f::UnitZ() - Vec3f::UnitZ().dot(a.up) * a.up).normalized();
  return a;
}

bool in_region(BodyPart part, BodyRegion r) {
  switch (r) {
    case BodyRegion::torso: return part != BodyPart::LeftArm && part != BodyPart::RightArm;
    case BodyRegion::left_arm: return part == BodyPart::LeftArm;
    case BodyRegion::right_arm: return part == BodyPart::RightArm;
    case BodyRegion::left_leg: return part == BodyPart::LeftLeg;
    case BodyRegion::right_leg: return part == BodyPart::RightLeg;
  }
  return false;
}

// A cross-section per station: ellipse centre (in the plane across the axis), semi-axes along
// `side` (a: across, the body's left for the torso) and `front` (b), and its arc-length table.
struct Section {
  Vec3f centre = Vec3f::Zero();
  float a = 0.1f, b = 0.1f;
  float body_b = 0.0f;  // the body's half depth here (no clearance), away from the midline (neck)
  std::vector<float> arc;  // arc length at angle index k of kAngles (phi from front towards side)
  float perimeter() const { return arc.back(); }
};
constexpr int kAngles = 256;

void build_arc(Section& s) {
  s.arc.assign(kAngles + 1, 0.0f);
  Vec2f prev(0.0f, s.b);
  for (int k = 1; k <= kAngles; ++k) {
    const float phi = 2 * kPi * static_cast<float>(k) / kAngles;
    const Vec2f p(s.a * std::sin(phi), s.b * std::cos(phi));
    s.arc[static_cast<size_t>(k)] = s.arc[static_cast<size_t>(k) - 1] + (p - prev).norm();
    prev = p;
  }
}

// Angle phi where the arc from the front reaches `s` (wrapped into [0, perimeter)).
float angle_at(const Section& sec, float s) {
  const float p = sec.perimeter();
  s = std::fmod(s, p);
  if (s < 0) s += p;
  const auto it = std::upper_bound(sec.arc.begin(), sec.arc.end(), s);
  const size_t k = static_cast<size_t>(std::clamp<std::ptrdiff_t>(it - sec.arc.begin(), 1, kAngles));
  const float s0 = sec.arc[k - 1], s1 = sec.arc[k];
  const float f = s1 > s0 ? (s - s0) / (s1 - s0) : 0.0f;
  return 2 * kPi * (static_cast<float>(k - 1) + f) / kAngles;
}

float side_angle(PanelSide side) {
  switch (side) {
    case PanelSide::front: return 0.0f;
    case PanelSide::left: return 0.5f * kPi;
    case PanelSide::back: return kPi;
    case PanelSide::right: return 1.5f * kPi;
  }
  return 0.0f;
}

// Arc length from the front (phi = 0) to angle phi on a section.
float arc_at(const Section& c, float phi) {
  float f = phi / (2 * kPi) * kAngles;
  f = std::fmod(f, static_cast<float>(kAngles));
  if (f < 0) f += kAngles;
  const size_t k = std::min(static_cast<size_t>(f), static_cast<size_t>(kAngles) - 1);
  const float w = f - static_cast<float>(k);
  return (1 - w) * c.arc[k] + w * c.arc[k + 1];
}

// One lofted surface: a section at every station t_min + s * kStation along an axis.
struct Stack {
  Axis axis;
  Vec3f side_dir = Vec3f::UnitX();
  float t_min = 0;
  std::vector<Section> sec;

  int stations() const { return static_cast<int>(sec.size()); }
  float t_of(int s) const { return t_min + kStation * static_cast<float>(s); }
  float t_max() const { return t_of(stations() - 1); }
  int station_of(float t) const {
    return std::clamp(static_cast<int>(std::lround((t - t_min) / kStation)), 0, stations() - 1);
  }
  Vec3f on(const Section& c, float t, float phi_c, float s) const {
    const float phi = angle_at(c, arc_at(c, phi_c) + s);
    const Vec3f centre = c.centre + (t - (c.centre - axis.origin).dot(axis.up)) * axis.up;
    return centre + c.a * std::sin(phi) * side_dir + c.b * std::cos(phi) * axis.front;
  }
  // The point at height t, `s` metres of arc from the line at angle phi_c (sections interpolated).
  Vec3f point(float t, float phi_c, float s) const {
    if (stations() == 1) return on(sec[0], t, phi_c, s);
    const float f = std::clamp((t - t_min) / kStation, 0.0f, static_cast<float>(stations() - 1));
    const int i = std::min(static_cast<int>(f), stations() - 2);
    const float w = f - static_cast<float>(i);
    return (1 - w) * on(sec[static_cast<size_t>(i)], t, phi_c, s) + w * on(sec[static_cast<size_t>(i) + 1], t, phi_c, s);
  }
};

// The body's sections of the vertices `in` accepts (those below t_cut left out), a running maximum
// over 3 cm so bumps are cleared, plus the clearance, scaled up where `needed` (arc per station)
// is longer than the perimeter, then a running mean so the surface has gentle slopes.
template <class InSurface>
Stack build_stack(const Body& body, InSurface in, const Axis& axis, float t_min, int stations, float clearance,
                  const std::vector<float>& needed, bool circles, float t_cut) {
  Stack st;
  st.axis = axis;
  st.side_dir = axis.up.cross(axis.front);  // u x front: the body's left for the torso
  st.t_min = t_min;
  st.sec.resize(static_cast<size_t>(stations));
  const size_t n = static_cast<size_t>(stations);

  // Body extent per station, in the axis frame (across = side_dir, depth = front); `beside` leaves
  // out a band of 14 cm around the midline (the neck), for the roof over the shoulders.
  constexpr float kNeckHalfWidth = 0.07f;
  std::vector<Bounds> extent(n), beside(n);
  for (size_t i = 0; i < body.mesh.positions.size(); ++i) {
    if (!in(body.parts[i])) continue;
    const Vec3f d = body.mesh.positions[i] - axis.origin;
    const float t = d.dot(axis.up);
    if (t < t_cut || t < t_min - kStation || t > st.t_max() + kStation) continue;
    const Vec3f e(d.dot(st.side_dir), d.dot(axis.front), 0.0f);
    extent[static_cast<size_t>(st.station_of(t))].extend(e);
    if (std::abs(e.x()) > kNeckHalfWidth) beside[static_cast<size_t>(st.station_of(t))].extend(e);
  }
  // Stations without body (above a limb's end, below the body) copy their nearest neighbour.
  for (int pass = 0; pass < 2; ++pass)
    for (int s = 0; s < stations; ++s) {
      const int from = pass == 0 ? s - 1 : stations - s;
      const int to = pass == 0 ? s : stations - 1 - s;
      if (from >= 0 && from < stations && extent[static_cast<size_t>(to)].empty())
        extent[static_cast<size_t>(to)] = extent[static_cast<size_t>(from)];
    }

  constexpr int kSmooth = 6;
  std::vector<Section>& sec = st.sec;
  std::vector<float> scale(n, 1.0f);
  for (int s = 0; s < stations; ++s) {
    Bounds e;
    for (int j = std::max(0, s - kSmooth); j <= std::min(stations - 1, s + kSmooth); ++j)
      if (!extent[static_cast<size_t>(j)].empty()) {
        e.extend(extent[static_cast<size_t>(j)].min);
        e.extend(extent[static_cast<size_t>(j)].max);
      }
    Section& c = sec[static_cast<size_t>(s)];
    const Vec3f ctr = e.empty() ? Vec3f::Zero() : e.center();
    const Vec3f half = e.empty() ? Vec3f(0.1f, 0.1f, 0) : Vec3f(0.5f * e.size());
    c.centre = axis.origin + st.t_of(s) * axis.up + ctr.x() * st.side_dir + ctr.y() * axis.front;
    c.body_b = 0;
    for (int j = std::max(0, s - kSmooth); j <= std::min(stations - 1, s + kSmooth); ++j)
      if (!beside[static_cast<size_t>(j)].empty()) {
        const Bounds& b = beside[static_cast<size_t>(j)];
        c.body_b = std::max({c.body_b, b.max.y() - ctr.y(), ctr.y() - b.min.y()});
      }
    if (circles) {
      c.a = c.b = std::max(half.x(), half.y()) + clearance;
    } else {
      c.a = half.x() + clearance;
      c.b = half.y() + clearance;
    }
    build_arc(c);
    if (!needed.empty()) scale[static_cast<size_t>(s)] = std::max(1.0f, needed[static_cast<size_t>(s)] / c.perimeter());
  }
  // The scale is smoothed (running maximum) so the surface has no steps.
  for (int s = 0; s < stations; ++s) {
    float m = 1.0f;
    for (int j = std::max(0, s - kSmooth); j <= std::min(stations - 1, s + kSmooth); ++j) m = std::max(m, scale[static_cast<size_t>(j)]);
    Section& c = sec[static_cast<size_t>(s)];
    if (m > 1.0f) {
      c.a *= m;
      c.b *= m;
      build_arc(c);
    }
  }
  // A running mean over the same window turns the running maxima's steps into gentle slopes; it
  // stays outside the body, as every maximum it averages covers this station.
  std::vector<Section> smooth = sec;
  for (int s = 0; s < stations; ++s) {
    float a = 0, b = 0, body_b = 0;
    Vec3f c = Vec3f::Zero();
    int count = 0;
    for (int j = std::max(0, s - kSmooth); j <= std::min(stations - 1, s + kSmooth); ++j, ++count) {
      a += sec[static_cast<size_t>(j)].a;
      b += sec[static_cast<size_t>(j)].b;
      body_b = std::max(body_b, sec[static_cast<size_t>(j)].body_b);
      c += sec[static_cast<size_t>(j)].centre - kStation * static_cast<float>(j - s) * axis.up;
    }
    Section& t = smooth[static_cast<size_t>(s)];
    t.a = a / static_cast<float>(count);
    t.b = b / static_cast<float>(count);
    t.body_b = body_b;
    t.centre = c / static_cast<float>(count);
    build_arc(t);
  }
  sec = std::move(smooth);
  return st;
}

// Where one panel goes: x -> arc from the line at phi_c on `surface`, flat y -> distance along the
// surface from the anchor's station. A trouser panel (a leg panel hung from the waist or hips) is
// blended: on the torso's surface above the hips, on its leg's below the crotch, a smooth mix
// between (both surfaces share one station grid).
struct PanelMap {
  const Stack* surface = nullptr;
  float phi_c = 0, x0 = 0;
  const Stack* leg = nullptr;
  float leg_phi_c = 0, leg_x0 = 0;
  float blend_lo = 0, blend_hi = 0;  // torso weight 0 below blend_lo, 1 above blend_hi
  float t_anchor = 0, y_anchor = 0;

  Vec3f at(float x, float t) const {
    const Vec3f p = surface->point(t, phi_c, x - x0);
    if (!leg || t >= blend_hi) return p;
    const Vec3f q = leg->point(t, leg_phi_c, x - leg_x0);
    if (t <= blend_lo) return q;
    const float f = (t - blend_lo) / (blend_hi - blend_lo);
    const float w = f * f * (3 - 2 * f);  // smoothstep
    return w * p + (1 - w) * q;
  }
};

// Rolls a panel with its map. The flat y distance becomes distance along the surface (measured
// where the surface is steepest across the panel), so no column of the panel is stretched;
// rolling along each section is isometric and a blend of two isometric rolls never stretches.
void roll_panel(const PanelMap& m, const std::vector<Vec3f>& q, bool along_surface, std::vector<Vec3f>& x) {
  const Stack& st = *m.surface;
  x.resize(q.size());
  if (!along_surface) {  // flat y is height
    for (size_t v = 0; v < q.size(); ++v) x[v] = m.at(q[v].x(), m.t_anchor + (q[v].y() - m.y_anchor));
    return;
  }
  const int stations = st.stations();
  float x_lo = std::numeric_limits<float>::max(), x_hi = -x_lo;
  for (const Vec3f& p : q) {
    x_lo = std::min(x_lo, p.x());
    x_hi = std::max(x_hi, p.x());
  }
  // The panel's x range per station at its nominal height (widened by a station each way).
  std::vector<Vec2f> range(static_cast<size_t>(stations), Vec2f(x_hi, x_lo));
  for (const Vec3f& p : q) {
    const int s0 = st.station_of(m.t_anchor + (p.y() - m.y_anchor));
    for (int s = std::max(0, s0 - 1); s <= std::min(stations - 1, s0 + 1); ++s) {
      Vec2f& r = range[static_cast<size_t>(s)];
      r = Vec2f(std::min(r.x(), p.x()), std::max(r.y(), p.x()));
    }
  }
  // Cumulative length along the surface, station by station.
  constexpr int kSamples = 16;
  std::vector<float> along(static_cast<size_t>(stations), 0.0f);
  for (int s = 0; s + 1 < stations; ++s) {
    Vec2f r = range[static_cast<size_t>(s)];
    if (r.y() < r.x()) r = Vec2f(x_lo, x_hi);
    float step = kStation;
    for (int j = 0; j <= kSamples; ++j) {
      const float xs = r.x() + (r.y() - r.x()) * static_cast<float>(j) / kSamples;
      step = std::max(step, (m.at(xs, st.t_of(s + 1)) - m.at(xs, st.t_of(s))).norm());
    }
    along[static_cast<size_t>(s) + 1] = along[static_cast<size_t>(s)] + step;
  }
  const auto along_at = [&](float t) {
    const float f = std::clamp((t - st.t_min) / kStation, 0.0f, static_cast<float>(stations - 1));
    const int i = std::min(static_cast<int>(f), std::max(0, stations - 2));
    const float w = f - static_cast<float>(i);
    return stations == 1 ? 0.0f : (1 - w) * along[static_cast<size_t>(i)] + w * along[static_cast<size_t>(i) + 1];
  };
  const float anchor_along = along_at(m.t_anchor);
  for (size_t v = 0; v < q.size(); ++v) {
    const float target = anchor_along + (q[v].y() - m.y_anchor);
    const auto it = std::lower_bound(along.begin(), along.end(), target);
    float t = st.t_min;
    if (it == along.end()) {
      t = st.t_max();
    } else if (it != along.begin()) {
      const size_t k = static_cast<size_t>(it - along.begin());
      const float a0 = along[k - 1], a1 = along[k];
      t = st.t_of(static_cast<int>(k) - 1) + kStation * (a1 > a0 ? (target - a0) / (a1 - a0) : 0.0f);
    }
    x[v] = m.at(q[v].x(), t);
  }
}

// A trouser panel: a leg panel anchored at the waist, the hips or the crotch, so it covers the
// torso above the crotch and its leg below.
bool spans_hips(const PlacementHint& h) {
  return (h.body_part == BodyRegion::left_leg || h.body_part == BodyRegion::right_leg) &&
         (h.landmark == Landmark::waist || h.landmark == Landmark::hip || h.landmark == Landmark::crotch);
}

// How far below where it was placed a skirt's or trousers' waistband sits (its top at height
// `top`): where the body's tape girth (the convex hull of its torso section) first reaches the
// band's girth less 2 cm, a little above where the garment would come to rest on a person (so it
// settles onto the body there rather than starting stretched round it), and at most down to the
// fullest hip section. The band is the top 3 cm of every panel (a back panel's top rises towards the centre),
// side by side. 0 unless every panel hangs from the waist.
float waistband_drop(const Body& body, const Garment& garment, const GarmentMesh& mesh, const std::vector<size_t>& panels,
                     float top) {
  constexpr float kBand = 0.03f, kEase = 0.02f;
  if (!garment.bands.empty()) return 0.0f;  // an elastic waistband holds it where it is placed
  float band = 0;
  for (size_t p : panels) {
    // Panels hung from their waistline; trousers hung from the crotch or the hips keep their
    // anchor, where their crotch seam meets the body's.
    if (garment.panels[p].placement->landmark != Landmark::waist) return 0.0f;
    const auto& q = mesh.panels[p].mesh.positions;
    float panel_top = -std::numeric_limits<float>::max();
    for (const Vec3f& v : q) panel_top = std::max(panel_top, v.y());
    float lo = std::numeric_limits<float>::max(), hi = -lo;
    for (const Vec3f& v : q)
      if (v.y() >= panel_top - kBand) {
        lo = std::min(lo, v.x());
        hi = std::max(hi, v.x());
      }
    band += std::max(0.0f, hi - lo);
  }
  const float start = top - 0.5f * kBand;  // the middle of the band
  const float lowest = std::min(start, body.landmarks.hip.y());
  const body::Slicer slicer(body.mesh);
  for (float drop = 0; start - drop > lowest; drop += kStation)
    if (body::torso_girth(slicer, start - drop) >= band - kEase) return drop;
  // Looser than the hips (or measured so: a flared panel's top is wider than its waist seam):
  // something else holds it, or nothing does; it starts where the file or the anchor puts it.
  return 0.0f;
}

struct RegionPanels {
  BodyRegion region;
  bool trousers = false;  // the leg panels that span the hips, placed together
  std::vector<size_t> panels;
};

// Whether the body vertex nearest to p belongs to a part the region does not wrap (an arm next to
// a torso panel): the region's surface is not grown for it, the cloth slides off it when sewn.
bool near_other_part(const Body& body, const Vec3f& p, const RegionPanels& rp) {
  size_t best = 0;
  float best_d = std::numeric_limits<float>::max();
  for (size_t i = 0; i < body.mesh.positions.size(); ++i) {
    const float d = (body.mesh.positions[i] - p).squaredNorm();
    if (d < best_d) {
      best_d = d;
      best = i;
    }
  }
  const BodyPart part = body.parts[best];
  if (rp.trousers) return part == BodyPart::LeftArm || part == BodyPart::RightArm;
  return !in_region(part, rp.region);
}

// Places the panels of one region at `extra` metres beyond their clearance.
void place_region(const Body& body, const Garment& garment, const GarmentMesh& mesh, const RegionPanels& rp,
                  float extra, PlacedPanels& out) {
  // Trousers use the torso's vertical axis for every surface, so torso and legs share stations.
  const Axis axis = rp.trousers ? Axis{} : region_axis(body, rp.region);
  const auto station_t = [&](const Vec3f& p) { return (p - axis.origin).dot(axis.up); };

  // Panel vertex heights along the axis (nominal: flat distance from the anchor).
  std::vector<std::vector<float>> vt(rp.panels.size());
  std::vector<float> t_anchor(rp.panels.size());
  float t_lo = std::numeric_limits<float>::max(), t_hi = -t_lo, clearance = 0;
  for (size_t k = 0; k < rp.panels.size(); ++k) {
    const size_t p = rp.panels[k];
    const PlacementHint& h = *garment.panels[p].placement;
    // Panels hung from the shoulders or neck start a little high, so their shoulder seams close
    // over the shoulders instead of having to climb them; gravity lowers them while draping.
    const bool hung = rp.region == BodyRegion::torso && (h.landmark == Landmark::shoulder || h.landmark == Landmark::neck);
    const BodyRegion lm_region = rp.trousers ? BodyRegion::torso : rp.region;
    t_anchor[k] = station_t(landmark_point(body.landmarks, h.landmark, lm_region)) + (hung ? kShoulderLift : 0.0f);
    clearance = std::max(clearance, static_cast<float>(h.clearance));
    for (const Vec3f& q : mesh.panels[p].mesh.positions) {
      vt[k].push_back(t_anchor[k] + (q.y() - static_cast<float>(h.anchor.y())));
      t_lo = std::min(t_lo, vt[k].back());
      t_hi = std::max(t_hi, vt[k].back());
    }
  }
  clearance += extra;

  // Skirts and trousers looser than the waist sit lower, where the body is as wide as their
  // waistband (as they would slide down on a person), so they do not drop while draping.
  if (rp.trousers || rp.region == BodyRegion::torso) {
    const float drop = waistband_drop(body, garment, mesh, rp.panels, t_hi);
    for (size_t k = 0; k < rp.panels.size(); ++k) {
      t_anchor[k] -= drop;
      for (float& t : vt[k]) t -= drop;
    }
    t_lo -= drop;
    t_hi -= drop;
  }

  // Stations: the panels' nominal heights plus room below (rolling along a slope takes more height),
  // never below 1 cm above the floor.
  constexpr float kRoomBelow = 0.25f, kRoomAbove = 0.05f, kAboveFloor = 0.01f;
  float t_min = t_lo - kRoomBelow;
  if (axis.up.y() > 0.2f) t_min = std::max(t_min, std::min(t_lo, (kAboveFloor - axis.origin.y()) / axis.up.y()));
  const int stations = std::max(2, static_cast<int>(std::ceil((t_hi + kRoomAbove - t_min) / kStation)) + 1);
  const auto station_of = [&](float t) {
    return std::clamp(static_cast<int>(std::lround((t - t_min) / kStation)), 0, stations - 1);
  };

  // Trousers: the torso's surface above the crotch, the legs' below, blended over the crotch curve.
  const float crotch = body.landmarks.crotch.y();
  const float blend_lo = crotch - 0.03f, blend_hi = crotch + 0.08f;

  // Panel arc widths per station (counted above blend_hi for the torso surface of trousers, below it
  // for their legs), to size the sections so a surface's panels fit side by side.
  const auto needed_for = [&](auto counts) {
    std::vector<float> needed(static_cast<size_t>(stations), 0.0f);
    for (size_t k = 0; k < rp.panels.size(); ++k) {
      const PlacementHint& h = *garment.panels[rp.panels[k]].placement;
      if (!counts(h)) continue;
      std::vector<Vec2f> range(static_cast<size_t>(stations), Vec2f(1e9f, -1e9f));
      const auto& q = mesh.panels[rp.panels[k]].mesh.positions;
      for (size_t v = 0; v < q.size(); ++v) {
        if (rp.trousers && (counts.torso ? vt[k][v] < blend_hi : vt[k][v] >= blend_hi)) continue;
        Vec2f& r = range[static_cast<size_t>(station_of(vt[k][v]))];
        r = Vec2f(std::min(r.x(), q[v].x()), std::max(r.y(), q[v].y()));
      }
      for (int s = 0; s < stations; ++s) {
        const Vec2f r = range[static_cast<size_t>(s)];
        if (r.y() >= r.x()) needed[static_cast<size_t>(s)] += (r.y() - r.x()) + 2 * kPanelGap;
      }
    }
    return needed;
  };
  struct Counts {
    bool torso;
    BodyRegion leg;
    bool operator()(const PlacementHint& h) const { return torso || h.body_part == leg; }
  };

  const float no_cut = -std::numeric_limits<float>::max();
  Stack surface = build_stack(
      body, [&](BodyPart part) { return in_region(part, rp.trousers ? BodyRegion::torso : rp.region); }, axis, t_min,
      stations, clearance, needed_for(Counts{true, rp.region}), !rp.trousers && is_limb(rp.region),
      rp.region == BodyRegion::left_leg || rp.region == BodyRegion::right_leg ? (rp.trousers ? no_cut : 0.0f) : no_cut);
  // Heights along the surface for trousers and for garments without sleeves. With sleeves, flat y
  // stays height: a sleeve's cap is placed on its arm's cylinder by height, and the torso's
  // armholes must stay level with it.
  bool sleeves = false;
  for (const Panel& panel : garment.panels)
    sleeves = sleeves || (panel.placement && (panel.placement->body_part == BodyRegion::left_arm ||
                                              panel.placement->body_part == BodyRegion::right_arm));
  const bool along_surface = rp.trousers || !sleeves;

  // Panels hung from the shoulders (without sleeves): the surface closes over the shoulders like a
  // roof, front and back meeting over the body (no closer than 1 cm to it), so shoulder seams
  // start nearly closed.
  float t_hung = -std::numeric_limits<float>::max();
  for (size_t k = 0; k < rp.panels.size(); ++k) {
    const PlacementHint& h = *garment.panels[rp.panels[k]].placement;
    if (rp.region == BodyRegion::torso && (h.landmark == Landmark::shoulder || h.landmark == Landmark::neck))
      t_hung = std::max(t_hung, t_anchor[k]);
  }
  if (along_surface && t_hung > t_min) {
    constexpr float kRoof = 0.08f, kOverBody = 0.01f;
    for (int s = 0; s < surface.stations(); ++s) {
      const float f = (surface.t_of(s) - (t_hung - kRoof)) / kRoof;
      if (f <= 0) continue;
      Section& c = surface.sec[static_cast<size_t>(s)];
      c.b = std::max(c.body_b + kOverBody, c.b * std::sqrt(std::max(0.0f, 1 - f * f)));
      build_arc(c);
    }
  }
  std::array<Stack, 2> legs;  // trousers: left, right
  if (rp.trousers)
    for (int side = 0; side < 2; ++side) {
      const BodyRegion leg = side == 0 ? BodyRegion::left_leg : BodyRegion::right_leg;
      const float ankle = (side == 0 ? body.landmarks.left_ankle : body.landmarks.right_ankle).y();
      legs[static_cast<size_t>(side)] = build_stack(body, [&](BodyPart part) { return in_region(part, leg); }, axis, t_min,
                                                    stations, clearance, needed_for(Counts{false, leg}), false, ankle);
    }

  // A limb wrapped by one panel (a one-piece sleeve or trouser leg sewn to itself) is centred on
  // the limb's top (arms) or outside (legs), whatever its side says; otherwise the side decides.
  float single_panel_angle = -1;
  if (!rp.trousers && is_limb(rp.region) && rp.panels.size() == 1) {
    const bool arm = rp.region == BodyRegion::left_arm || rp.region == BodyRegion::right_arm;
    const Vec3f outside = arm ? Vec3f::UnitY()
                              : (rp.region == BodyRegion::left_leg ? Vec3f::UnitX() : Vec3f(-Vec3f::UnitX()));
    const Vec3f dir = outside - outside.dot(axis.up) * axis.up;
    single_panel_angle = std::atan2(dir.dot(surface.side_dir), dir.dot(axis.front));
    if (single_panel_angle < 0) single_panel_angle += 2 * kPi;
  }

  // Roll every panel.
  for (size_t k = 0; k < rp.panels.size(); ++k) {
    const size_t p = rp.panels[k];
    const PlacementHint& h = *garment.panels[p].placement;
    const auto& q = mesh.panels[p].mesh.positions;
    PanelMap m;
    m.surface = &surface;
    m.phi_c = single_panel_angle >= 0 ? single_panel_angle : side_angle(h.side);
    m.x0 = static_cast<float>(h.anchor.x());
    m.t_anchor = t_anchor[k];
    m.y_anchor = static_cast<float>(h.anchor.y());
    if (rp.trousers) {
      // On the leg the panel is centred on its side by the middle of its lowest 2 cm (the hem).
      m.leg = &legs[h.body_part == BodyRegion::left_leg ? 0 : 1];
      m.leg_phi_c = side_angle(h.side);
      float y_low = std::numeric_limits<float>::max();
      for (const Vec3f& v : q) y_low = std::min(y_low, v.y());
      float lo = std::numeric_limits<float>::max(), hi = -lo;
      for (const Vec3f& v : q)
        if (v.y() < y_low + 0.02f) {
          lo = std::min(lo, v.x());
          hi = std::max(hi, v.x());
        }
      m.leg_x0 = 0.5f * (lo + hi);
      m.blend_lo = blend_lo;
      m.blend_hi = blend_hi;
    }
    roll_panel(m, q, along_surface, out.positions[p]);
    PanelPlacement& info = out.info[p];
    info.panel = garment.panels[p].name;
    info.region = rp.trousers ? "hips and " + std::string(to_string(h.body_part)) : std::string(to_string(rp.region));
    info.clearance = clearance;
  }
}

}  // namespace

PlacedPanels place_panels(const Body& body, const Garment& garment, const GarmentMesh& mesh,
                          const Collider& body_collider, float collision_thickness, PlacementUse use) {
  // Imports with the file's own 3D placement (GarmentCode, 2021 templates): placement_from_file.cpp.
  if (!garment.panels.empty() &&
      std::all_of(garment.panels.begin(), garment.panels.end(), [](const Panel& p) { return p.transform.has_value(); }))
    return place_panels_from_file(body, garment, mesh, body_collider, collision_thickness, use);
  PlacedPanels out;
  out.positions.resize(garment.panels.size());
  out.info.resize(garment.panels.size());

  // Panels grouped by region; a panel without a hint wraps the torso's front.
  std::vector<RegionPanels> regions;
  for (size_t p = 0; p < garment.panels.size(); ++p) {
    if (!garment.panels[p].placement)
      throw InputError(garment.source, "panel '" + garment.panels[p].name + "' has no placement (body_part, side, landmark)");
    const PlacementHint& h = *garment.panels[p].placement;
    const bool trousers = spans_hips(h);
    const BodyRegion r = trousers ? BodyRegion::torso : h.body_part;
    auto it = std::find_if(regions.begin(), regions.end(),
                           [&](const RegionPanels& x) { return x.region == r && x.trousers == trousers; });
    if (it == regions.end()) regions.push_back({r, trousers, {p}});
    else it->panels.push_back(p);
  }

  // Place each region; grow its clearance while it touches the body.
  std::vector<ContactSample> contact;
  constexpr int kTries = 5;
  constexpr float kGrow = 0.01f;
  for (const RegionPanels& rp : regions) {
    for (int attempt = 0; attempt < kTries; ++attempt) {
      place_region(body, garment, mesh, rp, kGrow * static_cast<float>(attempt), out);
      size_t touching = 0;
      for (size_t p : rp.panels) {
        const auto& x = out.positions[p];
        contact.resize(x.size());
        body_collider.query(x, 0.05f, contact);
        size_t n = 0;
        for (size_t v = 0; v < x.size(); ++v)
          if (contact[v].distance < 2 * collision_thickness && !near_other_part(body, x[v], rp)) ++n;
        out.info[p].vertices_touching = n;
        touching += n;
      }
      if (touching == 0) break;
    }
    // What still touches is pushed out along the body's normal.
    for (size_t p : rp.panels) {
      auto& x = out.positions[p];
      contact.resize(x.size());
      body_collider.query(x, 0.05f, contact);
      for (size_t v = 0; v < x.size(); ++v)
        if (contact[v].distance < 2 * collision_thickness)
          x[v] += (2 * collision_thickness - contact[v].distance) * contact[v].normal;
    }
  }
  return out;
}

}  // namespace drape::dressing
