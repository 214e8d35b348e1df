#include "web/service.hpp"

#include <fmt/format.h>
#include <omp.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "drape/error.hpp"
#include "drape/files.hpp"
#include "drape/io.hpp"
#include "drape/render.hpp"
#include "drape/size_advice.hpp"
#include "web/bodies.hpp"
#include "web/ids.hpp"
#include "web/redis_queue.hpp"
#include "web/redis_workers.hpp"
#include "web/request_error.hpp"
#include "web/tryon_job.hpp"

namespace drape::web {
namespace {

using Clock = std::chrono::steady_clock;

// Previews waiting to be drawn, at most: beyond it a worker draws one before its next try-on, so a
// shop that is never idle holds a bounded number of dressed scenes in memory.
constexpr size_t kMaxPendingPreviews = 8;

}  // namespace

void remove_inside(const std::filesystem::path& root, const std::filesystem::path& target) {
  // Every folder the service removes is a body's or a try-on's, strictly inside the data folder;
  // anything else is refused here, whatever a caller computed.
  const std::filesystem::path rel = target.lexically_normal().lexically_relative(root.lexically_normal());
  if (rel.empty() || rel == "." || *rel.begin() == ".." || rel.is_absolute()) {
    std::fprintf(stderr, "drape serve: refused to remove '%s': not inside the data folder\n",
                 target.string().c_str());
    return;
  }
  std::error_code ec;
  std::filesystem::remove_all(target, ec);
  if (ec)
    std::fprintf(stderr, "drape serve: could not remove files of a body or try-on: %s\n",
                 ec.message().c_str());
}

namespace {

// Removes what a previous run left: the bodies it held in memory are gone, so their files could
// never be reached or deleted through the API again.
void clear_unreachable(const std::filesystem::path& dir) {
  std::error_code ec;
  if (!std::filesystem::is_directory(dir, ec)) return;
  for (const auto& entry : std::filesystem::directory_iterator(dir, ec))
    if (is_id(entry.path().filename().string())) remove_inside(dir, entry.path());
}

}  // namespace

const char* to_string(TryOnState state) {
  switch (state) {
    case TryOnState::Queued:
      return "queued";
    case TryOnState::Running:
      return "running";
    case TryOnState::Done:
      return "done";
    case TryOnState::Failed:
      return "failed";
  }
  return "failed";
}

TryOnService::TryOnService(const ServeOptions& options, Catalogue& catalogue)
    : options_(options), catalogue_(catalogue) {
  const int cores = std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
  workers_count_ =
      options.workers < 0 ? 0 : static_cast<size_t>(options.workers > 0 ? options.workers : cores);
  if (workers_count_ == 0 && options.queue_url.empty())
    throw InputError("--workers", "a server without a shared queue (--queue) needs at least one worker");
  capacity_ = options.queue_capacity > 0 ? options.queue_capacity : 4 * std::max<size_t>(workers_count_, 1);
  // The cores are shared between the workers: each dressing's OpenMP loops get the rest.
  omp_threads_per_worker_ = std::max(1, cores / static_cast<int>(std::max<size_t>(workers_count_, 1)));
  std::filesystem::create_directories(options_.data_dir / "bodies");
  clear_unreachable(options_.data_dir / "bodies");
  clear_unreachable(options_.data_dir / "work");
  if (!options_.queue_url.empty()) {
    // Shared queue: this server's workers take try-ons from Redis like any worker-only process,
    // and a collector brings results back.
    redis_ = std::make_unique<RedisQueue>(options_.queue_url);
    reply_list_ = "drape:done:" + random_id();
    if (workers_count_ > 0)
      redis_workers_ = std::make_unique<RedisWorkers>(options_, catalogue_, workers_count_);
    collector_ = std::thread([this] { collector_loop(); });
  } else {
    if (options_.warm_up && workers_count_ > 0) warm_up_ = std::make_unique<WarmUp>(catalogue_, options_, transfers_);
    for (size_t i = 0; i < workers_count_; ++i) workers_.emplace_back([this] { worker_loop(); });
  }
  sweeper_ = std::thread([this] { sweeper_loop(); });
}

TryOnService::~TryOnService() {
  stop();
}

void TryOnService::stop() {
  {
    std::lock_guard lock(mutex_);
    if (stopped_) return;
    stopped_ = stopping_ = true;
  }
  queue_cv_.notify_all();
  sweeper_cv_.notify_all();
  for (std::thread& t : workers_) t.join();
  workers_.clear();
  if (redis_workers_) redis_workers_->stop();
  if (collector_.joinable()) collector_.join();
  if (sweeper_.joinable()) sweeper_.join();
  // Bodies live in this process's memory: once it stops, their files could never be reached or
  // deleted through the API, so they go now.
  std::lock_guard lock(mutex_);
  while (!bodies_.empty()) {
    const std::string id = bodies_.begin()->first;  // a copy: the map's own key dies with the entry
    remove_body_locked(id);
  }
}

std::filesystem::path TryOnService::body_dir(const std::string& id) const {
  return options_.data_dir / "bodies" / id;
}

BodyView TryOnService::add_body(Body body) {
  {
    // Bodies are held in memory until they expire: a bound keeps a flood of them from exhausting it.
    std::lock_guard lock(mutex_);
    if (bodies_.size() >= options_.max_bodies)
      throw RequestError(503, "the fitting room is full; please try again later");
  }
  BodyView view;
  view.id = random_id();
  view.measurements = measurements_json(body.measurements);
  view.height_m = std::round(1e4 * static_cast<double>(body.measurements.height)) / 1e4;
  // The file is written before the id is handed out, so a body that exists has its file.
  const std::vector<unsigned char> glb = encode_glb(body_scene(body));
  write_file_atomic(body_dir(view.id) / "body.glb", glb);
  std::lock_guard lock(mutex_);
  if (redis_) redis_->put_body(view.id, std::string(glb.begin(), glb.end()), options_.keep);
  BodyRecord& record = bodies_[view.id];
  record.body = std::make_shared<const Body>(std::move(body));
  record.view = view;
  record.expires = Clock::now() + options_.keep;
  return view;
}

std::optional<BodyView> TryOnService::body(const std::string& id) const {
  std::lock_guard lock(mutex_);
  const auto it = bodies_.find(id);
  if (it == bodies_.end()) return std::nullopt;
  return it->second.view;
}

std::optional<std::filesystem::path> TryOnService::body_file(const std::string& id,
                                                             const std::string& name) const {
  if (name != "body.glb") return std::nullopt;
  std::lock_guard lock(mutex_);
  if (!is_id(id) || !bodies_.count(id)) return std::nullopt;
  return body_dir(id) / name;
}

void TryOnService::remove_body_locked(const std::string& id_in) {
  // By value: `id_in` may be a key of bodies_ (or of something erased below), which erase() frees.
  const std::string id = id_in;
  if (!is_id(id)) return;  // never a path built from anything else
  const auto it = bodies_.find(id);
  if (it == bodies_.end()) return;
  for (const std::string& t : it->second.tryons) {
    const auto tr = tryons_.find(t);
    if (tr == tryons_.end()) continue;
    cache_.erase(tr->second.cache_key);
    if (redis_ && !tr->second.job.empty()) redis_try([&] { redis_->remove(tr->second.job); });
    tryons_.erase(tr);
    queue_.erase(std::remove(queue_.begin(), queue_.end(), t), queue_.end());
    previews_.erase(t);  // a worker drawing it meanwhile finds the try-on gone and writes nothing
  }
  if (redis_) redis_try([&] { redis_->delete_body(id); });
  bodies_.erase(it);
  remove_inside(options_.data_dir / "bodies", body_dir(id));
}

bool TryOnService::delete_body(const std::string& id) {
  std::lock_guard lock(mutex_);
  if (!bodies_.count(id)) return false;
  remove_body_locked(id);
  return true;
}

TryOnService::Submitted TryOnService::submit(const std::string& body_id, const std::string& garment,
                                             const std::string& size) {
  const CatalogueEntry* entry = catalogue_.find(garment);
  if (!entry) throw RequestError(400, fmt::format("garment: no garment '{}' in the catalogue", garment));
  const auto& sizes = entry->spec.sizes;
  if (size != "auto" && std::find(sizes.begin(), sizes.end(), size) == sizes.end())
    throw RequestError(400, fmt::format("size: {} comes in {} or \"auto\"", garment, fmt::join(sizes, ", ")));
  const std::string key = body_id + "/" + garment + "/" + size;
  std::lock_guard lock(mutex_);
  const auto body = bodies_.find(body_id);
  if (body == bodies_.end()) throw RequestError(404, "no such body (it may have expired or been deleted)");
  if (const auto hit = cache_.find(key); hit != cache_.end()) return {hit->second, true};
  if ((redis_ ? redis_->queued() : queue_.size()) >= capacity_) {
    ++rejected_;
    throw RequestError(503, "every fitting room is busy; try again shortly");
  }
  TryOnRecord record;
  record.view.id = random_id();
  record.view.body = body_id;
  record.view.garment = garment;
  record.view.size_requested = size;
  record.cache_key = key;
  const std::string id = record.view.id;
  // Queued first (a Redis that fails answers 500 and leaves nothing half made), then recorded.
  if (redis_) record.job = redis_->push(RedisJob{id, body_id, garment, size, reply_list_, {}});
  tryons_[id] = std::move(record);
  cache_[key] = id;
  body->second.tryons.push_back(id);
  if (!redis_) {
    queue_.push_back(id);
    queue_cv_.notify_one();
  }
  return {id, false};
}

std::optional<TryOnView> TryOnService::tryon(const std::string& id) const {
  std::lock_guard lock(mutex_);
  const auto it = tryons_.find(id);
  if (it == tryons_.end()) return std::nullopt;
  return it->second.view;
}

std::optional<std::filesystem::path> TryOnService::tryon_file(const std::string& id, const std::string& name) {
  if (name != "dressed.glb" && name != "fit.glb" && name != "preview.png" && name != "report.json")
    return std::nullopt;
  std::shared_ptr<PendingPreview> pending;
  {
    std::lock_guard lock(mutex_);
    const auto it = tryons_.find(id);
    if (it == tryons_.end() || it->second.view.state != TryOnState::Done) return std::nullopt;
    if (const auto p = previews_.find(id); name == "preview.png" && p != previews_.end()) pending = p->second;
  }
  if (pending) draw_preview(id, pending);
  std::lock_guard lock(mutex_);
  const auto it = tryons_.find(id);  // again: it may have been deleted while its preview was drawn
  if (it == tryons_.end()) return std::nullopt;
  return body_dir(it->second.view.body) / "tryons" / id / name;
}

void TryOnService::draw_preview(const std::string& id, const std::shared_ptr<PendingPreview>& preview) {
  const std::lock_guard drawing(preview->drawing);
  if (preview->drawn) return;
  std::vector<uint8_t> png;
  try {
    png = encode_preview_png(preview->scene);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "drape serve: a try-on's preview could not be drawn: %s\n", e.what());
  }
  std::lock_guard lock(mutex_);
  preview->drawn = true;
  preview->scene = DressPreview{};
  if (const auto p = previews_.find(id); p != previews_.end() && p->second == preview) previews_.erase(p);
  const auto it = tryons_.find(id);
  if (it == tryons_.end() || png.empty()) return;  // deleted or expired meanwhile: nothing of it may stay
  try {
    write_file_atomic(body_dir(it->second.view.body) / "tryons" / id / "preview.png", png);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "drape serve: a try-on's preview could not be kept: %s\n", e.what());
  }
}

