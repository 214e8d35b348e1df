// libFuzzer target for the PLY reader and the writers it round-trips through (see fuzz_checks.hpp).
#include "fuzz_checks.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  drape::fuzz::check_mesh_file({data, size}, drape::MeshFormat::Ply, "fuzz.ply");
  return 0;
}
