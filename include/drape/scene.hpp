#pragma once
// A scene as glTF describes it: meshes on named nodes, skins, animations. Bodies and garments
// are separate named nodes (`body`, then one per garment), per DESIGN.md.
#include <Eigen/Geometry>
#include <string>
#include <vector>

#include "drape/mesh.hpp"

namespace drape {

struct Node {
  std::string name;
  int parent = -1;  // index into Scene::nodes, -1 for a root
  Vec3f translation = Vec3f::Zero();
  Eigen::Quaternionf rotation = Eigen::Quaternionf::Identity();
  Vec3f scale = Vec3f::Ones();
  int mesh = -1;  // index into Scene::meshes
  int skin = -1;  // index into Scene::skins
};

struct Skin {
  std::string name;
  std::vector<int> joints;                   // node indices
  std::vector<Mat4f> inverse_bind_matrices;  // one per joint (identity when the file had none)
  int skeleton = -1;                         // root node, -1 when unspecified
};

enum class AnimationPath { Translation, Rotation, Scale, Weights };
enum class Interpolation { Linear, Step, CubicSpline };

struct AnimationChannel {
  int node = -1;
  AnimationPath path = AnimationPath::Translation;
  Interpolation interpolation = Interpolation::Linear;
  std::vector<float> times;   // seconds, increasing
  std::vector<float> values;  // flattened: 3 (T, S), 4 (R, xyzw) or #targets (W) per key; x3 for cubic
};

struct Animation {
  std::string name;
  std::vector<AnimationChannel> channels;
};

struct Scene {
  std::vector<Mesh> meshes;
  std::vector<Node> nodes;
  std::vector<Skin> skins;
  std::vector<Animation> animations;

  // First node with this name, or -1.
  int find_node(const std::string& name) const;
  // Node's transform in world space (parents applied).
  Mat4f world_transform(int node) const;
};

}  // namespace drape