ServiceStats TryOnService::stats() const {
  std::lock_guard lock(mutex_);
  size_t queued = queue_.size(), running = running_;
  if (redis_) {
    redis_try([&] { queued = redis_->queued(); });
    running = 0;
    for (const auto& [id, t] : tryons_) running += t.view.state == TryOnState::Running;
  }
  const WarmUp* warm = warm_up_ ? warm_up_.get() : redis_workers_ ? redis_workers_->warm_up() : nullptr;
  return {queued,  running, capacity_, workers_count_, done_, failed_, rejected_, warm ? warm->left() : 0,
          warm ? warm->kept() : 0};
}

int TryOnService::retry_after_seconds() const {
  std::lock_guard lock(mutex_);
  const double mean =
      done_ + failed_ > 0 ? dress_seconds_total_ / static_cast<double>(done_ + failed_) : 10.0;
  size_t queued = queue_.size();
  if (redis_) redis_try([&] { queued = redis_->queued(); });
  const double wait =
      mean * static_cast<double>(queued + 1) / static_cast<double>(std::max<size_t>(workers_count_, 1));
  return std::clamp(static_cast<int>(std::ceil(wait)), 1, 600);
}

void TryOnService::worker_loop() {
  omp_set_num_threads(omp_threads_per_worker_);
  for (;;) {
    std::string id;
    std::shared_ptr<PendingPreview> preview;
    std::optional<WarmUp::Job> warm;
    {
      std::unique_lock lock(mutex_);
      queue_cv_.wait(lock, [&] {
        return stopping_ || !queue_.empty() || !preview_queue_.empty() || (warm_up_ && warm_up_->ready());
      });
      if (stopping_) return;
      if (!preview_queue_.empty() && (queue_.empty() || previews_.size() > kMaxPendingPreviews)) {
        id = preview_queue_.front();
        preview_queue_.pop_front();
        const auto p = previews_.find(id);
        if (p == previews_.end()) continue;  // drawn when asked for, or its body deleted
        preview = p->second;
      } else if (!queue_.empty()) {
        id = queue_.front();
        queue_.pop_front();
        ++running_;
      } else {
        // Nothing a shopper waits for: the next warm-up, one worker at a time, so that a shopper
        // who comes meanwhile finds another worker free.
        warm = warm_up_->take();
        if (!warm) continue;
      }
    }
    if (preview) {
      draw_preview(id, preview);
      continue;
    }
    if (warm) {
      warm_up_->dress(*warm);
      {
        std::lock_guard lock(mutex_);  // so that no worker misses the wake-up between its check and its wait
      }
      queue_cv_.notify_all();
      continue;
    }
    const auto start = Clock::now();
    dress_one(id);
    std::lock_guard lock(mutex_);
    --running_;
    dress_seconds_total_ += std::chrono::duration<double>(Clock::now() - start).count();
  }
}

