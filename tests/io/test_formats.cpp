// Mesh formats: round trips keep what they must, encodings agree, loaders validate and count.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <Eigen/Geometry>
#include <fstream>

#include "drape/error.hpp"
#include "drape/io.hpp"
#include "support/gltf_validator.hpp"
#include "support/test_support.hpp"

using namespace drape;
namespace fs = std::filesystem;

namespace {

std::span<const unsigned char> bytes_of(const std::string& s) {
  return {reinterpret_cast<const unsigned char*>(s.data()), s.size()};
}

Scene parse_text(const std::string& text, MeshFormat format, MeshCheck* check = nullptr,
                 const LoadOptions& options = {}) {
  return parse_scene(bytes_of(text), format, "test", options, check);
}

// A unit cube with a UV seam on every edge: 8 positions, 14 texture coordinates, 6 quads, 2 groups.
const char* kCubeObj = R"(# cube
v 0 0 0
v 1 0 0
v 1 1 0
v 0 1 0
v 0 0 1
v 1 0 1
v 1 1 1
v 0 1 1
vt 0 0
vt 0.25 0
vt 0.5 0
vt 0.75 0
vt 1 0
vt 0 0.5
vt 0.25 0.5
vt 0.5 0.5
vt 0.75 0.5
vt 1 0.5
vt 0.25 1
vt 0.5 1
vt 0.25 0.75
vt 0.5 0.75
g sides
f 1/1 2/2 6/7 5/6
f 2/2 3/3 7/8 6/7
f 3/3 4/4 8/9 7/8
f 4/4 1/5 5/10 8/9
g caps
f 5/7 6/8 7/12 8/11
f 1/13 4/14 3/12 2/11
)";

// The (position, uv) pairs of each triangle corner, in order: what a round trip must keep.
std::vector<std::array<float, 5>> corners_of(const Mesh& m) {
  std::vector<std::array<float, 5>> out;
  for (const Tri& t : m.triangles)
    for (uint32_t v : t) {
      const Vec2f uv = m.uvs.empty() ? Vec2f::Zero() : m.uvs[v];
      out.push_back({m.positions[v].x(), m.positions[v].y(), m.positions[v].z(), uv.x(), uv.y()});
    }
  return out;
}

void expect_same_mesh(const Mesh& a, const Mesh& b) {
  ASSERT_EQ(a.positions.size(), b.positions.size());
  ASSERT_EQ(a.triangles.size(), b.triangles.size());
  for (size_t i = 0; i < a.positions.size(); ++i) EXPECT_EQ(a.positions[i], b.positions[i]) << "vertex " << i;
  for (size_t i = 0; i < a.triangles.size(); ++i)
    EXPECT_EQ(a.triangles[i], b.triangles[i]) << "triangle " << i;
  ASSERT_EQ(a.uvs.size(), b.uvs.size());
  for (size_t i = 0; i < a.uvs.size(); ++i) EXPECT_EQ(a.uvs[i], b.uvs[i]) << "uv " << i;
}

}  // namespace

TEST(Obj, SplitsSeamVerticesKeepingFileOrderAndTriangulates) {
  MeshCheck check;
  const Mesh cube = merge_scene(parse_text(kCubeObj, MeshFormat::Obj, &check));
  EXPECT_EQ(check.non_triangle_faces_triangulated, 6u);
  EXPECT_EQ(cube.triangles.size(), 12u);
  EXPECT_GT(cube.positions.size(), 8u);  // seams split
  // The file's vertices keep their indices.
  EXPECT_EQ(cube.positions[0], Vec3f(0, 0, 0));
  EXPECT_EQ(cube.positions[6], Vec3f(1, 1, 1));
  // Welded over seams, the cube is closed.
  EXPECT_EQ(check.boundary_loops, 0u);
  EXPECT_EQ(check.non_manifold_edges, 0u);
  ASSERT_EQ(cube.group_names.size(), 2u);
  EXPECT_EQ(cube.group_names[0], "sides");
  EXPECT_EQ(std::count(cube.triangle_groups.begin(), cube.triangle_groups.end(), 1u), 4);
  // Every corner carries the uv the file gave it: corner 0 of the first face is v1/vt1.
  ASSERT_EQ(cube.uvs.size(), cube.positions.size());
  bool found = false;
  for (const Tri& t : cube.triangles)
    for (uint32_t v : t)
      if (cube.positions[v] == Vec3f(1, 0, 0)) found |= cube.uvs[v] == Vec2f(0.25f, 0.0f);
  EXPECT_TRUE(found);
  // Outward winding: signed volume of a closed cube is +1.
  float volume = 0;
  for (const Tri& t : cube.triangles)
    volume += cube.positions[t[0]].dot(cube.positions[t[1]].cross(cube.positions[t[2]])) / 6.0f;
  EXPECT_NEAR(volume, 1.0f, 1e-6f);
}

