#pragma once
// Garments as the clothing industry describes them: flat 2D panels (cutting patterns) with seams,
// grain lines, grading to sizes, a fabric and hints for placing each panel around the body
// (Vassilev & Spanlang, sec. 6.1). The file format is documented in docs/garment-format.md.
//
//   GarmentSpec  - what a file says, every size (read_garment / parse_garment / builtin_garment)
//   Garment      - one size resolved to concrete curves, validated (garment_in_size)
//   GarmentMesh  - the panels meshed flat with matching seam vertex pairs (mesh_garment)
//
// Every length is in metres. Panel coordinates are 2D in the panel's own plane; the outline loop's
// winding gives the fabric's right side by the right-hand rule (counter-clockwise = +z), as in
// GarmentCode. Loops are never reordered on load.
#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "drape/mesh.hpp"

namespace drape {

using Vec2d = Eigen::Vector2d;

// ---------------------------------------------------------------------------------------------
// Specification (all sizes)

// polyline: a dense outline from a CAD export (DXF), parametrised by arc length.
enum class EdgeCurve : uint8_t { line, quadratic, cubic, arc, polyline };

// One edge of a panel outline, from vertex i to vertex (i + 1) mod n. Bezier control points are
// relative to the edge (GarmentCode convention): with d = end - start and perp = (-d.y, d.x),
// control = start + t * d + s * perp, stored as (t, s). They therefore follow the edge when grading
// moves its end points. Arcs are given by radius and the SVG flags; the radius scales with the
// chord when grading changes it.
struct EdgeSpec {
  std::string name;             // optional, for seams and messages
  EdgeCurve curve = EdgeCurve::line;
  std::array<Vec2d, 2> control{Vec2d::Zero(), Vec2d::Zero()};  // (t, s) per control point
  double radius = 0;            // arc, metres at the base size
  bool large_arc = false;       // arc: the longer of the two arcs
  bool counter_clockwise = true;  // arc: sweeps counter-clockwise about its centre
  std::vector<Vec2d> points;      // polyline: interior points, absolute panel coordinates
};

// The body region a panel wraps (body.hpp has the finer per-vertex BodyPart labels).
enum class BodyRegion : uint8_t { torso, left_arm, right_arm, left_leg, right_leg };
enum class PanelSide : uint8_t { front, back, left, right };
// Heights a panel may be anchored to (the body engineer's landmarks).
enum class Landmark : uint8_t { neck, shoulder, bust, waist, hip, crotch, knee, ankle, elbow, wrist };

// Where a panel goes on the body: it wraps `body_part` on its `side`, with the panel point `anchor`
// at the landmark's height and on the side's centre line, `clearance` metres off the skin.
struct PlacementHint {
  BodyRegion body_part = BodyRegion::torso;
  PanelSide side = PanelSide::front;
  Landmark landmark = Landmark::waist;
  Vec2d anchor = Vec2d::Zero();  // panel coordinates, metres
  double clearance = 0.03;
};

// A rigid 3D placement given by the source file (GarmentCode: p = R(x, y, 0) + t), in drape's world
// frame (metres, +Y up, +Z front, feet at y = 0 where the source said so).
struct PanelTransform {
  Vec3d translation = Vec3d::Zero();
  Vec3d rotation_deg = Vec3d::Zero();  // XYZ Euler, R = Rz * Ry * Rx, degrees
  // True for the 2021 templates, whose origin is the SMPL pelvis (y = 0 at hip height).
  bool pelvis_origin = false;
};

struct PanelSpec {
  std::string name;
  // vertices[size][i]: the outline's vertices in each size (grading already applied).
  std::vector<std::vector<Vec2d>> vertices;
  std::vector<EdgeSpec> edges;  // edges[i] joins vertex i to vertex (i + 1) mod n
  Vec2d grain = Vec2d::UnitY();  // warp direction in panel coordinates (unit)
  std::string fabric;            // empty: the garment's fabric
  std::optional<PlacementHint> placement;
  std::optional<PanelTransform> transform;
  std::string label;  // free text from imports (GarmentCode "label")
};

// One side of a seam: `edge_count` consecutive edges of a panel, starting at `first_edge`, walked in
// the outline's direction.
struct SeamSide {
  uint32_t panel = 0;
  uint32_t first_edge = 0;
  uint32_t edge_count = 1;
};

struct SeamSpec {
  std::string name;
  SeamSide a, b;
  // false (the default, "reversed"): a's start meets b's end, as when two panels are laid right side
  // to right side. true ("same"): start meets start.
  bool same_direction = false;
  // Allowed length difference as a fraction of the shorter side (gathering, sleeve-cap ease).
  double ease = 0;
};

// A size chart: for each size, the body measurements it is drafted for (metres, by the body layer's
// measurement keys: "bust", "waist", "hips", "shoulder_width", ...; see size_chart_keys()).
using SizeMeasurements = std::map<std::string, double, std::less<>>;

// An elastic band sewn along outline edges (a waistband): a ring of springs along the edges,
// relaxed at the wearer's waist girth times (1 + ease) (never longer than drafted), that gathers
// the fabric sewn to it. With negative ease it is stretched round the body and holds the garment
// up by its tension and friction; nothing is pinned (docs/garment-format.md, Elastic bands). An
// edge sewn to a band edge is gathered with it.
struct ElasticBand {
  std::vector<SeamSide> edges;  // the band's edges, all the way round the garment
  double ease = -0.05;          // relaxed girth / body waist girth - 1, in [-0.3, 0]
  // The elastic is as stiff as `stiffness` strips of the garment's fabric `width` metres wide.
  double width = 0.03;
  double stiffness = 4.0;
};

struct GarmentSpec {
  // size_chart[k]: the body sizes[k] is drafted for; empty (or an empty entry) where the file gives
  // none. The dressing picks the nearest size for the body when none is asked for (dress.hpp).
  std::vector<SizeMeasurements> size_chart;
  std::string name;
  std::string source;        // file name for messages
  std::string format;        // "drape", "garmentcode", "garmentcode-2021", "dxf"
  std::string description;
  std::string fabric = "cotton";
  int layer = 0;             // 0 innermost
  std::vector<std::string> sizes;  // at least one
  size_t base_size = 0;
  std::vector<PanelSpec> panels;
  std::vector<SeamSpec> seams;
  std::vector<ElasticBand> bands;
  // The wearing ease the pattern is drafted with at the bust, waist and hips (garment girth minus
  // body girth, metres); keys the file leaves out take default_intended_ease() (size_advice.hpp).
  // A size chart is made from it for a pattern that has none (chart_from_pattern).
  SizeMeasurements intended_ease;
};

// Seam sides may differ in length by this much plus the seam's ease (see docs/garment-format.md).
inline constexpr double kSeamLengthTolerance = 0.005;     // metres
inline constexpr double kSeamLengthRelTolerance = 0.01;   // of the shorter side
inline constexpr double kMaxSeamEase = 0.5;                // ease above this is refused

// Fabric names the cloth model has presets for.
const std::vector<std::string>& known_fabrics();
// Keys a size chart may use: the body's girths and lengths that grade a pattern.
const std::vector<std::string_view>& size_chart_keys();

// Reads a garment file; the format is detected from the content: drape garment JSON, GarmentCode
// specification, 2021 template JSON (with // comments), or an AAMA/ASTM DXF. Throws InputError
// naming the file and the element on any problem, including every size failing validation.
GarmentSpec read_garment(const std::filesystem::path& path);
// The same from text in memory; `source` names it in messages, `base_dir` resolves a DXF reference.
GarmentSpec parse_garment(std::string_view text, const std::string& source,
                          const std::filesystem::path& base_dir = {});

// Built-in garments (assets/garments/*.json, compiled into the binary).
struct BuiltinGarment {
  std::string name;
  std::string description;
  std::vector<std::string> sizes;
  std::string default_size;
};
std::vector<BuiltinGarment> builtin_garments();
const std::string& default_garment_name();  // "shirt"
// A built-in by name, or nullopt.
std::optional<GarmentSpec> builtin_garment(std::string_view name);
// A built-in name or a path: what `--garment G` means on the command line.
GarmentSpec load_garment(const std::string& name_or_path);

// ---------------------------------------------------------------------------------------------
// One size, concrete geometry

// A concrete edge curve in panel coordinates.
struct Curve {
  EdgeCurve kind = EdgeCurve::line;
  Vec2d start = Vec2d::Zero(), end = Vec2d::Zero();
  std::array<Vec2d, 2> control{Vec2d::Zero(), Vec2d::Zero()};  // absolute
  Vec2d centre = Vec2d::Zero();  // arc
  double radius = 0;
  double start_angle = 0, sweep = 0;  // arc: radians, sweep signed (> 0 counter-clockwise)
  std::vector<Vec2d> points;          // polyline: start, interior points, end

