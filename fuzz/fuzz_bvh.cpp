// libFuzzer target for BVH motion files: parse, check, retarget onto the default body; an input that
// starts as a JSON object is read as a joint map instead (see fuzz_checks.hpp).
#include "fuzz_checks.hpp"

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  drape::fuzz::prepare_motion_checks();
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  if (drape::fuzz::is_joint_map(text))
    drape::fuzz::check_joint_map(text, "fuzz_map.json");
  else
    drape::fuzz::check_motion_file(text, "fuzz.bvh");
  return 0;
}
