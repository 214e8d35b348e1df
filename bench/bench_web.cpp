// The web try-on's latency: from POST /api/tryons to the dressed body in the shopper's page (it
// polls every 20 ms and fetches dressed.glb once the try-on is done), with 1 and 4 shoppers at once
// on loopback against a server with one worker per core. Each try-on is a fresh body from measurements (made before the clock starts;
// heights 1.62-1.68 m, busts 0.90-0.94 m, each shopper's different) in the default shirt, size M,
// at drape's default resolution, so none is answered from the cache. The third argument is the
// server: 0, cold (no warm-up, an empty data folder: only the try-ons after the first can start
// from a drape on a body like the shopper's, docs/web.md); 1, warmed (cold, but the shop has
// dressed the shirt M once before the shoppers come: an untimed try-on on the default body); 2,
// restarted, as `drape serve` runs: an earlier server on the same data folder warmed up (dressed
// the catalogue on the default bodies, untimed) and the shoppers come the moment the new one
// listens. Reports the median and 95th percentile in seconds,
// and try-ons per minute.
//
//   build-*/bench/bench_web --benchmark_counters_tabular=true
#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <mutex>
#include <nlohmann/json.hpp>
#include <thread>
#include <vector>

#include "drape/web.hpp"
#include "web/http.hpp"

namespace drape {
namespace {

using Clock = std::chrono::steady_clock;

double percentile(std::vector<double> v, double q) {
  std::sort(v.begin(), v.end());
  const double at = q * static_cast<double>(v.size() - 1);
  const auto lo = static_cast<size_t>(at);
  const size_t hi = std::min(lo + 1, v.size() - 1);
  return v[lo] + (v[hi] - v[lo]) * (at - static_cast<double>(lo));
}

void BM_TryOnLatency(benchmark::State& state) {
  const int shoppers = static_cast<int>(state.range(0));
  const int per_shopper = static_cast<int>(state.range(1));
  const bool warmed = state.range(2) == 1;
  ServeOptions o;
  o.warm_up = state.range(2) == 2;
  o.data_dir = std::filesystem::temp_directory_path() / "drape_bench_web";
  std::filesystem::remove_all(o.data_dir);
  if (o.warm_up) {
    // The earlier run: its warm-up to the end, its starts left in the data folder.
    WebServer earlier(o);
    const int at = earlier.bind("127.0.0.1", 0);
    earlier.start();
    httplib::Client c("127.0.0.1", at);
    for (int left = 1; left > 0;) {
      std::this_thread::sleep_for(std::chrono::milliseconds(200));
      const auto h = c.Get("/api/health");
      left = h ? nlohmann::json::parse(h->body)["warm_up"].value("left", 0) : 0;
    }
    earlier.stop();
  }
  WebServer server(o);
  const int port = server.bind("127.0.0.1", 0);
  server.start();

  if (warmed) {
    httplib::Client c("127.0.0.1", port);
    c.set_read_timeout(600, 0);
    const auto body = c.Post("/api/bodies", R"({"sex": "female"})", "application/json");
    const std::string body_id = nlohmann::json::parse(body->body)["id"];
    const nlohmann::json request{{"body", body_id}, {"garment", "shirt"}, {"size", "M"}};
    const auto r = c.Post("/api/tryons", request.dump(), "application/json");
    const std::string id = nlohmann::json::parse(r->body)["id"];
    for (std::string at = "queued"; at == "queued" || at == "running";) {
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
      const auto t = c.Get("/api/tryons/" + id);
      at = t ? nlohmann::json::parse(t->body).value("state", "failed") : "failed";
    }
  }

  std::vector<double> latencies;
  size_t failed = 0;
  double wall = 0;
  for (auto _ : state) {
    std::mutex mutex;
    std::vector<std::thread> threads;
    const auto start = Clock::now();
    for (int s = 0; s < shoppers; ++s) {
      threads.emplace_back([&, s] {
        httplib::Client c("127.0.0.1", port);
        c.set_read_timeout(600, 0);
        for (int k = 0; k < per_shopper; ++k) {
          const int n = s * per_shopper + k;
          const nlohmann::json shopper{
              {"sex", "female"},
              {"measurements", {{"height", 1.62 + 0.02 * (n % 4)}, {"bust", 0.90 + 0.01 * ((3 * n + 1) % 5)}}}};
          const auto body = c.Post("/api/bodies", shopper.dump(), "application/json");
          if (!body || body->status != 201) continue;
          const std::string body_id = nlohmann::json::parse(body->body)["id"];
          const nlohmann::json request{{"body", body_id}, {"garment", "shirt"}, {"size", "M"}};
          const auto asked = Clock::now();
          const auto r = c.Post("/api/tryons", request.dump(), "application/json");
          if (!r || r->status != 202) {
            std::lock_guard lock(mutex);
            ++failed;
            continue;
          }
          const std::string id = nlohmann::json::parse(r->body)["id"];
          std::string at = "queued";
          while (at == "queued" || at == "running") {
            std::this_thread::sleep_for(std::chrono::milliseconds(20));
            const auto t = c.Get("/api/tryons/" + id);
            at = t ? nlohmann::json::parse(t->body).value("state", "failed") : "failed";
          }
          // Shown: the page fetches the dressed body once the try-on is done.
          if (at == "done") {
            const auto glb = c.Get("/api/tryons/" + id + "/dressed.glb");
            if (!glb || glb->status != 200) at = "failed";
          }
          const double seconds = std::chrono::duration<double>(Clock::now() - asked).count();
          std::lock_guard lock(mutex);
          if (at == "done")
            latencies.push_back(seconds);
          else
            ++failed;
          c.Delete("/api/bodies/" + body_id);
        }
      });
    }
    for (std::thread& t : threads) t.join();
    wall += std::chrono::duration<double>(Clock::now() - start).count();
  }
  server.stop();
  std::filesystem::remove_all(o.data_dir);
  if (latencies.empty()) {
    state.SkipWithError("no try-on finished");
    return;
  }
  state.counters["median_s"] = percentile(latencies, 0.5);
  state.counters["p95_s"] = percentile(latencies, 0.95);
  state.counters["tryons"] = static_cast<double>(latencies.size());
  state.counters["failed"] = static_cast<double>(failed);
  state.counters["per_minute"] = 60.0 * static_cast<double>(latencies.size()) / wall;
  state.counters["workers"] = std::max(1u, std::thread::hardware_concurrency());
}
BENCHMARK(BM_TryOnLatency)
    ->ArgNames({"shoppers", "each", "server"})
    ->Args({1, 4, 0})
    ->Args({4, 2, 0})
    ->Args({1, 4, 1})
    ->Args({4, 2, 1})
    ->Args({1, 4, 2})
    ->Args({4, 2, 2})
    ->Iterations(1)
    ->Unit(benchmark::kSecond)
    ->UseRealTime();

}  // namespace
}  // namespace drape
BENCHMARK_MAIN();
