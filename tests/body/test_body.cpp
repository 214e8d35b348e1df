// Bodies: generated from measurements, loaded from files, landmarks, measurements and parts.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <span>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>

#include "body/baked.hpp"
#include "body/surface_nets.hpp"
#include "drape/body.hpp"
#include "drape/error.hpp"
#include "drape/io.hpp"
#include "body/body_test_support.hpp"
#include "support/test_support.hpp"

using namespace drape;

// The path of a file under ../shared/data, or the test is skipped (a user's fresh clone has none).
#define SHARED_OR_SKIP(var, rel)                                                     \
  const auto var = ::drape::test::shared_file(rel);                                  \
  if (var.empty()) {                                                                 \
    GTEST_SKIP() << "shared test data not found: " << (rel) << " (needs ../shared/data)"; \
  }

namespace {

using test::sanitized;

using test::signed_volume;

struct Size {
  const char* name;
  Sex sex;
  float height, bust, waist, hips;
};

// Ready-to-wear size charts (approximate EU/ISO body dimensions), XS to XXL.
const std::vector<Size>& sizes() {
  static const std::vector<Size> all{
      {"female XS", Sex::Female, 1.60f, 0.80f, 0.62f, 0.86f}, {"female S", Sex::Female, 1.63f, 0.86f, 0.68f, 0.92f},
      {"female M", Sex::Female, 1.65f, 0.92f, 0.74f, 0.98f},  {"female L", Sex::Female, 1.68f, 0.98f, 0.80f, 1.04f},
      {"female XL", Sex::Female, 1.70f, 1.06f, 0.88f, 1.11f}, {"female XXL", Sex::Female, 1.72f, 1.14f, 0.97f, 1.19f},
      {"male XS", Sex::Male, 1.68f, 0.86f, 0.72f, 0.86f},     {"male S", Sex::Male, 1.72f, 0.92f, 0.78f, 0.92f},
      {"male M", Sex::Male, 1.77f, 0.98f, 0.84f, 0.98f},      {"male L", Sex::Male, 1.80f, 1.04f, 0.92f, 1.03f},
      {"male XL", Sex::Male, 1.83f, 1.12f, 1.00f, 1.09f},     {"male XXL", Sex::Male, 1.86f, 1.20f, 1.10f, 1.16f}};
  return all;
}

void expect_valid_body(const Body& body, const std::string& what) {
  const Mesh& m = body.mesh;
  EXPECT_TRUE(body::is_closed_manifold(m)) << what << ": not watertight / not consistently oriented";
  EXPECT_GT(signed_volume(m), 0.02) << what << ": triangles must face outwards";
  EXPECT_GE(m.triangle_count(), 15000u) << what;
  EXPECT_LE(m.triangle_count(), 60000u) << what;
  const Bounds b = bounds(m.positions);
  EXPECT_NEAR(b.min.y(), 0.0f, 1e-3f) << what << ": feet on the floor";
  // Rig: top-4 weights, normalised, valid joints; every part present.
  ASSERT_FALSE(body.skeleton.empty()) << what;
  ASSERT_EQ(m.joints.size(), m.vertex_count());
  ASSERT_EQ(m.weights.size(), m.vertex_count());
  for (size_t v = 0; v < m.vertex_count(); v += 97) {
    EXPECT_NEAR(m.weights[v].sum(), 1.0f, 1e-4f);
    for (int k = 0; k < 4; ++k) EXPECT_LT(m.joints[v][k], body.skeleton.joints.size());
  }
  std::array<size_t, kBodyPartCount> counts{};
  for (BodyPart p : body.parts) ++counts[static_cast<size_t>(p)];
  for (int i = 0; i < kBodyPartCount; ++i)
    EXPECT_GT(counts[static_cast<size_t>(i)], m.vertex_count() / 50) << what << ": part " << body_part_name(static_cast<BodyPart>(i));
  // Left is +X, the front is +Z.
  EXPECT_GT(body.landmarks.left_wrist.x(), 0.2f);
  EXPECT_LT(body.landmarks.right_wrist.x(), -0.2f);
  EXPECT_GT(body.landmarks.left_bust.z(), body.landmarks.hip.z());
}

std::map<std::string, double> read_yaml_numbers(const std::filesystem::path& path) {
  std::map<std::string, double> out;
  std::ifstream in(path);
  std::string line;
  while (std::getline(in, line)) {
    const auto colon = line.find(':');
    if (colon == std::string::npos) continue;
    std::string key = line.substr(0, colon);
    key.erase(0, key.find_first_not_of(' '));
    try {
      out[key] = std::stod(line.substr(colon + 1));
    } catch (...) {
    }
  }
  return out;
}

}  // namespace

