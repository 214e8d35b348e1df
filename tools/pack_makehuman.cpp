// Packs what drape's MakeHuman bodies need from MakeHuman's CC0 data (base.obj, the young-adult macro
// and height targets, the measurement targets, default.mhskel + default_weights.mhw, cmu_mb.mhskel)
// into one compact little-endian file, assets/bodies/makehuman.bin (src/body/makehuman.hpp reads it):
//
//   pack_makehuman ../shared/data/bodies/makehuman assets/bodies/makehuman.bin
//
// Only the body (base.obj vertices 0-13,379) and the helper vertices the skeletons' joints are the
// means of are kept, in metres. Targets are sparse: uint16 vertex, int16 x/y/z times a per-target
// scale. The three ethnic targets of each sex are averaged into one (drape's bodies are the mean of
// the three, as MakeHuman's default). Muscle stays average, so only the averagemuscle macro and
// height targets are kept. Skin weights are reduced to each skeleton's joints, top 4 per vertex.
//
// Format: "DRAPEMH1"; u32 body vertices B, u32 extra vertices E, u32 triangles T; f32 xyz[B + E];
// u16 triangles[3 T]; u32 target count, per target: u8 name length, name, u32 n, f32 scale,
// u16 vertex[n], i16 delta[3 n]; u32 skeleton count, per skeleton: u8 name length, name, u32 joints
// J, per joint: u8 name length, name, i32 parent, u32 group size G, u16 group[G]; then per body
// vertex u8 joint[4], u16 weight[4] (weight / 65535).
#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace fs = std::filesystem;
using json = nlohmann::json;

static_assert(std::endian::native == std::endian::little, "the pack is written little-endian");

