#pragma once
// Workers that dress try-ons taken from the shared Redis queue (redis_queue.hpp): the threads of a
// `drape serve --worker-only` process, or of a server started with --queue. Each worker has a
// random id and a lease that a heartbeat thread renews; the body comes from Redis as a GLB, the
// files go back into Redis with the result.
#include <atomic>
#include <chrono>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "drape/web.hpp"
#include "web/catalogue.hpp"
#include "web/warm_up.hpp"

namespace drape::web {

class RedisWorkers {
 public:
  // Starts `count` workers on options.queue_url; throws std::runtime_error when Redis is unreachable.
  RedisWorkers(const ServeOptions& options, const Catalogue& catalogue, size_t count);
  ~RedisWorkers();
  void stop();  // finishes the try-ons being dressed, then returns
  size_t running() const { return running_; }
  const WarmUp* warm_up() const { return warm_up_.get(); }  // ServeOptions::warm_up

 private:
  void work(const std::string& worker);
  void heartbeat();

  const ServeOptions& options_;
  const Catalogue& catalogue_;
  GarmentTransferStore transfers_;  // garments dressed here before, to start the next from
  std::unique_ptr<WarmUp> warm_up_;  // dressed by a worker the queue leaves idle
  std::vector<std::string> ids_;
  std::vector<std::thread> threads_;
  std::thread heartbeat_;
  std::atomic<bool> stopping_{false};
  std::atomic<size_t> running_{0};
};

}  // namespace drape::web