TEST(BodyMeasurements, ParsesKeysAndRefusesBadInput) {
  const auto m = parse_measurements("height=1.70,bust=0.92,waist=0.74");
  EXPECT_FLOAT_EQ(m.at("height"), 1.70f);
  EXPECT_FLOAT_EQ(m.at("waist"), 0.74f);
  EXPECT_FLOAT_EQ(parse_measurements("chest=1.04").at("bust"), 1.04f);  // a man's size label says chest
  for (const char* bad : {"height=1.70,elbow=0.3", "bust=abc", "height=170", "waist", "waist=0.7,waist=0.8",
                          "bust=1.0,chest=1.04"}) {
    try {
      parse_measurements(bad);
      ADD_FAILURE() << "accepted " << bad;
    } catch (const InputError& e) {
      EXPECT_EQ(e.source(), "--measurements");
    }
  }
  EXPECT_THROW(make_body(Sex::Female, {{"bust", 0.80f}, {"underbust", 0.90f}}), InputError);
}

TEST(BodyMeasurements, TableHasIsoNamesForEveryField) {
  EXPECT_EQ(measurement_table().size(), 13u);
  for (const auto& row : measurement_table()) EXPECT_FALSE(row.iso_8559_1.empty()) << row.key;
}

// Bodies made on MakeHuman's body: tests/body/test_makehuman.cpp.

// The generator's promise: what was asked for is what the tape measures, across sizes and sexes.
TEST(BodyFromMeasurements, SizesXsToXxlMeasureBackWithinOneCentimetre) {
  BodyBuildOptions options;
  options.grid_step = 0.014f;  // the coarse fitting grid: same accuracy, faster test
  for (const Size& size : sizes()) {
    if (sanitized() && size.name != std::string("female XS") && size.name != std::string("male XXL")) continue;
    const MeasurementRequest request{{"height", size.height}, {"bust", size.bust}, {"waist", size.waist}, {"hips", size.hips}};
    const Body body = make_body(size.sex, request, options);
    std::string line;
    for (const auto& [key, value] : request) {
      const auto& table = measurement_table();
      const auto row = std::find_if(table.begin(), table.end(), [&](const MeasurementInfo& r) { return r.key == key; });
      const float measured = body.measurements.*(row->field);
      EXPECT_NEAR(measured, value, 0.01f) << size.name << " " << key;
      char item[80];
      std::snprintf(item, sizeof item, " %s %.1f/%.1f", key.c_str(), 100 * value, 100 * measured);
      line += item;
    }
    std::printf("%-10s requested/measured cm:%s\n", size.name, line.c_str());
    expect_valid_body(body, size.name);
  }
}

