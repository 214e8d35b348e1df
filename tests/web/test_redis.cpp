// The shared queue (--queue redis://...): try-ons go through Redis to `drape serve --worker-only`
// processes; a worker killed mid-job has its try-on taken up by another, and nothing is lost.
// Runs redis-server on a free port; skipped with a message where redis-server is not installed.
#include <fcntl.h>
#include <netinet/in.h>
#include <signal.h>
#include <spawn.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <fstream>

#include "web/redis_queue.hpp"
#include "web/web_fixture.hpp"

extern char** environ;

namespace drape::test {
namespace {

using nlohmann::json;

int free_port() {
  const int s = ::socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  ::bind(s, reinterpret_cast<sockaddr*>(&a), sizeof a);
  socklen_t n = sizeof a;
  ::getsockname(s, reinterpret_cast<sockaddr*>(&a), &n);
  ::close(s);
  return ntohs(a.sin_port);
}

pid_t spawn(const std::vector<std::string>& args) {
  std::vector<char*> argv;
  for (const std::string& a : args) argv.push_back(const_cast<char*>(a.c_str()));
  argv.push_back(nullptr);
  posix_spawn_file_actions_t files;
  posix_spawn_file_actions_init(&files);
  posix_spawn_file_actions_addopen(&files, STDOUT_FILENO, "/dev/null", O_WRONLY, 0);
  pid_t pid = -1;
  const int rc = posix_spawn(&pid, argv[0], &files, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&files);
  return rc == 0 ? pid : -1;
}

void end(pid_t pid, int signal) {
  if (pid <= 0) return;
  ::kill(pid, signal);
  int status = 0;
  ::waitpid(pid, &status, 0);
}

class WebRedis : public ::testing::Test {
 protected:
  void SetUp() override {
    const std::filesystem::path redis = "/usr/bin/redis-server";
    if (!std::filesystem::exists(redis)) GTEST_SKIP() << "redis-server not installed (make deps installs it)";
    const int port = free_port();
    redis_pid_ = spawn({redis.string(), "--port", std::to_string(port), "--bind", "127.0.0.1", "--save", "",
                        "--appendonly", "no"});
    ASSERT_GT(redis_pid_, 0);
    url_ = "redis://127.0.0.1:" + std::to_string(port);
    for (int i = 0; i < 200 && !connection_; ++i) {
      try {
        connection_ = std::make_unique<web::RedisConnection>(url_);
      } catch (const std::runtime_error&) {
        std::this_thread::sleep_for(std::chrono::milliseconds(25));
      }
    }
    ASSERT_TRUE(connection_) << "redis-server did not start";
  }
  void TearDown() override {
    connection_.reset();
    end(redis_pid_, SIGTERM);
  }
  // A `drape serve --worker-only` process with its data in temp_dir(tag); cold unless `warm_up`.
  pid_t worker(const std::string& tag, const std::vector<std::string>& extra, bool warm_up = false) {
    std::vector<std::string> args{DRAPE_BINARY,          "serve", "--worker-only", "--queue", url_,
                                  "--workers",           "1",     "--lease",       "1s",      "--data",
                                  temp_dir(tag).string()};
    if (!warm_up) args.emplace_back("--no-warm-up");
    args.insert(args.end(), extra.begin(), extra.end());
    return spawn(args);
  }
  pid_t redis_pid_ = -1;
  std::string url_;
  std::unique_ptr<web::RedisConnection> connection_;
};

TEST_F(WebRedis, AWorkerKilledMidJobHasItsTryOnTakenUpByAnother) {
  ServeOptions o = quick_serve_options("web_redis_server");
  o.queue_url = url_;
  o.workers = -1;  // only the worker-only processes dress
  o.lease = std::chrono::seconds(1);
  TestServer server(o);
  auto c = server.client();
  const std::string body = json_of(c.Post("/api/bodies", "{}", "application/json"))["id"];
  EXPECT_EQ(connection_->command({"EXISTS", "drape:body:" + body}).value, "1");
  const auto r = c.Post("/api/tryons", json{{"body", body}, {"garment", "shirt"}, {"size", "M"}}.dump(),
                        "application/json");
  ASSERT_TRUE(r);
  ASSERT_EQ(r->status, 202) << r->body;
  const std::string id = json_of(r)["id"];

  // The first worker dresses at full resolution (seconds), and is killed as soon as it has begun.
  const pid_t first = worker("web_redis_a", {});
  ASSERT_GT(first, 0);
  json t;
  for (int i = 0; i < 12000; ++i) {
    t = json_of(c.Get("/api/tryons/" + id));
    if (t["state"] != "queued") break;
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  ASSERT_EQ(t["state"], "running") << t.dump();
  end(first, SIGKILL);
  EXPECT_EQ(json_of(c.Get("/api/tryons/" + id))["state"], "running");

  // A second worker (quick settings) takes the try-on up once the first one's lease lapses.
  const pid_t second = worker("web_redis_b", {"--edge", "0.06", "--max-iterations", "4"});
  ASSERT_GT(second, 0);
  t = wait_for_tryon(c, id, std::chrono::seconds(300));
  EXPECT_EQ(t["state"], "done") << t.dump();
  const auto dressed = c.Get("/api/tryons/" + id + "/dressed.glb");
  ASSERT_TRUE(dressed);
  EXPECT_EQ(dressed->body.substr(0, 4), "glTF");
  EXPECT_EQ(connection_->command({"LLEN", "drape:queue"}).value, "0");

  // Deleting the body removes it from Redis too.
  EXPECT_EQ(c.Delete("/api/bodies/" + body)->status, 204);
  EXPECT_EQ(connection_->command({"EXISTS", "drape:body:" + body}).value, "0");
  end(second, SIGTERM);
}

// A worker-only process that the queue leaves idle warms up (ServeOptions::warm_up): its first
// dressing of the catalogue on a default body is kept in its data folder as a start.
TEST_F(WebRedis, AnIdleWorkerWarmsUp) {
  const pid_t idle = worker("web_redis_warm", {}, true);
  ASSERT_GT(idle, 0);
  const std::filesystem::path starts =
      std::filesystem::temp_directory_path() / ("drape_test_web_redis_warm_" + std::to_string(::getpid())) / "starts";
  bool kept = false;
  for (int i = 0; i < 3000 && !kept; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
    std::error_code ec;
    for (const auto& e : std::filesystem::directory_iterator(starts, ec)) {
      std::ifstream in(e.path());
      kept = kept || json::parse(in, nullptr, false).value("fits", false);
    }
  }
  end(idle, SIGTERM);
  EXPECT_TRUE(kept) << "no start kept in " << starts;
}

TEST_F(WebRedis, ServerWorkersTakeTryOnsFromRedisAndTheQueueStaysBounded) {
  ServeOptions o = quick_serve_options("web_redis_local");
  o.queue_url = url_;
  o.workers = 1;
  o.queue_capacity = 1;
  TestServer server(o);
  auto c = server.client();
  std::vector<std::string> accepted;
  int turned_away = 0;
  for (const char* size : {"S", "M", "L", "XL"}) {
    const std::string body = json_of(c.Post("/api/bodies", "{}", "application/json"))["id"];
    const auto r = c.Post("/api/tryons", json{{"body", body}, {"garment", "shirt"}, {"size", size}}.dump(),
                          "application/json");
    ASSERT_TRUE(r);
    if (r->status == 503) {
      ++turned_away;
      EXPECT_FALSE(r->get_header_value("Retry-After").empty());
      continue;
    }
    ASSERT_EQ(r->status, 202) << r->body;
    accepted.push_back(json_of(r)["id"]);
  }
  EXPECT_GE(accepted.size(), 1u);
  EXPECT_GE(turned_away, 1);
  for (const std::string& id : accepted) {
    const json t = wait_for_tryon(c, id, std::chrono::seconds(300));
    EXPECT_TRUE(t["state"] == "done" || (t["state"] == "failed" && !t["error"].get<std::string>().empty()))
        << t.dump();
  }
  EXPECT_EQ(json_of(c.Get("/api/health"))["tryons"]["done"].get<size_t>(), accepted.size());
}

}  // namespace
}  // namespace drape::test
