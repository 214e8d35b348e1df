#include "body/baked.hpp"

#include <cstdint>
#include <cstring>
#include <stdexcept>

namespace drape::body {

namespace {

constexpr char kMagic[8] = {'D', 'R', 'A', 'P', 'E', 'B', 'B', '1'};

template <class T>
void put(std::string& out, const T* data, size_t count) {
  out.append(reinterpret_cast<const char*>(data), count * sizeof(T));
}

struct Reader {
  std::span<const unsigned char> bytes;
  size_t at = 0;
  template <class T>
  void get(T* data, size_t count) {
    const size_t size = count * sizeof(T);
    if (bytes.size() - at < size) throw std::runtime_error("baked default bodies: truncated data");
    std::memcpy(data, bytes.data() + at, size);
    at += size;
  }
  uint32_t u32() {
    uint32_t v = 0;
    get(&v, 1);
    return v;
  }
};

}  // namespace

std::string encode_baked_bodies(const std::vector<BakedBody>& bodies) {
  std::string out(kMagic, sizeof kMagic);
  const auto count = static_cast<uint32_t>(bodies.size());
  put(out, &count, 1);
  for (const BakedBody& b : bodies) {
    const Mesh& m = b.mesh;
    if (m.normals.size() != m.positions.size()) throw std::runtime_error("baked default bodies: a mesh without normals");
    const uint32_t head[3] = {b.sex == Sex::Male ? 1u : 0u, static_cast<uint32_t>(m.positions.size()),
                              static_cast<uint32_t>(m.triangles.size())};
    put(out, head, 3);
    for (const Vec3f& p : m.positions) put(out, p.data(), 3);
    for (const Vec3f& n : m.normals) put(out, n.data(), 3);
    for (const Tri& t : m.triangles) put(out, t.data(), 3);
  }
  return out;
}

Mesh decode_baked_body(std::span<const unsigned char> bytes, Sex sex) {
  Reader r{bytes};
  char magic[sizeof kMagic];
  r.get(magic, sizeof magic);
  if (std::memcmp(magic, kMagic, sizeof kMagic) != 0) throw std::runtime_error("baked default bodies: not a DRAPEBB1 bake");
  const uint32_t count = r.u32();
  for (uint32_t i = 0; i < count; ++i) {
    uint32_t head[3];
    r.get(head, 3);
    Mesh mesh;
    mesh.positions.resize(head[1]);
    mesh.normals.resize(head[1]);
    mesh.triangles.resize(head[2]);
    for (Vec3f& p : mesh.positions) r.get(p.data(), 3);
    for (Vec3f& n : mesh.normals) r.get(n.data(), 3);
    for (Tri& t : mesh.triangles) {
      r.get(t.data(), 3);
      for (uint32_t v : t)
        if (v >= head[1]) throw std::runtime_error("baked default bodies: a triangle names a vertex past the end");
    }
    if ((head[0] == 1) == (sex == Sex::Male)) return mesh;
  }
  throw std::runtime_error("baked default bodies: no body of the requested sex");
}

}  // namespace drape::body
