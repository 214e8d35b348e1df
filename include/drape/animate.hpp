#pragma once
// Dressed bodies in motion (Vassilev & Spanlang sec. 5; Cordier et al.): the garments are dressed on
// the body's bind pose (drape::dress), the motion is retargeted onto the body's rig, and the cloth
// is simulated on the skinned body frame by frame, its collider following the skin at every solver
// step (positions interpolated between frames, with the skin's velocity). See docs/animation.md.
//
//   AnimationResult r = animate(body, {{load_garment("shirt"), ""}}, read_motion("walk.bvh"), {});
//   write_animation_outputs("out", body, r, {});   // anim.glb, frames.png, report.json, the frames
#include <cstdint>
#include <filesystem>
#include <functional>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "drape/dress.hpp"
#include "drape/motion.hpp"
#include "drape/skin_layer.hpp"
#include "drape/soft_body.hpp"

namespace drape {

struct AnimateOptions {
  RetargetOptions retarget;                          // fps, frames, blend, calibration frame
  Skinning skinning = Skinning::Linear;
  DressOptions dress;                                // how the garments are dressed on the bind pose first
  CollisionMethod collision = CollisionMethod::bvh;  // the moving body's collider
  int substeps = 1;                                  // implicit solver steps per frame, at least
  // More steps in a frame where the body moves fast: enough that 95 % of the body's vertices near
  // the garments move at most this far in one step (m), so the cloth is not passed through (the
  // walk: 2.3 steps a frame, a run: 4.8). 3 cm, with each step started where the body carries the
  // cloth (ImplicitSolver::step): at 6 cm the walking shirt ended frames with 1.5 % of its vertices
  // inside the body, at 4 cm the run's shirt at 4 cm cells a frame 10.2 % stretched (the run's
  // test), and 8 Newton iterations a step at 4 cm took longer than 6 at 3 cm (docs/animation.md).
  float max_body_step = 0.03f;
  // Coulomb coefficient between cloth and the moving skin, which carries the cloth along with the
  // body; negative (the default): the fabric's.
  float friction = -1.0f;
  // Gates every frame must pass (docs/animation.md): at most 1 % of the garment vertices inside the
  // body, strain at most the fabric's threshold + 2 %, seams within 5 mm, nothing below the floor,
  // no garment sliding off (its centre 15 cm lower against the hips than when dressed), no NaN.
  QualityGates gates{0.005f, 0.01, 0.02f, 0.0f, 0.15f};
  // The skin layer (drape/skin_layer.hpp, Cordier et al.): each frame's skinned body is the
  // reference of a physical skin, and where skinning drives one body part into another (hands
  // lowered onto the hips, an arm against the torso) their skin is pushed apart, equal and opposite,
  // before the cloth meets it. The gap kept is at least twice the garments' thicknesses (a layer
  // of each garment on either skin), so the cloth caught between has room.
  bool skin_layer = false;
  SkinLayerOptions skin;
};

// One frame's measures: DESIGN.md's `quality` keys over all garments (settled: every solver step
// of the frame converged; residual: the largest of the frame's last step) and the drop.
struct AnimationFrame {
  double time = 0;  // s
  FitQuality quality;
  int newton_iterations = 0;
  // Outer garments' vertices that went through a garment beneath them (vertices_beneath), summed
  // over the layers; reported, not gated.
  size_t vertices_through_layers = 0;
  // With AnimateOptions::skin_layer: skin vertices more than 1 mm inside another body part, as
  // skinning left them and as the skin layer did.
  size_t skin_inside_skinned = 0, skin_inside = 0;
};

struct AnimationProgress {
  const char* phase = "";  // "dressing", "retargeting", "simulating"
  size_t frame = 0, frames = 0;
};
using AnimationProgressCallback = std::function<void(const AnimationProgress&)>;

// The body giving way in motion (DressOptions::soft_body, docs/soft-body.md): the support springs
// work in the bind pose, where the body was dressed. After each frame the cloth's contact forces
// (ImplicitSolver::contact_forces; their reaction, equal and opposite, spread over the skin) are
// turned into the bind pose by each vertex's rotation, the soft regions come to rest under them
// from where they were, and the next frame's body is the bind pose so displaced, skinned: the skin
// follows the skeleton and gives way where the cloth presses.
struct AnimatedSoftBody {
  std::vector<uint32_t> vertices;                // the soft regions' body vertices
  std::vector<std::vector<Vec3f>> displacement;  // per frame, per listed vertex: its move in the bind pose (m)
  // Per region, the most over the frames: volume change (by magnitude, its sign kept), compression
  // and bulge.
  std::vector<SoftRegionState> worst;
  double seconds = 0;         // wall: the forces handed to the body and its solves, every frame
  int newton_iterations = 0;  // of the body's solves
};

// The skin layer in motion (AnimateOptions::skin_layer): per frame, the skin's moves off the
// skinned body, turned into the bind pose (morphed before it is skinned, they give the skin as the
// cloth met it), over the vertices that moved.
struct AnimatedSkinLayer {
  std::vector<std::vector<uint32_t>> vertices;   // per frame
  std::vector<std::vector<Vec3f>> displacement;  // per frame, per listed vertex (m, bind pose)
  float gap_m = 0;
  // The most over the frames: vertices inside another body part, skinned and with the skin layer,
  // and their deepest; the largest move of a vertex off the skinned body.
  size_t inside_skinned = 0, inside = 0;
  float depth_skinned_m = 0, depth_m = 0, max_move_m = 0;
  size_t contacts = 0;  // the most contacts in a frame
  double seconds = 0;   // wall: the skin layer's solves (its measures not counted)
};

struct AnimationResult {
  BodyAnimation body;                      // the body's skeleton per frame
  DressResult dressed;                     // the garments on the bind pose (frame 0)
  // positions[g][f]: garment g's particles in frame f.
  std::vector<std::vector<std::vector<Vec3f>>> positions;
  std::vector<AnimationFrame> frames;
  size_t worst_frame = 0;                  // most vertices inside the body, then the highest strain
  FitQuality worst;                        // the worst of every key over the frames
  std::vector<GateResult> gates;
  StepStatus status = StepStatus::Ok;
  double dress_seconds = 0, retarget_seconds = 0;
  double simulation_seconds = 0;           // wall, the frames after the first (skinning, collider, cloth)
  double skinning_seconds = 0, collider_seconds = 0, measure_seconds = 0;
  ImplicitProfile profile;
  double time_step = 0;                    // s, the longest solver step
  uint64_t solver_steps = 0;               // over all frames (per garment), retaken ones included
  size_t frames_retaken = 0;               // frames taken again in shorter steps (past the strain gate)
  std::vector<float> friction;             // per garment: its Coulomb coefficient against the moving body
  std::optional<AnimatedSoftBody> soft_body;  // with DressOptions::soft_body
  std::optional<AnimatedSkinLayer> skin_layer;  // with AnimateOptions::skin_layer
  bool passed() const { return all_passed(gates); }
  double frames_per_wall_second() const;
};

// Dresses, retargets and simulates. InputError for bad garments, an unrigged body or a motion that
// does not fit it (naming the file or joint).
AnimationResult animate(const Body& body, const std::vector<GarmentRequest>& garments, const Motion& motion,
                        const AnimateOptions& options = {}, const AnimationProgressCallback& progress = {});

// The body's vertices in every frame (frames x vertices), skinned as the simulation saw them.
std::vector<std::vector<Vec3f>> skinned_frames(const Body& body, const BodyAnimation& animation, Skinning method);
// The body's vertices in every frame of an animation, as the cloth saw them: skinned, and with a
// soft body or the skin layer, displaced in the bind pose where it gave way first.
std::vector<std::vector<Vec3f>> animated_body_frames(const Body& body, const AnimationResult& result, Skinning method);
// Adds frame f's displacement of the body in the bind pose (a soft body's, the skin layer's) to
// `bind` (every body vertex); nothing without either.
void add_body_displacement(const AnimationResult& result, size_t frame, std::span<Vec3f> bind);

// anim.glb's scene: node `body` skinned, its joints animated (rotations; the root's translation),
// then one node per garment whose frames are morph targets with a weight animation (frame f: the
// f-th target at weight 1, linear in between).
Scene animation_scene(const Body& body, const AnimationResult& result);
// report.json: `frames` (DESIGN.md's quality keys per frame), `worst_frame`, `quality` (the worst
// over the frames), `simulation` (frames, wall_seconds, frames_per_wall_second, ...), the gates,
// and what retargeting did.
std::string animation_report_json(const Motion& motion, const AnimationResult& result, const AnimateOptions& options);

struct AnimationOutputOptions {
  int video_width = 640, video_height = 360;  // front and side views per frame
  bool video = true;                          // anim.mp4 (ffmpeg on the PATH) or frames/frame_NNNN.png
};
// Writes anim.glb, frames.png (a contact sheet of up to 12 frames), report.json and the video
// (anim.mp4 when ffmpeg is found, else frames/frame_NNNN.png) into `dir`, each file atomically.
// Returns the video's path (empty without one).
std::filesystem::path write_animation_outputs(const std::filesystem::path& dir, const Body& body, const Motion& motion,
                                              const AnimationResult& result, const AnimateOptions& options,
                                              const AnimationOutputOptions& output = {});

}  // namespace drape
