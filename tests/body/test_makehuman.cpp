// Bodies made on MakeHuman's base mesh: the pack, the mesh's soundness, agreement with the MakeHuman
// bodies in ../shared/data, the fit to measurements, the rig.
#include <gtest/gtest.h>

#include <algorithm>
#include <Eigen/Geometry>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <omp.h>
#include <unordered_map>

#include "body/makehuman.hpp"
#include "body/surface_nets.hpp"
#include "drape/body.hpp"
#include "drape/error.hpp"
#include "body/body_test_support.hpp"
#include "support/test_support.hpp"

using namespace drape;

namespace {

#define MH_SHARED_OR_SKIP(var, rel)                                                        \
  const auto var = ::drape::test::shared_file(rel);                                        \
  if (var.empty()) {                                                                       \
    GTEST_SKIP() << "shared test data not found: " << (rel) << " (needs ../shared/data)"; \
  }

using test::sanitized;

body::MhShape shape(Sex sex, float weight, float height = 0.5f) {
  body::MhShape s;
  s.sex = sex;
  s.weight = weight;
  s.height = height;
  return s;
}

// Whether segment pq crosses triangle abc (Möller-Trumbore, strictly inside the segment).
bool segment_crosses(const Vec3f& p, const Vec3f& q, const Vec3f& a, const Vec3f& b, const Vec3f& c) {
  const Vec3f d = q - p, e1 = b - a, e2 = c - a;
  const Vec3f h = d.cross(e2);
  const float det = e1.dot(h);
  if (std::abs(det) < 1e-12f) return false;
  const Vec3f s = p - a;
  const float u = s.dot(h) / det;
  if (u < 0 || u > 1) return false;
  const Vec3f qv = s.cross(e1);
  const float v = d.dot(qv) / det;
  if (v < 0 || u + v > 1) return false;
  const float t = e2.dot(qv) / det;
  return t > 1e-6f && t < 1 - 1e-6f;
}

// Pairs of triangles sharing no vertex that cross each other (a uniform grid finds the candidates).
size_t self_intersections(const Mesh& m) {
  const float cell = 0.02f;
  auto key = [&](int x, int y, int z) { return (int64_t{x} * 73856093) ^ (int64_t{y} * 19349663) ^ (int64_t{z} * 83492791); };
  std::unordered_map<int64_t, std::vector<uint32_t>> grid;
  std::vector<std::array<int, 6>> boxes(m.triangle_count());
  for (uint32_t t = 0; t < m.triangle_count(); ++t) {
    Bounds b;
    for (uint32_t v : m.triangles[t]) b.extend(m.positions[v]);
    auto& box = boxes[t];
    for (int k = 0; k < 3; ++k) {
      box[static_cast<size_t>(k)] = static_cast<int>(std::floor(b.min[k] / cell));
      box[static_cast<size_t>(k + 3)] = static_cast<int>(std::floor(b.max[k] / cell));
    }
    for (int x = box[0]; x <= box[3]; ++x)
      for (int y = box[1]; y <= box[4]; ++y)
        for (int z = box[2]; z <= box[5]; ++z) grid[key(x, y, z)].push_back(t);
  }
  size_t crossings = 0;
  for (const auto& [k, list] : grid)
    for (size_t i = 0; i < list.size(); ++i)
      for (size_t j = i + 1; j < list.size(); ++j) {
        const Tri& a = m.triangles[list[i]];
        const Tri& b = m.triangles[list[j]];
        bool shared = false;
        for (uint32_t u : a)
          for (uint32_t v : b) shared |= u == v;
        if (shared) continue;
        bool hit = false;
        for (int e = 0; e < 3 && !hit; ++e) {
          hit |= segment_crosses(m.positions[a[e]], m.positions[a[(e + 1) % 3]], m.positions[b[0]], m.positions[b[1]], m.positions[b[2]]);
          hit |= segment_crosses(m.positions[b[e]], m.positions[b[(e + 1) % 3]], m.positions[a[0]], m.positions[a[1]], m.positions[a[2]]);
        }
        crossings += hit;  // a pair sharing several cells is counted in each: 0 stays 0
      }
  return crossings;
}

using test::signed_volume;

float value_of(const Measurements& m, std::string_view key) {
  for (const auto& row : measurement_table())
    if (row.key == key) return m.*row.field;
  return NAN;
}

struct Derived {
  const char* name;
  Sex sex;
  float weight;
};
const Derived kDerived[] = {{"mh_female_average", Sex::Female, 0.5f},
                            {"mh_female_heavy", Sex::Female, 1.0f},
                            {"mh_male_average", Sex::Male, 0.5f},
                            {"mh_male_thin", Sex::Male, 0.0f}};

}  // namespace

