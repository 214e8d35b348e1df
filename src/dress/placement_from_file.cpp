// Stage 3 for imported patterns that carry their own 3D placement (GarmentCode specifications and
// the Korosteleva 2021 templates, ../shared/data/patterns/FORMAT_NOTES.md sections 1-2): each panel
// is a flat sheet put at p = R (x, y, 0) + T around the body the pattern was designed on.
//
// A garment without sleeves whose flat sheets lie clear of the body starts from the file's layout
// as it is (GarmentCode's own start). Otherwise flat sheets would have to close their seams across
// the A-posed arms (a shirt's side seams run in front of and behind them), so the file's placement
// is read as what it means and the panels are rolled by the torso/limb roll of placement.cpp, at a
// clearance, at the file's position:
//   - the region a panel wraps: an arm where its centre lies beyond the shoulders and above the
//     hips, a trouser leg where it stays on one side of the midline and reaches below the crotch,
//     else the torso;
//   - the side it faces: the horizontal direction of its right side's normal (the loop's winding
//     by the right-hand rule, turned by R), front, back, left or right;
//   - its orientation on that side: the panel's coordinates are turned (and mirrored for
//     clockwise loops, the right side facing -z) by an isometry so that y runs up the region's axis
//     as the file has it (the body's up for torso and legs; the design pose's arm axis for sleeves)
//     and x runs along up x outward normal, as the roll expects;
//   - its position: the point where the panel crosses the midline (front and back panels) or its
//     middle (sides, sleeves) goes on the side's centre line, and the file's heights are kept,
//     mapped from the design body's frame onto ours (GarmentCode: mean_all, feet at y = 0, scaled
//     by stature; 2021 templates: origin at the SMPL pelvis, put 5 cm above our waist).
// Rolling keeps lengths (isometric across, by distance along the surface downwards), so seams
// start open by about the distance the file's layout leaves between panels, never stretched.
#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include "dress/stages.hpp"

namespace drape::dressing {
namespace {

// GarmentCode patterns are fitted to mean_all (bodies/garmentcode/mean_all.yaml): stature 171.99 cm,
// arms 45.48 degrees below the horizontal (arm_pose_angle).
constexpr double kDesignStature = 1.7199;
constexpr double kGarmentCodeArmAngleDeg = 45.48;
// The 2021 templates: SMPL female body in a T-pose (sleeves lie horizontal), origin at its pelvis.
constexpr double kTemplateArmAngleDeg = 0.0;
// The SMPL pelvis origin of the 2021 templates sits this far above our body's waist landmark: the
// templates' waistbands lie 5 cm below their origin (skirts, pants) and the tee's shoulder-neck
// points 29 cm above it.
constexpr double kPelvisAboveWaist = 0.05;

// A flat layout is used as it is only where every vertex lies this far off the body.
constexpr float kFlatClearance = 0.01f;

constexpr double kDegToRad = std::numbers::pi / 180.0;

Eigen::Matrix3d rotation_of(const PanelTransform& t) {
  return (Eigen::AngleAxisd(t.rotation_deg.z() * kDegToRad, Vec3d::UnitZ()) *
          Eigen::AngleAxisd(t.rotation_deg.y() * kDegToRad, Vec3d::UnitY()) *
          Eigen::AngleAxisd(t.rotation_deg.x() * kDegToRad, Vec3d::UnitX()))
      .toRotationMatrix();
}

// The file's frame mapped onto the body: only heights change (y_body = scale * y_file + offset);
// x = 0 is the midline in both.
struct FileFrame {
  double scale = 1, offset = 0;
  double arm_angle_deg = kGarmentCodeArmAngleDeg;
  double height(double y_file) const { return scale * y_file + offset; }
};

FileFrame file_frame(const Body& body, bool pelvis_origin) {
  FileFrame f;
  if (pelvis_origin) {
    f.offset = body.landmarks.waist.y() + kPelvisAboveWaist;
    f.arm_angle_deg = kTemplateArmAngleDeg;
  } else {
    f.scale = body.measurements.height > 0 ? body.measurements.height / kDesignStature : 1.0;
  }
  return f;
}

// One panel as the file places it, in the body's frame.
struct FilePanel {
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();
  Vec3d origin = Vec3d::Zero();   // T, heights mapped
  Vec3d outward = Vec3d::UnitZ(); // the right side's normal
  // In-plane unit axes of the rolled coordinates (across = up x outward): up is the region's up
  // direction (the body's for torso and legs, the arm's axis towards the shoulder for sleeves).
  Vec3d up = Vec3d::UnitY(), across = Vec3d::UnitX();
  Vec3d centre = Vec3d::Zero();   // centroid of the panel's mesh vertices
  double scale = 1;               // the frame's height scale
  double x_lo = 0, x_hi = 0, y_top = 0;  // rolled coordinates' extent
  double world_x_lo = 0, world_x_hi = 0, world_y_lo = 0, world_y_hi = 0;

