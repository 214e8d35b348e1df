#include "web/ids.hpp"

#include <mutex>
#include <random>

namespace drape::web {

std::string random_id() {
  // One random_device for the process (it reads the kernel's entropy; a mutex because its
  // operator() is not required to be thread-safe). 4 x 32 bits, each drawn fresh: no PRNG state
  // that one id could reveal the next from.
  static std::random_device device;
  static std::mutex mutex;
  static constexpr char kHex[] = "0123456789abcdef";
  std::string id;
  id.reserve(kIdLength);
  std::lock_guard lock(mutex);
  for (int word = 0; word < 4; ++word) {
    uint32_t bits = device();
    for (int nibble = 0; nibble < 8; ++nibble, bits >>= 4) id.push_back(kHex[bits & 15u]);
  }
  return id;
}

bool is_id(std::string_view text) {
  if (text.size() != kIdLength) return false;
  for (const char c : text)
    if (!((c >= '0' && c <= '9') || (c >= 'a' && c <= 'f'))) return false;
  return true;
}

}  // namespace drape::web
