#pragma once
// Bodies: a triangle mesh with (optionally) a skeleton and skin weights, landmarks, per-vertex body
// parts and tape measurements. Bodies come from measurements (made on MakeHuman's CC0 body, packed
// into drape, or by drape's own parametric generator), from scans (OBJ/PLY) or from rigged glTF
// files. Every body is in drape's frame (DESIGN.md): metres, +Y up, facing +Z, +X = the body's
// left, feet on y = 0, centred in x and z.
//
// See docs/bodies.md for the measurement list (with ISO 8559-1 names), how bodies are made from
// measurements and how landmarks are found.
#include <array>
#include <cstdint>
#include <filesystem>
#include <map>
#include <string>
#include <string_view>
#include <vector>

#include "drape/io.hpp"
#include "drape/mesh.hpp"
#include "drape/scene.hpp"

namespace drape {

enum class Sex { Female, Male };

// The six body parts of Vassilev's deformable body (and the usual garment placement regions).
enum class BodyPart : uint8_t { Head, Torso, LeftArm, RightArm, LeftLeg, RightLeg };
constexpr int kBodyPartCount = 6;
std::string_view body_part_name(BodyPart part);  // "head", "torso", "left_arm", ...

// Bind-pose skeleton. Joint positions are in world space (the mesh's frame); each joint's rotation
// in the bind pose is the identity, so an inverse bind matrix is a pure translation by -position.
// Joint names follow the CMU/cgspeed convention (Hips, Spine, LeftUpLeg, ...) so motion capture
// can be retargeted by name.
struct Joint {
  std::string name;
  int parent = -1;  // index into Skeleton::joints, -1 for the root
  Vec3f position = Vec3f::Zero();
};
struct Skeleton {
  std::vector<Joint> joints;
  bool empty() const { return joints.empty(); }
  int find(std::string_view name) const;  // -1 when absent
};

// Anthropometric landmarks (points on or inside the surface, metres). Left = +X.
struct Landmarks {
  Vec3f crown = Vec3f::Zero();           // top of the head
  Vec3f neck_base = Vec3f::Zero();       // back of the neck base (cervicale), on the midline
  Vec3f neck = Vec3f::Zero();            // centre of the narrowest neck section
  Vec3f left_shoulder = Vec3f::Zero();   // acromion: outer end of the shoulder, on top
  Vec3f right_shoulder = Vec3f::Zero();
  Vec3f left_armpit = Vec3f::Zero();     // top of the gap between arm and torso
  Vec3f right_armpit = Vec3f::Zero();
  Vec3f left_bust = Vec3f::Zero();       // bust point (most prominent point of the chest)
  Vec3f right_bust = Vec3f::Zero();
  Vec3f underbust = Vec3f::Zero();       // front midline just under the bust
  Vec3f waist = Vec3f::Zero();           // front midline at the narrowest torso section
  Vec3f hip = Vec3f::Zero();             // back midline at the fullest hip section
  Vec3f crotch = Vec3f::Zero();          // deepest point between the legs
  Vec3f left_knee = Vec3f::Zero();       // centre of the leg section at knee height
  Vec3f right_knee = Vec3f::Zero();
  Vec3f left_ankle = Vec3f::Zero();      // centre of the narrowest section above the foot
  Vec3f right_ankle = Vec3f::Zero();
  Vec3f left_elbow = Vec3f::Zero();      // on the arm axis
  Vec3f right_elbow = Vec3f::Zero();
  Vec3f left_wrist = Vec3f::Zero();      // on the arm axis, at the narrowest section
  Vec3f right_wrist = Vec3f::Zero();
  Vec3f left_fingertip = Vec3f::Zero();  // end of the hand
  Vec3f right_fingertip = Vec3f::Zero();

