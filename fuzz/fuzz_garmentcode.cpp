// libFuzzer target for GarmentCode specifications and the 2021 templates: parse, validate every size, mesh (see fuzz_checks.hpp).
// Inputs of the other garment formats are left out of the corpus (-1), so the target stays on its parser.
#include "fuzz_checks.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  if (!drape::fuzz::is_garment_format(text, drape::fuzz::GarmentFormat::GarmentCode)) return -1;
  drape::fuzz::check_garment_file(text, "fuzz.json");
  return 0;
}
