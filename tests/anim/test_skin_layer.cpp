// The skin layer (drape/skin_layer.hpp): skinning drives hands lowered along the body into the
// hips; the skin layer keeps the parts apart on every frame, pushing both sides (equal and
// opposite), moves nothing where no parts meet, and in `animate` the cloth caught between keeps
// its room.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>

#include <nlohmann/json.hpp>

#include "drape/animate.hpp"
#include "drape/skin_layer.hpp"
#include "anim_test_support.hpp"
#include "support/gltf_validator.hpp"
#include "support/test_support.hpp"

namespace drape {
namespace {

using test::female;
using test::sanitized;

// The arms-raise clip with both arms taken 15 degrees further down at every frame: where the clip
// lowers them alongside the body (its last frames), linear blend skinning drives the hands into the
// hips of the default female body (up to 29 vertices, 5.5 mm deep).
Motion lowered_arms(const std::filesystem::path& path) {
  Motion m = read_motion(path);
  const int left = m.find("LeftArm"), right = m.find("RightArm");
  EXPECT_GE(left, 0);
  EXPECT_GE(right, 0);
  const float angle = 15.0f * static_cast<float>(M_PI) / 180.0f;
  for (size_t f = 0; f < m.frame_count; ++f) {
    Quatf& l = m.rotation[f * m.joint_count() + static_cast<size_t>(left)];
    Quatf& r = m.rotation[f * m.joint_count() + static_cast<size_t>(right)];
    l = Quatf(Eigen::AngleAxisf(-angle, Vec3f::UnitZ())) * l;
    r = Quatf(Eigen::AngleAxisf(angle, Vec3f::UnitZ())) * r;
  }
  return m;
}

TEST(SkinLayer, KeepsHandsLoweredOntoTheHipsOutOfThemOnEveryFrame) {
  const auto path = DRAPE_REQUIRE_SHARED("motions/synthetic/synthetic_arms_raise_cmu_skeleton.bvh");
  const Body& body = female();
  const BodyAnimation a = retarget(lowered_arms(path), body, {});
  SkinLayer layer(body);
  std::vector<Vec3f> skinned(body.mesh.vertex_count()), skin(skinned.size());
  size_t inside_skinned = 0, frames_inside = 0;
  float deepest = 0;
  for (size_t f = 0; f < a.frame_count; ++f) {
    skin_mesh(body, a.pose(f), Skinning::Linear, skinned);
    const SkinContactStats before = layer.inside(skinned);
    const SkinContactStats s = layer.solve(skinned, skin);
    const SkinContactStats after = layer.inside(skin);
    inside_skinned = std::max(inside_skinned, before.vertices_inside);
    deepest = std::max(deepest, before.max_depth_m);
    frames_inside += before.vertices_inside > 0 ? 1 : 0;
    EXPECT_EQ(after.vertices_inside, 0u) << "frame " << f << ": " << after.max_depth_m * 1e3f << " mm deep";
    // Only round the contacts: the head, the feet and most of the body stay where skinning put them.
    EXPECT_LT(s.moved, skin.size() / 20) << "frame " << f;
    for (size_t v = 0; v < skin.size(); ++v) {
      if (body.parts[v] == BodyPart::Head) {
        ASSERT_EQ(skin[v], skinned[v]) << "frame " << f << ", vertex " << v;
      }
    }
    if (before.vertices_inside > 0) {
      EXPECT_GT(s.contacts, 0u) << "frame " << f;
    }
  }
  std::printf("skinned: up to %zu vertices inside another part (%.1f mm), in %zu frames of %zu; skin layer: none\n",
              inside_skinned, 1e3 * static_cast<double>(deepest), frames_inside, a.frame_count);
  // The test means something: skinning alone does drive the hands in.
  EXPECT_GE(inside_skinned, 10u);
  EXPECT_GT(deepest, 0.003f);
}

TEST(SkinLayer, PushesBothPartsApartEqualAndOpposite) {
  const auto path = DRAPE_REQUIRE_SHARED("motions/synthetic/synthetic_arms_raise_cmu_skeleton.bvh");
  const Body& body = female();
  const BodyAnimation a = retarget(lowered_arms(path), body, {});
  SkinLayer layer(body);
  std::vector<Vec3f> skinned(body.mesh.vertex_count()), skin(skinned.size());
  // The clip's last frame: the arms all the way down.
  skin_mesh(body, a.pose(a.frame_count - 1), Skinning::Linear, skinned);
  const SkinContactStats s = layer.solve(skinned, skin);
  ASSERT_GT(s.contacts, 0u);
  // Both sides gave way: the hands moved out of the hips, and the hips were pressed in.
  float arm = 0, torso = 0;
  for (size_t v = 0; v < skin.size(); ++v) {
    const float move = (skin[v] - skinned[v]).norm();
    if (body.parts[v] == BodyPart::LeftArm || body.parts[v] == BodyPart::RightArm) arm = std::max(arm, move);
    if (body.parts[v] == BodyPart::Torso) torso = std::max(torso, move);
  }
  EXPECT_GT(arm, 0.001f);
  EXPECT_GT(torso, 0.001f);
  // At rest, the anchors carry every force: the contact forces between the parts are equal and
  // opposite and the membrane's are internal, so the anchors' forces on the skin sum to zero.
  EXPECT_GT(s.anchor_force_n, 0.0);
  EXPECT_LT(s.net_force_n, 1e-3 * s.anchor_force_n);
}

TEST(SkinLayer, MovesNothingWhereNoPartsMeet) {
  const Body& body = female();
  SkinLayer layer(body);
  std::vector<Vec3f> skin(body.mesh.vertex_count());
  // The bind pose: arms away from the body.
  const SkinContactStats s = layer.solve(body.mesh.positions, skin);
  EXPECT_EQ(s.contacts, 0u);
  EXPECT_EQ(s.moved, 0u);
  for (size_t v = 0; v < skin.size(); ++v) ASSERT_EQ(skin[v], body.mesh.positions[v]);
  EXPECT_EQ(layer.inside(body.mesh.positions).vertices_inside, 0u);
}

TEST(SkinLayer, RefusesAPoseOfAnotherMesh) {
  SkinLayer layer(female());
  std::vector<Vec3f> few(10), out(10);
  EXPECT_THROW(layer.solve(few, out), std::invalid_argument);
  Body no_parts = female();
  no_parts.parts.clear();
  EXPECT_THROW(SkinLayer{no_parts}, std::invalid_argument);
}

// In motion with a shirt: its sleeves and hem are caught between the hands and the hips. With the
// skin layer no skin is inside another part on any frame, and the shirt stays within the gates.
TEST(SkinLayer, InMotionKeepsThePartsApartAndTheShirtBetween) {
  const auto path = DRAPE_REQUIRE_SHARED("motions/synthetic/synthetic_arms_raise_cmu_skeleton.bvh");
  if (sanitized()) GTEST_SKIP() << "sanitized build: a motion is a Release test";
  AnimateOptions o;
  o.dress.mesh.edge_length = 0.04;
  o.retarget.first_frame = 95;  // the arms coming down
  o.skin_layer = true;
  const AnimationResult r = animate(female(), {{load_garment(default_garment_name()), ""}}, lowered_arms(path), o);
  ASSERT_EQ(r.status, StepStatus::Ok);
  ASSERT_TRUE(r.skin_layer.has_value());
  EXPECT_GE(r.skin_layer->gap_m, 2.0f * r.dressed.garments[0].model.fabric.collision_thickness);
  EXPECT_GT(r.skin_layer->inside_skinned, 0u);
  for (size_t f = 0; f < r.frames.size(); ++f) {
    EXPECT_EQ(r.frames[f].skin_inside, 0u) << "frame " << f;
    const FitQuality& q = r.frames[f].quality;
    EXPECT_LE(q.penetration_fraction, 0.01) << "frame " << f;
    EXPECT_LE(q.max_strain, r.dressed.garments[0].model.fabric.strain_threshold + 0.02f) << "frame " << f;
  }
  std::printf("skinned: up to %zu vertices inside another part (%.1f mm); skin layer: %zu; shirt: worst frame %.2f %% inside, "
              "%.2f %% strain; %.1f ms a frame for the skin layer\n",
              r.skin_layer->inside_skinned, 1e3 * static_cast<double>(r.skin_layer->depth_skinned_m), r.skin_layer->inside,
              100.0 * r.worst.penetration_fraction, 100.0 * static_cast<double>(r.worst.max_strain),
              1e3 * r.skin_layer->seconds / static_cast<double>(r.frames.size()));
  // The body as the cloth met it is what anim.glb shows: the skin layer's moves, in the bind pose,
  // skinned again, give the skin the cloth met.
  const std::vector<std::vector<Vec3f>> shown = animated_body_frames(female(), r, Skinning::Linear);
  const size_t last = r.frames.size() - 1;
  std::vector<Vec3f> skinned(female().mesh.vertex_count());
  skin_mesh(female(), r.body.pose(last), Skinning::Linear, skinned);
  SkinLayer layer(female());
  EXPECT_GT(layer.inside(skinned).vertices_inside, 0u);
  EXPECT_EQ(layer.inside(shown[last]).vertices_inside, 0u);
  // anim.glb plays it (a morph target per frame) and passes the Khronos validator; report.json has
  // the skin layer's figures, per frame and in all.
  const auto dir = test::temp_dir("animate_skin_layer");
  const Scene scene = test::written_animation(dir, female(), lowered_arms(path), r, o);
  const int body = scene.find_node("body");
  ASSERT_GE(body, 0);
  const Mesh& mesh = scene.meshes[static_cast<size_t>(scene.nodes[static_cast<size_t>(body)].mesh)];
  ASSERT_EQ(mesh.morph_targets.size(), r.frames.size());
  const AnimatedSkinLayer& k = *r.skin_layer;
  ASSERT_FALSE(k.vertices[last].empty());
  for (size_t i = 0; i < k.vertices[last].size(); ++i)
    ASSERT_EQ(mesh.morph_targets[last].position_deltas[k.vertices[last][i]], k.displacement[last][i]);
  std::ifstream in(dir / "report.json");
  const nlohmann::json j = nlohmann::json::parse(in);
  ASSERT_TRUE(j.contains("skin_layer"));
  for (const char* key : {"gap_m", "vertices_inside_skinned", "vertices_inside", "max_depth_m", "max_move_m", "seconds"})
    EXPECT_TRUE(j["skin_layer"].contains(key)) << key;
  EXPECT_EQ(j["skin_layer"]["vertices_inside"], 0);
  EXPECT_TRUE(j["frames"][last].contains("skin_layer"));
}

}  // namespace
}  // namespace drape
