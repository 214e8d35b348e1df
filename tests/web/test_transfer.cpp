// A try-on on a body from measurements starts from the same garment and size dressed before on
// another such body (drape/garment_transfer.hpp): the first is dressed from the flat pattern, the
// next from the first one's drape, and both pass every gate.
#include <fstream>

#include "drape/files.hpp"

#include "web/web_fixture.hpp"

namespace drape::test {
namespace {

using nlohmann::json;

// The full report.json a finished try-on left in the data folder.
json stored_report(const std::filesystem::path& data, const std::string& tryon) {
  for (const auto& e : std::filesystem::recursive_directory_iterator(data))
    if (e.path().filename() == "report.json" && e.path().parent_path().filename() == tryon) {
      std::ifstream in(e.path());
      return json::parse(in, nullptr, false);
    }
  return nullptr;
}

TEST(WebTransfer, NextShopperStartsFromTheLastDrapeOfTheGarment) {
  ServeOptions o;
  o.data_dir = temp_dir("web_transfer");
  o.workers = 1;
  TestServer server(o);
  auto c = server.client();
  const auto tryon = [&](const json& body_request) {
    SCOPED_TRACE(body_request.dump());
    const auto b = c.Post("/api/bodies", body_request.dump(), "application/json");
    EXPECT_TRUE(b && b->status == 201);
    const std::string body = json_of(b)["id"];
    const auto r = c.Post("/api/tryons", json{{"body", body}, {"garment", "shirt"}, {"size", "M"}}.dump(),
                          "application/json");
    EXPECT_TRUE(r && r->status == 202);
    const std::string id = json_of(r)["id"];
    const json t = wait_for_tryon(c, id);
    EXPECT_EQ(t["state"], "done") << t.dump();
    EXPECT_TRUE(t["report"]["passed"].get<bool>()) << t["report"]["gates"].dump();
    return stored_report(server.options.data_dir, id);
  };
  const json first = tryon({{"sex", "female"}});
  ASSERT_TRUE(first.is_object());
  EXPECT_EQ(first["garments"][0]["start"], "placed");
  const json second = tryon({{"sex", "female"}, {"measurements", {{"height", 1.68}, {"bust", 0.94}}}});
  ASSERT_TRUE(second.is_object());
  EXPECT_EQ(second["garments"][0]["start"], "transferred");
  EXPECT_LT(second["garments"][0]["newton_iterations"].get<int>(), first["garments"][0]["newton_iterations"].get<int>());
}

json health(httplib::Client& c) { return json_of(c.Get("/api/health")); }

// The warm-up dresses the catalogue on the default bodies while no shopper waits; what it kept is
// in the data folder, a start at once for the next server there; a shopper like the default body
// starts from it; a start file that does not read is named and dressed again.
TEST(WebWarmUp, StartsAreDressedKeptInTheDataFolderAndUsedByTheNextServer) {
  ServeOptions o;
  o.data_dir = temp_dir("web_warm_up");
  o.workers = 1;
  o.warm_up = true;
  size_t planned = 0;
  std::filesystem::path kept_file;
  {
    TestServer server(o);
    auto c = server.client();
    const json first = health(c);
    ASSERT_TRUE(first.is_object());
    planned = first["warm_up"]["left"].get<size_t>();
    EXPECT_GE(planned, 2u * 5u) << "every built-in in at least its chart's size on both default bodies";
    for (int k = 0; k < 3000 && health(c)["warm_up"]["kept"].get<size_t>() == 0; ++k)
      std::this_thread::sleep_for(std::chrono::milliseconds(100));
    ASSERT_GE(health(c)["warm_up"]["kept"].get<size_t>(), 1u);
    EXPECT_EQ(health(c)["tryons"]["done"], 0) << "warm-ups are not shoppers' try-ons";
    for (const auto& e : std::filesystem::directory_iterator(o.data_dir / "starts")) {
      std::ifstream in(e.path());
      const json j = json::parse(in, nullptr, false);
      if (j.is_object() && j.value("fits", false) && e.path().filename().string().ends_with("-female.json")) kept_file = e.path();
    }
  }
  ASSERT_FALSE(kept_file.empty()) << "no start on the default female body in " << (o.data_dir / "starts");
  std::ifstream in(kept_file);
  const json kept = json::parse(in, nullptr, false);
  const std::string garment = kept["garment"], size = kept["size"];

  // The next server on the same folder has the kept starts at once.
  {
    TestServer server(o);
    auto c = server.client();
    const json h = health(c);
    EXPECT_GE(h["warm_up"]["kept"].get<size_t>(), 1u);
    EXPECT_LT(h["warm_up"]["left"].get<size_t>(), planned);
    const auto b = c.Post("/api/bodies", json{{"sex", "female"}, {"measurements", {{"height", 1.67}, {"bust", 0.93}}}}.dump(),
                          "application/json");
    ASSERT_TRUE(b && b->status == 201);
    const auto r = c.Post("/api/tryons", json{{"body", json_of(b)["id"]}, {"garment", garment}, {"size", size}}.dump(),
                          "application/json");
    ASSERT_TRUE(r && r->status == 202);
    const std::string id = json_of(r)["id"];
    const json t = wait_for_tryon(c, id);
    EXPECT_EQ(t["state"], "done") << t.dump();
    const json report = stored_report(server.options.data_dir, id);
    ASSERT_TRUE(report.is_object());
    EXPECT_EQ(report["garments"][0]["start"], "transferred") << garment << " " << size;
  }

  // A start file that does not read is dressed again: the next server loads every other one.
  size_t fits = 0;
  for (const auto& e : std::filesystem::directory_iterator(o.data_dir / "starts")) {
    std::ifstream file(e.path());
    fits += json::parse(file, nullptr, false).value("fits", false) ? 1 : 0;
  }
  write_file_atomic(kept_file, std::string_view(R"({"format": "drape start", "version": ")" DRAPE_VERSION R"(", "fits": 3})"));
  {
    TestServer server(o);
    auto c = server.client();
    EXPECT_EQ(health(c)["warm_up"]["kept"].get<size_t>(), fits - 1);
  }
}

}  // namespace
}  // namespace drape::test
