// What `drape animate` writes: anim.glb (the skinned body with its joint animation, each garment's
// frames as morph targets under a weight animation), frames.png (a contact sheet), report.json and
// a video a person can watch: anim.mp4 when ffmpeg is on the PATH (drape does not link a video
// encoder: Debian's ffmpeg command line is the well-kept one), else the frames as PNG files.
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <fstream>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "drape/animate.hpp"
#include "drape/files.hpp"
#include "drape/io.hpp"
#include "drape/render.hpp"
#include "fit/quality_json.hpp"

namespace drape {
namespace {

double number(double v) { return std::isfinite(v) ? v : 0.0; }

std::vector<std::string> garment_node_names(const AnimationResult& r) {
  std::vector<std::string> used{"body"}, out;
  for (const DressedGarment& g : r.dressed.garments) {
    std::string name = g.name.empty() ? "garment" : g.name;
    for (int k = 2; std::find(used.begin(), used.end(), name) != used.end(); ++k) name = fmt::format("{}_{}", g.name, k);
    used.push_back(name);
    out.push_back(name);
  }
  return out;
}

// The scene of one frame for pictures: the skinned body and the garments.
struct FrameMeshes {
  Mesh body;
  std::vector<Mesh> garments;
};
FrameMeshes frame_meshes(const Body& body, const AnimationResult& r, const std::vector<Vec3f>& skin, size_t f) {
  FrameMeshes m;
  m.body.positions = skin;
  m.body.triangles = body.mesh.triangles;
  m.body.normals = vertex_normals(m.body.positions, m.body.triangles);
  for (size_t g = 0; g < r.dressed.garments.size(); ++g) {
    Mesh gm;
    gm.positions = r.positions[g][f];
    gm.triangles = r.dressed.garments[g].model.triangles;
    gm.normals = vertex_normals(gm.positions, gm.triangles);
    m.garments.push_back(std::move(gm));
  }
  return m;
}

Image render_frame(const FrameMeshes& m, const RenderOptions& o) {
  std::vector<RenderItem> items{body_item(m.body)};
  for (size_t g = 0; g < m.garments.size(); ++g) items.push_back(garment_item(m.garments[g], g));
  return render_views(items, o);
}

void blit(Image& dst, const Image& src, int x0, int y0) {
  for (int y = 0; y < src.height && y0 + y < dst.height; ++y)
    for (int x = 0; x < src.width && x0 + x < dst.width; ++x) std::copy_n(src.pixel(x, y), 3, dst.pixel(x0 + x, y0 + y));
}

// ffmpeg on the PATH, or empty.
std::string find_ffmpeg() {
  const char* path = std::getenv("PATH");
  if (!path) return {};
  std::string_view rest(path);
  while (!rest.empty()) {
    const size_t colon = rest.find(':');
    const std::filesystem::path candidate = std::filesystem::path(std::string(rest.substr(0, colon))) / "ffmpeg";
    if (::access(candidate.c_str(), X_OK) == 0) return candidate.string();
    rest = colon == std::string_view::npos ? std::string_view() : rest.substr(colon + 1);
  }
  return {};
}

std::string shell_quote(const std::string& s) {
  std::string out = "'";
  for (char c : s) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return out + "'";
}

}  // namespace

Scene animation_scene(const Body& body, const AnimationResult& r) {
  Scene scene = body_scene(body);
  const BodyAnimation& a = r.body;
  const size_t frames = r.frames.size();
  Animation anim;
  anim.name = "motion";
  std::vector<float> times(frames);
  for (size_t f = 0; f < frames; ++f) times[f] = static_cast<float>(static_cast<double>(f) * a.frame_time);
  if (frames >= 2 && !body.skeleton.empty()) {
    // Joint j is node 1 + j (body_scene). Local rotation = parent's world^-1 world (bind rotations
    // are the identity); translation only where a joint does not follow its parent rigidly (the root).
    for (size_t j = 0; j < a.joint_count; ++j) {
      const int parent = body.skeleton.joints[j].parent;
      AnimationChannel rot{static_cast<int>(1 + j), AnimationPath::Rotation, Interpolation::Linear, times, {}};
      AnimationChannel tr{static_cast<int>(1 + j), AnimationPath::Translation, Interpolation::Linear, times, {}};
      bool moves = false;
      Quatf previous = Quatf::Identity();
      for (size_t f = 0; f < frames; ++f) {
        const PoseView p = a.pose(f);
        Quatf local = parent < 0 ? p.rotation[j] : Quatf(p.rotation[static_cast<size_t>(parent)].conjugate() * p.rotation[j]);
        local.normalize();
        if (f > 0 && local.coeffs().dot(previous.coeffs()) < 0) local.coeffs() *= -1;  // no long way round
        previous = local;
        rot.values.insert(rot.values.end(), {local.x(), local.y(), local.z(), local.w()});
        const Vec3f rest = parent < 0 ? body.skeleton.joints[j].position
                                      : Vec3f(body.skeleton.joints[j].position - body.skeleton.joints[static_cast<size_t>(parent)].position);
        const Vec3f t = parent < 0 ? p.position[j]
                                   : Vec3f(p.rotation[static_cast<size_t>(parent)].conjugate() * (p.position[j] - p.position[static_cast<size_t>(parent)]));
        moves = moves || (t - rest).norm() > 1e-5f;
        tr.values.insert(tr.values.end(), {t.x(), t.y(), t.z()});
      }
      anim.channels.push_back(std::move(rot));
      if (moves) anim.channels.push_back(std::move(tr));
    }
  }
  if ((r.soft_body || r.skin_layer) && frames >= 2) {
    // The body as it gave way (a soft body) and as the skin layer kept its parts apart: frame f's
    // displacement in the bind pose is morph target f (glTF morphs before it skins, as the
    // simulation did), sparse over the vertices that moved.
    Mesh& m = scene.meshes[static_cast<size_t>(scene.nodes[0].mesh)];
    for (size_t f = 0; f < frames; ++f) {
      MorphTarget t;
      t.name = fmt::format("frame_{}", f);
      t.position_deltas.assign(m.positions.size(), Vec3f::Zero());
      add_body_displacement(r, f, t.position_deltas);
      m.morph_targets.push_back(std::move(t));
    }
    m.morph_weights.assign(frames, 0.0f);
    m.morph_weights[0] = 1.0f;
    AnimationChannel w{0, AnimationPath::Weights, Interpolation::Linear, times, {}};
    w.values.assign(frames * frames, 0.0f);
    for (size_t f = 0; f < frames; ++f) w.values[f * frames + f] = 1.0f;
    anim.channels.push_back(std::move(w));
  }
  const std::vector<std::string> names = garment_node_names(r);
  for (size_t g = 0; g < r.dressed.garments.size(); ++g) {
    const DressedGarment& dg = r.dressed.garments[g];
    Mesh m = dg.mesh();
    m.name = names[g];
    const std::vector<Vec3f>& base = r.positions[g][0];
    m.positions = base;
    m.normals = vertex_normals(m.positions, m.triangles);
    // Frame f (f >= 1) is morph target f - 1.
    for (size_t f = 1; f < frames; ++f) {
      MorphTarget t;
      t.name = fmt::format("frame_{}", f);
      t.position_deltas.resize(base.size());
      for (size_t v = 0; v < base.size(); ++v) t.position_deltas[v] = r.positions[g][f][v] - base[v];
      m.morph_targets.push_back(std::move(t));
    }
    m.morph_weights.assign(m.morph_targets.size(), 0.0f);
    const int node = add_mesh_node(scene, std::move(m), names[g]);
    if (frames >= 2) {
      AnimationChannel w{node, AnimationPath::Weights, Interpolation::Linear, times, {}};
      w.values.assign(frames * (frames - 1), 0.0f);
      for (size_t f = 1; f < frames; ++f) w.values[f * (frames - 1) + (f - 1)] = 1.0f;
      anim.channels.push_back(std::move(w));
    }
  }
  if (!anim.channels.empty()) scene.animations.push_back(std::move(anim));
  return scene;
}

std::string animation_report_json(const Motion& motion, const AnimationResult& r, const AnimateOptions& o) {
  nlohmann::ordered_json j;
  nlohmann::ordered_json frames = nlohmann::ordered_json::array();
  for (size_t f = 0; f < r.frames.size(); ++f)
    frames.push_back({{"frame", f},
                      {"time_s", r.frames[f].time},
                      {"quality", quality_json(r.frames[f].quality)},
                      {"drop_m", number(r.frames[f].quality.drop_m)},
                      {"lowest_y_m", number(r.frames[f].quality.lowest_y)},
                      {"newton_iterations", r.frames[f].newton_iterations},
                      {"vertices_through_layers", r.frames[f].vertices_through_layers}});
  if (r.skin_layer)
    for (size_t f = 0; f < r.frames.size(); ++f)
      frames[f]["skin_layer"] = {{"vertices_inside_skinned", r.frames[f].skin_inside_skinned},
                                 {"vertices_inside", r.frames[f].skin_inside}};
  j["quality"] = quality_json(r.worst);
  j["frames"] = frames;
  j["worst_frame"] = r.worst_frame;
  const size_t simulated = r.frames.size() > 1 ? r.frames.size() - 1 : 0;
  j["simulation"] = {{"frames", r.frames.size()},
                     {"frames_simulated", simulated},
                     {"wall_seconds", number(r.simulation_seconds)},
                     {"frames_per_wall_second", number(r.frames_per_wall_second())},
                     {"solver", "implicit"},
                     {"time_step_s", r.time_step},
                     {"steps_per_frame_at_least", o.substeps},
                     {"solver_steps", r.solver_steps},
                     {"frames_retaken", r.frames_retaken},
                     {"collision", std::string(to_string(o.collision))},
                     {"skinning", std::string(to_string(o.skinning))},
                     {"status", std::string(to_string(r.status))},
                     {"newton_iterations", r.profile.newton_iterations},
                     {"factorizations", r.profile.factorizations},
                     {"stage_seconds",
                      {{"skinning", r.skinning_seconds},
                       {"collider", r.collider_seconds},
                       {"contacts", r.profile.contacts},
                       {"self_contacts", r.profile.self_contacts},
                       {"assemble", r.profile.assemble},
                       {"factorize", r.profile.factorize},
                       {"solve", r.profile.solve},
                       {"line_search", r.profile.line_search},
                       {"block_sweeps", r.profile.sweeps}}},
                     {"measure_seconds", r.measure_seconds},
                     {"dress_seconds", r.dress_seconds},
                     {"retarget_seconds", r.retarget_seconds}};
  nlohmann::ordered_json gates = nlohmann::ordered_json::array();
  std::vector<std::string> failed;
  for (const GateResult& g : r.gates) {
    gates.push_back({{"name", g.name}, {"passed", g.passed}, {"value", number(g.value)}, {"limit", number(g.limit)}, {"detail", g.detail}});
    if (!g.passed) failed.push_back(g.name);
  }
  j["gates"] = {{"passed", failed.empty()}, {"failed", failed}, {"checks", gates}};
  const BodyAnimation& a = r.body;
  j["motion"] = {{"file", motion.source},
                 {"format", motion.format},
                 {"up_axis", motion.up == UpAxis::Z ? "z" : "y"},
                 {"joints", motion.joint_count()},
                 {"frames", motion.frame_count},
                 {"frame_time_s", motion.frame_time},
                 {"skeleton", a.motion_convention},
                 {"skipped_calibration_frame", a.skipped_calibration},
                 {"frames_used", {a.motion_first, a.motion_last}}};
  j["retarget"] = {{"body_skeleton", a.body_convention},
                   {"joints", a.mapped},
                   {"fps", 1.0 / a.frame_time},
                   {"blend_frames", a.blend_frames},
                   {"root_scale", a.root_scale},
                   {"feet",
                    {{"lowest_y_m", a.feet.lowest_y},
                     {"floor_shift_m", a.feet.floor_shift_m},
                     {"floor_slope_m_per_s", a.feet.floor_slope_m_per_s},
                     {"contact_fraction", a.feet.contact_fraction},
                     {"sliding_m", a.feet.sliding_m},
                     {"max_sliding_speed_m_per_s", a.feet.max_sliding_speed}}},
                   {"joint_ranges",
                    {{"knee_flexion_deg", {a.limits.min_knee_flexion_deg, a.limits.max_knee_flexion_deg}},
                     {"elbow_flexion_deg", {a.limits.min_elbow_flexion_deg, a.limits.max_elbow_flexion_deg}},
                     {"neck_bend_deg", a.limits.max_neck_bend_deg},
                     {"violations", a.limits.violations}}}};
  nlohmann::ordered_json garments = nlohmann::ordered_json::array();
  for (size_t i = 0; i < r.dressed.garments.size(); ++i) {
    const DressedGarment& g = r.dressed.garments[i];
    garments.push_back({{"name", g.name}, {"size", g.size}, {"fabric", g.fabric}, {"vertices", g.model.particle_count()},
                        {"strain_threshold", g.model.fabric.strain_threshold}});
    if (i < r.friction.size()) garments.back()["friction"] = r.friction[i];
  }
  j["garments"] = garments;
  j["dressing"] = {{"passed", r.dressed.passed()}, {"quality", quality_json(r.dressed.quality)}};
  if (r.soft_body) {
    nlohmann::ordered_json regions = nlohmann::ordered_json::array();
    for (const SoftRegionState& g : r.soft_body->worst)
      regions.push_back({{"name", g.name},
                         {"vertices", g.vertices},
                         {"volume_change", g.volume_change},
                         {"compression_m", g.compression_m},
                         {"bulge_m", g.bulge_m}});
    j["soft_body"] = {{"regions", regions},
                      {"newton_iterations", r.soft_body->newton_iterations},
                      {"seconds", r.soft_body->seconds},
                      {"seconds_per_frame", simulated ? r.soft_body->seconds / static_cast<double>(simulated) : 0.0}};
  }
  if (r.skin_layer) {
    const AnimatedSkinLayer& k = *r.skin_layer;
    j["skin_layer"] = {{"gap_m", k.gap_m},
                       {"vertices_inside_skinned", k.inside_skinned},
                       {"max_depth_skinned_m", k.depth_skinned_m},
                       {"vertices_inside", k.inside},
                       {"max_depth_m", k.depth_m},
                       {"max_move_m", k.max_move_m},
                       {"contacts", k.contacts},
                       {"seconds", k.seconds},
                       {"seconds_per_frame", r.frames.empty() ? 0.0 : k.seconds / static_cast<double>(r.frames.size())}};
  }
  return j.dump(2) + "\n";
}

std::filesystem::path write_animation_outputs(const std::filesystem::path& dir, const Body& body, const Motion& motion,
                                              const AnimationResult& r, const AnimateOptions& o,
                                              const AnimationOutputOptions& out) {
  const std::vector<std::vector<Vec3f>> skin = animated_body_frames(body, r, o.skinning);
  const size_t frames = r.frames.size();

  // One scale for every picture, from the body's extent over the whole clip.
  Bounds all;
  for (size_t f = 0; f < frames; ++f)
    for (size_t v = 0; v < skin[f].size(); v += 7) all.extend(skin[f][v]);
  const float height = std::max(all.size().y(), 1.0f);

  // Contact sheet: up to 12 frames, front view, evenly spaced, the worst frame among them.
  std::vector<size_t> picked;
  const size_t count = std::min<size_t>(12, frames);
  for (size_t k = 0; k < count; ++k) picked.push_back(count == 1 ? 0 : k * (frames - 1) / (count - 1));
  if (std::find(picked.begin(), picked.end(), r.worst_frame) == picked.end() && !picked.empty()) picked[picked.size() / 2] = r.worst_frame;
  std::sort(picked.begin(), picked.end());
  RenderOptions cell;
  cell.width = 240;
  cell.height = 360;
  cell.views = {{"front", 0.0f}};
  cell.supersample = 2;
  cell.view_labels = false;
  cell.pixels_per_metre = 0.85f * static_cast<float>(cell.height) / height;
  const int columns = static_cast<int>(std::min<size_t>(6, picked.size()));
  const int rows = static_cast<int>((picked.size() + 5) / 6);
  Image sheet(columns * cell.width, rows * (cell.height + 18), Vec3f::Ones());
  for (size_t k = 0; k < picked.size(); ++k) {
    const size_t f = picked[k];
    const Image img = render_frame(frame_meshes(body, r, skin[f], f), cell);
    const int x = static_cast<int>(k % 6) * cell.width, y = static_cast<int>(k / 6) * (cell.height + 18);
    blit(sheet, img, x, y + 18);
    draw_text(sheet, x + 6, y + 3,
              fmt::format("frame {} t={:.2f}s{}", f, r.frames[f].time, f == r.worst_frame ? " (worst)" : ""),
              srgb8(40, 40, 40));
  }

  // The video: front and side per frame.
  std::filesystem::path video;
  std::vector<std::vector<uint8_t>> video_frames;
  if (out.video) {
    RenderOptions v;
    v.width = out.video_width;
    v.height = out.video_height;
    v.views = {{"front", 0.0f}, {"side", 270.0f}};
    v.supersample = 1;
    v.ambient_occlusion = false;
    v.pixels_per_metre = 0.85f * static_cast<float>(v.height) / height;
    for (size_t f = 0; f < frames; ++f) {
      v.title = fmt::format("t = {:.2f} s", r.frames[f].time);
      video_frames.push_back(encode_png(render_frame(frame_meshes(body, r, skin[f], f), v)));
    }
  }

  // Everything is made before anything is written.
  const std::vector<unsigned char> glb = encode_glb(animation_scene(body, r));
  const std::string report = animation_report_json(motion, r, o);
  write_file_atomic(dir / "anim.glb", glb);
  write_png(dir / "frames.png", sheet);
  if (out.video) {
    const std::string ffmpeg = find_ffmpeg();
    const std::filesystem::path frame_dir = ffmpeg.empty() ? dir / "frames" : dir / ".anim_frames.tmp";
    std::filesystem::remove_all(frame_dir);
    for (size_t f = 0; f < video_frames.size(); ++f)
      write_file_atomic(frame_dir / fmt::format("frame_{:04d}.png", f), video_frames[f]);
    video = frame_dir;
    if (!ffmpeg.empty()) {
      const std::filesystem::path tmp = dir / ".anim.tmp.mp4";
      const std::string cmd = fmt::format("{} -loglevel error -y -framerate {} -i {} -pix_fmt yuv420p -vf {} {}", shell_quote(ffmpeg),
                                          1.0 / r.body.frame_time, shell_quote((frame_dir / "frame_%04d.png").string()),
                                          shell_quote("pad=ceil(iw/2)*2:ceil(ih/2)*2"), shell_quote(tmp.string()));
      const int rc = std::system(cmd.c_str());
      std::filesystem::remove_all(frame_dir);
      if (rc != 0) {
        std::filesystem::remove(tmp);
        throw std::runtime_error(fmt::format("ffmpeg could not write {}", (dir / "anim.mp4").string()));
      }
      std::filesystem::rename(tmp, dir / "anim.mp4");
      video = dir / "anim.mp4";
    }
  }
  write_file_atomic(dir / "report.json", report);
  return video;
}

}  // namespace drape