namespace {

constexpr int kBodyVertices = 13380;
constexpr float kDecimetre = 0.1f;

struct Vec {
  float x = 0, y = 0, z = 0;
};

std::string read_text(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error("cannot read " + path.string());
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

// A target as a dense map vertex -> displacement (base.obj indices, decimetres).
std::map<int, Vec> read_target(const fs::path& path) {
  std::istringstream in(read_text(path));
  std::map<int, Vec> out;
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    std::istringstream l(line);
    int i = 0;
    Vec d;
    if (!(l >> i >> d.x >> d.y >> d.z)) throw std::runtime_error(path.string() + ": bad line '" + line + "'");
    out[i] = d;
  }
  return out;
}

struct Writer {
  std::string bytes;
  template <class T>
  void put(T v) {
    char b[sizeof(T)];
    std::memcpy(b, &v, sizeof(T));
    bytes.append(b, sizeof(T));
  }
  void name(const std::string& s) {
    put<uint8_t>(static_cast<uint8_t>(s.size()));
    bytes += s;
  }
};

struct SkeletonJoint {
  std::string name, parent, head_bone;  // head_bone: the MakeHuman bone whose head places the joint
  std::vector<std::string> takes;       // MakeHuman bones whose weights it takes
};

// drape's skeleton (CMU names, rig.cpp's joint order) from MakeHuman's default skeleton: each joint
// is placed at the head of one MakeHuman bone and takes the weights of a run of them.
std::vector<SkeletonJoint> drape_joints() {
  std::vector<SkeletonJoint> j{{"Hips", "", "root", {"root", "spine05", "pelvis.L", "pelvis.R"}}};
  for (const char* s : {"L", "R"}) {
    const std::string side = s[0] == 'L' ? "Left" : "Right", x = std::string(".") + s;
    j.push_back({side + "UpLeg", "Hips", "upperleg01" + x, {"upperleg01" + x, "upperleg02" + x}});
    j.push_back({side + "Leg", side + "UpLeg", "lowerleg01" + x, {"lowerleg01" + x, "lowerleg02" + x}});
    j.push_back({side + "Foot", side + "Leg", "foot" + x, {"foot" + x}});
    j.push_back({side + "ToeBase", side + "Foot", "toe1-1" + x, {}});
    for (const char* toe : {"toe1-1", "toe1-2", "toe2-1", "toe2-2", "toe2-3", "toe3-1", "toe3-2", "toe3-3", "toe4-1",
                            "toe4-2", "toe4-3", "toe5-1", "toe5-2", "toe5-3"})
      j.back().takes.push_back(toe + x);
  }
  j.push_back({"Spine", "Hips", "spine04", {"spine04", "spine03"}});
  j.push_back({"Spine1", "Spine", "spine02", {"spine02", "spine01", "breast.L", "breast.R"}});
  j.push_back({"Neck", "Spine1", "neck01", {"neck01", "neck02", "neck03"}});
  j.push_back({"Head", "Neck", "head", {"head"}});
  for (const char* s : {"L", "R"}) {
    const std::string side = s[0] == 'L' ? "Left" : "Right", x = std::string(".") + s;
    j.push_back({side + "Shoulder", "Spine1", "clavicle" + x, {"clavicle" + x, "shoulder01" + x}});
    j.push_back({side + "Arm", side + "Shoulder", "upperarm01" + x, {"upperarm01" + x, "upperarm02" + x}});
    j.push_back({side + "ForeArm", side + "Arm", "lowerarm01" + x, {"lowerarm01" + x, "lowerarm02" + x}});
    j.push_back({side + "Hand", side + "ForeArm", "wrist" + x, {"wrist" + x}});
  }
  return j;
}

// cmu_mb.mhskel's bones as joints: placed at their heads, taking the weights of their
// weights_reference (else reference) bones.
std::vector<SkeletonJoint> cmu_joints(const json& skel) {
  std::vector<SkeletonJoint> out;
  // Parents before children.
  std::set<std::string> placed;
  while (out.size() < skel["bones"].size()) {
    const size_t before = out.size();
    for (const auto& [name, bone] : skel["bones"].items()) {
      if (placed.count(name)) continue;
      const std::string parent = bone["parent"].is_null() ? "" : bone["parent"].get<std::string>();
      if (!parent.empty() && !placed.count(parent)) continue;
      SkeletonJoint j{name, parent, "", {}};
      const json& refs = bone.contains("weights_reference") ? bone["weights_reference"] : bone["reference"];
      for (const auto& r : refs) j.takes.push_back(r.get<std::string>());
      out.push_back(j);
      placed.insert(name);
    }
    if (out.size() == before) throw std::runtime_error("cmu_mb.mhskel: bones with no placed parent");
  }
  return out;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 3) {
    std::fprintf(stderr, "usage: %s MAKEHUMAN_DIR OUTPUT\n", argv[0]);
    return 2;
  }
  try {
    const fs::path dir = argv[1];
    // base.obj: vertices (decimetres) and the body's quads.
    std::vector<Vec> base;
    std::vector<std::array<int, 4>> quads;
    {
      std::istringstream in(read_text(dir / "base.obj"));
      std::string line;
      while (std::getline(in, line)) {
        std::istringstream l(line);
        std::string tag;
        l >> tag;
        if (tag == "v") {
          Vec v;
          l >> v.x >> v.y >> v.z;
          base.push_back(v);
        } else if (tag == "f") {
          std::array<int, 4> q{};
          std::string item;
          int k = 0;
          while (l >> item && k < 4) q[static_cast<size_t>(k++)] = std::stoi(item.substr(0, item.find('/'))) - 1;
          if (k != 4) throw std::runtime_error("base.obj: a face that is not a quad");
          if (*std::max_element(q.begin(), q.end()) < kBodyVertices) quads.push_back(q);
        }
      }
    }
    // Skeletons: which helper vertices their joints need.
    const json def = json::parse(read_text(dir / "default.mhskel"));
    const json cmu = json::parse(read_text(dir / "cmu_mb.mhskel"));
    const json mhw = json::parse(read_text(dir / "default_weights.mhw"))["weights"];
    std::map<int, int> packed;  // base.obj index -> packed index
    for (int i = 0; i < kBodyVertices; ++i) packed[i] = i;
    std::vector<int> extra;
    auto use = [&](int i) {
      if (!packed.count(i)) {
        packed[i] = kBodyVertices + static_cast<int>(extra.size());
        extra.push_back(i);
      }
      return packed[i];
    };

    Writer w;
    w.bytes = "DRAPEMH1";
    // Joint groups first (to know the extra vertices), written after the targets.
    struct PackedSkeleton {
      std::string name;
      std::vector<SkeletonJoint> joints;
      std::vector<std::vector<int>> groups;
    };
    std::vector<PackedSkeleton> skeletons{{"default", drape_joints(), {}}, {"cmu_mb", cmu_joints(cmu), {}}};
    for (auto& s : skeletons)
      for (const auto& j : s.joints) {
        const json& groups = s.name == "default" ? def["joints"] : cmu["joints"];
        const std::string key = s.name == "default" ? def["bones"][j.head_bone]["head"].get<std::string>()
                                                    : cmu["bones"][j.name]["head"].get<std::string>();
        std::vector<int> g;
        for (const auto& v : groups[key]) g.push_back(use(v.get<int>()));
        s.groups.push_back(g);
      }

    w.put<uint32_t>(kBodyVertices);
    w.put<uint32_t>(static_cast<uint32_t>(extra.size()));
    w.put<uint32_t>(static_cast<uint32_t>(2 * quads.size()));
    auto at = [&](int packed_index) {
      return base[static_cast<size_t>(packed_index < kBodyVertices ? packed_index : extra[static_cast<size_t>(packed_index - kBodyVertices)])];
    };
    for (int i = 0; i < kBodyVertices + static_cast<int>(extra.size()); ++i) {
      const Vec v = at(i);
      w.put(v.x * kDecimetre);
      w.put(v.y * kDecimetre);
      w.put(v.z * kDecimetre);
    }
    // Quads split along their shorter diagonal on the base mesh.
    auto dist2 = [&](int a, int b) {
      const Vec p = base[static_cast<size_t>(a)], q = base[static_cast<size_t>(b)];
      return (p.x - q.x) * (p.x - q.x) + (p.y - q.y) * (p.y - q.y) + (p.z - q.z) * (p.z - q.z);
    };
    for (const auto& q : quads) {
      const bool diag02 = dist2(q[0], q[2]) <= dist2(q[1], q[3]);
      const std::array<int, 6> t = diag02 ? std::array<int, 6>{q[0], q[1], q[2], q[0], q[2], q[3]}
                                          : std::array<int, 6>{q[0], q[1], q[3], q[1], q[2], q[3]};
      for (int i : t) w.put<uint16_t>(static_cast<uint16_t>(i));
    }

    // Targets: name -> sparse displacement over the packed vertices.
    std::vector<std::pair<std::string, std::map<int, Vec>>> targets;
    auto add = [&](const std::string& name, const std::map<int, Vec>& t) {
      std::map<int, Vec> p;
      for (const auto& [i, d] : t)
        if (packed.count(i) && (d.x != 0 || d.y != 0 || d.z != 0)) p[packed[i]] = d;
      targets.emplace_back(name, p);
    };
    const fs::path tdir = dir / "targets";
    for (const std::string sex : {"female", "male"}) {
      std::map<int, Vec> ethnic;
      for (const char* e : {"african", "asian", "caucasian"})
        for (const auto& [i, d] : read_target(tdir / (std::string(e) + "-" + sex + "-young.target"))) {
          Vec& s = ethnic[i];
          s.x += d.x / 3;
          s.y += d.y / 3;
          s.z += d.z / 3;
        }
      add("ethnic-" + sex, ethnic);
      for (const char* wt : {"min", "average", "max"}) {
        add("universal-" + sex + "-" + wt + "weight",
            read_target(tdir / ("universal-" + sex + "-young-averagemuscle-" + wt + "weight.target")));
        for (const char* h : {"min", "max"})
          add("height-" + sex + "-" + wt + "weight-" + h + "height",
              read_target(tdir / "height" / (sex + "-young-averagemuscle-" + wt + "weight-" + h + "height.target")));
      }
    }
    for (const char* m : {"neck-circ", "bust-circ", "underbust-circ", "waist-circ", "hips-circ", "thigh-circ",
                          "upperarm-circ", "wrist-circ", "upperleg-height", "lowerleg-height", "upperarm-length",
                          "lowerarm-length", "shoulder-dist", "napetowaist-dist"})
      for (const char* dirn : {"decr", "incr"})
        add(std::string("measure-") + m + "-" + dirn,
            read_target(tdir / "measure" / (std::string("measure-") + m + "-" + dirn + ".target")));
    w.put<uint32_t>(static_cast<uint32_t>(targets.size()));
    for (const auto& [name, t] : targets) {
      float peak = 0;
      for (const auto& [i, d] : t) peak = std::max({peak, std::abs(d.x), std::abs(d.y), std::abs(d.z)});
      const float scale = std::max(peak * kDecimetre / 32767.0f, 1e-9f);
      w.name(name);
      w.put<uint32_t>(static_cast<uint32_t>(t.size()));
      w.put(scale);
      for (const auto& [i, d] : t) w.put<uint16_t>(static_cast<uint16_t>(i));
      for (const auto& [i, d] : t)
        for (float c : {d.x, d.y, d.z}) w.put<int16_t>(static_cast<int16_t>(std::lround(c * kDecimetre / scale)));
    }

    // Skeletons: joints, groups, then the weights reduced to their joints. A MakeHuman bone that no
    // joint takes gives its weights to the nearest ancestor that one does (face -> head, fingers -> hand).
    w.put<uint32_t>(static_cast<uint32_t>(skeletons.size()));
    for (const auto& s : skeletons) {
      std::map<std::string, int> owner;
      for (size_t j = 0; j < s.joints.size(); ++j)
        for (const auto& b : s.joints[j].takes) owner.emplace(b, static_cast<int>(j));
      auto owner_of = [&](std::string bone) {
        while (!owner.count(bone)) {
          const json& parent = def["bones"][bone]["parent"];
          if (parent.is_null()) throw std::runtime_error(s.name + ": no joint takes MakeHuman bone " + bone);
          bone = parent.get<std::string>();
        }
        return owner.at(bone);
      };
      std::vector<std::map<int, float>> vw(kBodyVertices);
      for (const auto& [bone, list] : mhw.items()) {
        const int j = owner_of(bone);
        for (const auto& e : list) {
          const int v = e[0].get<int>();
          if (v < kBodyVertices) vw[static_cast<size_t>(v)][j] += e[1].get<float>();
        }
      }
      w.name(s.name);
      w.put<uint32_t>(static_cast<uint32_t>(s.joints.size()));
      std::map<std::string, int> index;
      for (size_t j = 0; j < s.joints.size(); ++j) index[s.joints[j].name] = static_cast<int>(j);
      for (size_t j = 0; j < s.joints.size(); ++j) {
        w.name(s.joints[j].name);
        w.put<int32_t>(s.joints[j].parent.empty() ? -1 : index.at(s.joints[j].parent));
        w.put<uint32_t>(static_cast<uint32_t>(s.groups[j].size()));
        for (int v : s.groups[j]) w.put<uint16_t>(static_cast<uint16_t>(v));
      }
      for (int v = 0; v < kBodyVertices; ++v) {
        std::vector<std::pair<float, int>> list;
        for (const auto& [j, x] : vw[static_cast<size_t>(v)]) list.emplace_back(x, j);
        std::sort(list.rbegin(), list.rend());
        list.resize(4, {0.0f, 0});
        float sum = 0;
        for (const auto& [x, j] : list) sum += x;
        if (sum <= 0) throw std::runtime_error(s.name + ": vertex " + std::to_string(v) + " has no weight");
        for (const auto& [x, j] : list) w.put<uint8_t>(static_cast<uint8_t>(j));
        for (const auto& [x, j] : list) w.put<uint16_t>(static_cast<uint16_t>(std::lround(65535.0f * x / sum)));
      }
    }

    const fs::path out = argv[2];
    std::ofstream file(out, std::ios::binary);
    file.write(w.bytes.data(), static_cast<std::streamsize>(w.bytes.size()));
    if (!file) throw std::runtime_error("cannot write " + out.string());
    std::printf("%s: %zu bytes, %d body + %zu helper vertices, %zu triangles, %zu targets\n", out.string().c_str(),
                w.bytes.size(), kBodyVertices, extra.size(), 2 * quads.size(), targets.size());
  } catch (const std::exception& e) {
    std::fprintf(stderr, "pack_makehuman: %s\n", e.what());
    return 1;
  }
  return 0;
}
