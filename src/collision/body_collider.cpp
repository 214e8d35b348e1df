// Body collider factory and the shared moving-body plumbing; see drape/collision.hpp.
#include <stdexcept>

#include "collision/bvh_collider.hpp"
#include "collision/image_collider.hpp"
#include "collision/sdf_collider.hpp"
#include "drape/collision.hpp"

namespace drape {

std::string_view to_string(CollisionMethod method) {
  switch (method) {
    case CollisionMethod::image: return "image";
    case CollisionMethod::bvh: return "bvh";
    case CollisionMethod::sdf: return "sdf";
  }
  return "?";
}

std::optional<CollisionMethod> parse_collision_method(std::string_view text) {
  if (text == "image") return CollisionMethod::image;
  if (text == "bvh") return CollisionMethod::bvh;
  if (text == "sdf") return CollisionMethod::sdf;
  return std::nullopt;
}

void BodyCollider::update(double t) {
  if (!motion_) return;
  motion_positions_.resize(vertex_count());
  motion_(t, motion_positions_);
  set_surface(motion_positions_, t);
}

std::unique_ptr<BodyCollider> make_body_collider(const Mesh& body, CollisionMethod method,
                                                 const BodyColliderOptions& options) {
  if (body.positions.empty() || body.triangles.empty())
    throw std::invalid_argument("body collider: the body mesh has no triangles");
  switch (method) {
    case CollisionMethod::image: return std::make_unique<collision::ImageCollider>(body, options);
    case CollisionMethod::bvh: return std::make_unique<collision::BvhCollider>(body, options.candidate_grid);
    case CollisionMethod::sdf: return std::make_unique<collision::SdfCollider>(body, options.voxel_size, options.band);
  }
  throw std::invalid_argument("body collider: unknown method");
}

}  // namespace drape