  // (name, point) pairs in a fixed order, for printing.
  std::vector<std::pair<std::string_view, Vec3f>> named() const;
};

// Tape measurements in metres. Circumferences are the perimeter of the convex hull of the body's
// cross-section at the landmark (arms excluded from torso sections), as a tape measure would lie.
struct Measurements {
  float height = 0;          // stature
  float neck = 0;            // neck girth (narrowest)
  float bust = 0;            // bust girth (women) / chest girth (men)
  float underbust = 0;       // underbust girth
  float waist = 0;           // waist girth
  float hips = 0;            // hip girth
  float thigh = 0;           // thigh girth (fullest, one leg; mean of both)
  float upper_arm = 0;       // upper arm girth (mean of both)
  float wrist = 0;           // wrist girth (mean of both)
  float inseam = 0;          // crotch height (inside leg length to the floor)
  float arm_length = 0;      // shoulder point to wrist (mean of both)
  float shoulder_width = 0;  // acromion to acromion, straight line
  float back_length = 0;     // cervicale to waist level along the back midline
};

// One row of the measurement table: the key users type (`--measurements waist=0.74`), the
// ISO 8559-1 term, and the field it fills. Circumferences are the *_girth rows.
struct MeasurementInfo {
  std::string_view key;
  std::string_view iso_8559_1;
  float Measurements::*field;
  bool circumference;
};
const std::vector<MeasurementInfo>& measurement_table();

// A body and everything known about it.
struct Body {
  Sex sex = Sex::Female;          // for generated bodies; loaded bodies keep the default
  Mesh mesh;                      // mesh.joints / mesh.weights filled when rigged
  Skeleton skeleton;              // empty for an unrigged scan
  Landmarks landmarks;
  std::vector<BodyPart> parts;    // one per vertex
  Measurements measurements;
};

// ---- Bodies from measurements -------------------------------------------------------------------

// Requested measurements by key (see measurement_table), metres. Keys not given take values
// proportional to the given height from an average adult of that sex.
using MeasurementRequest = std::map<std::string, float, std::less<>>;

// Parses "height=1.70,bust=0.92,..." (metres). InputError("--measurements", ...) on an unknown key,
// a malformed number or a value outside what a person can measure.
MeasurementRequest parse_measurements(std::string_view text);

// Which skeleton make_human_body rigs its body with: MakeHuman's default skeleton reduced to drape's
// CMU-named joints (Hips, Spine, Spine1, Neck, Head, Left/Right Shoulder, Arm, ForeArm, Hand, UpLeg,
// Leg, Foot, ToeBase: the joints rig_body places), or MakeHuman's cmu_mb skeleton (31 joints, CMU
// motion-builder names: LHipJoint, LowerBack, Neck1, LeftFingerBase, LThumb, ...). docs/bodies.md.
enum class BodySkeleton { Drape, CmuMb };

struct BodyBuildOptions {
  float grid_step = 0.011f;  // make_body (the generator): polygonisation step (metres), ~30k triangles
  int max_fit_iterations = 8;  // make_body: fitting rounds
  BodySkeleton skeleton = BodySkeleton::Drape;  // make_human_body: the rig
};

// A body that looks like a person, made on MakeHuman's CC0 base mesh (A-pose, 13,380 vertices,
// watertight, no self-intersections), whose measurements, taken back off the mesh by measure_body,
// match every requested key within 1 cm: the weight and height macros and one MakeHuman measurement
// target per key are solved for. Height is always fitted (the average adult's when not given);
// keys not given stay as MakeHuman's average body of that build has them. Rigged from MakeHuman's
// skeleton (options.skeleton) and skinned with its weights. InputError("measurements") for a
// combination no human body has (underbust above bust, waist and hips far apart, an inseam outside
// 36-56 % of the height, a wrist not smaller than the upper arm, thighs larger than the hips). A
// combination beyond the targets' range is built as close as it gets: compare body.measurements
// with the request (`drape body` names such keys and marks them "within_1cm": false).
Body make_human_body(Sex sex, const MeasurementRequest& request, const BodyBuildOptions& options = {});

// drape's parametric generator (implicit sweeps around a skeleton, polygonised; docs/bodies.md):
// a smooth, watertight, rigged mannequin whose measurements match the request within 1 cm where the
// shape can reach it (what the default bodies, and the dressing tests' bodies, are made with).
// InputError("--measurements") when the request is not self-consistent enough to build.
Body make_body(Sex sex, const MeasurementRequest& request, const BodyBuildOptions& options = {});

// The built-in average adult female (1.65 m) and male (1.78 m): make_human_body on
// default_body_request. Their shapes are solved for when drape is built and compiled into the
// binary (src/default_bodies), so this only builds, analyses and rigs the body, once per process
// and sex. Defined in drape_default_bodies.
Body default_body(Sex sex);
// The average adult of that sex (default_measurements) without shoulder width and back length,
// which follow from the shape: what the default bodies are made to.
MeasurementRequest default_body_request(Sex sex);
// The generator's average adult: make_body on default_body_request. Options (a finer grid) give it
// at another resolution (the benchmarks' fine body).
Body generate_default_body(Sex sex, const BodyBuildOptions& options = {});
// The generator's last step, on the mesh it settled on: named, analysed, rigged.
Body finish_generated_body(Sex sex, Mesh mesh);
// Average measurements of an adult of that sex, every key.
MeasurementRequest default_measurements(Sex sex);

// ---- Bodies from files --------------------------------------------------------------------------

// Loads a scan (OBJ/PLY) or a rigged glTF/GLB, converts units and up axis (options), turns it to face
// +Z (see docs/bodies.md), puts the feet on y = 0 and centres it in x and z, then finds landmarks,
// measurements and parts. A glTF skin is kept; an unrigged body gets a skeleton and weights from its
// landmarks. InputError naming the file when there is no mesh or the height is not 0.5-2.5 m.
Body load_body(const std::filesystem::path& path, const LoadOptions& options = {});

// Normalises placement and orientation as load_body does; `source` names the input in errors.
// Returns the rigid transform applied (rotation about Y, then translation).
Eigen::Affine3f normalise_body_placement(Mesh& mesh, const std::string& source);

// ---- Analysis of any standing body (A- or T-pose, normalised placement) --------------------------

// InputError(source, ...) when the landmarks cannot be found (not a standing person).
Landmarks find_landmarks(const Mesh& mesh, const std::string& source = "body");
Measurements measure_body(const Mesh& mesh, const Landmarks& landmarks);
std::vector<BodyPart> segment_body(const Mesh& mesh, const Landmarks& landmarks);

// Landmarks, measurements and parts in one go (fills body.landmarks/measurements/parts).
void analyse_body(Body& body, const std::string& source = "body");

// A skeleton placed from the landmarks and smooth skin weights (distance to bones, restricted to
// the vertex's body part and its neighbours, top 4, normalised). Fills skeleton, mesh.joints/weights.
void rig_body(Body& body);

// The body as a glTF scene: node `body` with the skinned mesh, joint nodes, one skin.
Scene body_scene(const Body& body);

}  // namespace drape