// Every key at once (the controls interact: shoulder width moves the arms, the rib cage moves the
// bust, ...), for a small woman, an average woman and an average man.
TEST(BodyFromMeasurements, AllKeysAtOnce) {
  if (sanitized()) GTEST_SKIP() << "slow under sanitizers";
  BodyBuildOptions options;
  options.grid_step = 0.014f;
  const std::vector<std::pair<Sex, const char*>> requests{
      {Sex::Female,
       "height=1.60,neck=0.32,bust=0.80,underbust=0.68,waist=0.62,hips=0.86,thigh=0.50,upper_arm=0.24,"
       "wrist=0.145,inseam=0.72,arm_length=0.53,shoulder_width=0.35,back_length=0.39"},
      {Sex::Female,
       "height=1.70,neck=0.34,bust=0.94,underbust=0.80,waist=0.76,hips=1.00,thigh=0.58,upper_arm=0.29,"
       "wrist=0.16,inseam=0.77,arm_length=0.57,shoulder_width=0.37,back_length=0.41"},
      {Sex::Male,
       "height=1.80,neck=0.40,bust=1.02,underbust=0.92,waist=0.88,hips=1.00,thigh=0.58,upper_arm=0.32,"
       "wrist=0.18,inseam=0.83,arm_length=0.61,shoulder_width=0.42,back_length=0.46"}};
  for (const auto& [sex, text] : requests) {
    const MeasurementRequest request = parse_measurements(text);
    ASSERT_EQ(request.size(), measurement_table().size());
    const Body body = make_body(sex, request, options);
    float worst = 0;
    for (const auto& row : measurement_table()) {
      const float error = body.measurements.*row.field - request.at(std::string(row.key));
      EXPECT_NEAR(error, 0.0f, 0.01f) << row.key << " of " << text;
      worst = std::max(worst, std::abs(error));
    }
    std::printf("all keys, %s %.2f m: worst key off by %.1f mm\n", sex == Sex::Female ? "female" : "male",
                request.at("height"), 1000 * worst);
  }
}

TEST(BodyFromMeasurements, DefaultBodiesAreAverageAdults) {
  const Body female = default_body(Sex::Female);
  const Body male = default_body(Sex::Male);
  expect_valid_body(female, "default female");
  expect_valid_body(male, "default male");
  EXPECT_NEAR(female.measurements.height, 1.65f, 0.01f);
  EXPECT_NEAR(male.measurements.height, 1.78f, 0.01f);
  EXPECT_GT(male.measurements.shoulder_width, female.measurements.shoulder_width);
  // The defaults are made from the average measurements (all but shoulder width and back length,
  // which follow from the rest): each measures back within 1 cm.
  for (const Body* body : {&female, &male}) {
    for (const auto& [key, value] : default_measurements(body->sex)) {
      if (key == "shoulder_width" || key == "back_length") continue;
      const auto& table = measurement_table();
      const auto row = std::find_if(table.begin(), table.end(), [&](const MeasurementInfo& r) { return r.key == key; });
      EXPECT_NEAR(body->measurements.*(row->field), value, 0.01f) << (body == &female ? "female " : "male ") << key;
    }
  }
  // The glTF scene: a `body` node with a skin over named joints.
  const Scene scene = body_scene(female);
  const int node = scene.find_node("body");
  ASSERT_GE(node, 0);
  EXPECT_EQ(scene.nodes[static_cast<size_t>(node)].skin, 0);
  EXPECT_EQ(scene.skins[0].joints.size(), female.skeleton.joints.size());
  EXPECT_GE(scene.find_node("LeftForeArm"), 0);
}

TEST(BodyFromFiles, GarmentCodeMeanBodyMatchesPublishedMeasurements) {
  SHARED_OR_SKIP(dir, "bodies/garmentcode");
  const Body body = load_body(dir / "mean_all.obj");
  const auto yaml = read_yaml_numbers(dir / "mean_all.yaml");
  const Measurements& m = body.measurements;
  const std::vector<std::tuple<const char*, float, double>> checks{
      {"height", m.height, 0.02},       {"bust", m.bust, 0.03},           {"underbust", m.underbust, 0.02},
      {"waist", m.waist, 0.02},         {"hips", m.hips, 0.02},           {"leg_circ", m.thigh, 0.02},
      {"wrist", m.wrist, 0.02},         {"arm_length", m.arm_length, 0.02}, {"shoulder_w", m.shoulder_width, 0.02},
      {"waist_line", m.back_length, 0.02}};
  // Printed so that the figures in docs/bodies.md can be re-run:
  //   build/tests/test_body --gtest_filter='*GarmentCodeMean*'
  for (const auto& [key, ours, tolerance] : checks) {
    ASSERT_TRUE(yaml.count(key)) << key;
    EXPECT_NEAR(ours, yaml.at(key) / 100.0, tolerance) << key << ": ours " << ours * 100 << " cm, yaml " << yaml.at(key);
    std::printf("mean_all %-10s ours %6.1f cm, mean_all.yaml %6.1f cm, difference %+5.1f cm\n", key, 100.0 * ours,
                yaml.at(key), 100.0 * ours - yaml.at(key));
  }
}