void TryOnService::dress_one(const std::string& id) {
  std::shared_ptr<const Body> body;
  std::string garment_name, size;
  {
    std::lock_guard lock(mutex_);
    const auto it = tryons_.find(id);
    if (it == tryons_.end()) return;  // its body was deleted while it waited
    it->second.view.state = TryOnState::Running;
    body = bodies_.at(it->second.view.body).body;
    garment_name = it->second.view.garment;
    size = it->second.view.size_requested;
  }
  const auto set_progress = [&](double p) {
    std::lock_guard lock(mutex_);
    if (const auto it = tryons_.find(id); it != tryons_.end())
      it->second.view.progress = std::max(it->second.view.progress, std::clamp(p, 0.0, 0.99));
  };
  const std::filesystem::path staged = options_.data_dir / "work" / id;
  try {
    TryOnOutcome outcome = run_tryon(*body, *catalogue_.find(garment_name), size, options_.dress, set_progress,
                                     staged, &transfers_, PreviewOutput::Leave);
    finish(id, TryOnState::Done, outcome.size, {}, outcome.report, staged, std::move(outcome.preview));
    keep_transfers(transfers_, *body, outcome.passed);
  } catch (const InputError& e) {
    // A garment file the catalogue took in every size still failed to mesh or place on this body.
    finish(id, TryOnState::Failed, {},
           fmt::format("{} could not be dressed on this body: {}", garment_name, e.what()), {}, staged);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "drape serve: a try-on failed: %s\n", e.what());
    finish(id, TryOnState::Failed, {},
           "the dressing failed on the server; please try again or pick another size", {}, staged);
  }
}

