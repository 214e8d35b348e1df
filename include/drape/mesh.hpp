#pragma once
// Triangle meshes: the exchange type between io, body, pattern, sim and render.
// Attribute arrays are either empty or hold exactly one entry per vertex.
#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

namespace drape {

using Vec2f = Eigen::Vector2f;
using Vec3f = Eigen::Vector3f;
using Vec4f = Eigen::Vector4f;
using Vec3d = Eigen::Vector3d;
using Mat4f = Eigen::Matrix4f;
using Tri = std::array<uint32_t, 3>;

struct MorphTarget {
  std::string name;
  std::vector<Vec3f> position_deltas;  // one per vertex
  std::vector<Vec3f> normal_deltas;    // empty or one per vertex
};

struct Mesh {
  std::string name;
  std::vector<Vec3f> positions;
  std::vector<Tri> triangles;  // counter-clockwise seen from outside

  std::vector<Vec3f> normals;  // unit vertex normals
  std::vector<Vec2f> uvs;      // TEXCOORD_0; on garments the flat pattern position in metres
  std::vector<Vec4f> colors;   // linear RGBA in [0, 1]

  // Skinning: up to four influences per vertex; joint indices index Skin::joints.
  std::vector<std::array<uint16_t, 4>> joints;
  std::vector<Vec4f> weights;

  std::vector<MorphTarget> morph_targets;
  std::vector<float> morph_weights;  // default weights, one per target

  // Named groups (OBJ `g`/`o`): group index per triangle; both empty when the file had none.
  std::vector<std::string> group_names;
  std::vector<uint32_t> triangle_groups;

  size_t vertex_count() const { return positions.size(); }
  size_t triangle_count() const { return triangles.size(); }
};

struct Bounds {
  Vec3f min{Vec3f::Constant(std::numeric_limits<float>::max())};
  Vec3f max{Vec3f::Constant(-std::numeric_limits<float>::max())};
  bool empty() const { return (max.array() < min.array()).any(); }
  Vec3f size() const { return empty() ? Vec3f::Zero() : Vec3f(max - min); }
  Vec3f center() const { return 0.5f * (min + max); }
  void extend(const Vec3f& p) {
    min = min.cwiseMin(p);
    max = max.cwiseMax(p);
  }
};

Bounds bounds(const std::vector<Vec3f>& points);

// Area-weighted vertex normals (unit; zero for isolated vertices).
std::vector<Vec3f> vertex_normals(const std::vector<Vec3f>& positions, const std::vector<Tri>& triangles);

}  // namespace drape
