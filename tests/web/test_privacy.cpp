// Privacy: bodies are reachable only through ids that cannot be listed or guessed; DELETE and
// expiry remove every file of a body and its try-ons; nothing reaches outside the data folder.
#include <array>
#include <cmath>
#include <fstream>
#include <set>

#include "drape/error.hpp"
#include "web/ids.hpp"
#include "web/service.hpp"
#include "web/web_fixture.hpp"

namespace drape::test {
namespace {

using nlohmann::json;

// Every file under `dir` whose path names `id`.
std::vector<std::string> files_naming(const std::filesystem::path& dir, const std::string& id) {
  std::vector<std::string> found;
  for (const auto& e : std::filesystem::recursive_directory_iterator(dir))
    if (e.path().string().find(id) != std::string::npos) found.push_back(e.path().string());
  return found;
}

TEST(WebIds, AreRandom128BitHex) {
  // 4000 ids: all distinct, and each hex digit at each position about equally often (a counter, a
  // clock or a weak generator would skew the leading digits).
  std::set<std::string> ids;
  std::array<std::array<int, 16>, 32> counts{};
  for (int i = 0; i < 4000; ++i) {
    const std::string id = web::random_id();
    ASSERT_TRUE(web::is_id(id)) << id;
    ids.insert(id);
    for (size_t k = 0; k < id.size(); ++k)
      ++counts[k][static_cast<size_t>(std::stoi(id.substr(k, 1), nullptr, 16))];
  }
  EXPECT_EQ(ids.size(), 4000u);
  for (size_t k = 0; k < 32; ++k) {
    double chi2 = 0;
    for (int c : counts[k]) chi2 += (c - 250.0) * (c - 250.0) / 250.0;
    EXPECT_LT(chi2, 60.0) << "digit " << k;  // 15 degrees of freedom: p < 1e-6
  }
  EXPECT_FALSE(web::is_id("../" + std::string(29, 'a')));
  EXPECT_FALSE(web::is_id(std::string(32, 'A')));
  EXPECT_FALSE(web::is_id(std::string(31, 'a')));
}

TEST(WebPrivacy, BodiesAreNeverListedAndPathsStayInside) {
  ServeOptions o = quick_serve_options("web_privacy_list");
  o.web_root = std::filesystem::path(DRAPE_SOURCE_DIR) / "web";
  TestServer server(o);
  auto c = server.client();
  std::set<std::string> ids;
  for (int i = 0; i < 5; ++i) ids.insert(json_of(c.Post("/api/bodies", "{}", "application/json"))["id"]);
  EXPECT_EQ(ids.size(), 5u);
  for (const char* path :
       {"/api/bodies", "/api/bodies/", "/api/tryons", "/static/", "/static/../../CMakeLists.txt",
        "/three/build/../../../package.json", "/static/%2e%2e/%2e%2e/CMakeLists.txt"}) {
    const auto r = c.Get(path);
    ASSERT_TRUE(r) << path;
    EXPECT_GE(r->status, 400) << path;
    for (const std::string& id : ids) EXPECT_EQ(r->body.find(id), std::string::npos) << path;
    EXPECT_EQ(r->body.find("cmake_minimum_required"), std::string::npos) << path;
  }
  // A neighbour of a real id (one digit changed) is nobody.
  std::string near = *ids.begin();
  near.back() = near.back() == '0' ? '1' : '0';
  const auto r = c.Get("/api/bodies/" + near);
  ASSERT_TRUE(r);
  EXPECT_EQ(r->status, 404);
}

TEST(WebPrivacy, DeleteRemovesEveryFileOfABodyAndItsTryOns) {
  TestServer server(quick_serve_options("web_privacy_delete"));
  auto c = server.client();
  const std::string body = json_of(c.Post("/api/bodies", R"({"sex": "male"})", "application/json"))["id"];
  const auto r = c.Post("/api/tryons", json{{"body", body}, {"garment", "skirt"}, {"size", "S"}}.dump(),
                        "application/json");
  ASSERT_TRUE(r);
  const std::string tryon = json_of(r)["id"];
  ASSERT_EQ(wait_for_tryon(c, tryon)["state"], "done");
  const std::filesystem::path data = server.options.data_dir;
  EXPECT_FALSE(files_naming(data, body).empty());
  EXPECT_FALSE(files_naming(data, tryon).empty());
  ASSERT_EQ(c.Delete("/api/bodies/" + body)->status, 204);
  EXPECT_TRUE(files_naming(data, body).empty());
  EXPECT_TRUE(files_naming(data, tryon).empty());
}

TEST(WebPrivacy, DeletedWhileDressingLeavesNothingBehind) {
  TestServer server(quick_serve_options("web_privacy_running"));
  auto c = server.client();
  const std::string body = json_of(c.Post("/api/bodies", "{}", "application/json"))["id"];
  const auto r = c.Post("/api/tryons", json{{"body", body}, {"garment", "skirt"}, {"size", "L"}}.dump(),
                        "application/json");
  ASSERT_TRUE(r);
  const std::string tryon = json_of(r)["id"];
  // Deleted while a worker dresses it.
  for (int i = 0; i < 6000 && json_of(c.Get("/api/tryons/" + tryon))["state"] == "queued"; ++i)
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  ASSERT_EQ(json_of(c.Get("/api/tryons/" + tryon))["state"], "running");
  ASSERT_EQ(c.Delete("/api/bodies/" + body)->status, 204);
  // Wait until the worker is idle again, then look.
  for (int i = 0; i < 6000; ++i) {
    const json h = json_of(c.Get("/api/health"));
    if (h["queue"]["running"] == 0 && h["queue"]["queued"] == 0) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  EXPECT_EQ(json_of(c.Get("/api/health"))["queue"]["running"], 0);
  EXPECT_EQ(c.Get("/api/tryons/" + tryon)->status, 404);
  EXPECT_TRUE(files_naming(server.options.data_dir, body).empty());
  EXPECT_TRUE(files_naming(server.options.data_dir, tryon).empty());
}

// A try-on is answered once its dressed body is written; its preview.png is drawn when the worker
// has no try-on waiting. A body deleted before that leaves no preview behind, and the next try-on's
// preview is drawn without anyone asking for it.
TEST(WebPrivacy, PreviewsAreDrawnWhenIdleAndNotForADeletedBody) {
  TestServer server(quick_serve_options("web_privacy_preview"));
  auto c = server.client();
  const std::string first = json_of(c.Post("/api/bodies", R"({"sex": "female"})", "application/json"))["id"];
  const std::string second = json_of(c.Post("/api/bodies", R"({"sex": "male"})", "application/json"))["id"];
  const auto a = c.Post("/api/tryons", json{{"body", first}, {"garment", "skirt"}, {"size", "M"}}.dump(),
                        "application/json");
  const auto b = c.Post("/api/tryons", json{{"body", second}, {"garment", "skirt"}, {"size", "L"}}.dump(),
                        "application/json");
  ASSERT_TRUE(a && b);
  const std::string tryon_a = json_of(a)["id"], tryon_b = json_of(b)["id"];
  ASSERT_EQ(wait_for_tryon(c, tryon_a)["state"], "done");
  // The one worker went on to the second try-on before drawing the first's preview.
  ASSERT_EQ(c.Delete("/api/bodies/" + first)->status, 204);
  ASSERT_EQ(wait_for_tryon(c, tryon_b)["state"], "done");
  const std::filesystem::path preview =
      server.options.data_dir / "bodies" / second / "tryons" / tryon_b / "preview.png";
  for (int i = 0; i < 3000 && !std::filesystem::exists(preview); ++i)
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  EXPECT_TRUE(std::filesystem::exists(preview));
  EXPECT_TRUE(files_naming(server.options.data_dir, first).empty());
  EXPECT_TRUE(files_naming(server.options.data_dir, tryon_a).empty());
  const auto png = c.Get("/api/tryons/" + tryon_b + "/preview.png");
  ASSERT_TRUE(png);
  EXPECT_EQ(png->status, 200);
  EXPECT_EQ(png->body.substr(1, 3), "PNG");
}

TEST(WebPrivacy, StoppingRemovesTheBodiesItHeldAndNothingElse) {
  ServeOptions o = quick_serve_options("web_privacy_stop");
  // Beside the data folder and inside it: files the server must leave alone.
  const std::filesystem::path beside = o.data_dir.parent_path() / "web_privacy_stop_neighbour.txt";
  std::ofstream(beside) << "keep";
  std::filesystem::create_directories(o.data_dir / "kept");
  std::ofstream(o.data_dir / "kept" / "note.txt") << "keep";
  std::vector<std::string> ids;
  {
    TestServer server(o);
    auto c = server.client();
    for (int i = 0; i < 4; ++i) ids.push_back(json_of(c.Post("/api/bodies", "{}", "application/json"))["id"]);
    for (const std::string& id : ids) EXPECT_FALSE(files_naming(o.data_dir, id).empty());
  }
  for (const std::string& id : ids) EXPECT_TRUE(files_naming(o.data_dir, id).empty()) << id;
  EXPECT_TRUE(std::filesystem::exists(beside));
  EXPECT_TRUE(std::filesystem::exists(o.data_dir / "kept" / "note.txt"));
  EXPECT_TRUE(std::filesystem::is_directory(o.data_dir / "bodies"));
  std::filesystem::remove(beside);
}

TEST(WebPrivacy, RemovalsStayInsideTheDataFolder) {
  const std::filesystem::path root = temp_dir("web_privacy_inside");
  const std::filesystem::path outside = root.parent_path() / "web_privacy_inside_outside";
  std::filesystem::create_directories(outside);
  std::filesystem::create_directories(root / "bodies" / "x");
  for (const std::filesystem::path& target : {outside, root, root / "..", root / "bodies" / ".." / "..",
                                              std::filesystem::path("/"), std::filesystem::path{}})
    web::remove_inside(root, target);
  EXPECT_TRUE(std::filesystem::is_directory(outside));
  EXPECT_TRUE(std::filesystem::is_directory(root / "bodies" / "x"));
  web::remove_inside(root, root / "bodies" / "x");
  EXPECT_FALSE(std::filesystem::exists(root / "bodies" / "x"));
  std::filesystem::remove_all(outside);
}

TEST(WebPrivacy, BodiesExpire) {
  ServeOptions o = quick_serve_options("web_privacy_expiry");
  o.keep = std::chrono::milliseconds(400);
  TestServer server(o);
  auto c = server.client();
  const std::string body = json_of(c.Post("/api/bodies", "{}", "application/json"))["id"];
  EXPECT_EQ(c.Get("/api/bodies/" + body)->status, 200);
  const auto start = std::chrono::steady_clock::now();
  while (c.Get("/api/bodies/" + body)->status == 200 &&
         std::chrono::steady_clock::now() - start < std::chrono::seconds(20))
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  EXPECT_EQ(c.Get("/api/bodies/" + body)->status, 404);
  EXPECT_GE(std::chrono::steady_clock::now() - start, std::chrono::milliseconds(300));
  EXPECT_TRUE(files_naming(server.options.data_dir, body).empty());
}

TEST(WebPrivacy, KeepDurations) {
  EXPECT_EQ(parse_keep("90s"), std::chrono::seconds(90));
  EXPECT_EQ(parse_keep("30m"), std::chrono::minutes(30));
  EXPECT_EQ(parse_keep("24h"), std::chrono::hours(24));
  EXPECT_EQ(parse_keep("7d"), std::chrono::hours(7 * 24));
  for (const char* bad : {"", "h", "0h", "-1h", "1.5h", "24", "24 h", "1w", "99999999999d"})
    EXPECT_THROW(parse_keep(bad), InputError) << bad;
}

}  // namespace
}  // namespace drape::test
