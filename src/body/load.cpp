// Bodies from files: scans (OBJ/PLY) and rigged glTF, normalised to drape's frame.
//
// Units and the up axis come from the caller (DESIGN.md: never guessed). What remains is the turn
// about the vertical and the placement, which a scan leaves arbitrary:
//  - left-right axis: the major axis of the horizontal spread of the upper body (shoulders and arms
//    are wider than the body is deep), turned onto X;
//  - front: feet point forwards, so the centroid of the feet (lowest 4 % of the height) lies in
//    front of the centroid of the shins (8-15 %); if it lies behind, the body is turned by 180°;
//  - feet on y = 0, and centred in x and z on the torso (30-85 % of the height).
// Small turns (under 2°) are left alone so bodies already in the frame keep their exact coordinates.
#include <Eigen/Geometry>
#include <cmath>

#include "drape/body.hpp"
#include "drape/error.hpp"

namespace drape {

namespace {

Vec2f band_centroid(const std::vector<Vec3f>& p, float lo, float hi) {
  Vec2f sum = Vec2f::Zero();
  int n = 0;
  for (const auto& q : p)
    if (q.y() >= lo && q.y() <= hi) {
      sum += Vec2f(q.x(), q.z());
      ++n;
    }
  return n ? Vec2f(sum / static_cast<float>(n)) : Vec2f::Zero();
}

}  // namespace

Eigen::Affine3f normalise_body_placement(Mesh& mesh, const std::string& source) {
  if (mesh.positions.empty() || mesh.triangles.empty()) throw InputError(source, "no mesh: the file holds no triangles");
  const Bounds box = bounds(mesh.positions);
  const float height = box.size().y();
  if (!(height >= 0.5f && height <= 2.5f))
    throw InputError(source, "not a standing person: height " + std::to_string(height) +
                                 " m after unit conversion is outside 0.5-2.5 m (check --units and --up)");
  const float y0 = box.min.y();
  auto at = [&](float f) { return y0 + f * height; };

  // Turn the upper body's widest horizontal direction onto X.
  // The major axis of a 2x2 covariance [[xx, xz], [xz, zz]] is at 0.5 atan2(2 xz, xx - zz) from +X.
  double xx = 0, xz = 0, zz = 0;
  const Vec2f upper = band_centroid(mesh.positions, at(0.55f), at(0.85f));
  for (const auto& q : mesh.positions)
    if (q.y() >= at(0.55f) && q.y() <= at(0.85f)) {
      const double dx = q.x() - upper.x(), dz = q.z() - upper.y();
      xx += dx * dx;
      xz += dx * dz;
      zz += dz * dz;
    }
  float yaw = static_cast<float>(0.5 * std::atan2(2 * xz, xx - zz));  // major axis angle from +X (x-z)
  if (yaw > static_cast<float>(M_PI) / 2) yaw -= static_cast<float>(M_PI);
  if (yaw < -static_cast<float>(M_PI) / 2) yaw += static_cast<float>(M_PI);
  if (std::abs(yaw) < 2.0f * static_cast<float>(M_PI) / 180.0f) yaw = 0.0f;
  // Rotating about +Y by +yaw maps direction (cos yaw, sin yaw) in (x, z) onto +X.
  Eigen::Matrix3f turn = Eigen::AngleAxisf(yaw, Vec3f::UnitY()).toRotationMatrix();
  // Facing: feet in front of the shins.
  {
    std::vector<Vec3f> turned(mesh.positions.size());
    for (size_t i = 0; i < turned.size(); ++i) turned[i] = turn * mesh.positions[i];
    const float feet = band_centroid(turned, at(0.0f), at(0.04f)).y();
    const float shins = band_centroid(turned, at(0.08f), at(0.15f)).y();
    if (feet < shins) turn = Eigen::AngleAxisf(static_cast<float>(M_PI), Vec3f::UnitY()).toRotationMatrix() * turn;
  }
  for (auto& q : mesh.positions) q = turn * q;
  for (auto& n : mesh.normals) n = turn * n;
  const Vec2f centre = band_centroid(mesh.positions, at(0.30f), at(0.85f));
  const Vec3f shift(-centre.x(), -y0, -centre.y());
  for (auto& q : mesh.positions) q += shift;
  Eigen::Affine3f transform = Eigen::Affine3f::Identity();
  transform.linear() = turn;
  transform.translation() = shift;
  return transform;
}

Body load_body(const std::filesystem::path& path, const LoadOptions& options) {
  const std::string source = path.string();
  Scene scene = read_scene(path, options);
  Body body;
  body.mesh = merge_scene(scene);
  body.mesh.name = "body";
  // Keep a glTF skin: joint names, hierarchy and bind-pose positions.
  if (!scene.skins.empty() && !body.mesh.joints.empty()) {
    const Skin& skin = scene.skins.front();
    for (size_t j = 0; j < skin.joints.size(); ++j) {
      const int node = skin.joints[j];
      Joint joint;
      joint.name = scene.nodes[static_cast<size_t>(node)].name;
      const Mat4f world = skin.inverse_bind_matrices.size() > j ? Mat4f(skin.inverse_bind_matrices[j].inverse())
                                                                : scene.world_transform(node);
      joint.position = world.block<3, 1>(0, 3);
      const int parent_node = scene.nodes[static_cast<size_t>(node)].parent;
      for (size_t k = 0; k < skin.joints.size(); ++k)
        if (skin.joints[k] == parent_node) joint.parent = static_cast<int>(k);
      body.skeleton.joints.push_back(joint);
    }
  } else {
    body.mesh.joints.clear();
    body.mesh.weights.clear();
  }
  const Eigen::Affine3f placed = normalise_body_placement(body.mesh, source);
  for (auto& j : body.skeleton.joints) j.position = placed * j.position;
  analyse_body(body, source);
  if (body.skeleton.empty()) rig_body(body);
  return body;
}

}  // namespace drape