TEST(Obj, RoundTripThroughGlbKeepsPositionsUvsFacesAndValidates) {
  const Mesh original = merge_scene(parse_text(kCubeObj, MeshFormat::Obj));
  const fs::path dir = test::temp_dir("obj_glb");
  write_mesh(dir / "cube.glb", original);
  EXPECT_TRUE(test::gltf_is_valid(dir / "cube.glb"));
  const Mesh from_glb = read_mesh(dir / "cube.glb");
  expect_same_mesh(original, from_glb);
  write_mesh(dir / "cube.obj", from_glb);
  const Mesh back = read_mesh(dir / "cube.obj");
  expect_same_mesh(original, back);
  EXPECT_EQ(corners_of(original), corners_of(back));
  fs::remove_all(dir);
}

TEST(Obj, GroupsSurviveObjRoundTrip) {
  const Mesh cube = merge_scene(parse_text(kCubeObj, MeshFormat::Obj));
  const Mesh back = merge_scene(parse_text(encode_obj(cube), MeshFormat::Obj));
  EXPECT_EQ(back.group_names, cube.group_names);
  EXPECT_EQ(back.triangle_groups, cube.triangle_groups);
}

TEST(Obj, NonConvexPolygonIsEarClipped) {
  // An L-shaped hexagon: a fan from vertex 1 would leave the polygon; ear clipping keeps its area.
  const char* obj = "v 0 0 0\nv 2 0 0\nv 2 1 0\nv 1 1 0\nv 1 2 0\nv 0 2 0\nf 4 5 6 1 2 3\n";
  MeshCheck check;
  const Mesh m = merge_scene(parse_text(obj, MeshFormat::Obj, &check));
  ASSERT_EQ(m.triangles.size(), 4u);
  float area = 0;
  for (const Tri& t : m.triangles) {
    const Vec3f n = (m.positions[t[1]] - m.positions[t[0]]).cross(m.positions[t[2]] - m.positions[t[0]]);
    EXPECT_GT(n.z(), 0.0f) << "every triangle keeps the polygon's winding";
    area += 0.5f * n.norm();
  }
  EXPECT_NEAR(area, 3.0f, 1e-6f);
  EXPECT_EQ(check.boundary_loops, 1u);
  EXPECT_EQ(check.boundary_edges, 6u);
}

TEST(Obj, DegenerateFacesAreDroppedAndCounted) {
  const char* obj = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 2 0 0\nf 1 2 3\nf 1 2 2\nf 1 2 4\nf 1 2\n";
  MeshCheck check;
  const Mesh m = merge_scene(parse_text(obj, MeshFormat::Obj, &check));
  EXPECT_EQ(m.triangles.size(), 1u);
  EXPECT_EQ(check.degenerate_faces_removed, 3u);  // repeated corner, zero area, two corners
}

TEST(Topology, CountsHolesAndNonManifoldEdges) {
  // Three triangles on one edge (a "book"), plus a separate triangle.
  const char* obj =
      "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 -1 0\nv 0 0 1\nv 5 0 0\nv 6 0 0\nv 5 1 0\n"
      "f 1 2 3\nf 2 1 4\nf 1 2 5\nf 6 7 8\n";
  MeshCheck check;
  parse_text(obj, MeshFormat::Obj, &check);
  EXPECT_EQ(check.non_manifold_edges, 1u);
  EXPECT_EQ(check.boundary_edges, 9u);
  EXPECT_EQ(check.boundary_loops, 2u);
}