// Head and torso are one label ("body") in GarmentCode's segmentation, so they are scored together;
// "face_internal" (inside the mouth and eyes) counts as head.
TEST(BodyFromFiles, SegmentationAgreesWithGarmentCode) {
  SHARED_OR_SKIP(dir, "bodies/garmentcode");
  const Body body = load_body(dir / "mean_all.obj");
  std::ifstream in(dir / "ggg_body_segmentation.json");
  const auto labels = nlohmann::json::parse(in);
  auto ours_as_theirs = [](BodyPart p) -> std::string {
    switch (p) {
      case BodyPart::LeftArm: return "left_arm";
      case BodyPart::RightArm: return "right_arm";
      case BodyPart::LeftLeg: return "left_leg";
      case BodyPart::RightLeg: return "right_leg";
      default: return "body";
    }
  };
  size_t agree = 0, total = 0;
  std::map<std::string, std::pair<size_t, size_t>> per_label;
  for (const auto& [label, indices] : labels.items()) {
    const std::string theirs = label == "face_internal" ? "body" : label;
    for (const auto& index : indices) {
      const size_t v = index.get<size_t>();
      ASSERT_LT(v, body.parts.size());
      const bool same = ours_as_theirs(body.parts[v]) == theirs;
      agree += same;
      ++total;
      per_label[label].first += same;
      ++per_label[label].second;
    }
  }
  const double fraction = static_cast<double>(agree) / static_cast<double>(total);
  std::string detail;
  for (const auto& [label, c] : per_label) detail += " " + label + "=" + std::to_string(c.first * 100 / c.second) + "%";
  EXPECT_GE(fraction, 0.95) << "agreement " << fraction << detail;
  std::printf("segmentation agreement with GarmentCode: %.2f %%%s\n", 100 * fraction, detail.c_str());
}

TEST(BodyFromFiles, MakeHumanBodiesAgreeWithTheirMetadata) {
  SHARED_OR_SKIP(dir, "bodies/makehuman/derived");
  for (const char* name : {"mh_female_average", "mh_male_average", "mh_female_heavy", "mh_male_thin"}) {
    const Body body = load_body(dir / (std::string(name) + ".obj"));
    std::ifstream in(dir / (std::string(name) + ".meta.json"));
    const auto meta = nlohmann::json::parse(in)["measurements_approx_cm"];
    const Measurements& m = body.measurements;
    const std::vector<std::tuple<const char*, float>> checks{{"height_cm", m.height},
                                                             {"bust_chest_circ_cm", m.bust},
                                                             {"waist_circ_cm", m.waist},
                                                             {"hip_circ_cm", m.hips},
                                                             {"crotch_height_cm", m.inseam}};
    for (const auto& [key, ours] : checks) {
      const double theirs = meta[key].get<double>();
      EXPECT_NEAR(ours * 100, theirs, 1.5) << name << " " << key;
      std::printf("%s %s: ours %.1f, meta %.1f cm\n", name, key, ours * 100, theirs);
    }
  }
}

TEST(BodyFromFiles, RiggedGltfKeepsItsSkeleton) {
  SHARED_OR_SKIP(path, "bodies/makehuman/derived/mh_female_average_cmu_mb.glb");
  const Body body = load_body(path);
  EXPECT_EQ(body.skeleton.joints.size(), 31u);
  EXPECT_GE(body.skeleton.find("LeftArm"), 0);
  EXPECT_EQ(body.mesh.joints.size(), body.mesh.vertex_count());
  EXPECT_NEAR(body.measurements.waist, 0.652f, 0.015f);
}

