#pragma once
// Image-space body collider (Vassilev & Spanlang sec. 4.2). The body is rendered orthographically
// along Z from the front and from the back into depth maps and maps of per-pixel interpolated vertex
// normals (the paper used the graphics hardware's depth and colour buffers; here the CPU rasterizer,
// see geometry/rasterize.hpp). A cloth vertex maps to one pixel in O(1): it is inside the body when
// its z lies between the back and the front depth; its distance is measured to the tangent plane of
// the nearer of the two visible surface points, along that point's normal.
//
// Blind spots: two views see only the first and the last surface along each Z ray. Where the ray
// crosses the body more than once (an arm in front of the torso, a bent leg) the air between the
// layers counts as body; where the surface is seen edge-on (armpits, between the legs, under the
// bust, side walls) a pixel's depth says little about points beside it. With hidden-region handling
// on, such pixels are found when the maps are rendered (a third pass draws only the surfaces that
// face away from the front viewer, giving the first exit along each ray: more than one layer when
// it differs from the last exit; plus |n_z| below a threshold in either map), grown by two pixels,
// and queries there are answered exactly by the BVH.
#include <memory>

#include "collision/body_surface.hpp"
#include "collision/triangle_bvh.hpp"
#include "drape/collision.hpp"
#include "geometry/rasterize.hpp"

namespace drape::collision {

class ImageCollider final : public BodyCollider {
 public:
  ImageCollider(const Mesh& body, const BodyColliderOptions& options);
  std::string_view name() const override { return "image"; }
  void set_surface(std::span<const Vec3f> positions, double t) override;
  void query(std::span<const Vec3f> points, float radius, std::span<ContactSample> out) const override;
  BodyColliderBuildStats build_stats() const override { return stats_; }
  size_t vertex_count() const override { return surface_.vertex_count(); }

 private:
  // Hot per-pixel data of both views, packed so one query touches one 32-byte record.
  struct Texel {
    float z_front;  // -inf where no body; NaN where the pixel is hidden (answered by the BVH)
    float z_back;
    Vec3f n_front, n_back;
  };
  static_assert(sizeof(Texel) == 32);

  void render_maps();
  ContactSample sample(const Vec3f& p, float radius) const;

  BodyColliderOptions options_;
  BodySurface surface_;
  std::unique_ptr<TriangleBvh> bvh_;  // for hidden pixels; null when handling is off
  int width_ = 0, height_ = 0;
  float inverse_pixel_ = 1.0f;
  Vec2f origin_ = Vec2f::Zero();
  std::vector<Texel> texels_;
  // Visible triangle per pixel of each view, for the surface velocity at the query's nearest point
  // on it; only kept, and only read, while the body moves (a static body's velocity is zero).
  std::vector<uint32_t> front_triangle_, back_triangle_;
  bool moving_ = false;
  // Rendering scratch, kept across frames of a moving body.
  DepthNormalMap front_, back_;
  VisibilityBuffer visibility_;
  std::vector<ScreenVertex> screen_;
  std::vector<Tri> reversed_;  // triangles with flipped winding: the back-facing pass
  std::vector<uint8_t> hidden_, dilated_;
  BodyColliderBuildStats stats_;
};

}  // namespace drape::collision