  // A panel-mesh point where the file puts it, heights mapped onto the body.
  Vec3d world(const Vec3f& q) const {
    const Vec3d d = rotation * Vec3d(q.x(), q.y(), 0);
    return origin + Vec3d(d.x(), scale * d.y(), d.z());
  }
};

FilePanel file_panel(const Panel& panel, const PanelMesh& mesh, const FileFrame& frame) {
  const PanelTransform& t = *panel.transform;
  FilePanel f;
  f.rotation = rotation_of(t);
  f.origin = Vec3d(t.translation.x(), frame.height(t.translation.y()), t.translation.z());
  f.scale = frame.scale;
  const double winding = panel.signed_area() >= 0 ? 1.0 : -1.0;
  f.outward = winding * f.rotation.col(2);

  // The centre of the panel's mesh, where the file puts it (decides the region).
  Vec3d centre = Vec3d::Zero();
  for (const Vec3f& q : mesh.mesh.positions) centre += f.rotation * Vec3d(q.x(), q.y(), 0);
  centre /= static_cast<double>(std::max<size_t>(1, mesh.mesh.positions.size()));
  f.centre = f.origin + centre;

  f.world_x_lo = f.world_y_lo = std::numeric_limits<double>::max();
  f.world_x_hi = f.world_y_hi = -f.world_x_lo;
  for (const Vec3f& q : mesh.mesh.positions) {
    const Vec3d p = f.world(q);
    f.world_x_lo = std::min(f.world_x_lo, p.x());
    f.world_x_hi = std::max(f.world_x_hi, p.x());
    f.world_y_lo = std::min(f.world_y_lo, p.y());
    f.world_y_hi = std::max(f.world_y_hi, p.y());
  }
  return f;
}

// In-plane axes once the region's up direction is known: up projected into the panel's plane.
void set_axes(FilePanel& f, const Vec3d& region_up, const PanelMesh& mesh) {
  const Vec3d n = f.outward;
  Vec3d up = region_up - region_up.dot(n) * n;
  if (up.norm() < 1e-3) up = f.rotation.col(1);  // a panel across the axis: its own y
  f.up = up.normalized();
  f.across = f.up.cross(n).normalized();
  f.x_lo = std::numeric_limits<double>::max();
  f.x_hi = f.y_top = -f.x_lo;
  for (const Vec3f& q : mesh.mesh.positions) {
    const Vec3d d = f.rotation * Vec3d(q.x(), q.y(), 0);
    f.x_lo = std::min(f.x_lo, d.dot(f.across));
    f.x_hi = std::max(f.x_hi, d.dot(f.across));
    f.y_top = std::max(f.y_top, d.dot(f.up));
  }
}

PanelSide side_of(const Vec3d& outward) {
  if (std::abs(outward.z()) >= std::abs(outward.x())) return outward.z() >= 0 ? PanelSide::front : PanelSide::back;
  return outward.x() >= 0 ? PanelSide::left : PanelSide::right;
}

Vec3f to_f(const Vec3d& v) { return v.cast<float>(); }

// Whether the straight line between a seam pair's two vertices, where a layout puts them, passes
// through the body: sewing pulls the partners together along it, and the body stops them on the
// way instead of the seam closing around it.
bool seam_crosses_body(const std::vector<std::vector<Vec3f>>& positions, const std::vector<SeamVertexPair>& pairs,
                       const Collider& body_collider) {
  constexpr float kStep = 0.01f;        // m between the points tested along a pair's line
  constexpr float kRadius = 0.25f;      // m: the query reaches the surface from deep inside the torso
  constexpr float kInside = -0.005f;    // m: a point this far inside the body is in it
  std::vector<Vec3f> points;
  for (const SeamVertexPair& s : pairs) {
    const Vec3f a = positions[s.panel_a][s.vertex_a];
    const Vec3f b = positions[s.panel_b][s.vertex_b];
    const int n = static_cast<int>(std::ceil((b - a).norm() / kStep));
    for (int i = 1; i < n; ++i) points.push_back(a + (b - a) * (static_cast<float>(i) / static_cast<float>(n)));
  }
  std::vector<ContactSample> contact(points.size());
  body_collider.query(points, kRadius, contact);
  return std::any_of(contact.begin(), contact.end(), [](const ContactSample& c) { return c.distance < kInside; });
}

}  // namespace

PlacedPanels place_panels_from_file(const Body& body, const Garment& garment, const GarmentMesh& mesh,
                                    const Collider& body_collider, float collision_thickness, PlacementUse use) {
  const Landmarks& l = body.landmarks;
  bool pelvis_origin = false;
  for (const Panel& p : garment.panels) pelvis_origin = pelvis_origin || p.transform->pelvis_origin;
  const FileFrame frame = file_frame(body, pelvis_origin);
  const double shoulder_x = 0.5 * (std::abs(l.left_shoulder.x()) + std::abs(l.right_shoulder.x()));
  const double armpit_y = 0.5 * (l.left_armpit.y() + l.right_armpit.y());
  constexpr double kMidlineSlack = 0.03;  // a trouser panel's crotch extension may cross the midline

  // A copy of the garment with hints derived from the file, and its meshes in rolled coordinates.
  bool any_arm = false;
  std::vector<double> rise(garment.panels.size(), 0.0);  // body height per unit of rolled y
  std::vector<FilePanel> files;
  files.reserve(garment.panels.size());
  Garment rolled = garment;
  GarmentMesh rolled_mesh = mesh;
  for (size_t p = 0; p < garment.panels.size(); ++p) {
    const Panel& panel = garment.panels[p];
    FilePanel& f = files.emplace_back(file_panel(panel, mesh.panels[p], frame));

    // Region, by where the file puts the panel.
    BodyRegion region = BodyRegion::torso;
    set_axes(f, Vec3d::UnitY(), mesh.panels[p]);
    if (std::abs(f.centre.x()) > shoulder_x && f.centre.y() > 0.5 * (l.waist.y() + l.crotch.y())) {
      region = f.centre.x() > 0 ? BodyRegion::left_arm : BodyRegion::right_arm;
      const double a = frame.arm_angle_deg * kDegToRad;
      const Vec3d arm_up(region == BodyRegion::left_arm ? -std::cos(a) : std::cos(a), std::sin(a), 0.0);
      set_axes(f, arm_up, mesh.panels[p]);
    } else if (f.world_y_lo < l.crotch.y() && (f.world_x_lo > -kMidlineSlack || f.world_x_hi < kMidlineSlack)) {
      region = f.world_x_lo > -kMidlineSlack ? BodyRegion::left_leg : BodyRegion::right_leg;
    }

    PlacementHint h;
    h.body_part = region;
    h.side = side_of(f.outward);
    h.clearance = 0.03;
    if (region == BodyRegion::left_arm || region == BodyRegion::right_arm) {
      // A sleeve hangs from the shoulder by its top, centred on its side of the arm.
      h.landmark = Landmark::shoulder;
      h.anchor = {0.5 * (f.x_lo + f.x_hi), f.y_top};
    } else {
      // The file's heights are kept: the anchor is the panel point at the landmark's height, on
      // the midline for front and back panels, in the middle for side panels.
      const bool top = f.world_y_hi > armpit_y && region == BodyRegion::torso;
      h.landmark = top ? Landmark::shoulder : Landmark::waist;
      const double target = top ? 0.5 * (l.left_shoulder.y() + l.right_shoulder.y()) : l.waist.y();
      rise[p] = frame.scale * f.up.y();
      h.anchor.y() = rise[p] > 1e-3 ? (target - f.origin.y()) / rise[p] : f.y_top;
      const bool front_back = h.side == PanelSide::front || h.side == PanelSide::back;
      h.anchor.x() = front_back && std::abs(f.across.x()) > 0.1 ? -f.origin.x() / f.across.x() : 0.5 * (f.x_lo + f.x_hi);
      // A trouser panel's centre front (back) at the waist goes on the midline, as a pattern maker
      // means it, and its crotch extension crosses it between the legs. A file may lay the panels
      // out apart (the 2021 pants: crotch points on the midline, waist corners 11 cm off it), and
      // a seam that starts 22 cm open at the waist stays open there under the band's tension.
      const bool leg = region == BodyRegion::left_leg || region == BodyRegion::right_leg;
      if (leg && front_back) {
        constexpr double kTopBand = 0.01;  // m: vertices this close to the panel's top are its waist
        double best = std::numeric_limits<double>::max();
        for (const Vec3f& q : mesh.panels[p].mesh.positions) {
          const Vec3d d = f.rotation * Vec3d(q.x(), q.y(), 0);
          if (d.dot(f.up) < f.y_top - kTopBand) continue;
          const double off_midline = std::abs(f.world(q).x());
          if (off_midline < best) {
            best = off_midline;
            h.anchor.x() = d.dot(f.across);
          }
        }
      }
    }
    any_arm = any_arm || region == BodyRegion::left_arm || region == BodyRegion::right_arm;
    rolled.panels[p].placement = h;
    rolled.panels[p].transform.reset();

    // Panel coordinates turned (or mirrored) into the rolled frame: an isometry of the flat pattern.
    for (Vec3f& q : rolled_mesh.panels[p].mesh.positions) {
      const Vec3d d = f.rotation * Vec3d(q.x(), q.y(), 0);
      q = to_f(Vec3d(d.dot(f.across), d.dot(f.up), 0.0));
    }
  }

  // With sleeves the roll has no roof over the shoulders, only a 4 cm lift of panels anchored
  // there, which would move the torso above the sleeves' heights: the file's heights are where
  // the garment hangs, so such panels are anchored at the waist (measured on mean_all: the
  // GarmentCode shirt's shoulder seams close from the file's heights, 15 mm stay open 4 cm higher).
  if (any_arm)
    for (size_t p = 0; p < rolled.panels.size(); ++p) {
      PlacementHint& h = *rolled.panels[p].placement;
      if (h.landmark != Landmark::shoulder || h.body_part != BodyRegion::torso || rise[p] <= 1e-3) continue;
      h.landmark = Landmark::waist;
      h.anchor.y() += (l.waist.y() - 0.5 * (l.left_shoulder.y() + l.right_shoulder.y())) / rise[p];
    }

  // A GarmentCode garment without sleeves whose flat sheets already lie clear of the body, and
  // whose seams close without passing through it, starts from the file's own layout, as
  // GarmentCode's simulator starts it (measured on mean_all: the hoody's seams all close from
  // there, rolled its side seams stay 11 cm open). With sleeves the flat side and underarm seams
  // would have to close across the A-posed arms, and the 2021 templates were laid out around
  // another body in another pose: those are rolled. So is a layout with a seam whose partners face
  // each other through the body: the pencil dress's straps lie 3-6 cm below mean_all's shoulders,
  // front and back, and pulled together they closed under the arms, not over the shoulders (the
  // dress then slid 0.25 m down the body; rolled, it passes every gate). Measuring the pattern
  // keeps the file's layout wherever it lies clear of the body: rolled over the shoulders, a
  // bodice's heights are no longer its lengths.
  if (!pelvis_origin && !any_arm) {
    PlacedPanels out;
    out.positions.resize(garment.panels.size());
    out.info.resize(garment.panels.size());
    std::vector<ContactSample> contact;
    bool clear = true;
    for (size_t p = 0; p < garment.panels.size() && clear; ++p) {
      auto& x = out.positions[p];
      for (const Vec3f& q : mesh.panels[p].mesh.positions) x.push_back(to_f(files[p].world(q)));
      contact.resize(x.size());
      body_collider.query(x, kFlatClearance, contact);
      for (const ContactSample& c : contact) clear = clear && c.distance >= kFlatClearance;
      out.info[p] = {garment.panels[p].name, "transform: flat, as in the file", kFlatClearance, 0};
    }
    if (clear && (use == PlacementUse::measuring || !seam_crosses_body(out.positions, mesh.seam_pairs, body_collider)))
      return out;
  }

  PlacedPanels out = place_panels(body, rolled, rolled_mesh, body_collider, collision_thickness);
  for (PanelPlacement& info : out.info) info.region = "transform: rolled on " + info.region;
  return out;
}

}  // namespace drape::dressing