// The same body written in centimetres with Z up loads exactly as in metres with Y up; turned away
// from +Z it is turned back.
TEST(BodyFromFiles, UnitsAxesAndFacingAreNormalised) {
  SHARED_OR_SKIP(path, "bodies/garmentcode/mean_all.obj");
  const Body reference = load_body(path);
  const Mesh original = read_mesh(path);
  const auto dir = drape::test::temp_dir("body_frames");

  Mesh cm_zup = original;
  for (auto& p : cm_zup.positions) p = Vec3f(p.x(), -p.z(), p.y()) * 100.0f;  // inverse of z-up -> y-up
  write_mesh(dir / "cm_zup.obj", cm_zup);
  LoadOptions cm_z;
  cm_z.metres_per_unit = 0.01;
  cm_z.up = UpAxis::Z;
  const Body converted = load_body(dir / "cm_zup.obj", cm_z);

  Mesh turned = original;
  const Eigen::Matrix3f r = Eigen::AngleAxisf(3.14159f + 0.5f, Vec3f::UnitY()).toRotationMatrix();
  for (auto& p : turned.positions) p = r * p + Vec3f(2.0f, 0.7f, -3.0f);
  write_mesh(dir / "turned.obj", turned);
  const Body unturned = load_body(dir / "turned.obj");

  for (const Body* b : {&converted, &unturned}) {
    for (const auto& row : measurement_table())
      EXPECT_NEAR(b->measurements.*row.field, reference.measurements.*row.field, 0.006f) << row.key;
    const auto a = b->landmarks.named(), ref = reference.landmarks.named();
    for (size_t i = 0; i < a.size(); ++i)
      EXPECT_LT((a[i].second - ref[i].second).norm(), 0.015f) << a[i].first;
  }
}

TEST(BodyFromFiles, WhatIsNotABodyIsRefusedWithExitTwo) {
  const auto dir = drape::test::temp_dir("not_a_body");
  // A 1 m cube: a plausible height, but no legs, arms or neck.
  {
    std::ofstream out(dir / "cube.obj");
    out << "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\n"
           "f 1 4 3 2\nf 5 6 7 8\nf 1 2 6 5\nf 2 3 7 6\nf 3 4 8 7\nf 4 1 5 8\n";
  }
  // A 10 cm figure: out of the 0.5-2.5 m range.
  {
    std::ofstream out(dir / "tiny.obj");
    out << "v 0 0 0\nv 0.05 0 0\nv 0 0.1 0\nv 0 0 0.05\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n";
  }
  // A 1.7 m cylinder: the right height, but no legs. And a file that is not a mesh at all.
  {
    std::ofstream out(dir / "pillar.obj");
    constexpr int n = 24;
    for (float y : {0.0f, 1.7f})
      for (int i = 0; i < n; ++i) {
        const float a = 2.0f * 3.14159265f * static_cast<float>(i) / n;
        out << "v " << 0.15f * std::cos(a) << ' ' << y << ' ' << 0.15f * std::sin(a) << '\n';
      }
    for (int i = 0; i < n; ++i) {
      const int j = (i + 1) % n;
      out << "f " << i + 1 << ' ' << j + 1 << ' ' << n + j + 1 << "\nf " << i + 1 << ' ' << n + j + 1 << ' ' << n + i + 1 << '\n';
    }
  }
  {
    std::ofstream out(dir / "letter.obj");
    out << "Dear customer,\nthis is not a mesh.\n";
  }
  for (const char* name : {"cube.obj", "tiny.obj", "pillar.obj", "letter.obj"}) {
    const auto r = drape::test::run_drape("measure " + (dir / name).string());
    EXPECT_EQ(r.exit_code, 2) << name << ": " << r.err;
    EXPECT_NE(r.err.find(name), std::string::npos) << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_TRUE(r.out.empty());
  }
}

