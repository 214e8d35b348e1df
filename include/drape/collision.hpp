#pragma once
// Cloth-body collision geometry (Vassilev & Spanlang sec. 4): three ways to answer "how far is this
// cloth vertex from the body, which way is out, how fast is the skin moving there", behind the
// drape::Collider interface, plus the exact inside test that report.json's penetration keys use.
//
//   image  sec. 4.2: the body rendered orthographically from the front and the back into depth,
//          normal and velocity maps; an O(1) lookup per cloth vertex. Regions hidden from both views
//          (armpits, crotch, inside of bent arms) are detected per pixel and answered by the BVH.
//   bvh    sec. 4.1: closest point on the body triangles through a bounding volume hierarchy
//          (Embree 3 point queries), sign from angle-weighted pseudo-normals.
//   sdf    a sparse narrow-band signed distance grid (bricks), trilinear distance, gradient normal.
//
// The response (eq. 5, sec. 5 forces) lives in the simulation; this layer only supplies geometry.
// Thickness is the cloth's: the simulation adds it to the distances these colliders return.
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <string_view>
#include <vector>

#include "drape/collider.hpp"
#include "drape/mesh.hpp"

namespace drape {

enum class CollisionMethod { image, bvh, sdf };

std::string_view to_string(CollisionMethod method);
// "image", "bvh" or "sdf"; nullopt for anything else.
std::optional<CollisionMethod> parse_collision_method(std::string_view text);

struct BodyColliderOptions {
  // image: size of one map pixel (metres); the maps cover the body's x-y bounds plus a margin.
  float pixel_size = 0.003f;
  // image: answer pixels hidden from both views (several surface layers along the view ray,
  // or surfaces seen edge-on) with the exact BVH query instead of the maps.
  bool hidden_region_handling = true;
  // image: |n_z| below which a surface counts as seen edge-on (its depth is unreliable).
  float edge_on_cosine = 0.25f;
  // sdf: grid spacing (metres) and the half width of the narrow band that is stored exactly.
  float voxel_size = 0.004f;
  float band = 0.02f;
  // bvh, and image's hidden pixels: index the space near the body (a candidate list per 7 mm cell)
  // for fast queries. It takes about 0.2 s on a 20k-triangle body and pays off over the explicit
  // step's thousands of iterations; a few thousand queries (measuring a dressed garment) or the
  // implicit solver's (contacts found anew only where a particle moved 1 mm: 0.02 s of the default
  // shirt's dressing) are cheaper straight from the tree.
  bool candidate_grid = true;
};

// Body vertex positions at time t, written into `positions` (already sized to the vertex count).
using BodyMotion = std::function<void(double t, std::span<Vec3f> positions)>;

// Timings of the last (re)build, for benchmarks and the CLI's profile.
struct BodyColliderBuildStats {
  double build_seconds = 0;  // last set_surface (maps / BVH refit / field update)
  size_t memory_bytes = 0;   // size of the collision structure
  double hidden_fraction = 0;  // image: fraction of covered pixels answered by the BVH
  double rebuilt_fraction = 1;  // sdf: fraction of the stored bricks re-sampled by the last update
};

// A collider for a (possibly moving or deforming) body mesh of fixed topology.
class BodyCollider : public Collider {
 public:
  // New body vertex positions (same vertex count as the mesh given to the factory) at time t.
  // The surface velocity is the finite difference to the previous positions (zero for the first).
  virtual void set_surface(std::span<const Vec3f> positions, double t) = 0;

  // Drives the body from a motion: update(t) asks it for the positions at t and calls set_surface.
  void set_motion(BodyMotion motion) { motion_ = std::move(motion); }
  void update(double t) override;

  virtual BodyColliderBuildStats build_stats() const = 0;
  virtual size_t vertex_count() const = 0;

 private:
  BodyMotion motion_;
  std::vector<Vec3f> motion_positions_;
};

// A body collider of the chosen method. The body must be a non-empty triangle mesh, closed apart from
// small holes, with triangles counter-clockwise seen from outside. Throws std::invalid_argument on an
// empty mesh or non-positive sizes.
std::unique_ptr<BodyCollider> make_body_collider(const Mesh& body, CollisionMethod method,
                                                 const BodyColliderOptions& options = {});

// The independent inside test: generalized winding number (Jacobson et al. 2013) evaluated
// hierarchically (Barill et al. 2018), robust to small holes, plus the exact distance to the surface.
// Build once per body pose; const queries are thread-safe.
class InsideTest {
 public:
  explicit InsideTest(const Mesh& body);
  ~InsideTest();
  InsideTest(InsideTest&&) noexcept;
  InsideTest& operator=(InsideTest&&) noexcept;

  double winding_number(const Vec3f& p) const;          // ~1 inside, ~0 outside
  bool inside(const Vec3f& p) const { return winding_number(p) > 0.5; }
  float unsigned_distance(const Vec3f& p) const;       // exact distance to the nearest triangle

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

struct PenetrationStats {
  size_t penetrating = 0;     // points inside the body deeper than the tolerance
  double fraction = 0;        // penetrating / points
  float max_depth_m = 0;      // deepest point's distance to the surface (0 when none)
};

// Points inside the body (winding number > 1/2) deeper than `tolerance` metres.
PenetrationStats measure_penetration(const InsideTest& body, std::span<const Vec3f> points, float tolerance = 0);
PenetrationStats measure_penetration(const Mesh& body, std::span<const Vec3f> points, float tolerance = 0);

}  // namespace drape
