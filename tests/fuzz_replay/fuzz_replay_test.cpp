// Replays every kept fuzz input through the fuzz targets' checks (fuzz/fuzz_checks.hpp) in the
// normal build, so an input that once broke a parser, or that covers a path the fuzzers found, fails
// CI when it breaks again. Also the malformed-input corpus through the same checks, and the
// round-trip corpus through `drape convert` and the Khronos validator.
#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <optional>
#include <span>
#include <vector>

#include "fuzz/fuzz_checks.hpp"
#include "support/gltf_validator.hpp"
#include "support/test_support.hpp"

namespace fs = std::filesystem;
using drape::MeshFormat;
using drape::fuzz::GarmentFormat;

namespace {

const fs::path kCorpus = fs::path(DRAPE_SOURCE_DIR) / "tests" / "corpus";

std::vector<fs::path> files_in(const fs::path& dir) {
  std::vector<fs::path> files;
  if (fs::is_directory(dir))
    for (const auto& entry : fs::directory_iterator(dir))
      if (entry.is_regular_file()) files.push_back(entry.path());
  std::sort(files.begin(), files.end());
  return files;
}

std::string contents(const fs::path& file) {
  std::string bytes(fs::file_size(file), '\0');
  std::ifstream(file, std::ios::binary).read(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  return bytes;
}

std::span<const unsigned char> bytes_of(const std::string& s) {
  return {reinterpret_cast<const unsigned char*>(s.data()), s.size()};
}

// Runs one check; a finding or any exception escaping it fails the test, naming the file.
template <class Check>
std::optional<bool> replay(const fs::path& file, Check check) {
  try {
    return check(contents(file));
  } catch (const std::exception& e) {
    ADD_FAILURE() << file << ": " << e.what();
  } catch (...) {
    ADD_FAILURE() << file << ": a non-standard exception";
  }
  return std::nullopt;
}

void replay_mesh_corpus(const std::string& target, MeshFormat format) {
  const auto files = files_in(kCorpus / "fuzz" / target);
  ASSERT_FALSE(files.empty()) << "no corpus in tests/corpus/fuzz/" << target;
  for (const fs::path& f : files)
    replay(f, [&](const std::string& bytes) { return drape::fuzz::check_mesh_file(bytes_of(bytes), format, f.string()); });
}

void replay_garment_corpus(const std::string& target, GarmentFormat format) {
  const auto files = files_in(kCorpus / "fuzz" / target);
  ASSERT_FALSE(files.empty()) << "no corpus in tests/corpus/fuzz/" << target;
  for (const fs::path& f : files)
    replay(f, [&](const std::string& text) {
      return drape::fuzz::is_garment_format(text, format) && drape::fuzz::check_garment_file(text, f.string());
    });
}

// What fuzz_bvh does with an input: a joint map when it starts as a JSON object, else a BVH file.
bool check_motion(const std::string& text, const std::string& source) {
  return drape::fuzz::is_joint_map(text) ? drape::fuzz::check_joint_map(text, source)
                                         : drape::fuzz::check_motion_file(text, source);
}

std::optional<MeshFormat> mesh_format_by_extension(const fs::path& f) {
  const std::string ext = f.extension().string();
  if (ext == ".obj") return MeshFormat::Obj;
  if (ext == ".ply") return MeshFormat::Ply;
  if (ext == ".gltf") return MeshFormat::Gltf;
  if (ext == ".glb") return MeshFormat::Glb;
  return std::nullopt;
}

}  // namespace

TEST(FuzzCorpus, Obj) { replay_mesh_corpus("obj", MeshFormat::Obj); }
TEST(FuzzCorpus, Ply) { replay_mesh_corpus("ply", MeshFormat::Ply); }
TEST(FuzzCorpus, Gltf) { replay_mesh_corpus("gltf", MeshFormat::Gltf); }
TEST(FuzzCorpus, GarmentJson) { replay_garment_corpus("garment_json", GarmentFormat::DrapeJson); }
TEST(FuzzCorpus, GarmentCode) { replay_garment_corpus("garmentcode", GarmentFormat::GarmentCode); }
TEST(FuzzCorpus, Dxf) { replay_garment_corpus("dxf", GarmentFormat::Dxf); }
TEST(FuzzCorpus, Bvh) {
  const auto files = files_in(kCorpus / "fuzz" / "bvh");
  ASSERT_FALSE(files.empty()) << "no corpus in tests/corpus/fuzz/bvh";
  for (const fs::path& f : files) replay(f, [&](const std::string& text) { return check_motion(text, f.string()); });
}
TEST(FuzzCorpus, Web) {
  const auto files = files_in(kCorpus / "fuzz" / "web");
  ASSERT_FALSE(files.empty()) << "no corpus in tests/corpus/fuzz/web";
  for (const fs::path& f : files)
    replay(f, [&](const std::string& input) { return drape::fuzz::check_web_request(input).value_or(false); });
}

// The hand-made seeds are good files: each reads and round-trips through every writer.
TEST(FuzzCorpus, SeedsReadAndRoundTrip) {
  size_t checked = 0;
  for (const char* target : {"obj", "ply"})
    for (const fs::path& f : files_in(fs::path(DRAPE_SOURCE_DIR) / "fuzz" / "seeds" / target)) {
      const auto read = replay(f, [&](const std::string& bytes) {
        return drape::fuzz::check_mesh_file(bytes_of(bytes), *mesh_format_by_extension(f), f.string());
      });
      EXPECT_EQ(read, std::optional<bool>(true)) << f << " was refused";
      ++checked;
    }
  EXPECT_GE(checked, 6u);
}

// The hand-made motion seeds are good files (BVH and joint maps): each reads and retargets.
TEST(FuzzCorpus, MotionSeedsRead) {
  const auto files = files_in(fs::path(DRAPE_SOURCE_DIR) / "fuzz" / "seeds" / "bvh");
  for (const fs::path& f : files)
    EXPECT_EQ(replay(f, [&](const std::string& text) { return check_motion(text, f.string()); }), std::optional<bool>(true))
        << f << " was refused";
  EXPECT_GE(files.size(), 5u);
}

// The hand-made request seeds: those named refused_* end in a 4xx RequestError, every other one is taken.
TEST(FuzzCorpus, WebSeedsAnswerAsNamed) {
  const auto files = files_in(fs::path(DRAPE_SOURCE_DIR) / "fuzz" / "seeds" / "web");
  for (const fs::path& f : files) {
    const bool refused = f.filename().string().starts_with("refused_");
    EXPECT_EQ(replay(f, [&](const std::string& input) { return drape::fuzz::check_web_request(input); }),
              std::optional<bool>(!refused))
        << f;
  }
  EXPECT_GE(files.size(), 5u);
}

// Motion files and requests that once broke a property the checks hold (tests/corpus/findings/bvh,
// tests/corpus/findings/web, named for the defect): each now passes its check, read or refused.
TEST(FuzzCorpus, FixedMotionAndRequestFindingsHold) {
  size_t checked = 0;
  for (const fs::path& f : files_in(kCorpus / "findings" / "bvh")) {
    replay(f, [&](const std::string& text) { return check_motion(text, f.string()); });
    ++checked;
  }
  for (const fs::path& f : files_in(kCorpus / "findings" / "web")) {
    replay(f, [&](const std::string& input) { return drape::fuzz::check_web_request(input).value_or(false); });
    ++checked;
  }
  EXPECT_GT(checked, 0u);
}

// Garment files that once broke a property the fuzz checks hold (tests/corpus/findings, named for
// the defect): each now passes its check, read or refused.
TEST(FuzzCorpus, FixedGarmentFindingsHold) {
  size_t checked = 0;
  for (const fs::path& f : files_in(kCorpus / "findings")) {
    replay(f, [&](const std::string& text) { return drape::fuzz::check_garment_file(text, f.string()); });
    ++checked;
  }
  EXPECT_GT(checked, 0u);
}

// Every malformed mesh file is refused with an InputError, never another exception.
TEST(FuzzCorpus, MalformedMeshFilesAreRefused) {
  size_t checked = 0;
  for (const fs::path& f : files_in(kCorpus / "info")) {
    const auto format = mesh_format_by_extension(f);
    if (!format) continue;
    const auto read = replay(f, [&](const std::string& bytes) {
      return drape::fuzz::check_mesh_file(bytes_of(bytes), *format, f.string());
    });
    EXPECT_EQ(read, std::optional<bool>(false)) << f << " was read";
    ++checked;
  }
  EXPECT_GT(checked, 0u);
}

// Every malformed garment file is refused with an InputError, never another exception.
TEST(FuzzCorpus, MalformedGarmentFilesAreRefused) {
  size_t checked = 0;
  for (const fs::path& f : files_in(kCorpus / "garment")) {
    const auto read = replay(f, [&](const std::string& text) { return drape::fuzz::check_garment_file(text, f.string()); });
    EXPECT_EQ(read, std::optional<bool>(false)) << f << " was read";
    ++checked;
  }
  EXPECT_GT(checked, 0u);
}

// Files that once read but wrote what drape (or another viewer) refused: each reads and round-trips
// through every writer, and `drape convert` makes a GLB that reads back and passes the validator.
TEST(RoundTripCorpus, ConvertsToAValidGlbThatReadsBack) {
  const auto files = files_in(kCorpus / "round_trip");
  ASSERT_FALSE(files.empty());
  const fs::path dir = drape::test::temp_dir("round_trip");
  for (const fs::path& f : files) {
    const auto format = mesh_format_by_extension(f);
    ASSERT_TRUE(format) << f;
    const auto read = replay(f, [&](const std::string& bytes) {
      return drape::fuzz::check_mesh_file(bytes_of(bytes), *format, f.string());
    });
    EXPECT_EQ(read, std::optional<bool>(true)) << f << " was refused";
    const fs::path glb = dir / (f.stem().string() + ".glb");
    const auto convert = drape::test::run_drape("convert \"" + f.string() + "\" \"" + glb.string() + "\"");
    ASSERT_EQ(convert.exit_code, 0) << f << ": " << convert.err;
    const auto info = drape::test::run_drape("info \"" + glb.string() + "\"");
    EXPECT_EQ(info.exit_code, 0) << glb << ": " << info.err;
    EXPECT_TRUE(drape::test::gltf_is_valid(glb)) << f;
  }
}