TEST(BodyCommand, WritesRiggedGlbAndRefusesBadMeasurements) {
  if (sanitized()) GTEST_SKIP() << "slow under sanitizers";
  const auto dir = drape::test::temp_dir("body_cli");
  const auto out = dir / "b.glb";
  const auto ok = drape::test::run_drape("body --sex male --measurements height=1.80,bust=1.00,waist=0.86,hips=1.00 -o " + out.string());
  ASSERT_EQ(ok.exit_code, 0) << ok.err;
  const auto report = nlohmann::json::parse(ok.out);
  EXPECT_NEAR(report["measurements"]["waist"]["measured_m"].get<double>(), 0.86, 0.01);
  const Scene scene = read_scene(out);
  EXPECT_GE(scene.find_node("body"), 0);
  ASSERT_EQ(scene.skins.size(), 1u);
  const auto measured = drape::test::run_drape("measure " + out.string());
  ASSERT_EQ(measured.exit_code, 0) << measured.err;
  EXPECT_NEAR(nlohmann::json::parse(measured.out)["measurements"]["hips"].get<double>(), 1.00, 0.01);

  // Shoulders far narrower than a large chest allows: built as close as it gets, and the key is
  // named as approximate.
  const auto narrow = drape::test::run_drape("body --measurements bust=1.14,shoulder_width=0.30 -o " +
                                             (dir / "narrow.glb").string());
  ASSERT_EQ(narrow.exit_code, 0) << narrow.err;
  EXPECT_NE(narrow.err.find("no human body has this combination"), std::string::npos) << narrow.err;
  EXPECT_NE(narrow.err.find("shoulder_width"), std::string::npos) << narrow.err;
  EXPECT_FALSE(nlohmann::json::parse(narrow.out)["measurements"]["shoulder_width"]["within_1cm"].get<bool>());

  // MakeHuman's cmu_mb skeleton on request.
  const auto cmu = drape::test::run_drape("body --skeleton cmu_mb --measurements height=1.70 -o " + (dir / "cmu.glb").string());
  ASSERT_EQ(cmu.exit_code, 0) << cmu.err;
  EXPECT_EQ(nlohmann::json::parse(cmu.out)["joints"].get<size_t>(), 31u);
  EXPECT_GE(read_scene(dir / "cmu.glb").find_node("LHipJoint"), 0);

  // No measurements: the built-in average adult; with the cmu_mb skeleton, the same body made now.
  const auto plain = drape::test::run_drape("body -o " + (dir / "plain.glb").string());
  const auto plain_cmu = drape::test::run_drape("body --skeleton cmu_mb -o " + (dir / "plain_cmu.glb").string());
  ASSERT_EQ(plain.exit_code, 0) << plain.err;
  ASSERT_EQ(plain_cmu.exit_code, 0) << plain_cmu.err;
  const auto plain_report = nlohmann::json::parse(plain.out), cmu_report = nlohmann::json::parse(plain_cmu.out);
  EXPECT_EQ(cmu_report["triangles"].get<size_t>(), plain_report["triangles"].get<size_t>());
  EXPECT_EQ(cmu_report["joints"].get<size_t>(), 31u);
  EXPECT_NEAR(cmu_report["measurements"]["hips"]["measured_m"].get<double>(),
              plain_report["measurements"]["hips"]["measured_m"].get<double>(), 1e-6);

  const auto bad = drape::test::run_drape("body --measurements waist=7.4 -o " + (dir / "bad.glb").string());
  EXPECT_EQ(bad.exit_code, 2);
  EXPECT_NE(bad.err.find("--measurements"), std::string::npos) << bad.err;
  EXPECT_FALSE(std::filesystem::exists(dir / "bad.glb"));
}

