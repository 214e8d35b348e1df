// Reads the MakeHuman pack (format in tools/pack_makehuman.cpp) and blends its targets the way
// MakeHuman does for a young adult of average muscle and mixed ethnicity: the weight macro picks
// between the min/average/max-weight targets (piecewise linear around 0.5), the height targets are
// weighted by the weight factors times the height factor, and the measurement targets add on top.
#include "body/makehuman.hpp"

#include <algorithm>
#include <cstring>
#include <stdexcept>

#ifndef DRAPE_MAKEHUMAN_PACK
#error "DRAPE_MAKEHUMAN_PACK must name assets/bodies/makehuman.bin (set by CMakeLists.txt)"
#endif

__asm__(".pushsection .rodata\n"
        ".balign 16\n"
        ".globl drape_makehuman_begin\n"
        ".hidden drape_makehuman_begin\n"
        "drape_makehuman_begin:\n"
        ".incbin \"" DRAPE_MAKEHUMAN_PACK "\"\n"
        ".globl drape_makehuman_end\n"
        ".hidden drape_makehuman_end\n"
        "drape_makehuman_end:\n"
        ".popsection\n");

extern "C" const unsigned char drape_makehuman_begin[];
extern "C" const unsigned char drape_makehuman_end[];

namespace drape::body {
namespace {

// Bounds-checked little-endian reads.
struct Reader {
  std::span<const unsigned char> bytes;
  size_t at = 0;
  template <class T>
  T get() {
    if (bytes.size() - at < sizeof(T)) throw std::runtime_error("MakeHuman pack: truncated");
    T v;
    std::memcpy(&v, bytes.data() + at, sizeof(T));
    at += sizeof(T);
    return v;
  }
  std::string name() {
    const size_t n = get<uint8_t>();
    if (bytes.size() - at < n) throw std::runtime_error("MakeHuman pack: truncated");
    std::string s(reinterpret_cast<const char*>(bytes.data() + at), n);
    at += n;
    return s;
  }
  uint32_t count(size_t limit) {
    const uint32_t n = get<uint32_t>();
    if (n > limit) throw std::runtime_error("MakeHuman pack: a count out of range");
    return n;
  }
};

constexpr std::array<std::array<const char*, 2>, kMhMeasureCount> kTargets{{
    {"neck-circ", nullptr},        {"bust-circ", nullptr},       {"underbust-circ", nullptr},
    {"waist-circ", nullptr},       {"hips-circ", nullptr},       {"thigh-circ", nullptr},
    {"upperarm-circ", nullptr},    {"wrist-circ", nullptr},      {"upperleg-height", "lowerleg-height"},
    {"upperarm-length", "lowerarm-length"}, {"shoulder-dist", nullptr}, {"napetowaist-dist", nullptr}}};
constexpr std::array<std::string_view, kMhMeasureCount> kKeys{
    "neck", "bust", "underbust", "waist", "hips", "thigh", "upper_arm", "wrist", "inseam", "arm_length",
    "shoulder_width", "back_length"};

// Per sex, the targets a shape blends, looked up once.
struct SexTargets {
  const MhTarget* ethnic = nullptr;
  std::array<const MhTarget*, 3> universal{};           // min, average, max weight
  std::array<std::array<const MhTarget*, 2>, 3> height{};  // [weight][min, max height]
};
struct Lookup {
  std::array<SexTargets, 2> sex;
  std::array<std::array<std::array<const MhTarget*, 2>, 2>, kMhMeasureCount> measure{};  // [m][part][decr, incr]
};

Lookup lookup(const MhModel& model) {
  Lookup l;
  for (int s = 0; s < 2; ++s) {
    const std::string sex = s == 0 ? "female" : "male";
    SexTargets& t = l.sex[static_cast<size_t>(s)];
    t.ethnic = &model.target("ethnic-" + sex);
    const char* weights[3] = {"min", "average", "max"};
    for (size_t w = 0; w < 3; ++w) {
      t.universal[w] = &model.target("universal-" + sex + "-" + weights[w] + "weight");
      t.height[w][0] = &model.target("height-" + sex + "-" + weights[w] + "weight-minheight");
      t.height[w][1] = &model.target("height-" + sex + "-" + weights[w] + "weight-maxheight");
    }
  }
  for (size_t m = 0; m < kMhMeasureCount; ++m)
    for (size_t p = 0; p < 2; ++p)
      if (kTargets[m][p]) {
        l.measure[m][p][0] = &model.target(std::string("measure-") + kTargets[m][p] + "-decr");
        l.measure[m][p][1] = &model.target(std::string("measure-") + kTargets[m][p] + "-incr");
      }
  return l;
}

void add(std::vector<Vec3f>& out, const MhTarget* t, float w) {
  if (!t || w == 0.0f) return;
  for (size_t i = 0; i < t->vertex.size(); ++i) out[t->vertex[i]] += w * t->delta[i];
}

}  // namespace

const MhTarget& MhModel::target(std::string_view name) const {
  for (const auto& t : targets)
    if (t.name == name) return t;
  throw std::out_of_range("MakeHuman pack: no target " + std::string(name));
}

const MhSkeleton& MhModel::skeleton(std::string_view name) const {
  for (const auto& s : skeletons)
    if (s.name == name) return s;
  throw std::out_of_range("MakeHuman pack: no skeleton " + std::string(name));
}

std::string_view mh_measure_key(int measure) { return kKeys.at(static_cast<size_t>(measure)); }

MhModel decode_makehuman(std::span<const unsigned char> bytes) {
  Reader r{bytes};
  if (bytes.size() < 8 || std::memcmp(bytes.data(), "DRAPEMH1", 8) != 0)
    throw std::runtime_error("MakeHuman pack: not a DRAPEMH1 file");
  r.at = 8;
  MhModel m;
  m.body_vertices = r.count(65536);
  const uint32_t extra = r.count(65536 - m.body_vertices);
  const uint32_t triangles = r.count(1u << 20);
  const size_t n = size_t{m.body_vertices} + extra;
  m.base.resize(n);
  for (auto& p : m.base) {
    const float x = r.get<float>(), y = r.get<float>(), z = r.get<float>();
    p = Vec3f(x, y, z);
  }
  m.triangles.resize(triangles);
  for (auto& t : m.triangles)
    for (auto& i : t) {
      i = r.get<uint16_t>();
      if (i >= m.body_vertices) throw std::runtime_error("MakeHuman pack: a triangle outside the body");
    }
  m.topology = SliceTopology(m.triangles);
  const uint32_t targets = r.count(1024);
  m.targets.resize(targets);
  for (auto& t : m.targets) {
    t.name = r.name();
    const uint32_t k = r.count(n);
    const float scale = r.get<float>();
    t.vertex.resize(k);
    t.delta.resize(k);
    for (auto& v : t.vertex) {
      v = r.get<uint16_t>();
      if (v >= n) throw std::runtime_error("MakeHuman pack: target " + t.name + " moves a vertex out of range");
    }
    for (auto& d : t.delta) {
      const float x = r.get<int16_t>(), y = r.get<int16_t>(), z = r.get<int16_t>();
      d = scale * Vec3f(x, y, z);
    }
  }
  const uint32_t skeletons = r.count(16);
  m.skeletons.resize(skeletons);
  for (auto& s : m.skeletons) {
    s.name = r.name();
    const uint32_t joints = r.count(256);
    s.joints.resize(joints);
    for (size_t j = 0; j < joints; ++j) {
      auto& joint = s.joints[j];
      joint.name = r.name();
      joint.parent = r.get<int32_t>();
      if (joint.parent < -1 || joint.parent >= static_cast<int>(j))
        throw std::runtime_error("MakeHuman pack: joint " + joint.name + " has a bad parent");
      joint.group.resize(r.count(n));
      if (joint.group.empty()) throw std::runtime_error("MakeHuman pack: joint " + joint.name + " has no vertices");
      for (auto& v : joint.group) {
        v = r.get<uint16_t>();
        if (v >= n) throw std::runtime_error("MakeHuman pack: joint " + joint.name + " names a vertex out of range");
      }
    }
    s.vertex_joints.resize(m.body_vertices);
    s.vertex_weights.resize(m.body_vertices);
    for (uint32_t v = 0; v < m.body_vertices; ++v) {
      for (auto& j : s.vertex_joints[v]) {
        j = r.get<uint8_t>();
        if (j >= joints) throw std::runtime_error("MakeHuman pack: a weight names a joint out of range");
      }
      Vec4f w;
      for (int k = 0; k < 4; ++k) w[k] = static_cast<float>(r.get<uint16_t>()) / 65535.0f;
      s.vertex_weights[v] = w / w.sum();
    }
  }
  if (r.at != bytes.size()) throw std::runtime_error("MakeHuman pack: trailing bytes");
  lookup(m);  // every target drape blends is there
  return m;
}

const MhModel& makehuman_model() {
  static const MhModel model = decode_makehuman({drape_makehuman_begin, drape_makehuman_end});
  return model;
}

void mh_positions(const MhModel& model, const MhShape& shape, std::vector<Vec3f>& out) {
  const Lookup l = lookup(model);  // ~50 name look-ups: negligible beside the blend
  const SexTargets& t = l.sex[shape.sex == Sex::Female ? 0 : 1];

  out = model.base;
  add(out, t.ethnic, 1.0f);
  // MakeHuman's macro factors: min/average/max weight, then min/max height.
  // Beyond the maximum weight (drape's heaviest sizes) the max-weight target is extrapolated.
  const float w = std::max(shape.weight, 0.0f), h = std::clamp(shape.height, 0.0f, 1.0f);
  const std::array<float, 3> wf{std::max(0.0f, 1 - 2 * w), std::max(0.0f, 1 - std::abs(2 * w - 1)), std::max(0.0f, 2 * w - 1)};
  const std::array<float, 2> hf{std::max(0.0f, 1 - 2 * h), std::max(0.0f, 2 * h - 1)};
  for (size_t i = 0; i < 3; ++i) {
    add(out, t.universal[i], wf[i]);
    for (size_t k = 0; k < 2; ++k) add(out, t.height[i][k], wf[i] * hf[k]);
  }
  for (size_t m = 0; m < kMhMeasureCount; ++m) {
    const float x = shape.measure[m];
    for (size_t p = 0; p < 2; ++p) add(out, l.measure[m][p][x < 0 ? 0 : 1], std::abs(x));
  }
  float floor = out[0].y();
  for (uint32_t v = 0; v < model.body_vertices; ++v) floor = std::min(floor, out[v].y());
  for (auto& p : out) {
    p.y() -= floor;
    p *= shape.scale;
  }
}

}  // namespace drape::body
