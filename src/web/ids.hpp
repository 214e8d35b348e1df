#pragma once
// Ids of bodies and try-ons: 128 random bits from std::random_device as 32 lowercase hex digits.
// An id is the only key to a body (never listed), so it must not be guessable, and it is checked
// to be exactly that before it is looked up or used in a path.
#include <string>
#include <string_view>

namespace drape::web {

inline constexpr size_t kIdLength = 32;

std::string random_id();
bool is_id(std::string_view text);

}  // namespace drape::web