// The default bodies' shapes are baked into the binary at build time (src/default_bodies): what
// default_body returns must be the body make_human_body makes now, bit for bit, analysis and rig
// included, and it must measure as requested.
TEST(DefaultBodies, BakedBodyIsTheMadeBody) {
  if (sanitized()) GTEST_SKIP() << "slow under sanitizers (the shape is solved for anew)";
  for (const Sex sex : {Sex::Female, Sex::Male}) {
    const Body baked = default_body(sex);
    const MeasurementRequest request = default_body_request(sex);
    const Body made = make_human_body(sex, request);
    const char* who = sex == Sex::Female ? "female" : "male";
    ASSERT_EQ(baked.mesh.positions.size(), made.mesh.positions.size()) << who;
    EXPECT_TRUE(baked.mesh.positions == made.mesh.positions) << who;
    EXPECT_TRUE(baked.mesh.normals == made.mesh.normals) << who;
    EXPECT_TRUE(baked.mesh.triangles == made.mesh.triangles) << who;
    EXPECT_TRUE(baked.mesh.joints == made.mesh.joints) << who;
    EXPECT_TRUE(baked.mesh.weights == made.mesh.weights) << who;
    EXPECT_TRUE(baked.parts == made.parts) << who;
    EXPECT_EQ(baked.mesh.name, made.mesh.name);
    EXPECT_EQ(baked.sex, made.sex);
    for (const auto& row : measurement_table())
      EXPECT_EQ(baked.measurements.*(row.field), made.measurements.*(row.field)) << who << " " << row.key;
    for (const auto& [key, value] : request) {
      const auto& table = measurement_table();
      const auto row = std::find_if(table.begin(), table.end(), [&](const MeasurementInfo& m) { return m.key == key; });
      ASSERT_NE(row, table.end()) << key;
      EXPECT_NEAR(baked.measurements.*(row->field), value, 0.01f) << who << " " << key;
    }
    const auto a = baked.landmarks.named(), b = made.landmarks.named();
    for (size_t i = 0; i < a.size(); ++i) EXPECT_TRUE(a[i].second == b[i].second) << who << " " << a[i].first;
    ASSERT_EQ(baked.skeleton.joints.size(), made.skeleton.joints.size());
    for (size_t j = 0; j < baked.skeleton.joints.size(); ++j)
      EXPECT_TRUE(baked.skeleton.joints[j].position == made.skeleton.joints[j].position) << baked.skeleton.joints[j].name;
  }
}

// The bake format round-trips, and damaged bytes are refused rather than read past their end.
TEST(DefaultBodies, BakeFormatRoundTripsAndRefusesDamagedBytes) {
  body::MhShape female, male;
  female.weight = 0.4f;
  female.measure[2] = 0.25f;
  male.sex = Sex::Male;
  male.height = 0.7f;
  male.scale = 1.02f;
  male.measure.back() = -0.5f;
  const std::string bytes = body::encode_baked_shapes({female, male});
  const std::span<const unsigned char> span(reinterpret_cast<const unsigned char*>(bytes.data()), bytes.size());
  const body::MhShape m = body::decode_baked_shape(span, Sex::Male);
  EXPECT_EQ(m.sex, Sex::Male);
  EXPECT_EQ(m.height, 0.7f);
  EXPECT_EQ(m.scale, 1.02f);
  EXPECT_TRUE(m.measure == male.measure);
  const body::MhShape f = body::decode_baked_shape(span, Sex::Female);
  EXPECT_EQ(f.weight, 0.4f);
  EXPECT_TRUE(f.measure == female.measure);

  auto refused = [](std::span<const unsigned char> b, const std::string& why) {
    try {
      body::decode_baked_shape(b, Sex::Male);
    } catch (const std::runtime_error& e) {
      EXPECT_NE(std::string(e.what()).find(why), std::string::npos) << e.what();
      return;
    }
    ADD_FAILURE() << "accepted damaged bytes (" << why << ")";
  };
  refused(span.first(span.size() - 5), "truncated");
  std::string bad_magic = bytes;
  bad_magic[0] = 'X';
  refused({reinterpret_cast<const unsigned char*>(bad_magic.data()), bad_magic.size()}, "not a DRAPEBB2");
  const std::string female_only = body::encode_baked_shapes({female});
  refused({reinterpret_cast<const unsigned char*>(female_only.data()), female_only.size()}, "no body of the requested sex");
}
