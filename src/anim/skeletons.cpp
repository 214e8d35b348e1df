// The skeletons people have, by their joint names, and joint maps from files. Each convention lists,
// per canonical joint (drape's rig names), the names that play it, best first; a convention applies
// when its signature joints are present, and of those that apply the one that finds the most
// canonical joints wins. Where a skeleton has several spine links, drape's Spine (waist) and Spine1
// (chest) take the links nearest those heights. docs/animation.md has the tables.
#include <algorithm>
#include <array>
#include <cctype>
#include <fstream>
#include <sstream>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "anim/motion_internal.hpp"
#include "drape/error.hpp"
#include "drape/motion.hpp"

namespace drape {
namespace {

constexpr std::array<std::string_view, 21> kCanonical{
    "Hips",       "Spine",       "Spine1",       "Neck",          "Head",       "LeftShoulder", "LeftArm",
    "LeftForeArm", "LeftHand",   "RightShoulder", "RightArm",     "RightForeArm", "RightHand",  "LeftUpLeg",
    "LeftLeg",    "LeftFoot",    "LeftToeBase",  "RightUpLeg",    "RightLeg",   "RightFoot",    "RightToeBase"};

// Canonical joints a map must find for a motion to drive a body.
constexpr std::array<std::string_view, 10> kRequired{"Hips",     "LeftUpLeg", "RightUpLeg", "LeftLeg", "RightLeg",
                                                     "LeftFoot", "RightFoot", "LeftArm",    "RightArm", "Spine1"};

struct Convention {
  std::string_view name;
  std::vector<std::string_view> signature;  // all present (case-insensitive) for the convention to apply
  std::vector<std::string_view> absent;     // none present
  // Per canonical joint, candidate names, best first ("|"-separated); "" for none.
  std::array<std::string_view, 21> candidates;
};

// Left side names; the right side is derived by the convention's own rule below.
const std::vector<Convention>& conventions() {
  static const std::vector<Convention> table{
      // cgspeed's MotionBuilder-friendly CMU conversion (31 joints).
      {"cmu", {"LHipJoint", "LowerBack"}, {"LeftHandFinger1"},
       {"Hips", "Spine", "Spine1", "Neck|Neck1", "Head", "LeftShoulder", "LeftArm", "LeftForeArm", "LeftHand",
        "RightShoulder", "RightArm", "RightForeArm", "RightHand", "LeftUpLeg", "LeftLeg", "LeftFoot", "LeftToeBase",
        "RightUpLeg", "RightLeg", "RightFoot", "RightToeBase"}},
      // MakeHuman's cmu_mb skeleton: cgspeed's names, LeftHandFinger1 for LeftHandIndex1.
      {"makehuman_cmu_mb", {"LHipJoint", "LeftHandFinger1"}, {},
       {"Hips", "Spine", "Spine1", "Neck|Neck1", "Head", "LeftShoulder", "LeftArm", "LeftForeArm", "LeftHand",
        "RightShoulder", "RightArm", "RightForeArm", "RightHand", "LeftUpLeg", "LeftLeg", "LeftFoot", "LeftToeBase",
        "RightUpLeg", "RightLeg", "RightFoot", "RightToeBase"}},
      // drape's own rig (rig_body; MakeHuman's default skeleton reduced to these names).
      {"drape", {"Hips", "Spine1", "LeftUpLeg", "LeftForeArm"}, {"LHipJoint", "Spine2"},
       {"Hips", "Spine", "Spine1", "Neck", "Head", "LeftShoulder", "LeftArm", "LeftForeArm", "LeftHand",
        "RightShoulder", "RightArm", "RightForeArm", "RightHand", "LeftUpLeg", "LeftLeg", "LeftFoot", "LeftToeBase",
        "RightUpLeg", "RightLeg", "RightFoot", "RightToeBase"}},
      // Mixamo (prefix "mixamorig:" removed): Spine, Spine1, Spine2 from the hips up.
      {"mixamo", {"Spine2", "LeftUpLeg", "LeftForeArm"}, {"LHipJoint"},
       {"Hips", "Spine1|Spine", "Spine2", "Neck", "Head", "LeftShoulder", "LeftArm", "LeftForeArm", "LeftHand",
        "RightShoulder", "RightArm", "RightForeArm", "RightHand", "LeftUpLeg", "LeftLeg", "LeftFoot", "LeftToeBase",
        "RightUpLeg", "RightLeg", "RightFoot", "RightToeBase"}},
      // CMU's old 19-joint conversion (10_01) and cgspeed's 3ds Max-friendly (Biped) conversion:
      // Chest..Chest7 up the spine, Collar, Shoulder = upper arm, Elbow, Wrist, Hip = thigh, Knee, Ankle.
      {"cmu_19", {"LeftHip", "LeftKnee", "CS_BVH"}, {},
       {"Hips", "Chest", "CS_BVH", "Neck", "Head", "LeftCollar", "LeftShoulder", "LeftElbow", "LeftWrist",
        "RightCollar", "RightShoulder", "RightElbow", "RightWrist", "LeftHip", "LeftKnee", "LeftAnkle", "LeftToe",
        "RightHip", "RightKnee", "RightAnkle", "RightToe"}},
      {"cmu_3dsmax", {"Chest"}, {"CS_BVH"},
       {"Hips", "Chest", "Chest3|Chest2|Chest4", "Neck", "Head", "LeftCollar", "LeftShoulder|LeftUpArm",
        "LeftElbow|LeftLowArm", "LeftWrist|LeftHand", "RightCollar", "RightShoulder|RightUpArm",
        "RightElbow|RightLowArm", "RightWrist|RightHand", "LeftHip|LeftUpLeg", "LeftKnee|LeftLowLeg",
        "LeftAnkle|LeftFoot", "LeftToe", "RightHip|RightUpLeg", "RightKnee|RightLowLeg", "RightAnkle|RightFoot",
        "RightToe"}},
      // cgspeed's Daz-friendly conversion (Poser names).
      {"cmu_daz", {"hip", "abdomen", "lThigh"}, {},
       {"hip", "abdomen", "chest", "neck", "head", "lCollar", "lShldr", "lForeArm", "lHand", "rCollar", "rShldr",
        "rForeArm", "rHand", "lThigh", "lShin", "lFoot", "lToe", "rThigh", "rShin", "rFoot", "rToe"}},
      // MakeHuman's default skeleton (163 bones; its pose files).
      {"makehuman", {"spine05", "upperleg01.L"}, {},
       {"root", "spine03", "spine01", "neck01", "head", "clavicle.L", "upperarm01.L", "lowerarm01.L", "wrist.L",
        "clavicle.R", "upperarm01.R", "lowerarm01.R", "wrist.R", "upperleg01.L", "lowerleg01.L", "foot.L",
        "toe1-1.L", "upperleg01.R", "lowerleg01.R", "foot.R", "toe1-1.R"}},
      // SMPL / SMPL-H / SMPL-X (both the capitalised and the lower-case spellings).
      {"smpl", {"L_Hip"}, {},
       {"Pelvis", "Spine2", "Spine3", "Neck", "Head", "L_Collar", "L_Shoulder", "L_Elbow", "L_Wrist", "R_Collar",
        "R_Shoulder", "R_Elbow", "R_Wrist", "L_Hip", "L_Knee", "L_Ankle", "L_Foot", "R_Hip", "R_Knee", "R_Ankle",
        "R_Foot"}},
      {"smpl", {"left_hip", "pelvis"}, {},
       {"pelvis", "spine2", "spine3", "neck", "head", "left_collar", "left_shoulder", "left_elbow", "left_wrist",
        "right_collar", "right_shoulder", "right_elbow", "right_wrist", "left_hip", "left_knee", "left_ankle",
        "left_foot", "right_hip", "right_knee", "right_ankle", "right_foot"}},
  };
  return table;
}

std::string lower(std::string_view s) {
  std::string out(s);
  for (char& c : out) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return out;
}

// A joint name without a namespace prefix ("mixamorig:Hips" -> "hips"), lower case.
std::string bare(std::string_view name) {
  const size_t colon = name.rfind(':');
  if (colon != std::string_view::npos) name.remove_prefix(colon + 1);
  return lower(name);
}

int find_bare(std::span<const std::string> names, std::string_view wanted) {
  const std::string w = lower(wanted);
  for (size_t i = 0; i < names.size(); ++i)
    if (bare(names[i]) == w) return static_cast<int>(i);
  return -1;
}

std::string missing_required(const JointMap& map) {
  std::string missing;
  for (std::string_view r : kRequired)
    if (map.joint[static_cast<size_t>(motion_detail::canonical_index(r))] < 0)
      missing += (missing.empty() ? "" : ", ") + std::string(r);
  return missing;
}

}  // namespace

std::span<const std::string_view> canonical_joints() { return kCanonical; }

int motion_detail::canonical_index(std::string_view name) {
  for (size_t i = 0; i < kCanonical.size(); ++i)
    if (kCanonical[i] == name) return static_cast<int>(i);
  return -1;
}

JointMap find_joint_map(std::span<const std::string> names, const std::string& source) {
  JointMap best;
  size_t best_found = 0;
  for (const Convention& c : conventions()) {
    const bool applies = std::all_of(c.signature.begin(), c.signature.end(), [&](std::string_view s) { return find_bare(names, s) >= 0; }) &&
                         std::none_of(c.absent.begin(), c.absent.end(), [&](std::string_view s) { return find_bare(names, s) >= 0; });
    if (!applies) continue;
    JointMap map{std::string(c.name), std::vector<int>(kCanonical.size(), -1)};
    size_t found = 0;
    for (size_t k = 0; k < kCanonical.size(); ++k) {
      std::string_view options = c.candidates[k];
      while (!options.empty() && map.joint[k] < 0) {
        const size_t bar = options.find('|');
        map.joint[k] = find_bare(names, options.substr(0, bar));
        options = bar == std::string_view::npos ? std::string_view() : options.substr(bar + 1);
      }
      found += map.joint[k] >= 0;
    }
    if (missing_required(map).empty() && found > best_found) best = std::move(map), best_found = found;
  }
  if (best_found == 0) {
    std::string sample;
    for (size_t i = 0; i < names.size() && i < 8; ++i) sample += (i ? ", " : "") + motion_detail::printable(names[i]);
    if (names.size() > 8) sample += ", ...";
    throw InputError(source, fmt::format("unknown skeleton: its joints ({}) are not CMU (cgspeed MotionBuilder, 3ds Max, "
                                         "Daz, old 19-joint), Mixamo, MakeHuman (default, cmu_mb), SMPL or drape's; "
                                         "found no joint for the hips, thighs, knees, feet, chest and upper arms: give a joint map",
                                         sample));
  }
  return best;
}

JointMap parse_joint_map(std::string_view json, const std::string& source, std::span<const std::string> names) {
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(json);
  } catch (const nlohmann::json::parse_error& e) {
    throw InputError(source, fmt::format("not JSON (byte {})", e.byte));
  } catch (const nlohmann::json::out_of_range&) {
    // A number too large for a double ("1e999"); nlohmann does not say where it is.
    throw InputError(source, "not JSON (a number too large for a double)");
  }
  if (!j.is_object()) throw InputError(source, "a joint map is a JSON object {\"Hips\": \"joint name\", ...}");
  JointMap map{"file", std::vector<int>(kCanonical.size(), -1)};
  for (const auto& [key, value] : j.items()) {
    const int k = motion_detail::canonical_index(key);
    if (k < 0) {
      std::string all;
      for (std::string_view c : kCanonical) all += (all.empty() ? "" : ", ") + std::string(c);
      throw InputError(source, fmt::format("'{}' is not a joint drape drives (one of {})", motion_detail::printable(key), all));
    }
    if (!value.is_string()) throw InputError(source, fmt::format("joint '{}': the value must be a joint name (a string)", key));
    const std::string name = value.get<std::string>();
    int found = -1;
    for (size_t i = 0; i < names.size() && found < 0; ++i)
      if (names[i] == name) found = static_cast<int>(i);
    if (found < 0) throw InputError(source, fmt::format("joint '{}' (for {}) is not in the skeleton", motion_detail::printable(name), key));
    map.joint[static_cast<size_t>(k)] = found;
  }
  if (const std::string missing = missing_required(map); !missing.empty())
    throw InputError(source, fmt::format("the joint map does not name the skeleton's {}", missing));
  return map;
}

JointMap read_joint_map(const std::filesystem::path& file, std::span<const std::string> names) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw InputError(file.string(), "cannot open the joint map");
  std::stringstream ss;
  ss << in.rdbuf();
  return parse_joint_map(ss.str(), file.string(), names);
}

}  // namespace drape
