#pragma once
// What the fuzz targets check on every input, shared by the libFuzzer entry points (fuzz/fuzz_*.cpp)
// and the corpus replay in the tests (tests/fuzz_replay), so CI runs the same checks over every kept
// input in the release build without libFuzzer.
//
// Each check parses the input as a user's file; bad input must end in an InputError. Anything else is
// a finding: a sanitizer report, a crash, another exception escaping, or a Finding thrown when a
// property of what was read does not hold.
#include <cstdint>
#include <optional>
#include <span>
#include <stdexcept>
#include <string>
#include <string_view>

#include "drape/io.hpp"

namespace drape::fuzz {

// A property that does not hold for an input that parsed.
class Finding : public std::logic_error {
 public:
  using std::logic_error::logic_error;
};

// Parses `bytes` as a mesh file. When it reads, the merged mesh is written as OBJ, PLY (three
// encodings) and the scene as GLB, and each must read back to the same mesh (same triangles, the
// same positions within float rounding). Returns whether the input was read.
bool check_mesh_file(std::span<const unsigned char> bytes, MeshFormat format, const std::string& source);

// Garment formats, as parse_garment detects them from the content.
enum class GarmentFormat { DrapeJson, GarmentCode, Dxf };

// True when `text` would be read as `format`; a target skips inputs of the other formats, so each
// target explores its own parser.
bool is_garment_format(std::string_view text, GarmentFormat format);

// Parses `text` as a garment file. When it parses (every size validated), each size must resolve
// again and mesh with the grid mesher, either to a consistent mesh (indices in range, seam pairs on
// existing vertices, finite positions) or to an InputError. Returns whether the input was read.
bool check_garment_file(std::string_view text, const std::string& source);

// Motion files (fuzz_checks_motion.cpp). Parses `text` as BVH. When it parses, every array holds
// one entry per joint (and frame), parents precede their children, every offset, translation and
// world pose is finite and every rotation a unit quaternion; and at most 2 s of it retarget onto the
// default female body either to a finite pose of every body joint in every frame or to an
// InputError. Returns whether the input was read.
bool check_motion_file(std::string_view text, const std::string& source);

// Builds what the motion checks share (the default body, about 2.5 s under the sanitizers, and the
// joint maps' skeleton) before the first input, so that no input is timed with it.
void prepare_motion_checks();

// True when `text` starts as a JSON object: fuzz_bvh reads it as a joint map.
bool is_joint_map(std::string_view text);

// Parses `text` as a joint map of a skeleton with CMU's names. When it parses, every canonical
// joint maps to one of the skeleton's joints or none, and that skeleton's motion retargets through
// the map as above. Returns whether the input was read.
bool check_joint_map(std::string_view text, const std::string& source);

// Request bodies of the web service (fuzz_checks_web.cpp). The first line of `input` names the
// request; the rest is its body:
//   bodies\n JSON          POST /api/bodies with measurements (parse_body_request)
//   tryons\n JSON          POST /api/tryons (parse_tryon_request)
//   upload\n NAME\n UNITS\n UP\n BYTES
//                          POST /api/bodies as a form (upload_from_form, body_from_upload): the
//                          file part's filename, the units and up fields and the file's bytes;
//                          a missing line leaves that part, and the ones after it, out
// Bad input must end in a RequestError with a 4xx status and a message the server can send as
// JSON. What parsed must be what was sent (every measurement under its own key, with its value);
// a body made from an upload must be a rigged mesh with finite positions. Returns whether the
// request was taken, nullopt when the first line names no request.
std::optional<bool> check_web_request(std::string_view input);

}  // namespace drape::fuzz
