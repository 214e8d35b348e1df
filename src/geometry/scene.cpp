#include "drape/scene.hpp"

namespace drape {

int Scene::find_node(const std::string& name) const {
  for (size_t i = 0; i < nodes.size(); ++i)
    if (nodes[i].name == name) return static_cast<int>(i);
  return -1;
}

Mat4f Scene::world_transform(int node) const {
  Mat4f m = Mat4f::Identity();
  // Walk up the parent chain; a cycle guard keeps malformed files from hanging us.
  for (size_t guard = 0; node >= 0 && guard <= nodes.size(); ++guard) {
    const Node& n = nodes[static_cast<size_t>(node)];
    Eigen::Affine3f local = Eigen::Translation3f(n.translation) * n.rotation * Eigen::Scaling(n.scale);
    m = local.matrix() * m;
    node = n.parent;
  }
  return m;
}

}  // namespace drape
