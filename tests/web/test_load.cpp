// Many shoppers at once on loopback against one worker and a tiny queue: every accepted try-on
// ends done or failed with a reason, none is lost, the queue never holds more than its bound, and
// the shoppers turned away got 503 with Retry-After.
#include <atomic>
#include <mutex>
#include <vector>

#include "web/web_fixture.hpp"

namespace drape::test {
namespace {

using nlohmann::json;

TEST(WebLoad, BoundedQueueLosesNothing) {
  ServeOptions o = quick_serve_options("web_load");
  o.workers = 1;
  o.queue_capacity = 2;
  TestServer server(o);
  constexpr int kShoppers = 8;
  const char* sizes[] = {"S", "M", "L"};
  const char* garments[] = {"skirt", "shirt"};

  // Bodies first, so that the try-ons arrive together.
  std::vector<std::string> bodies;
  {
    auto c = server.client();
    for (int i = 0; i < kShoppers; ++i)
      bodies.push_back(json_of(c.Post("/api/bodies", "{}", "application/json"))["id"]);
  }
  std::atomic<bool> watching{true};
  std::atomic<int> max_queued{0}, max_running{0};
  std::thread watcher([&] {
    auto c = server.client();
    while (watching) {
      const json h = json_of(c.Get("/api/health"));
      max_queued = std::max(max_queued.load(), h["queue"]["queued"].get<int>());
      max_running = std::max(max_running.load(), h["queue"]["running"].get<int>());
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
  });

  std::mutex mutex;
  std::vector<std::string> accepted;
  std::vector<json> finished;
  int turned_away = 0;
  std::atomic<int> ready{0};
  std::vector<std::thread> shoppers;
  for (int i = 0; i < kShoppers; ++i) {
    shoppers.emplace_back([&, i] {
      auto c = server.client();
      const json request{{"body", bodies[static_cast<size_t>(i)]},
                         {"garment", garments[i % 2]},
                         {"size", sizes[(i / 2) % 3]}};
      ++ready;
      while (ready < kShoppers) std::this_thread::yield();
      const auto r = c.Post("/api/tryons", request.dump(), "application/json");
      ASSERT_TRUE(r);
      if (r->status == 503) {
        EXPECT_FALSE(r->get_header_value("Retry-After").empty());
        EXPECT_FALSE(error_of(r).empty());
        std::lock_guard lock(mutex);
        ++turned_away;
        return;
      }
      ASSERT_EQ(r->status, 202) << r->body;
      const std::string id = json_of(r)["id"];
      {
        std::lock_guard lock(mutex);
        accepted.push_back(id);
      }
      const json t = wait_for_tryon(c, id);
      std::lock_guard lock(mutex);
      finished.push_back(t);
    });
  }
  for (std::thread& t : shoppers) t.join();
  watching = false;
  watcher.join();

  EXPECT_EQ(static_cast<int>(accepted.size()) + turned_away, kShoppers);
  EXPECT_GE(turned_away, 1) << "8 shoppers at once and room for 3: some must be turned away";
  EXPECT_GE(accepted.size(), 1u);
  ASSERT_EQ(finished.size(), accepted.size());
  for (const json& t : finished) {
    ASSERT_TRUE(t.is_object());
    const bool done = t["state"] == "done", failed = t["state"] == "failed";
    EXPECT_TRUE(done || failed) << t.dump();
    if (failed) {
      EXPECT_FALSE(t["error"].get<std::string>().empty());
    }
  }
  EXPECT_LE(max_queued.load(), 2);
  EXPECT_LE(max_running.load(), 1);
  const json h = json_of(server.client().Get("/api/health"));
  EXPECT_EQ(h["tryons"]["turned_away"].get<int>(), turned_away);
  EXPECT_EQ(h["tryons"]["done"].get<size_t>() + h["tryons"]["failed"].get<size_t>(), accepted.size());
}

}  // namespace
}  // namespace drape::test
