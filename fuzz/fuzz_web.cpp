// libFuzzer target for the web service's request bodies: JSON measurements, try-on requests and
// body uploads (see fuzz_checks.hpp). Inputs whose first line names no request are left out of the
// corpus (-1).
#include "fuzz_checks.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string_view input(reinterpret_cast<const char*>(data), size);
  return drape::fuzz::check_web_request(input) ? 0 : -1;
}
