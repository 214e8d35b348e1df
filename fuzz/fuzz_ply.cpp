// libFuzzer target for the PLY reader (see fuzz_target.hpp).
#include "fuzz_target.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  return drape::fuzz::parse_and_round_trip(data, size, drape::MeshFormat::Ply, "fuzz.ply");
}