// The pack compiled into drape decodes, and damaged bytes are refused rather than read past.
TEST(MakeHumanPack, DecodesAndRefusesDamagedBytes) {
  const body::MhModel& model = body::makehuman_model();
  EXPECT_EQ(model.body_vertices, 13380u);
  EXPECT_EQ(model.triangles.size(), 2u * 13378u);
  EXPECT_EQ(model.skeleton("default").joints.size(), 21u);
  EXPECT_EQ(model.skeleton("cmu_mb").joints.size(), 31u);
  const std::filesystem::path pack = std::string(DRAPE_SOURCE_DIR) + "/assets/bodies/makehuman.bin";
  std::string bytes(std::filesystem::file_size(pack), '\0');
  std::ifstream(pack, std::ios::binary).read(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  ASSERT_GT(bytes.size(), 1000u);
  auto span = [](const std::string& s) { return std::span<const unsigned char>(reinterpret_cast<const unsigned char*>(s.data()), s.size()); };
  EXPECT_EQ(body::decode_makehuman(span(bytes)).targets.size(), model.targets.size());
  EXPECT_THROW(body::decode_makehuman(span(bytes.substr(0, bytes.size() / 2))), std::runtime_error);
  EXPECT_THROW(body::decode_makehuman(span("DRAPEBB1" + bytes.substr(8))), std::runtime_error);
  EXPECT_THROW(body::decode_makehuman(span(bytes + "x")), std::runtime_error);
}

// The made body is one closed, outward-facing surface with no triangle crossing another, standing on
// y = 0 and facing +Z (left = +X), thin to heavy, short to tall.
TEST(MakeHumanBody, IsWatertightWithoutSelfIntersectionsOnTheFloorFacingFront) {
  for (const auto& s : {shape(Sex::Female, 0.5f), shape(Sex::Female, 1.0f, 1.0f), shape(Sex::Male, 0.0f, 0.0f),
                        shape(Sex::Male, 1.0f, 1.0f)}) {
    const Body b = body::mh_body(s);
    const Mesh& m = b.mesh;
    const std::string what = std::string(s.sex == Sex::Female ? "female" : "male") + " weight " +
                             std::to_string(s.weight) + " height " + std::to_string(s.height);
    EXPECT_TRUE(body::is_closed_manifold(m)) << what;
    EXPECT_GT(signed_volume(m), 0.03) << what;
    EXPECT_EQ(self_intersections(m), 0u) << what;
    const Bounds box = bounds(m.positions);
    EXPECT_NEAR(box.min.y(), 0.0f, 1e-5f) << what;
    // Facing +Z: the toes and the bust are in front of the heels and the back.
    EXPECT_GT(b.landmarks.left_bust.z(), b.landmarks.hip.z()) << what;
    float toe = -1, heel = 1;
    for (const auto& p : m.positions)
      if (p.y() < 0.02f) {
        toe = std::max(toe, p.z());
        heel = std::min(heel, p.z());
      }
    EXPECT_GT(toe - b.landmarks.left_ankle.z(), 2 * (b.landmarks.left_ankle.z() - heel)) << what;
    EXPECT_GT(b.landmarks.left_shoulder.x(), 0.1f) << what;
    EXPECT_LT(b.landmarks.right_shoulder.x(), -0.1f) << what;
  }
}

// With the macros of each MakeHuman body in ../shared/data, the made body is that body (same
// vertices), and drape finds the same landmarks and body parts on both.
TEST(MakeHumanBody, IsTheMakeHumanBodyOfTheSameMacros) {
  MH_SHARED_OR_SKIP(dir, "bodies/makehuman/derived");
  for (const Derived& d : kDerived) {
    const Body theirs = load_body(dir / (std::string(d.name) + ".obj"));
    const Body ours = body::mh_body(shape(d.sex, d.weight));
    ASSERT_EQ(ours.mesh.vertex_count(), theirs.mesh.vertex_count()) << d.name;
    // The same vertices but at the toes, which drape parts where they pass through each other.
    float worst = 0;
    size_t moved = 0;
    for (size_t v = 0; v < ours.mesh.vertex_count(); ++v) {
      const float off = (ours.mesh.positions[v] - theirs.mesh.positions[v]).norm();
      worst = std::max(worst, off);
      moved += off > 1e-4f;
    }
    EXPECT_LT(worst, 0.005f) << d.name;
    EXPECT_LT(moved, ours.mesh.vertex_count() / 100) << d.name;
    const auto a = ours.landmarks.named(), b = theirs.landmarks.named();
    // The OBJ's quads are split the other way round: sections differ by a hair, the crotch (found
    // by bisection where the legs part) by up to a centimetre.
    float landmark_worst = 0;
    for (size_t i = 0; i < a.size(); ++i) {
      const float off = (a[i].second - b[i].second).norm();
      EXPECT_LT(off, a[i].first == "crotch" ? 0.01f : 0.005f) << d.name << " " << a[i].first;
      landmark_worst = std::max(landmark_worst, off);
    }
    size_t same = 0;
    for (size_t v = 0; v < ours.parts.size(); ++v) same += ours.parts[v] == theirs.parts[v];
    EXPECT_GE(static_cast<double>(same) / static_cast<double>(ours.parts.size()), 0.999) << d.name;
    std::printf("%s: %zu vertices moved (toes), by up to %.2f mm; landmarks within %.1f mm; parts agree on %.2f %%\n", d.name, moved, 1000 * worst, 1000 * landmark_worst,
                100.0 * static_cast<double>(same) / static_cast<double>(ours.parts.size()));
  }
}

// A body made to the measurements of each MakeHuman body (its meta.json) measures them back within
// 1 cm, and is close in shape: the mean distance between corresponding vertices is reported.
TEST(MakeHumanBody, MadeToTheMeasurementsOfEachMakeHumanBody) {
  MH_SHARED_OR_SKIP(dir, "bodies/makehuman/derived");
  for (const Derived& d : kDerived) {
    std::ifstream in(dir / (std::string(d.name) + ".meta.json"));
    const auto meta = nlohmann::json::parse(in)["measurements_approx_cm"];
    const MeasurementRequest request{{"height", meta["height_cm"].get<float>() / 100},
                                     {"bust", meta["bust_chest_circ_cm"].get<float>() / 100},
                                     {"waist", meta["waist_circ_cm"].get<float>() / 100},
                                     {"hips", meta["hip_circ_cm"].get<float>() / 100},
                                     {"inseam", meta["crotch_height_cm"].get<float>() / 100}};
    const Body ours = make_human_body(d.sex, request);
    const Body theirs = load_body(dir / (std::string(d.name) + ".obj"));
    std::string line;
    for (const auto& [key, value] : request) {
      EXPECT_NEAR(value_of(ours.measurements, key), value, 0.01f) << d.name << " " << key;
      char item[96];
      std::snprintf(item, sizeof item, " %s %.1f/%.1f", key.c_str(), 100 * value, 100 * value_of(ours.measurements, key));
      line += item;
    }
    double sum = 0;
    for (size_t v = 0; v < ours.mesh.vertex_count(); ++v) sum += (ours.mesh.positions[v] - theirs.mesh.positions[v]).norm();
    const double mean = sum / static_cast<double>(ours.mesh.vertex_count());
    EXPECT_LT(mean, 0.015) << d.name;
    std::printf("%s requested/measured cm:%s; mean vertex distance %.1f mm\n", d.name, line.c_str(), 1000 * mean);
  }
}

// The skeleton follows the shape: joints sit inside the body where their landmarks are, on the
// correct side, and a taller body has its joints higher.
TEST(MakeHumanBody, RiggedFromMakeHumansSkeleton) {
  const Body b = body::mh_body(shape(Sex::Female, 0.5f));
  const Skeleton& sk = b.skeleton;
  ASSERT_EQ(sk.joints.size(), 21u);
  const Landmarks& lm = b.landmarks;
  auto at = [&](const char* name) {
    const int j = sk.find(name);
    EXPECT_GE(j, 0) << name;
    return j >= 0 ? sk.joints[static_cast<size_t>(j)].position : Vec3f(NAN, NAN, NAN);
  };
  EXPECT_EQ(sk.joints[0].name, "Hips");
  EXPECT_EQ(sk.joints[0].parent, -1);
  for (size_t j = 1; j < sk.joints.size(); ++j) EXPECT_LT(sk.joints[j].parent, static_cast<int>(j));
  EXPECT_NEAR(at("LeftLeg").y(), lm.left_knee.y(), 0.05f);
  // MakeHuman's ankle and wrist joints are the joints' centres, a few cm below drape's ankle
  // landmark (the narrowest section, above the malleoli) and beyond its wrist (the narrowest section).
  EXPECT_NEAR(at("LeftFoot").y(), lm.left_ankle.y(), 0.06f);
  EXPECT_NEAR((at("LeftHand") - lm.left_wrist).norm(), 0.0f, 0.06f);
  EXPECT_NEAR((at("RightForeArm") - lm.right_elbow).norm(), 0.0f, 0.06f);
  EXPECT_GT(at("LeftArm").x(), 0.1f);
  EXPECT_LT(at("RightArm").x(), -0.1f);
  EXPECT_GT(at("Neck").y(), lm.right_armpit.y());
  EXPECT_GT(at("Hips").y(), lm.crotch.y());
  EXPECT_LT(at("Hips").y(), lm.waist.y());
  // Weights: top 4, normalised; a wrist vertex follows the forearm or the hand.
  for (size_t v = 0; v < b.mesh.vertex_count(); v += 53) EXPECT_NEAR(b.mesh.weights[v].sum(), 1.0f, 1e-4f);
  const Body tall = body::mh_body(shape(Sex::Female, 0.5f, 1.0f));
  EXPECT_GT(tall.skeleton.joints[static_cast<size_t>(tall.skeleton.find("Head"))].position.y(), at("Head").y() + 0.05f);
  // MakeHuman's cmu_mb skeleton, as an option.
  const Body cmu = body::mh_body(shape(Sex::Male, 0.5f), BodySkeleton::CmuMb);
  EXPECT_EQ(cmu.skeleton.joints.size(), 31u);
  for (const char* name : {"Hips", "LHipJoint", "LowerBack", "Neck1", "LeftFingerBase", "RThumb"})
    EXPECT_GE(cmu.skeleton.find(name), 0) << name;
}

// The rig animates the body: the arms raised to the horizontal by linear blend skinning (every
// joint from the upper arm down turned about the upper-arm joint) move the wrists up to the
// shoulders and leave the torso and legs where they were.
TEST(MakeHumanBody, ArmsRaiseByItsSkin) {
  for (const BodySkeleton which : {BodySkeleton::Drape, BodySkeleton::CmuMb}) {
    const Body a = body::mh_body(shape(Sex::Female, 0.5f, 0.6f), which);
    const Skeleton& s = a.skeleton;
    std::vector<Eigen::Affine3f> pose(s.joints.size(), Eigen::Affine3f::Identity());
    for (const char* side : {"Left", "Right"}) {
      const int arm = s.find(std::string(side) + "Arm"), hand = s.find(std::string(side) + "Hand");
      ASSERT_GE(arm, 0);
      ASSERT_GE(hand, 0);
      const Vec3f pivot = s.joints[static_cast<size_t>(arm)].position;
      const Vec3f axis = s.joints[static_cast<size_t>(hand)].position - pivot;
      const float up = (axis.x() > 0 ? 1.0f : -1.0f) * std::atan2(-axis.y(), std::abs(axis.x()));
      const Eigen::Affine3f turn =
          Eigen::Translation3f(pivot) * Eigen::AngleAxisf(up, Vec3f::UnitZ()) * Eigen::Translation3f(-pivot);
      for (size_t j = 0; j < s.joints.size(); ++j)
        for (int k = static_cast<int>(j); k >= 0; k = s.joints[static_cast<size_t>(k)].parent)
          if (k == arm) {
            pose[j] = turn;
            break;
          }
    }
    Body t = a;
    for (size_t v = 0; v < t.mesh.vertex_count(); ++v) {
      Vec3f p = Vec3f::Zero();
      for (int k = 0; k < 4; ++k) p += a.mesh.weights[v][k] * (pose[a.mesh.joints[v][static_cast<size_t>(k)]] * a.mesh.positions[v]);
      t.mesh.positions[v] = p;
    }
    analyse_body(t, "raised arms");
    const char* who = which == BodySkeleton::Drape ? "drape" : "cmu_mb";
    EXPECT_NEAR(t.landmarks.left_wrist.y(), t.landmarks.left_shoulder.y(), 0.06f) << who;
    EXPECT_NEAR(t.landmarks.right_wrist.y(), t.landmarks.right_shoulder.y(), 0.06f) << who;
    EXPECT_NEAR(t.measurements.waist, a.measurements.waist, 0.01f) << who;
    EXPECT_NEAR(t.measurements.hips, a.measurements.hips, 0.01f) << who;
    EXPECT_NEAR(t.landmarks.crotch.y(), a.landmarks.crotch.y(), 0.01f) << who;
  }
}

// Every size of both sexes measures back within 1 cm on height, bust, waist and hips, and is one
// closed surface that crosses itself nowhere, standing on y = 0.
TEST(MadeBody, SizesXsToXxlMeasureBackWithinOneCentimetre) {
  struct Size {
    const char* name;
    Sex sex;
    float height, bust, waist, hips;
  };
  const Size sizes[] = {
      {"female XS", Sex::Female, 1.60f, 0.80f, 0.62f, 0.86f}, {"female S", Sex::Female, 1.63f, 0.86f, 0.68f, 0.92f},
      {"female M", Sex::Female, 1.65f, 0.92f, 0.74f, 0.98f},  {"female L", Sex::Female, 1.68f, 0.98f, 0.80f, 1.04f},
      {"female XL", Sex::Female, 1.70f, 1.06f, 0.88f, 1.11f}, {"female XXL", Sex::Female, 1.72f, 1.14f, 0.97f, 1.19f},
      {"male XS", Sex::Male, 1.68f, 0.86f, 0.72f, 0.86f},     {"male S", Sex::Male, 1.72f, 0.92f, 0.78f, 0.92f},
      {"male M", Sex::Male, 1.77f, 0.98f, 0.84f, 0.98f},      {"male L", Sex::Male, 1.80f, 1.04f, 0.92f, 1.03f},
      {"male XL", Sex::Male, 1.83f, 1.12f, 1.00f, 1.09f},     {"male XXL", Sex::Male, 1.86f, 1.20f, 1.10f, 1.16f}};
  for (const Size& size : sizes) {
    const MeasurementRequest request{{"height", size.height}, {"bust", size.bust}, {"waist", size.waist}, {"hips", size.hips}};
    const Body b = make_human_body(size.sex, request);
    std::string line;
    float worst = 0;
    for (const auto& [key, value] : request) {
      const float measured = value_of(b.measurements, key);
      EXPECT_NEAR(measured, value, 0.01f) << size.name << " " << key;
      worst = std::max(worst, std::abs(measured - value));
      char item[96];
      std::snprintf(item, sizeof item, " %s %.1f/%.1f", key.c_str(), 100 * value, 100 * measured);
      line += item;
    }
    EXPECT_TRUE(body::is_closed_manifold(b.mesh)) << size.name;
    EXPECT_EQ(self_intersections(b.mesh), 0u) << size.name;
    EXPECT_NEAR(bounds(b.mesh.positions).min.y(), 0.0f, 1e-5f) << size.name;
    std::printf("%-10s requested/measured cm:%s (worst %.1f mm)\n", size.name, line.c_str(), 1000 * worst);
  }
}

// All thirteen keys at once converge.
TEST(MadeBody, AllKeysAtOnce) {
  if (sanitized()) GTEST_SKIP() << "slow under sanitizers";
  const std::vector<std::pair<Sex, const char*>> requests{
      {Sex::Female,
       "height=1.60,neck=0.32,bust=0.80,underbust=0.68,waist=0.62,hips=0.86,thigh=0.50,upper_arm=0.24,"
       "wrist=0.145,inseam=0.72,arm_length=0.53,shoulder_width=0.35,back_length=0.39"},
      {Sex::Female,
       "height=1.70,neck=0.34,bust=0.94,underbust=0.80,waist=0.76,hips=1.00,thigh=0.58,upper_arm=0.29,"
       "wrist=0.16,inseam=0.77,arm_length=0.57,shoulder_width=0.37,back_length=0.41"},
      {Sex::Male,
       "height=1.80,neck=0.40,bust=1.02,underbust=0.92,waist=0.88,hips=1.00,thigh=0.58,upper_arm=0.32,"
       "wrist=0.18,inseam=0.83,arm_length=0.61,shoulder_width=0.42,back_length=0.46"},
      {Sex::Male, ""}};
  for (const auto& [sex, text] : requests) {
    MeasurementRequest request = *text ? parse_measurements(text) : MeasurementRequest{};
    if (!*text) {
      // A man's: every key as drape measures a MakeHuman man of a lighter build with longer legs,
      // broader shoulders and a smaller chest than MakeHuman's average.
      body::MhShape s = shape(Sex::Male, 0.3f, 0.55f);
      s.measure[body::kMhShoulderWidth] = 0.3f;
      s.measure[body::kMhBust] = -0.2f;
      s.measure[body::kMhInseam] = 0.2f;
      const Measurements m = body::mh_body(s).measurements;
      for (const auto& row : measurement_table()) request[std::string(row.key)] = m.*row.field;
    }
    const Body b = make_human_body(sex, request);
    float worst = 0;
    std::string where;
    for (const auto& row : measurement_table()) {
      const float error = b.measurements.*row.field - request.at(std::string(row.key));
      EXPECT_NEAR(error, 0.0f, 0.01f) << row.key << " of " << text;
      if (std::abs(error) > worst) {
        worst = std::abs(error);
        where = std::string(row.key);
      }
    }
    std::printf("all keys, %s %.2f m: worst key %s off by %.1f mm\n", sex == Sex::Female ? "female" : "male",
                request.at("height"), where.c_str(), 1000 * worst);
  }
}

// The maker shares its work between the cores (a Jacobian's columns, the waist and hip searches'
// sections, the finished body's tape and segmentation): the body is the same to the bit on one
// thread as on two.
TEST(MadeBody, SameBodyBitForBitOnOneAndTwoThreads) {
  const MeasurementRequest request = parse_measurements(
      "height=1.70,neck=0.34,bust=0.94,underbust=0.80,waist=0.76,hips=1.00,thigh=0.58,upper_arm=0.29,"
      "wrist=0.16,inseam=0.77,arm_length=0.57,shoulder_width=0.37,back_length=0.41");
  const int threads = omp_get_max_threads();
  omp_set_num_threads(1);
  const Body one = make_human_body(Sex::Female, request);
  omp_set_num_threads(2);
  const Body two = make_human_body(Sex::Female, request);
  omp_set_num_threads(threads);
  ASSERT_EQ(one.mesh.positions.size(), two.mesh.positions.size());
  size_t differ = 0;
  for (size_t i = 0; i < one.mesh.positions.size(); ++i) differ += one.mesh.positions[i] != two.mesh.positions[i];
  EXPECT_EQ(differ, 0u) << "vertices placed differently on two threads";
  EXPECT_EQ(one.parts, two.parts);
  for (const auto& row : measurement_table()) EXPECT_EQ(one.measurements.*row.field, two.measurements.*row.field) << row.key;
  ASSERT_EQ(one.skeleton.joints.size(), two.skeleton.joints.size());
  for (size_t j = 0; j < one.skeleton.joints.size(); ++j)
    EXPECT_EQ(one.skeleton.joints[j].position, two.skeleton.joints[j].position) << one.skeleton.joints[j].name;
}

// Combinations no human body has are refused, naming what is wrong; unreachable ones are built as
// close as they get, and the miss shows in the measurements.
TEST(MadeBody, ImpossibleCombinationsAreRefusedWithAMessage) {
  const std::vector<std::pair<MeasurementRequest, const char*>> impossible{
      {{{"bust", 0.80f}, {"underbust", 0.90f}}, "underbust is larger than bust"},
      {{{"waist", 1.40f}, {"hips", 0.80f}}, "waist and hips"},
      {{{"height", 1.50f}, {"inseam", 0.95f}}, "inseam"},
      {{{"wrist", 0.30f}, {"upper_arm", 0.25f}}, "wrist"}};
  for (const auto& [request, words] : impossible) {
    try {
      make_human_body(Sex::Female, request);
      ADD_FAILURE() << "accepted " << words;
    } catch (const InputError& e) {
      EXPECT_EQ(e.source(), "measurements");
      EXPECT_NE(std::string(e.what()).find(words), std::string::npos) << e.what();
    }
  }
  const Body narrow = make_human_body(Sex::Female, {{"bust", 1.14f}, {"shoulder_width", 0.28f}});
  EXPECT_GT(std::abs(narrow.measurements.shoulder_width - 0.28f), 0.01f);
}
