#pragma once
// A real body read from file with its exact inside test and the image-space collider twice: plain
// front/back maps and with hidden-region handling, for the tests that compare the two.
#include <filesystem>
#include <memory>

#include "drape/collision.hpp"
#include "drape/io.hpp"

namespace drape::test {

struct ImageCollidersWithTruth {
  explicit ImageCollidersWithTruth(const std::filesystem::path& path)
      : body(read_mesh(path)), truth(body), plain(make(false)), handled(make(true)) {}

  Mesh body;
  InsideTest truth;  // the independent judge (generalized winding number)
  std::unique_ptr<BodyCollider> plain, handled;

 private:
  std::unique_ptr<BodyCollider> make(bool hidden_region_handling) const {
    BodyColliderOptions options;
    options.hidden_region_handling = hidden_region_handling;
    return make_body_collider(body, CollisionMethod::image, options);
  }
};

}  // namespace drape::test
