#include "body/baked.hpp"

#include <cstdint>
#include <cstring>
#include <stdexcept>

namespace drape::body {

namespace {

constexpr char kMagic[8] = {'D', 'R', 'A', 'P', 'E', 'B', 'B', '2'};

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

std::string encode_baked_shapes(const std::vector<MhShape>& shapes) {
  std::string out(kMagic, sizeof kMagic);
  const auto count = static_cast<uint32_t>(shapes.size());
  put(out, &count, 1);
  for (const MhShape& s : shapes) {
    const uint32_t sex = s.sex == Sex::Male ? 1u : 0u;
    put(out, &sex, 1);
    const float macros[3] = {s.weight, s.height, s.scale};
    put(out, macros, 3);
    const auto targets = static_cast<uint32_t>(s.measure.size());
    put(out, &targets, 1);
    put(out, s.measure.data(), s.measure.size());
  }
  return out;
}

MhShape decode_baked_shape(std::span<const unsigned char> bytes, Sex sex) {
  Reader r{bytes};
  char magic[sizeof kMagic];
  r.get(magic, sizeof magic);
  if (std::memcmp(magic, kMagic, sizeof kMagic) != 0) throw std::runtime_error("baked default bodies: not a DRAPEBB2 bake");
  const uint32_t count = r.u32();
  for (uint32_t i = 0; i < count; ++i) {
    MhShape s;
    s.sex = r.u32() == 1 ? Sex::Male : Sex::Female;
    float macros[3];
    r.get(macros, 3);
    s.weight = macros[0];
    s.height = macros[1];
    s.scale = macros[2];
    if (r.u32() != s.measure.size()) throw std::runtime_error("baked default bodies: made for other MakeHuman targets");
    r.get(s.measure.data(), s.measure.size());
    if (s.sex == sex) return s;
  }
  throw std::runtime_error("baked default bodies: no body of the requested sex");
}

}  // namespace drape::body
