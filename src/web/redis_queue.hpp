#pragma once
// Try-ons through Redis (`--queue redis://HOST:PORT`), so that `drape serve --worker-only`
// processes on other machines share the work (docs/web.md, "Shared queue").
//
// Keys (all under "drape:"): `queue`, a list of jobs (JSON: try-on, body, garment, size, reply
// list); `body:ID`, a body's GLB (expires with --keep); `processing:WORKER`, the job a worker took
// (moved there atomically by BLMOVE); `alive:WORKER`, the worker's lease, refreshed by a heartbeat
// thread, and `workers`, the set of workers seen; `progress:TRYON`; `result:TRYON`, a hash with the state,
// size, report or error and the four files; `done:SERVER`, the try-ons finished for that server. A worker
// that dies mid-job stops refreshing its lease; the server moves the job of a worker without a lease back to
// the front of the queue, and another worker takes it up.
//
// hiredis contexts are not thread-safe: each thread opens its own RedisConnection.
#include <chrono>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

struct redisContext;

namespace drape::web {

class RedisConnection {
 public:
  // "redis://HOST:PORT" (PORT defaults to 6379). InputError("--queue") for another form;
  // std::runtime_error when Redis cannot be reached.
  explicit RedisConnection(const std::string& url);
  ~RedisConnection();
  RedisConnection(const RedisConnection&) = delete;
  RedisConnection& operator=(const RedisConnection&) = delete;

  // One command, arguments binary-safe. The reply: nil -> nullopt, integer -> its text, string and
  // status -> the bytes, array -> its elements in `elements`. std::runtime_error on an error reply
  // or a lost connection.
  struct Reply {
    std::optional<std::string> value;
    std::vector<std::optional<std::string>> elements;
  };
  Reply command(const std::vector<std::string>& args);

 private:
  redisContext* context_ = nullptr;
};

struct RedisJob {
  std::string tryon, body, garment, size, reply;
  std::string text;  // the job as queued (what LREM and LMOVE match)
};

struct RedisResult {
  std::string tryon;
  bool done = false;
  std::string size, error;
  nlohmann::json report;
  std::vector<std::pair<std::string, std::string>> files;  // name, bytes
};

// The keys a server and its workers use, one connection per thread.
class RedisQueue {
 public:
  explicit RedisQueue(const std::string& url) : redis_(url) {}

  // Server side.
  void put_body(const std::string& id, const std::string& glb, std::chrono::milliseconds keep);
  void delete_body(const std::string& id);
  size_t queued();
  std::string push(const RedisJob& job);  // returns the job as queued
  void remove(const std::string& job);    // a queued job taken back (its body was deleted)
  std::optional<std::string> pop_done(const std::string& reply, std::chrono::milliseconds wait);
  std::optional<RedisResult> take_result(const std::string& tryon);
  std::optional<double> progress(const std::string& tryon);
  // Moves the jobs of workers whose lease has lapsed back to the front of the queue; returns how many.
  size_t requeue_abandoned();

  // Worker side.
  void renew_lease(const std::string& worker, std::chrono::milliseconds lease);
  std::optional<RedisJob> take(const std::string& worker, std::chrono::milliseconds wait);
  std::optional<std::string> body(const std::string& id);
  void set_progress(const std::string& tryon, double progress, std::chrono::milliseconds keep);
  void finish(const std::string& worker, const RedisJob& job, const RedisResult& result,
              std::chrono::milliseconds keep);

 private:
  RedisConnection redis_;
};

}  // namespace drape::web