TEST(Obj, MalformedInputIsRefusedWithLine) {
  const auto message = [](const std::string& text) {
    try {
      parse_scene(bytes_of(text), MeshFormat::Obj, "bad.obj");
    } catch (const InputError& e) {
      EXPECT_EQ(e.source(), "bad.obj");
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  EXPECT_NE(message("v 0 0 0\nv 1 0 0\nv 0 1\nf 1 2 3\n").find("line 3"), std::string::npos);
  EXPECT_NE(message("v 0 0 0\nv 1 0 nan\nv 0 1 0\nf 1 2 3\n").find("non-finite"), std::string::npos);
  EXPECT_NE(message("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n").find("line 4: vertex index 4 out of range"),
            std::string::npos);
  EXPECT_NE(message("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 -4\n").find("relative"), std::string::npos);
  EXPECT_NE(message("v 0 0 0\nv 1 0 0\nv 0 1 0\n").find("no faces"), std::string::npos);
  EXPECT_NE(message("v 0 0 0\nv 1 0 x\nv 0 1 0\nf 1 2 3\n").find("not a number"), std::string::npos);
  EXPECT_NE(message(std::string("v 0 0 0\0\x01", 9)).find("binary"), std::string::npos);
}

// A lone carriage return ends a line, as in the loader: "v\r1 2 3" is a vertex without numbers, refused
// by line, never counted as a fourth vertex that the loader does not read.
TEST(Obj, CarriageReturnsEndLinesLikeTheLoader) {
  const Scene ok = parse_text("v 0 0 0\rv 1 0 0\r\nv 0 1 0\rf 1 2 3\r", MeshFormat::Obj);
  EXPECT_EQ(merge_scene(ok).triangles.size(), 1u);
  try {
    parse_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nv\r1 2 3\nf 1 2 4\n", MeshFormat::Obj);
    ADD_FAILURE() << "a face on a vertex the loader does not read was accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("line 4: vertex has 0 numbers"), std::string::npos) << e.what();
  }
}

TEST(Ply, AsciiAndBinaryEncodingsReadTheSame) {
  Mesh m = merge_scene(parse_text(kCubeObj, MeshFormat::Obj));
  m.normals = vertex_normals(m.positions, m.triangles);
  m.colors.assign(m.positions.size(), Vec4f(0.2f, 0.4f, 0.6f, 1.0f));
  for (size_t i = 0; i < m.colors.size(); ++i) m.colors[i].x() = static_cast<float>(i % 256) / 255.0f;
  const auto read = [](const std::vector<unsigned char>& bytes) {
    return merge_scene(parse_scene(bytes, MeshFormat::Ply, "t.ply"));
  };
  const Mesh ascii = read(encode_ply(m, PlyEncoding::Ascii));
  const Mesh little = read(encode_ply(m, PlyEncoding::BinaryLittleEndian));
  const Mesh big = read(encode_ply(m, PlyEncoding::BinaryBigEndian));
  for (const Mesh* r : {&ascii, &little, &big}) {
    expect_same_mesh(m, *r);
    ASSERT_EQ(r->normals.size(), m.normals.size());
    for (size_t i = 0; i < m.normals.size(); ++i) EXPECT_LT((r->normals[i] - m.normals[i]).norm(), 1e-6f);
    ASSERT_EQ(r->colors.size(), m.colors.size());
    for (size_t i = 0; i < m.colors.size(); ++i)
      EXPECT_LT((r->colors[i] - m.colors[i]).norm(), 0.5f / 255.0f);
  }
  EXPECT_NE(encode_ply(m, PlyEncoding::BinaryLittleEndian), encode_ply(m, PlyEncoding::BinaryBigEndian));
}

TEST(Ply, ReadsForeignPropertiesListsAndQuads) {
  // double coordinates, u/v names, an extra element and property, a quad with an int count.
  const std::string ply =
      "ply\nformat ascii 1.0\ncomment made by hand\nelement vertex 4\nproperty double x\nproperty double y\n"
      "property double z\nproperty float confidence\nproperty float u\nproperty float v\n"
      "element face 1\nproperty list int int vertex_index\nelement edge 1\nproperty int vertex1\n"
      "property int vertex2\nend_header\n0 0 0 1 0 0\n1 0 0 1 1 0\n1 1 0 1 1 1\n0 1 0 1 0 1\n4 0 1 2 3\n0 "
      "1\n";
  MeshCheck check;
  const Mesh m = merge_scene(parse_text(ply, MeshFormat::Ply, &check));
  EXPECT_EQ(m.triangles.size(), 2u);
  EXPECT_EQ(check.non_triangle_faces_triangulated, 1u);
  ASSERT_EQ(m.uvs.size(), 4u);
  EXPECT_EQ(m.uvs[2], Vec2f(1, 1));
}

TEST(Ply, TruncatedAndWrongCountsAreRefused) {
  Mesh m = merge_scene(parse_text(kCubeObj, MeshFormat::Obj));
  std::vector<unsigned char> bin = encode_ply(m, PlyEncoding::BinaryLittleEndian);
  bin.resize(bin.size() - 5);
  EXPECT_THROW(parse_scene(bin, MeshFormat::Ply, "t.ply"), InputError);
  std::string text =
      "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
      "element face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 3\n";
  try {
    parse_text(text, MeshFormat::Ply);
    ADD_FAILURE() << "out-of-range index accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("face 0: vertex index 3 out of range"), std::string::npos)
        << e.what();
  }
}

TEST(Gltf, SkinnedBodySurvivesReadWriteAndValidates) {
  const fs::path body = DRAPE_REQUIRE_SHARED("bodies/makehuman/derived/mh_female_average_cmu_mb.glb");
  const Scene a = read_scene(body);
  ASSERT_EQ(a.skins.size(), 1u);
  ASSERT_EQ(a.skins[0].joints.size(), 31u);
  const fs::path dir = test::temp_dir("skin_rt");
  write_scene(dir / "body.glb", a);
  EXPECT_TRUE(test::gltf_is_valid(dir / "body.glb"));
  const Scene b = read_scene(dir / "body.glb");

  ASSERT_EQ(b.nodes.size(), a.nodes.size());
  for (size_t i = 0; i < a.nodes.size(); ++i) {
    EXPECT_EQ(b.nodes[i].name, a.nodes[i].name);
    EXPECT_EQ(b.nodes[i].parent, a.nodes[i].parent);
    EXPECT_EQ(b.nodes[i].mesh, a.nodes[i].mesh);
    EXPECT_EQ(b.nodes[i].skin, a.nodes[i].skin);
    EXPECT_LT((b.nodes[i].translation - a.nodes[i].translation).norm(), 1e-6f);
  }
  ASSERT_EQ(b.skins.size(), 1u);
  EXPECT_EQ(b.skins[0].joints, a.skins[0].joints);
  for (size_t j = 0; j < a.skins[0].joints.size(); ++j)
    EXPECT_TRUE(b.skins[0].inverse_bind_matrices[j].isApprox(a.skins[0].inverse_bind_matrices[j], 1e-6f))
        << j;
  const Mesh& ma = a.meshes[0];
  const Mesh& mb = b.meshes[0];
  EXPECT_EQ(mb.positions, ma.positions);
  EXPECT_EQ(mb.triangles, ma.triangles);
  EXPECT_EQ(mb.joints.size(), ma.joints.size());
  size_t influences = 0;
  for (size_t v = 0; v < ma.joints.size(); ++v) {
    EXPECT_NEAR(mb.weights[v].sum(), 1.0f, 1e-6f);
    for (int k = 0; k < 4; ++k) {
      EXPECT_NEAR(mb.weights[v][k], ma.weights[v][k], 1e-6f);
      if (ma.weights[v][k] > 0.0f) {
        EXPECT_EQ(mb.joints[v][static_cast<size_t>(k)], ma.joints[v][static_cast<size_t>(k)]);
        ++influences;
      }
    }
  }
  EXPECT_GT(influences, ma.joints.size());  // really skinned: most vertices have several influences
  fs::remove_all(dir);
}

// Morph targets that move few vertices are written sparse, and one that moves none without data
// (the spec's zeros); both read back exactly and validate.
TEST(Gltf, SparseAndEmptyMorphTargetsRoundTrip) {
  Scene s;
  Mesh grid;
  for (int j = 0; j < 10; ++j)
    for (int i = 0; i < 10; ++i) grid.positions.emplace_back(0.1f * static_cast<float>(i), 0.1f * static_cast<float>(j), 0.0f);
  for (uint32_t j = 0; j < 9; ++j)
    for (uint32_t i = 0; i < 9; ++i) {
      const uint32_t a = 10 * j + i;
      grid.triangles.push_back({a, a + 1, a + 11});
      grid.triangles.push_back({a, a + 11, a + 10});
    }
  MorphTarget few{"few", std::vector<Vec3f>(100, Vec3f::Zero()), {}};
  few.position_deltas[3] = Vec3f(0, 0, 0.01f);
  few.position_deltas[42] = Vec3f(-0.02f, 0, 0.005f);
  few.position_deltas[99] = Vec3f(0, 0.03f, 0);
  grid.morph_targets = {few, MorphTarget{"none", std::vector<Vec3f>(100, Vec3f::Zero()), {}}};
  grid.morph_weights = {1.0f, 0.0f};
  add_mesh_node(s, grid, "grid");
  const fs::path dir = test::temp_dir("sparse_morph");
  write_scene(dir / "scene.glb", s);
  EXPECT_TRUE(test::gltf_is_valid(dir / "scene.glb"));
  const Scene r = read_scene(dir / "scene.glb");
  ASSERT_EQ(r.meshes.size(), 1u);
  ASSERT_EQ(r.meshes[0].morph_targets.size(), 2u);
  EXPECT_EQ(r.meshes[0].morph_targets[0].position_deltas, grid.morph_targets[0].position_deltas);
  EXPECT_EQ(r.meshes[0].morph_targets[1].position_deltas, grid.morph_targets[1].position_deltas);
  // Smaller than the dense targets would be (2 x 100 x 12 bytes).
  EXPECT_LT(fs::file_size(dir / "scene.glb"), 100 * 12 + 100 * 12 + 2000u);
  fs::remove_all(dir);

  // A sparse accessor that reaches outside its elements, or says nothing of its indices' type, is
  // refused naming it.
  const nlohmann::json good = nlohmann::json::parse(encode_gltf(s));
  size_t sparse = 0;
  while (sparse < good["accessors"].size() && !good["accessors"][sparse].contains("sparse")) ++sparse;
  ASSERT_LT(sparse, good["accessors"].size());
  const auto refused = [&](const nlohmann::json& j, const std::string& says) {
    const std::string text = j.dump();
    try {
      parse_scene(std::span(reinterpret_cast<const unsigned char*>(text.data()), text.size()), MeshFormat::Gltf, "t.gltf");
      ADD_FAILURE() << "accepted: " << says;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(says), std::string::npos) << e.what();
    }
  };
  nlohmann::json more = good;
  more["accessors"][sparse]["sparse"]["count"] = 101;
  refused(more, "101 sparse values for 100 elements");
  nlohmann::json float_indices = good;
  float_indices["accessors"][sparse]["sparse"]["indices"]["componentType"] = 5126;
  refused(float_indices, "sparse indices of component type 5126");
  nlohmann::json outside = good;
  outside["accessors"][sparse]["sparse"]["indices"]["byteOffset"] = 1 << 20;
  refused(outside, "do not fit in buffer view");
}

TEST(Gltf, AnimationsMorphTargetsAndHierarchyRoundTrip) {
  Scene s;
  Mesh tri = merge_scene(parse_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", MeshFormat::Obj));
  tri.normals = vertex_normals(tri.positions, tri.triangles);
  tri.morph_targets.push_back({"smile", {Vec3f(0, 0, 0.1f), Vec3f::Zero(), Vec3f(0, 0.2f, 0)}, {}});
  tri.morph_weights = {0.25f};
  tri.joints.assign(3, {0, 1, 0, 0});
  tri.weights.assign(3, Vec4f(0.5f, 0.5f, 0, 0));
  const int root = add_mesh_node(s, tri, "body");
  Node hip;
  hip.name = "hip";
  hip.translation = Vec3f(0, 1, 0);
  s.nodes.push_back(hip);
  Node knee;
  knee.name = "knee";
  knee.parent = 1;
  knee.rotation = Eigen::Quaternionf(Eigen::AngleAxisf(0.3f, Vec3f::UnitX()));
  s.nodes.push_back(knee);
  s.nodes[static_cast<size_t>(root)].skin = 0;
  s.skins.push_back({"rig", {1, 2}, {Mat4f::Identity(), Mat4f::Identity()}, 1});
  s.skins[0].inverse_bind_matrices[0](1, 3) = -1.0f;
  Animation walk;
  walk.name = "walk";
  walk.channels.push_back(
      {1, AnimationPath::Translation, Interpolation::Linear, {0, 1}, {0, 1, 0, 0, 1.1f, 0}});
  walk.channels.push_back(
      {2, AnimationPath::Rotation, Interpolation::Step, {0, 0.5f}, {0, 0, 0, 1, 0.1987f, 0, 0, 0.98f}});
  walk.channels.push_back({1,
                           AnimationPath::Scale,
                           Interpolation::CubicSpline,
                           {0, 1},
                           {0, 0, 0, 1, 1, 1, 0, 0, 0, 0, 0, 0, 2, 2, 2, 0, 0, 0}});
  walk.channels.push_back({0, AnimationPath::Weights, Interpolation::Linear, {0, 1, 2}, {0, 1, 0}});
  s.animations.push_back(walk);

  const fs::path dir = test::temp_dir("anim_rt");
  write_scene(dir / "scene.glb", s);
  EXPECT_TRUE(test::gltf_is_valid(dir / "scene.glb"));
  const Scene r = read_scene(dir / "scene.glb");
  ASSERT_EQ(r.nodes.size(), 3u);
  EXPECT_EQ(r.nodes[2].parent, 1);
  EXPECT_TRUE(r.nodes[2].rotation.isApprox(knee.rotation, 1e-6f));
  ASSERT_EQ(r.meshes[0].morph_targets.size(), 1u);
  EXPECT_EQ(r.meshes[0].morph_targets[0].name, "smile");
  EXPECT_EQ(r.meshes[0].morph_targets[0].position_deltas, tri.morph_targets[0].position_deltas);
  EXPECT_EQ(r.meshes[0].morph_weights, tri.morph_weights);
  ASSERT_EQ(r.animations.size(), 1u);
  ASSERT_EQ(r.animations[0].channels.size(), 4u);
  for (size_t c = 0; c < 4; ++c) {
    const AnimationChannel& x = walk.channels[c];
    const AnimationChannel& y = r.animations[0].channels[c];
    EXPECT_EQ(y.node, x.node);
    EXPECT_EQ(y.path, x.path);
    EXPECT_EQ(y.interpolation, x.interpolation);
    EXPECT_EQ(y.times, x.times);
    ASSERT_EQ(y.values.size(), x.values.size());
    // Rotation keys are written as unit quaternions; the rest exactly.
    for (size_t k = 0; k < x.values.size(); ++k)
      EXPECT_NEAR(y.values[k], x.values[k], 2e-3f) << c << " " << k;
  }
  EXPECT_TRUE(r.skins[0].inverse_bind_matrices[0].isApprox(s.skins[0].inverse_bind_matrices[0]));
  fs::remove_all(dir);
}

// An unnamed node with nothing on it (a bare joint or group) is written as a node, not as null.
TEST(Gltf, UnnamedEmptyNodeIsWrittenAsANode) {
  Scene s;
  add_mesh_node(s, merge_scene(parse_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", MeshFormat::Obj)), "");
  s.nodes.emplace_back();
  const Scene again = parse_scene(encode_glb(s), MeshFormat::Glb, "again.glb");
  ASSERT_EQ(again.nodes.size(), 2u);
  EXPECT_TRUE(again.nodes[1].name.empty());
  EXPECT_EQ(again.nodes[1].mesh, -1);
  EXPECT_EQ(again.nodes[1].translation, Vec3f::Zero());
  EXPECT_EQ(encode_gltf(s).find("null"), std::string::npos);
}

TEST(Units, CentimetreZUpCopyLoadsLikeTheMetreYUpOriginal) {
  const Mesh original = merge_scene(parse_text(kCubeObj, MeshFormat::Obj));
  // The same cube as a Z-up scanner in centimetres would store it: (x, y, z) -> (x, -z, y) * 100.
  Mesh scanned = original;
  for (Vec3f& p : scanned.positions) p = 100.0f * Vec3f(p.x(), -p.z(), p.y());
  MeshCheck check;
  const Mesh loaded =
      merge_scene(parse_text(encode_obj(scanned), MeshFormat::Obj, &check, load_options("cm", "z")));
  ASSERT_EQ(loaded.positions.size(), original.positions.size());
  for (size_t i = 0; i < original.positions.size(); ++i)
    EXPECT_LT((loaded.positions[i] - original.positions[i]).norm(), 1e-6f) << i;
  EXPECT_EQ(loaded.triangles, original.triangles);  // a rotation keeps the winding
  EXPECT_EQ(check.boundary_loops, 0u);
}

TEST(Units, ZUpSkinnedSceneConvertsConsistently) {
  const fs::path body = DRAPE_REQUIRE_SHARED("bodies/makehuman/derived/mh_female_average_cmu_mb.glb");
  const Scene y_up = read_scene(body);
  // Load the same file as if it were Z-up millimetres: joints, IBMs and vertices all move together, so
  // each joint's world position times its inverse bind matrix is still the identity.
  const Scene converted = read_scene(body, load_options("mm", "z"));
  const Skin& skin = converted.skins[0];
  Eigen::Matrix3f r;
  r << 1, 0, 0, 0, 0, 1, 0, -1, 0;  // (x, y, z) -> (x, z, -y)
  for (size_t j = 0; j < skin.joints.size(); ++j) {
    const Mat4f product = converted.world_transform(skin.joints[j]) * skin.inverse_bind_matrices[j];
    const Mat4f original =
        y_up.world_transform(y_up.skins[0].joints[j]) * y_up.skins[0].inverse_bind_matrices[j];
    const Eigen::Matrix3f expected = r * original.topLeftCorner<3, 3>() * r.transpose();
    const Eigen::Matrix3f linear = product.topLeftCorner<3, 3>();
    EXPECT_TRUE(linear.isApprox(expected, 1e-4f)) << j;
    const Vec3f offset = product.col(3).head<3>() - 1e-3f * r * original.col(3).head<3>();
    EXPECT_LT(offset.norm(), 1e-6f) << j;
    // A joint's head moves like the vertices do.
    const Vec3f head = converted.world_transform(skin.joints[j]).col(3).head<3>();
    const Vec3f head_y_up = y_up.world_transform(y_up.skins[0].joints[j]).col(3).head<3>();
    EXPECT_LT((head - 1e-3f * r * head_y_up).norm(), 1e-6f) << j;
  }
  const Vec3f p0 = y_up.meshes[0].positions[0];
  EXPECT_LT((converted.meshes[0].positions[0] - 1e-3f * Vec3f(p0.x(), p0.z(), -p0.y())).norm(), 1e-6f);
}

TEST(Units, BadOptionsNameTheOption) {
  EXPECT_THROW(load_options("inch", "y"), InputError);
  try {
    load_options("m", "x");
  } catch (const InputError& e) {
    EXPECT_EQ(e.source(), "--up");
  }
}

TEST(Io, WriteSceneRefusesUnknownExtensionAndWritesNothing) {
  const fs::path dir = test::temp_dir("ext");
  Mesh m = merge_scene(parse_text(kCubeObj, MeshFormat::Obj));
  EXPECT_THROW(write_mesh(dir / "cube.stl", m), InputError);
  EXPECT_TRUE(fs::is_empty(dir));
  fs::remove_all(dir);
}
