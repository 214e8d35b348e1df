// `drape animate`: dresses a body on its bind pose, retargets a motion onto its rig and simulates the
// garments on the moving body. Writes DIR/anim.glb, DIR/frames.png, DIR/report.json and a video
// (DIR/anim.mp4 with ffmpeg, else DIR/frames/). Exit 2 on bad input (nothing written), 3 when a
// frame failed a quality gate (outputs written, report.json's `gates.failed` names it).
#include <omp.h>

#include <charconv>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "commands.hpp"
#include "drape/animate.hpp"
#include "drape/error.hpp"
#include "progress.hpp"

namespace drape::app {
namespace {

struct AnimateArgs {
  std::string body = "female";
  std::vector<std::string> garments;
  std::vector<std::string> sizes;
  std::string motion;
  std::string joint_map;
  double fps = 30;
  std::string frames;
  double blend = 0.5;
  bool keep_first_frame = false;
  std::string motion_up = "auto";
  std::string skinning = "linear";
  std::string collision = "bvh";
  std::string dress_solver = "implicit";
  bool soft_body = false;
  bool skin_layer = false;
  int substeps = 1;
  double edge = kPaperEdgeLength;
  float friction = AnimateOptions{}.friction;
  int threads = 0;
  bool no_video = false;
  std::string out = "out";
  LoadOptions load;
};

long parse_frame(std::string_view s, std::string_view whole) {
  long v = 0;
  const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
  if (ec != std::errc() || end != s.data() + s.size() || v < 0)
    throw InputError("--frames", "'" + std::string(whole) + "' is not FIRST:LAST (motion frames, e.g. 0:120 or 30:)");
  return v;
}

void run_animate(const AnimateArgs& a) {
  AnimateOptions o;
  o.retarget.fps = a.fps;
  o.retarget.blend_seconds = a.blend;
  o.retarget.skip_calibration = !a.keep_first_frame;
  if (!a.frames.empty()) {
    const size_t colon = a.frames.find(':');
    if (colon == std::string::npos) throw InputError("--frames", "'" + a.frames + "' is not FIRST:LAST (e.g. 0:120 or 30:)");
    o.retarget.first_frame = parse_frame(std::string_view(a.frames).substr(0, colon), a.frames);
    const std::string_view last = std::string_view(a.frames).substr(colon + 1);
    o.retarget.last_frame = last.empty() ? -1 : parse_frame(last, a.frames);
  }
  o.skinning = a.skinning == "dq" ? Skinning::DualQuaternion : Skinning::Linear;
  o.collision = *parse_collision_method(a.collision);
  o.substeps = a.substeps;
  o.friction = a.friction;
  if (!(a.edge >= 0.002 && a.edge <= 0.2)) throw InputError("--edge", "the edge length must be in [0.002, 0.2] m");
  o.dress.mesh.edge_length = a.edge;
  o.dress.solver = a.dress_solver == "explicit" ? Solver::Explicit : Solver::Implicit;
  if (a.soft_body) {
    // The body gives way under the implicit solver's contact forces: dressed with it too.
    if (o.dress.solver != Solver::Implicit)
      throw InputError("--soft-body", "needs the implicit dressing (--dress-solver implicit)");
    o.dress.soft_body = true;
  }
  o.skin_layer = a.skin_layer;
  if (a.threads > 0) omp_set_num_threads(a.threads);

  // Everything the user gave is read and checked before the long work starts.
  MotionOptions mo;
  mo.up = a.motion_up == "y" ? MotionUp::Y : a.motion_up == "z" ? MotionUp::Z : MotionUp::Auto;
  const Motion motion = read_motion(a.motion, mo);
  JointMap map;
  if (!a.joint_map.empty()) {
    map = read_joint_map(a.joint_map, motion.names);
    o.retarget.motion_map = &map;
  }
  std::vector<std::string> names = a.garments;
  if (names.empty()) names.push_back(default_garment_name());
  if (a.sizes.size() > 1 && a.sizes.size() != names.size())
    throw InputError("--size", "give one size for all garments or one per --garment");
  std::vector<GarmentRequest> requests;
  for (size_t i = 0; i < names.size(); ++i) {
    GarmentRequest r{load_garment(names[i]), a.sizes.empty() ? std::string() : a.sizes.size() == 1 ? a.sizes[0] : a.sizes[i]};
    garment_in_size(r.spec, r.size);
    requests.push_back(std::move(r));
  }
  Body body;
  if (a.body == "female" || a.body == "male") {
    body = default_body(a.body == "male" ? Sex::Male : Sex::Female);
  } else {
    if (!std::filesystem::exists(a.body)) throw InputError(a.body, "no such body file (or use --body female|male)");
    body = load_body(a.body, drape::load_options(a.load.units, a.load.up));
  }

  std::fprintf(stderr, "animating a %.2f m body (%zu triangles, %zu joints) with %s\n",
               static_cast<double>(body.measurements.height), body.mesh.triangle_count(), body.skeleton.joints.size(),
               a.motion.c_str());
  Progress progress("animating", 1.0);
  const AnimationResult r = animate(body, requests, motion, o, [&](const AnimationProgress& p) {
    progress.update(p.frames ? static_cast<double>(p.frame) / static_cast<double>(p.frames) : 0.0, p.phase);
  });
  progress.finish();
  AnimationOutputOptions out;
  out.video = !a.no_video;
  const std::filesystem::path video = write_animation_outputs(a.out, body, motion, r, o, out);

  const BodyAnimation& b = r.body;
  std::fprintf(stderr,
               "%s -> %s skeleton (%s); %zu frames at %.0f fps (the first %zu blended from the dressed pose), root scale %.4f, "
               "feet: lowest %.1f mm, "
               "sliding %.2f m\n",
               b.motion_convention.c_str(), b.body_convention.c_str(), b.skipped_calibration ? "calibration frame skipped" : "no calibration frame",
               b.frame_count, 1.0 / b.frame_time, b.blend_frames, static_cast<double>(b.root_scale), 1e3 * static_cast<double>(b.feet.lowest_y),
               static_cast<double>(b.feet.sliding_m));
  const FitQuality& q = r.worst;
  std::fprintf(stderr,
               "%s: %zu frames simulated in %.2f s (%.2f frames per wall second); worst frame %zu: max strain %.2f %%, "
               "%.2f %% of the vertices inside the body, seam gap max %.2f mm\n",
               r.passed() ? "animated" : "FAILED quality gates", r.frames.size() > 0 ? r.frames.size() - 1 : 0,
               r.simulation_seconds, r.frames_per_wall_second(), r.worst_frame, 100.0 * static_cast<double>(q.max_strain),
               100.0 * q.penetration_fraction, 1e3 * static_cast<double>(q.max_seam_gap_m));
  if (r.soft_body) {
    std::fprintf(stderr, "soft body: %d Newton iterations in %.2f s (%.1f ms a frame)", r.soft_body->newton_iterations,
                 r.soft_body->seconds, r.frames.size() > 1 ? 1e3 * r.soft_body->seconds / static_cast<double>(r.frames.size() - 1) : 0.0);
    for (const SoftRegionState& g : r.soft_body->worst)
      std::fprintf(stderr, "; %s in %.1f mm, volume %+.2f %%", g.name.c_str(), 1e3 * static_cast<double>(g.compression_m),
                   100.0 * g.volume_change);
    std::fprintf(stderr, "\n");
  }
  if (r.skin_layer) {
    const AnimatedSkinLayer& k = *r.skin_layer;
    std::fprintf(stderr,
                 "skin layer: %.1f mm kept between body parts; skinned, up to %zu vertices inside another part (%.1f mm "
                 "deep); with the skin layer %zu (%.1f mm); skin moved up to %.1f mm; %.1f ms a frame\n",
                 1e3 * static_cast<double>(k.gap_m), k.inside_skinned, 1e3 * static_cast<double>(k.depth_skinned_m), k.inside,
                 1e3 * static_cast<double>(k.depth_m), 1e3 * static_cast<double>(k.max_move_m),
                 r.frames.empty() ? 0.0 : 1e3 * k.seconds / static_cast<double>(r.frames.size()));
  }
  std::fprintf(stderr, "wrote %s/anim.glb, frames.png, report.json%s%s\n", a.out.c_str(), video.empty() ? "" : ", ",
               video.empty() ? "" : video.string().c_str());
  if (!r.passed()) {
    for (const GateResult& g : r.gates)
      if (!g.passed) std::fprintf(stderr, "drape: animate: gate %s failed: %s\n", g.name.c_str(), g.detail.c_str());
    std::exit(kExitQualityGate);
  }
}

}  // namespace

void add_animate_command(CLI::App& app) {
  auto args = std::make_shared<AnimateArgs>();
  CLI::App* cmd = app.add_subcommand(
      "animate", "Dress a body, retarget a motion (BVH, FBX, glTF/GLB) onto its rig and simulate the garments on the moving body");
  cmd->add_option("--body", args->body, "female, male (built-in bodies) or a body file (rigged glTF/GLB, or a scan: rigged from its landmarks)")
      ->capture_default_str();
  cmd->add_option("--garment", args->garments,
                  "built-in garment name (see `drape garments`) or garment file; repeat for layers, outermost last");
  cmd->add_option("--size", args->sizes, "size to make (one for all garments, or one per --garment); default: from the size chart");
  cmd->add_option("--motion", args->motion, "motion file: BVH, FBX (Mixamo's format) or glTF/GLB with an animation")->required();
  cmd->add_option("--joint-map", args->joint_map,
                  "JSON file naming the motion's joint for each joint drape drives, {\"Hips\": \"pelvis\", ...} "
                  "(default: found from the names; docs/animation.md)");
  cmd->add_option("--motion-up", args->motion_up, "the motion file's up axis: auto (FBX: the file's; else from its skeleton), y or z")
      ->capture_default_str()->check(CLI::IsMember({"auto", "y", "z"}));
  cmd->add_option("--fps", args->fps, "frames per second of the animation (the motion is resampled)")
      ->capture_default_str()->check(CLI::Range(1.0, 240.0));
  cmd->add_option("--frames", args->frames, "FIRST:LAST motion frames to use (after a skipped calibration frame), e.g. 0:240 or 30:");
  cmd->add_option("--blend", args->blend, "seconds of lead-in: the motion plays from its first frame while its weight against the dressed pose rises from 0 to 1")
      ->capture_default_str()->check(CLI::Range(0.0, 5.0));
  cmd->add_flag("--keep-first-frame", args->keep_first_frame, "use a calibration T-pose in the motion's first frame as a frame");
  cmd->add_option("--skinning", args->skinning, "linear (blend skinning) or dq (dual quaternion)")
      ->capture_default_str()->check(CLI::IsMember({"linear", "dq"}));
  cmd->add_option("--collision", args->collision, "the moving body's collider: bvh, image or sdf")
      ->capture_default_str()->check(CLI::IsMember({"image", "bvh", "sdf"}));
  cmd->add_option("--dress-solver", args->dress_solver, "solver that dresses the garments on the bind pose first: explicit or implicit")
      ->capture_default_str()->check(CLI::IsMember({"implicit", "explicit"}));
  cmd->add_flag("--soft-body", args->soft_body,
                "let the body give way where the cloth presses, in every frame: its soft regions (belly, buttocks, "
                "thighs, bust, upper arms) on support springs (docs/soft-body.md; dresses with the implicit solver)");
  cmd->add_flag("--skin-layer", args->skin_layer,
                "keep the body's parts out of each other where skinning drives them in (hands lowered onto the hips, an "
                "arm against the torso): a skin on zero-length springs to the skinned body, pushed apart where two parts "
                "meet, with room for the cloth between (docs/soft-body.md)");
  cmd->add_option("--substeps", args->substeps, "implicit solver steps per frame, at least (more where the body moves more than 3 cm in a step)")->capture_default_str()->check(CLI::Range(1, 64));
  cmd->add_option("--edge", args->edge, "cloth edge length in metres (0.026: the paper's; the dress at 0.016 has about 4,000 vertices)")
      ->capture_default_str();
  cmd->add_option("--friction", args->friction,
                  "friction between the cloth and the moving skin, which carries the cloth along with the body "
                  "(Coulomb coefficient; negative: the fabric's)")
      ->capture_default_str()->check(CLI::Range(-1.0, 2.0));
  cmd->add_option("--threads", args->threads, "OpenMP threads (0: all cores)")->check(CLI::Range(0, 1024));
  cmd->add_flag("--no-video", args->no_video, "write no video (anim.mp4 or frames/)");
  cmd->add_option("--out", args->out, "output directory")->capture_default_str();
  add_load_options(*cmd, args->load);
  cmd->callback([args] { run_animate(*args); });
}

}  // namespace drape::app
