#include "geometry/units.hpp"

#include <Eigen/Geometry>
#include <cassert>

namespace drape::geometry {

Eigen::Matrix3f z_up_to_y_up() {
  Eigen::Matrix3f m;
  m << 1, 0, 0,  //
      0, 0, 1,   //
      0, -1, 0;
  return m;
}

void change_frame(Scene& scene, float scale, const Eigen::Matrix3f& axis_map) {
  assert(scale > 0.0f);
  assert(std::abs(axis_map.determinant() - 1.0f) < 1e-6f);
  const Eigen::Matrix3f& r = axis_map;
  const Eigen::Matrix3f abs_r = r.cwiseAbs();  // permutes per-axis scales
  const Eigen::Quaternionf qr(r);
  const auto rotate = [&](const Eigen::Quaternionf& q) {
    return Eigen::Quaternionf(qr * q * qr.conjugate());
  };

  // Mesh data: p -> s R p; directions -> R n.
  for (Mesh& mesh : scene.meshes) {
    for (Vec3f& p : mesh.positions) p = scale * (r * p);
    for (Vec3f& n : mesh.normals) n = r * n;
    for (MorphTarget& target : mesh.morph_targets) {
      for (Vec3f& d : target.position_deltas) d = scale * (r * d);
      for (Vec3f& d : target.normal_deltas) d = r * d;
    }
  }
  // Node transforms are conjugated, L -> C L C^-1, so world transforms become C W C^-1 and a vertex
  // C v of a mesh on that node lands at C (W v): the whole scene moves as one.
  for (Node& node : scene.nodes) {
    node.translation = scale * (r * node.translation);
    node.rotation = rotate(node.rotation);
    node.scale = abs_r * node.scale;
  }
  for (Skin& skin : scene.skins)
    for (Mat4f& ibm : skin.inverse_bind_matrices) {
      const Eigen::Matrix3f linear = r * ibm.topLeftCorner<3, 3>() * r.transpose();
      const Vec3f translation = scale * (r * ibm.topRightCorner<3, 1>());
      ibm.topLeftCorner<3, 3>() = linear;
      ibm.topRightCorner<3, 1>() = translation;
    }
  // Animation keys (and cubic-spline tangents, which transform the same way).
  for (Animation& animation : scene.animations)
    for (AnimationChannel& channel : animation.channels) {
      std::vector<float>& v = channel.values;
      if (channel.path == AnimationPath::Translation || channel.path == AnimationPath::Scale) {
        for (size_t i = 0; i + 3 <= v.size(); i += 3) {
          const Vec3f x(v[i], v[i + 1], v[i + 2]);
          const Vec3f y =
              channel.path == AnimationPath::Translation ? Vec3f(scale * (r * x)) : Vec3f(abs_r * x);
          v[i] = y.x(), v[i + 1] = y.y(), v[i + 2] = y.z();
        }
      } else if (channel.path == AnimationPath::Rotation) {
        for (size_t i = 0; i + 4 <= v.size(); i += 4) {
          const Eigen::Quaternionf q = rotate(Eigen::Quaternionf(v[i + 3], v[i], v[i + 1], v[i + 2]));
          v[i] = q.x(), v[i + 1] = q.y(), v[i + 2] = q.z(), v[i + 3] = q.w();
        }
      }
    }
}

}  // namespace drape::geometry
