// Building cloth models: the grid of sec. 2.1, triangle meshes, masses, colouring, fabrics.
#include <gtest/gtest.h>

#include <set>

#include "drape/cloth.hpp"
#include "drape/error.hpp"

namespace drape {
namespace {

GridClothOptions square(uint32_t n) {
  GridClothOptions o;
  o.nx = o.ny = n;
  return o;
}

TEST(GridCloth, HasExactlyTheSpringsOfSection21) {
  const uint32_t n = 9;
  const ClothModel m = grid_cloth(fabric_or_throw("cotton"), square(n));
  EXPECT_EQ(m.particle_count(), n * n);
  EXPECT_EQ(m.range(SpringKind::Structural).size(), 2 * n * (n - 1));
  EXPECT_EQ(m.range(SpringKind::Shear).size(), 2 * (n - 1) * (n - 1));
  EXPECT_EQ(m.range(SpringKind::Flexion).size(), 2 * n * (n - 2));
  EXPECT_EQ(m.range(SpringKind::Seam).size(), 0u);
  // Each kind links the index offsets the paper lists: [i+1,j], [i,j+1]; diagonals; [i+2,j], [i,j+2].
  const auto offsets = [&](SpringKind kind) {
    std::set<int> out;
    for (uint32_t s = m.range(kind).begin; s < m.range(kind).end; ++s)
      out.insert(static_cast<int>(m.spring_b[s]) - static_cast<int>(m.spring_a[s]));
    return out;
  };
  const int N = static_cast<int>(n);
  EXPECT_EQ(offsets(SpringKind::Structural), (std::set<int>{1, N}));
  EXPECT_EQ(offsets(SpringKind::Shear), (std::set<int>{N + 1, N - 1}));
  EXPECT_EQ(offsets(SpringKind::Flexion), (std::set<int>{2, 2 * N}));
}

TEST(GridCloth, MassComesFromArealDensityTimesArea) {
  const Fabric denim = fabric_or_throw("denim");
  GridClothOptions o = square(17);
  o.width = 0.8f;
  o.height = 1.5f;
  const ClothModel m = grid_cloth(denim, o);
  EXPECT_NEAR(m.total_mass(), denim.areal_density * 0.8f * 1.5f, 1e-5f);
}

TEST(GridCloth, WarpAndWeftStiffnessDiffer) {
  Fabric f = fabric_or_throw("cotton");
  f.stretch_warp = 40;
  f.stretch_weft = 10;
  const ClothModel m = grid_cloth(f, square(5));
  for (uint32_t s = m.range(SpringKind::Structural).begin; s < m.range(SpringKind::Structural).end; ++s) {
    const bool along_u = m.spring_b[s] - m.spring_a[s] == 1;  // ix direction = weft
    EXPECT_FLOAT_EQ(m.stiffness[s], along_u ? 10.0f : 40.0f);
  }
}

TEST(GridCloth, ColoursOfLimitedSpringsShareNoParticle) {
  const ClothModel m = grid_cloth(fabric_or_throw("cotton"), square(12));
  ASSERT_GE(m.limit_colour_begin.size(), 2u);
  EXPECT_EQ(m.limit_colour_begin.back(), m.range(SpringKind::Structural).size());
  for (size_t c = 0; c + 1 < m.limit_colour_begin.size(); ++c) {
    std::set<uint32_t> seen;
    for (uint32_t s = m.limit_colour_begin[c]; s < m.limit_colour_begin[c + 1]; ++s) {
      EXPECT_TRUE(seen.insert(m.limit_a[s]).second);
      EXPECT_TRUE(seen.insert(m.limit_b[s]).second);
    }
  }
}

TEST(GridCloth, IncidenceListsEverySpringTwiceWithOppositeSigns) {
  const ClothModel m = grid_cloth(fabric_or_throw("silk"), square(6));
  std::vector<float> sign_sum(m.spring_count(), 0.0f);
  std::vector<int> seen(m.spring_count(), 0);
  for (size_t i = 0; i < m.particle_count(); ++i)
    for (uint32_t e = m.incident_begin[i]; e < m.incident_begin[i + 1]; ++e) {
      const uint32_t s = m.incident_spring[e];
      EXPECT_TRUE(m.spring_a[s] == i || m.spring_b[s] == i);
      sign_sum[s] += m.incident_sign[e];
      ++seen[s];
    }
  for (size_t s = 0; s < m.spring_count(); ++s) {
    EXPECT_EQ(seen[s], 2);
    EXPECT_EQ(sign_sum[s], 0.0f);
  }
}

TEST(GridCloth, StableTimeStepFollowsEquation4) {
  const ClothModel m = grid_cloth(fabric_or_throw("cotton"), square(20));
  const float dt = m.stable_time_step();
  EXPECT_GT(dt, 0);
  // Four times the stiffness, half the step (dt ~ sqrt(m / K)).
  Fabric stiff = fabric_or_throw("cotton");
  stiff.stretch_warp *= 4;
  stiff.stretch_weft *= 4;
  stiff.shear *= 4;
  stiff.bend *= 4;
  EXPECT_NEAR(grid_cloth(stiff, square(20)).stable_time_step(), dt / 2, dt * 1e-3f);
}

Mesh unit_square_mesh() {
  Mesh mesh;
  mesh.positions = {Vec3f(0, 0, 0), Vec3f(1, 0, 0), Vec3f(1, 0, 1), Vec3f(0, 0, 1)};
  mesh.uvs = {Vec2f(0, 0), Vec2f(1, 0), Vec2f(1, 1), Vec2f(0, 1)};
  mesh.triangles = {Tri{0, 1, 2}, Tri{0, 2, 3}};
  return mesh;
}

TEST(MeshCloth, EdgeSpringsAndOneBendingSpringAcrossTheInteriorEdge) {
  const ClothModel m = mesh_cloth(unit_square_mesh(), fabric_or_throw("cotton"), "square.obj");
  EXPECT_EQ(m.range(SpringKind::Structural).size(), 5u);
  ASSERT_EQ(m.range(SpringKind::Flexion).size(), 1u);
  const uint32_t s = m.range(SpringKind::Flexion).begin;
  EXPECT_EQ(std::set<uint32_t>({m.spring_a[s], m.spring_b[s]}), (std::set<uint32_t>{1, 3}));
  EXPECT_NEAR(m.rest_length[s], std::sqrt(2.0f), 1e-6f);
  EXPECT_NEAR(m.total_mass(), fabric_or_throw("cotton").areal_density, 1e-6f);
}

TEST(MeshCloth, RestShapeIsTheFlatPatternNotThePlacedMesh) {
  Mesh mesh = unit_square_mesh();
  for (Vec3f& p : mesh.positions) p *= 0.5f;  // placed shrunk (e.g. wrapped around a body)
  const ClothModel m = mesh_cloth(mesh, fabric_or_throw("cotton"), "square.obj");
  const uint32_t s = m.range(SpringKind::Structural).begin;
  EXPECT_NEAR(m.rest_length[s], (mesh.uvs[m.spring_b[s]] - mesh.uvs[m.spring_a[s]]).norm(), 1e-6f);
  EXPECT_EQ(m.flat_position[2], Vec2f(1, 1));
}

TEST(MeshCloth, BadMeshesAreRefusedNamingTheSource) {
  Mesh bad = unit_square_mesh();
  bad.triangles.push_back({0, 1, 7});
  try {
    mesh_cloth(bad, fabric_or_throw("cotton"), "shirt.obj");
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_EQ(e.source(), "shirt.obj");
    EXPECT_NE(std::string(e.what()).find("triangle 2"), std::string::npos) << e.what();
  }
  Mesh flat = unit_square_mesh();
  flat.uvs[2] = flat.uvs[1];
  flat.uvs[3] = flat.uvs[0];
  EXPECT_THROW(mesh_cloth(flat, fabric_or_throw("cotton"), "flat.obj"), InputError);
  EXPECT_THROW(mesh_cloth(Mesh{}, fabric_or_throw("cotton"), "empty.obj"), InputError);
}

TEST(Fabrics, PresetsAreValidAndKeepWangsBendingOrder) {
  for (const Fabric& f : fabric_presets()) EXPECT_NO_THROW(validate_fabric(f, "presets")) << f.name;
  // Wang et al. 2011's measured bending ranking: interlock (jersey) < polyester < rib knit < denim.
  EXPECT_LT(fabric_or_throw("jersey").bend, fabric_or_throw("polyester").bend);
  EXPECT_LT(fabric_or_throw("polyester").bend, fabric_or_throw("rib_knit").bend);
  EXPECT_LT(fabric_or_throw("rib_knit").bend, fabric_or_throw("denim").bend);
  for (const char* name : {"cotton", "denim", "silk", "jersey", "wool"}) EXPECT_NE(find_fabric(name), nullptr) << name;
}

TEST(Fabrics, UnknownNameListsTheKnownOnes) {
  try {
    fabric_or_throw("tweed");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_EQ(e.source(), "--fabric");
    EXPECT_NE(std::string(e.what()).find("denim"), std::string::npos);
  }
  Fabric f = fabric_or_throw("cotton");
  f.areal_density = -1;
  EXPECT_THROW(validate_fabric(f, "fabric.json"), InputError);
}

}  // namespace
}  // namespace drape
