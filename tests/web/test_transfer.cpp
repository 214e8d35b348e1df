// A try-on on a body from measurements starts from the same garment and size dressed before on
// another such body (drape/garment_transfer.hpp): the first is dressed from the flat pattern, the
// next from the first one's drape, and both pass every gate.
#include <fstream>

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
    const auto r = c.Post("/api/tryons", json{{"body", body}, {"garment", "skirt"}, {"size", "M"}}.dump(),
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

}  // namespace
}  // namespace drape::test
