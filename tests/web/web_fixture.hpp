#pragma once
// A try-on server started in this process on a free loopback port, with its own data folder and
// try-ons dressed coarse and capped (these tests are about the service, not the cloth), and a
// client talking to it.
#include <gtest/gtest.h>

#include <chrono>
#include <filesystem>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <thread>

#include "drape/web.hpp"
#include "support/test_support.hpp"
#include "web/http.hpp"

namespace drape::test {

// Quick dressings: a coarse grid and an iteration cap (a capped try-on still writes every file).
inline ServeOptions quick_serve_options(const std::string& tag) {
  ServeOptions o;
  o.data_dir = temp_dir(tag);
  o.workers = 1;
  o.dress.mesh.edge_length = 0.06;
  o.dress.max_iterations = 4;
  return o;
}

struct TestServer {
  ServeOptions options;
  std::unique_ptr<WebServer> server;
  int port = 0;

  explicit TestServer(ServeOptions o) : options(std::move(o)) {
    server = std::make_unique<WebServer>(options);
    port = server->bind("127.0.0.1", 0);
    server->start();
  }
  ~TestServer() { server->stop(); }

  httplib::Client client() const {
    httplib::Client c("127.0.0.1", port);
    c.set_read_timeout(120, 0);
    c.set_write_timeout(60, 0);
    return c;
  }
};

inline nlohmann::json json_of(const httplib::Result& r) {
  if (!r) return nullptr;
  return nlohmann::json::parse(r->body, nullptr, false);
}

// The error text of an answer, or "" when it is not {"error": "..."}.
inline std::string error_of(const httplib::Result& r) {
  const nlohmann::json j = json_of(r);
  return j.is_object() && j.contains("error") && j["error"].is_string() ? j["error"].get<std::string>() : "";
}

// Polls a try-on until it is done or failed (or `limit` passes); returns its last state.
inline nlohmann::json wait_for_tryon(httplib::Client& c, const std::string& id,
                                     std::chrono::seconds limit = std::chrono::seconds(600)) {
  const auto end = std::chrono::steady_clock::now() + limit;
  nlohmann::json t;
  while (std::chrono::steady_clock::now() < end) {
    t = json_of(c.Get("/api/tryons/" + id));
    if (!t.is_object() || t["state"] == "done" || t["state"] == "failed") return t;
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  return t;
}

inline bool is_hex_id(const std::string& s) {
  return s.size() == 32 && s.find_first_not_of("0123456789abcdef") == std::string::npos;
}

}  // namespace drape::test