  Vec2d point(double t) const;     // t in [0, 1]
  Vec2d tangent(double t) const;   // derivative, not normalised
  double length() const;
  // Points at parameters giving equal arc length: count + 1 points from start to end.
  std::vector<Vec2d> sample_by_length(size_t count) const;
};

struct Panel {
  std::string name;
  std::vector<Curve> edges;  // closed loop
  std::vector<std::string> edge_names;
  Vec2d grain = Vec2d::UnitY();
  std::string fabric;
  std::optional<PlacementHint> placement;
  std::optional<PanelTransform> transform;
  std::string label;

  double signed_area() const;  // > 0 for counter-clockwise loops, exact for all curve kinds
  double perimeter() const;
  // The outline as a polygon with points no further apart than `spacing` (curves flattened).
  std::vector<Vec2d> polygon(double spacing) const;
};

struct Garment {
  std::string name;
  std::string source;
  std::string size;
  std::string fabric;
  int layer = 0;
  std::vector<Panel> panels;
  std::vector<SeamSpec> seams;
  std::vector<ElasticBand> bands;

  double seam_side_length(const SeamSide& side) const;
};

// Resolves one size (by name; empty = the base size) and validates it: outlines closed and not
// self-intersecting, non-zero area, seams naming existing edges, each edge in at most one seam,
// seam lengths matching within tolerance plus ease, every panel of a multi-panel garment seamed
// into one connected piece, known fabric. Throws InputError("file", "panel 'x' edge 3: ...").
Garment garment_in_size(const GarmentSpec& spec, std::string_view size = {});

// ---------------------------------------------------------------------------------------------
// Meshing

enum class Mesher : uint8_t {
  grid,      // the paper's rectangular-topology grid, aligned with the grain, clipped to the outline
  triangle,  // CGAL constrained Delaunay refinement to the target edge length
};

struct MeshOptions {
  Mesher mesher = Mesher::grid;
  double edge_length = 0.01;  // metres: grid spacing / target triangle edge length
};

// Per-vertex flags of a panel mesh.
enum VertexFlag : uint8_t {
  kVertexBoundary = 1,  // on the outline
  kVertexSeam = 2,      // on an edge that is sewn
  kVertexHem = 4,       // on an edge that is not sewn (hem, opening, neckline)
  kVertexCorner = 8,    // an outline vertex (end of an edge)
};

// Grid mesher only: the rectangular topology behind the cloth core's springs (paper sec. 2).
struct GridTopology {
  Vec2d origin = Vec2d::Zero();  // panel coordinates of lattice cell (0, 0)
  Vec2d warp = Vec2d::UnitY();   // unit grain direction (lattice j axis)
  Vec2d weft = Vec2d::UnitX();   // unit cross-grain direction (lattice i axis)
  double spacing = 0;
  // Lattice coordinates (i, j) per vertex; (INT32_MIN, INT32_MIN) for boundary vertices off the lattice.
  std::vector<std::array<int32_t, 2>> lattice;
  // Spring index pairs: structural = lattice 4-neighbours plus every triangle edge that touches a
  // boundary vertex; shear = lattice diagonals; flexion = lattice neighbours two apart along warp or
  // weft (with the middle vertex present).
  std::vector<std::array<uint32_t, 2>> structural, shear, flexion;
};

struct PanelMesh {
  // positions: (x, y, 0) in panel coordinates; uvs: (x, y), the flat pattern position in metres.
  // Triangles wind like the outline loop, so their normal is the fabric's right side.
  Mesh mesh;
  std::vector<uint8_t> flags;  // VertexFlag bits per vertex
  // Boundary vertices in loop order, and for each the outline edge it starts or lies on.
  std::vector<uint32_t> boundary;
  std::vector<uint32_t> boundary_edge;
  std::optional<GridTopology> grid;
};

// A pair of vertices sewn together: both ends of every seam, and the same arc-length fraction of
// each side in between (both sides have the same number of vertices).
struct SeamVertexPair {
  uint32_t seam = 0;
  uint32_t panel_a = 0, vertex_a = 0;
  uint32_t panel_b = 0, vertex_b = 0;
};

struct GarmentMesh {
  std::vector<PanelMesh> panels;  // same order as Garment::panels
  std::vector<SeamVertexPair> seam_pairs;
  size_t vertex_count() const;
  size_t triangle_count() const;
};

// Meshes every panel; throws InputError when an outline cannot be meshed (e.g. narrower than the
// edge length allows) and std::invalid_argument for options out of range (edge_length <= 0).
GarmentMesh mesh_garment(const Garment& garment, const MeshOptions& options = {});

// Helpers the placement stage needs.
const char* to_string(BodyRegion part);
const char* to_string(PanelSide side);
const char* to_string(Landmark landmark);
const char* to_string(EdgeCurve curve);

}  // namespace drape
