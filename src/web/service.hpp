#pragma once
// The try-on service behind the HTTP routes: bodies and try-ons in memory (a body is only reachable
// through its id), their files under data_dir/bodies/ID/, a bounded queue of try-ons and a pool of
// workers that dress them, a cache of body + garment + size, and expiry.
//
// Files: data_dir/bodies/BODY/body.glb, and per finished try-on data_dir/bodies/BODY/tryons/TRYON/
// {dressed.glb, fit.glb, preview.png, report.json}. A worker writes into data_dir/work/TRYON/ and
// moves the folder into place under the service's lock only if the body still exists, so a body
// deleted (or expired) while it was being dressed leaves nothing behind.
#include <chrono>
#include <condition_variable>
#include <deque>
#include <filesystem>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "drape/body.hpp"
#include "drape/web.hpp"
#include "web/catalogue.hpp"
#include "web/redis_queue.hpp"
#include "web/redis_workers.hpp"
#include "web/warm_up.hpp"

namespace drape::web {

// Removes `target` (a folder) when it lies strictly inside `root`; anything else is refused and named
// on stderr. Every removal of the service goes through it.
void remove_inside(const std::filesystem::path& root, const std::filesystem::path& target);

enum class TryOnState { Queued, Running, Done, Failed };
const char* to_string(TryOnState state);

struct TryOnView {
  std::string id, body, garment, size_requested;
  TryOnState state = TryOnState::Queued;
  double progress = 0;    // 0..1
  std::string size;       // the size dressed (known once done; for "auto", the recommended one)
  std::string error;      // why it failed, in the shopper's words
  nlohmann::json report;  // done: passed, quality, gates, fit (and size_advice for "auto")
};

struct BodyView {
  std::string id;
  nlohmann::json measurements;
  double height_m = 0;
};

struct ServiceStats {
  size_t queued = 0, running = 0, capacity = 0, workers = 0, done = 0, failed = 0, rejected = 0;
  size_t warm_up_left = 0, warm_up_kept = 0;  // warm-up dressings still to do; those kept as starts
};

class TryOnService {
 public:
  TryOnService(const ServeOptions& options, Catalogue& catalogue);
  ~TryOnService();

  BodyView add_body(Body body);
  std::optional<BodyView> body(const std::string& id) const;
  // Removes the body, every try-on of it and their files; false when there is no such body.
  bool delete_body(const std::string& id);
  // Existing file of a body: "body.glb". nullopt when the id or the file is unknown.
  std::optional<std::filesystem::path> body_file(const std::string& id, const std::string& name) const;

  struct Submitted {
    std::string id;
    bool cached = false;  // the same body, garment and size asked before: that try-on's id
  };
  // RequestError 404 (unknown body), 400 (unknown garment or size), 503 (queue full).
  Submitted submit(const std::string& body_id, const std::string& garment, const std::string& size);
  std::optional<TryOnView> tryon(const std::string& id) const;
  // A finished try-on's file: dressed.glb, fit.glb, preview.png or report.json. A preview not drawn
  // yet is drawn now.
  std::optional<std::filesystem::path> tryon_file(const std::string& id, const std::string& name);

  ServiceStats stats() const;
  // Seconds a shopper turned away by a full queue should wait: the queue's length times the
  // mean dressing time so far, over the workers (at least 1).
  int retry_after_seconds() const;
  void stop();

 private:
  struct BodyRecord {
    std::shared_ptr<const Body> body;
    BodyView view;
    std::chrono::steady_clock::time_point expires;
    std::vector<std::string> tryons;
  };
  struct TryOnRecord {
    TryOnView view;
    std::string cache_key;
    std::string job;  // shared queue: the job as queued in Redis
  };


  void worker_loop();
  void collector_loop();
  void redis_try(const std::function<void()>& action) const;  // a Redis failure is logged, not thrown
  void sweeper_loop();
  void dress_one(const std::string& tryon_id);
  void remove_body_locked(const std::string& id);
  void finish(const std::string& tryon_id, TryOnState state, const std::string& size,
              const std::string& error, nlohmann::json report, const std::filesystem::path& staged,
              std::optional<DressPreview> preview = std::nullopt);
  // preview.png of a try-on done by this process's workers: the shopper is answered once the
  // dressed body is written, and the picture (a third of a warmed try-on's work) is drawn by a
  // worker when no try-on waits, or at once when it is asked for, whichever comes first.
  struct PendingPreview {
    std::mutex drawing;  // taken before mutex_, never while holding it
    bool drawn = false;
    DressPreview scene;
  };
  void draw_preview(const std::string& tryon_id, const std::shared_ptr<PendingPreview>& preview);
  std::filesystem::path body_dir(const std::string& id) const;

  ServeOptions options_;
  Catalogue& catalogue_;
  // Garments dressed before on bodies from measurements: a try-on on another such body starts from
  // the nearest one's (docs/web.md).
  GarmentTransferStore transfers_;
  size_t workers_count_ = 1, capacity_ = 4;
  int omp_threads_per_worker_ = 1;

  mutable std::mutex mutex_;
  std::condition_variable queue_cv_, sweeper_cv_;
  bool stopping_ = false, stopped_ = false;
  std::map<std::string, BodyRecord> bodies_;
  std::map<std::string, TryOnRecord> tryons_;
  std::map<std::string, std::string> cache_;  // body + garment + size -> try-on id
  std::deque<std::string> queue_;
  std::map<std::string, std::shared_ptr<PendingPreview>> previews_;  // try-on id -> its preview to draw
  std::deque<std::string> preview_queue_;                            // in the order they were done
  std::unique_ptr<WarmUp> warm_up_;  // ServeOptions::warm_up with the in-process queue
  size_t running_ = 0, done_ = 0, failed_ = 0, rejected_ = 0;
  double dress_seconds_total_ = 0;
  std::vector<std::thread> workers_;
  std::thread sweeper_;
  // Shared queue (options.queue_url): a connection for the request threads (under mutex_), this
  // server's own results list, its workers and the thread that collects results.
  std::unique_ptr<RedisQueue> redis_;
  std::string reply_list_;
  std::unique_ptr<RedisWorkers> redis_workers_;
  std::thread collector_;
};

}  // namespace drape::web
