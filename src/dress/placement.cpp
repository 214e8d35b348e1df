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
#include <cmath>
#include <numbers>

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

struct RegionPanels {
  BodyRegion region;
  std::vector<size_t> panels;
};

// Places the panels of one region at `extra` metres beyond their clearance.
void place_region(const Body& body, const Garment& garment, const GarmentMesh& mesh, const RegionPanels& rp,
                  float extra, PlacedPanels& out) {
  const Axis axis = region_axis(body, rp.region);
  const Vec3f side_dir = axis.up.cross(axis.front);  // u x front: the body's left for the torso
  const auto station_t = [&](const Vec3f& p) { return (p - axis.origin).dot(axis.up); };

  // Panel vertex heights along the axis: anchor at the landmark's station.
  std::vector<std::vector<float>> vt(rp.panels.size());
  float t_min = std::numeric_limits<float>::max(), t_max = -t_min, clearance = 0;
  for (size_t k = 0; k < rp.panels.size(); ++k) {
    const size_t p = rp.panels[k];
    const PlacementHint& h = *garment.panels[p].placement;
    // Panels hung from the shoulders or neck start a little high, so their shoulder seams close
    // over the shoulders instead of having to climb them; gravity lowers them while draping.
    const bool hung = rp.region == BodyRegion::torso && (h.landmark == Landmark::shoulder || h.landmark == Landmark::neck);
    const float t_anchor = station_t(landmark_point(body.landmarks, h.landmark, rp.region)) + (hung ? kShoulderLift : 0.0f);
    clearance = std::max(clearance, static_cast<float>(h.clearance));
    for (const Vec3f& q : mesh.panels[p].mesh.positions) {
      vt[k].push_back(t_anchor + (q.y() - static_cast<float>(h.anchor.y())));
      t_min = std::min(t_min, vt[k].back());
      t_max = std::max(t_max, vt[k].back());
    }
  }
  clearance += extra;
  const int stations = std::max(1, static_cast<int>(std::ceil((t_max - t_min) / kStation)) + 1);
  const auto station_of = [&](float t) {
    return std::clamp(static_cast<int>(std::lround((t - t_min) / kStation)), 0, stations - 1);
  };

  // Body extent per station, in the axis frame (across = side_dir, depth = front).
  std::vector<Bounds> extent(static_cast<size_t>(stations));
  for (size_t i = 0; i < body.mesh.positions.size(); ++i) {
    if (!in_region(body.parts[i], rp.region)) continue;
    const Vec3f d = body.mesh.positions[i] - axis.origin;
    const float t = d.dot(axis.up);
    if (t < t_min - kStation || t > t_max + kStation) continue;
    // The foot is not part of the leg's tube (the leg axis starts at the ankle).
    if ((rp.region == BodyRegion::left_leg || rp.region == BodyRegion::right_leg) && t < 0.0f) continue;
    extent[static_cast<size_t>(station_of(t))].extend(Vec3f(d.dot(side_dir), d.dot(axis.front), 0.0f));
  }
  // Stations without body (above a limb's end, below the body) copy their nearest neighbour.
  for (int pass = 0; pass < 2; ++pass)
    for (int s = 0; s < stations; ++s) {
      const int from = pass == 0 ? s - 1 : stations - s;
      const int to = pass == 0 ? s : stations - 1 - s;
      if (from >= 0 && from < stations && extent[static_cast<size_t>(to)].empty())
        extent[static_cast<size_t>(to)] = extent[static_cast<size_t>(from)];
    }

  // Panel arc widths per station, to size the ellipse so the region's panels fit side by side.
  std::vector<float> needed(static_cast<size_t>(stations), 0.0f);
  for (size_t k = 0; k < rp.panels.size(); ++k) {
    std::vector<Vec2f> range(static_cast<size_t>(stations), Vec2f(1e9f, -1e9f));
    const auto& q = mesh.panels[rp.panels[k]].mesh.positions;
    for (size_t v = 0; v < q.size(); ++v) {
      Vec2f& r = range[static_cast<size_t>(station_of(vt[k][v]))];
      r = Vec2f(std::min(r.x(), q[v].x()), std::max(r.y(), q[v].y()));
    }
    for (int s = 0; s < stations; ++s) {
      const Vec2f r = range[static_cast<size_t>(s)];
      if (r.y() >= r.x()) needed[static_cast<size_t>(s)] += (r.y() - r.x()) + 2 * kPanelGap;
    }
  }

  // Sections: the body's ellipse (a running maximum over 3 cm, so bumps are cleared) plus the
  // clearance, scaled up where the panels need more room.
  constexpr int kSmooth = 6;
  std::vector<Section> sec(static_cast<size_t>(stations));
  std::vector<float> scale(static_cast<size_t>(stations), 1.0f);
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
    c.centre = axis.origin + (t_min + kStation * static_cast<float>(s)) * axis.up + ctr.x() * side_dir + ctr.y() * axis.front;
    if (is_limb(rp.region)) {  // limbs: circles
      c.a = c.b = std::max(half.x(), half.y()) + clearance;
    } else {
      c.a = half.x() + clearance;
      c.b = half.y() + clearance;
    }
    build_arc(c);
    scale[static_cast<size_t>(s)] = std::max(1.0f, needed[static_cast<size_t>(s)] / c.perimeter());
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

  // A limb wrapped by one panel (a one-piece sleeve or trouser leg sewn to itself) is centred on
  // the limb's top (arms) or outside (legs), whatever its side says; otherwise the side decides.
  float single_panel_angle = -1;
  if (is_limb(rp.region) && rp.panels.size() == 1) {
    const bool arm = rp.region == BodyRegion::left_arm || rp.region == BodyRegion::right_arm;
    const Vec3f outside = arm ? Vec3f::UnitY()
                              : (rp.region == BodyRegion::left_leg ? Vec3f::UnitX() : Vec3f(-Vec3f::UnitX()));
    const Vec3f dir = outside - outside.dot(axis.up) * axis.up;
    single_panel_angle = std::atan2(dir.dot(side_dir), dir.dot(axis.front));
    if (single_panel_angle < 0) single_panel_angle += 2 * kPi;
  }

  // A running mean over the same window turns the running maximum's steps into gentle slopes, so
  // the rolled panel is hardly stretched along the axis.
  {
    std::vector<Section> smooth = sec;
    for (int s = 0; s < stations; ++s) {
      float a = 0, b = 0;
      Vec3f c = Vec3f::Zero();
      int n = 0;
      for (int j = std::max(0, s - kSmooth); j <= std::min(stations - 1, s + kSmooth); ++j, ++n) {
        a += sec[static_cast<size_t>(j)].a;
        b += sec[static_cast<size_t>(j)].b;
        c += sec[static_cast<size_t>(j)].centre - kStation * static_cast<float>(j - s) * axis.up;
      }
      Section& t = smooth[static_cast<size_t>(s)];
      t.a = a / static_cast<float>(n);  // >= the body's extent here: a mean of running maxima
      t.b = b / static_cast<float>(n);
      t.centre = c / static_cast<float>(n);
      build_arc(t);
    }
    sec = std::move(smooth);
  }

  // Roll every panel: x -> arc from its side's centre line, y -> station.
  for (size_t k = 0; k < rp.panels.size(); ++k) {
    const size_t p = rp.panels[k];
    const PlacementHint& h = *garment.panels[p].placement;
    const float phi_c = single_panel_angle >= 0 ? single_panel_angle : side_angle(h.side);
    const auto& q = mesh.panels[p].mesh.positions;
    std::vector<Vec3f>& x = out.positions[p];
    x.resize(q.size());
    for (size_t v = 0; v < q.size(); ++v) {
      const float t = vt[k][v];
      const Section& c = sec[static_cast<size_t>(station_of(t))];
      const float s0 = c.arc[static_cast<size_t>(std::lround(phi_c / (2 * kPi) * kAngles)) % kAngles];
      const float phi = angle_at(c, s0 + q[v].x() - static_cast<float>(h.anchor.x()));
      const Vec3f centre = c.centre + (t - (c.centre - axis.origin).dot(axis.up)) * axis.up;
      x[v] = centre + c.a * std::sin(phi) * side_dir + c.b * std::cos(phi) * axis.front;
    }
    PanelPlacement& info = out.info[p];
    info.panel = garment.panels[p].name;
    info.region = to_string(rp.region);
    info.clearance = clearance;
  }
}

}  // namespace

PlacedPanels place_panels(const Body& body, const Garment& garment, const GarmentMesh& mesh,
                          const Collider& body_collider, float collision_thickness) {
  PlacedPanels out;
  out.positions.resize(garment.panels.size());
  out.info.resize(garment.panels.size());

  // Panels grouped by region; a panel without a hint wraps the torso's front.
  std::vector<RegionPanels> regions;
  for (size_t p = 0; p < garment.panels.size(); ++p) {
    if (!garment.panels[p].placement)
      throw InputError(garment.source, "panel '" + garment.panels[p].name + "' has no placement (body_part, side, landmark)");
    const BodyRegion r = garment.panels[p].placement->body_part;
    auto it = std::find_if(regions.begin(), regions.end(), [&](const RegionPanels& x) { return x.region == r; });
    if (it == regions.end()) regions.push_back({r, {p}});
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
        for (const ContactSample& c : contact) n += c.distance < 2 * collision_thickness ? 1 : 0;
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