void TryOnService::finish(const std::string& id, TryOnState state, const std::string& size,
                          const std::string& error, nlohmann::json report,
                          const std::filesystem::path& staged, std::optional<DressPreview> preview) {
  std::error_code ec;
  std::lock_guard lock(mutex_);
  const auto it = tryons_.find(id);
  if (it == tryons_.end()) {  // deleted or expired meanwhile: nothing of it may stay
    remove_inside(options_.data_dir / "work", staged);
    return;
  }
  TryOnView& view = it->second.view;
  if (view.state == TryOnState::Done || view.state == TryOnState::Failed) {  // answered twice: keep the first
    remove_inside(options_.data_dir / "work", staged);
    return;
  }
  if (state == TryOnState::Done) {
    const std::filesystem::path dir = body_dir(view.body) / "tryons" / id;
    std::filesystem::create_directories(dir.parent_path(), ec);
    if (!ec) std::filesystem::rename(staged, dir, ec);
    if (ec) {
      std::fprintf(stderr, "drape serve: could not keep a try-on's files: %s\n", ec.message().c_str());
      state = TryOnState::Failed;
    }
  }
  remove_inside(options_.data_dir / "work", staged);
  view.state = state;
  if (state == TryOnState::Done) {
    view.progress = 1.0;
    view.size = size;
    view.report = std::move(report);
    ++done_;
    if (preview) {
      auto pending = std::make_shared<PendingPreview>();
      pending->scene = std::move(*preview);
      previews_[id] = std::move(pending);
      preview_queue_.push_back(id);
      queue_cv_.notify_one();
    }
  } else {
    view.error = error.empty() ? "the try-on's results could not be kept on the server" : error;
    // A failed try-on is not the cached answer: asking again tries again.
    cache_.erase(it->second.cache_key);
    ++failed_;
  }
}

