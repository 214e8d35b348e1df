#pragma once
// A dressed garment carried onto another body of the same mesh, as a start for dressing there.
//
// Every body made from measurements is the generator's one mesh in another shape (drape/body.hpp),
// so a garment dressed on one of them says where the same garment, in the same size and at the
// same resolution, lies on any other: each particle is kept where it was relative to its nearest
// body triangle (the point on it, by barycentric weights, and the offset from that point in the
// triangle's own frame). Dressing from there skips placement and sewing (the seams arrive closed)
// and drapes to the new body's equilibrium with the same solver, settling test and gates as a
// dressing from the flat pattern: the start changes how long it takes, not what counts as done.
// docs/dressing.md, "Starting from a dressed garment".
#include <cstdint>
#include <deque>
#include <map>
#include <memory>
#include <mutex>
#include <span>
#include <string>
#include <tuple>
#include <vector>

#include "drape/body.hpp"
#include "drape/mesh.hpp"

namespace drape {

struct DressedGarment;

// Bodies with the same fingerprint share a mesh: the same vertex count and the same triangles.
uint64_t mesh_fingerprint(const Mesh& mesh);

struct GarmentTransfer {
  std::string garment, size;    // the garment's name and size it was dressed in
  size_t particles = 0;         // its particle count (the mesh resolution it was dressed at)
  uint64_t body_mesh = 0;       // mesh_fingerprint of the body it was dressed on
  Measurements body_measurements;  // of that body: callers choose the nearest body's transfer
  // Per particle: the nearest body triangle, the barycentric weights of corners 1 and 2 of the
  // nearest point on it, and the particle's offset from that point along the triangle's first edge,
  // across it in its plane and along its normal.
  std::vector<uint32_t> triangle;
  std::vector<std::array<float, 5>> where;

  // Whether it can start `garment` in `size` with `particles` particles on a body of `body` mesh.
  bool matches(std::string_view garment, std::string_view size, size_t particles, uint64_t body) const;
};

// The transfer of garment `g` as dressed on `body`.
GarmentTransfer make_garment_transfer(const Body& body, const DressedGarment& g);

// Positions of the transferred garment's particles on `body` (which must have the mesh the transfer
// was made on: throws std::invalid_argument otherwise).
std::vector<Vec3f> transfer_positions(const GarmentTransfer& t, const Mesh& body);

// Transfers kept for the dressings to come (the web service's): per garment, size and body mesh,
// those of the last `per_key` bodies. Thread-safe.
class GarmentTransferStore {
 public:
  explicit GarmentTransferStore(size_t per_key = 8, double max_difference = 0.05)
      : per_key_(per_key), max_difference_(max_difference) {}
  // Those that can start `garment` in `size` on `body`, the nearest body first, from bodies that
  // differ from it by at most `max_difference` (the root mean square of the relative differences in
  // height, bust, waist and hips; a garment moved further starts far from its rest on the new body
  // and gains little).
  std::vector<std::shared_ptr<const GarmentTransfer>> for_body(const std::string& garment, const std::string& size,
                                                               const Body& body) const;
  void add(std::shared_ptr<const GarmentTransfer> transfer);
  size_t size() const;

 private:
  using Key = std::tuple<std::string, std::string, uint64_t>;
  size_t per_key_;
  double max_difference_;
  mutable std::mutex mutex_;
  std::map<Key, std::deque<std::shared_ptr<const GarmentTransfer>>> kept_;
};

}  // namespace drape
