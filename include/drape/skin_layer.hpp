#pragma once
// The skin layer (Cordier, Volino & Magnenat-Thalmann 2001,
// ../shared/papers/cordier-volino-thalmann-body-cloth-integration.txt): the skinned body is the
// reference surface, and a physical skin rests on it, each vertex held to its reference point by a
// zero-rest-length spring and to its neighbours by springs along the mesh's edges. Where skeletal
// skinning drives one body part into another (an arm lowered against the torso, thigh against
// thigh), contact between the two parts' skin pushes both apart, equal and opposite, until they
// keep a gap between them (room for the cloth caught between).
//
//   SkinLayer skin(body);
//   skin_mesh(body, pose, Skinning::Linear, reference);
//   const SkinContactStats s = skin.solve(reference, positions);   // positions: the skin at rest
//
// Per vertex u = x - reference, the skin's rest is the minimum of
//
//   E(u) = sum_i a_i/2 |u_i|^2 + sum_edges m/2 |u_i - u_j|^2 + sum_contacts k_c/2 min(0, g_c(u))^2
//
// a_i = the anchor's stiffness per area (firmer over bone than on the soft regions) times the
// vertex's area, m the membrane's stiffness, and g_c the gap of a contact of a vertex with a
// triangle of another part, less the gap kept, along that triangle's normal (linear in u: the
// vertex's displacement against its contact point's, the triangle's corners weighted by their
// barycentric weights). Contacts are found on the reference surface, and the quadratic is solved
// over the contacts that are closed, again until that set stops changing (an active-set method),
// on the vertices within a few rings of a contact; every other vertex stays on its reference.
// Contact inside one part (a forearm folded onto its upper arm) is not handled.
#include <cstddef>
#include <memory>
#include <span>

#include "drape/body.hpp"

namespace drape {

struct SkinLayerOptions {
  // The anchors' stiffness per square metre of skin (Pa/m): over bone and firm tissue, and on the
  // soft regions of drape/soft_body.hpp (belly, buttocks, thighs, bust, upper arms). 1e5 Pa/m: a
  // pressure of 1 kPa moves the skin 1 cm off its reference.
  float firm_stiffness = 3.0e5f;
  float soft_stiffness = 1.0e5f;
  // The membrane: a spring along each edge of the mesh (N/m), spreading a dent over its neighbours.
  float membrane = 40.0f;
  // The gap kept between the skin of two body parts (m); DressOptions-free: animate() sets it from
  // the garments' thickness, so the cloth caught between has room.
  float gap = 0.001f;
  // A vertex and a triangle of another part closer than this in the bind pose meet at a joint (the
  // armpit, the crotch, the neck) and are never in contact (m).
  float joint_separation = 0.06f;
};

struct SkinContactStats {
  size_t vertices_inside = 0;  // vertices more than the tolerance inside another body part
  float max_depth_m = 0;       // the deepest of them
  size_t contacts = 0;         // solve(): contacts closed at the rest
  size_t moved = 0;            // solve(): vertices the solve moved off the reference
  int iterations = 0;          // solve(): active-set iterations
  float max_move_m = 0;        // solve(): the largest move off the reference
  // solve(): the anchors' forces on the skin at its rest, summed (|sum|, N) and in magnitude (sum of
  // |a_i u_i|, N). Contact between parts is equal and opposite and the membrane internal, so at
  // rest the first is zero (what keeps two parts apart is their reaction on the skeleton).
  double net_force_n = 0, anchor_force_n = 0;
};

class SkinLayer {
 public:
  // `body`: its mesh in the bind pose and its parts (drape::analyse_body). Throws
  // std::invalid_argument when the body has no parts.
  explicit SkinLayer(const Body& body, const SkinLayerOptions& options = {});
  ~SkinLayer();
  SkinLayer(SkinLayer&&) noexcept;
  SkinLayer& operator=(SkinLayer&&) noexcept;

  // The skin at rest on `reference` (every body vertex, posed): into `out` (the same size; may be
  // `reference` itself).
  SkinContactStats solve(std::span<const Vec3f> reference, std::span<Vec3f> out);
  // The vertices of `positions` more than `tolerance` inside another body part (along that part's
  // surface normal at the nearest point), away from the joints where parts meet.
  SkinContactStats inside(std::span<const Vec3f> positions, float tolerance = 0.001f);

  const SkinLayerOptions& options() const;
  void set_gap(float gap);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace drape