void TryOnService::redis_try(const std::function<void()>& action) const {
  try {
    action();
  } catch (const std::exception& e) {
    std::fprintf(stderr, "drape serve: %s\n", e.what());
  }
}

void TryOnService::collector_loop() {
  // Results come back through this server's own list; between them, the progress of the try-ons
  // in flight is read, and the jobs of workers whose lease lapsed are queued again.
  std::unique_ptr<RedisQueue> redis;
  auto last_sweep = Clock::now();
  for (;;) {
    {
      std::lock_guard lock(mutex_);
      if (stopping_) return;
    }
    try {
      if (!redis) redis = std::make_unique<RedisQueue>(options_.queue_url);
      if (const auto done = redis->pop_done(reply_list_, std::chrono::milliseconds(200))) {
        const std::optional<RedisResult> result = redis->take_result(*done);
        if (result && is_id(result->tryon)) {
          const std::filesystem::path staged = options_.data_dir / "work" / result->tryon;
          remove_inside(options_.data_dir / "work", staged);
          for (const auto& [name, bytes] : result->files)
            if (std::find(std::begin(kTryOnFiles), std::end(kTryOnFiles), name) != std::end(kTryOnFiles))
              write_file_atomic(staged / name, bytes);
          finish(result->tryon, result->done ? TryOnState::Done : TryOnState::Failed, result->size,
                 result->error, result->report, staged);
        }
      }
      std::vector<std::string> waiting;
      {
        std::lock_guard lock(mutex_);
        for (const auto& [id, t] : tryons_)
          if (t.view.state == TryOnState::Queued || t.view.state == TryOnState::Running)
            waiting.push_back(id);
      }
      for (const std::string& id : waiting) {
        const std::optional<double> p = redis->progress(id);
        if (!p) continue;
        std::lock_guard lock(mutex_);
        const auto it = tryons_.find(id);
        if (it == tryons_.end() || it->second.view.state == TryOnState::Done ||
            it->second.view.state == TryOnState::Failed)
          continue;
        it->second.view.state = TryOnState::Running;
        it->second.view.progress = std::max(it->second.view.progress, std::clamp(*p, 0.0, 0.99));
      }
      if (Clock::now() - last_sweep > options_.lease / 2) {
        last_sweep = Clock::now();
        if (const size_t requeued = redis->requeue_abandoned())
          std::fprintf(stderr, "drape serve: %zu try-on(s) of a worker that stopped answering queued again\n",
                       requeued);
      }
    } catch (const std::exception& e) {
      std::fprintf(stderr, "drape serve: shared queue: %s\n", e.what());
      redis.reset();
      std::this_thread::sleep_for(std::chrono::milliseconds(500));
    }
  }
}

void TryOnService::sweeper_loop() {
  // Checks a few times per keep period (at most every minute), so nothing outlives it by much.
  const auto interval = std::clamp<std::chrono::milliseconds>(
      options_.keep / 4, std::chrono::milliseconds(20), std::chrono::minutes(1));
  std::unique_lock lock(mutex_);
  while (!stopping_) {
    sweeper_cv_.wait_for(lock, interval, [&] { return stopping_; });
    const auto now = Clock::now();
    std::vector<std::string> expired;
    for (const auto& [id, record] : bodies_)
      if (record.expires <= now) expired.push_back(id);
    for (const std::string& id : expired) remove_body_locked(id);
  }
}

}  // namespace drape::web
