#include "web/redis_workers.hpp"

#include <fmt/format.h>
#include <omp.h>

#include <algorithm>
#include <cstdio>
#include <fstream>
#include <optional>
#include <sstream>

#include "drape/error.hpp"
#include "web/bodies.hpp"
#include "web/ids.hpp"
#include "web/redis_queue.hpp"
#include "web/request_error.hpp"
#include "web/service.hpp"
#include "web/tryon_job.hpp"

namespace drape::web {
namespace {

std::string read_file(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream bytes;
  bytes << in.rdbuf();
  return bytes.str();
}

// How long a blocking take waits before looking at the stop flag again.
constexpr std::chrono::milliseconds kTakeWait{500};

}  // namespace

RedisWorkers::RedisWorkers(const ServeOptions& options, const Catalogue& catalogue, size_t count)
    : options_(options), catalogue_(catalogue) {
  RedisQueue probe(options.queue_url);  // fails here, loudly, when Redis cannot be reached
  for (size_t i = 0; i < count; ++i) {
    ids_.push_back(random_id());
    probe.renew_lease(ids_.back(), options.lease);
  }
  if (options.warm_up && count > 0) warm_up_ = std::make_unique<WarmUp>(catalogue, options, transfers_);
  heartbeat_ = std::thread([this] { heartbeat(); });
  for (const std::string& id : ids_) threads_.emplace_back([this, id] { work(id); });
}

RedisWorkers::~RedisWorkers() {
  stop();
}

void RedisWorkers::stop() {
  stopping_ = true;
  for (std::thread& t : threads_)
    if (t.joinable()) t.join();
  if (heartbeat_.joinable()) heartbeat_.join();
}

void RedisWorkers::heartbeat() {
  // Renewed three times per lease: a worker busy dressing keeps its job; a dead process's lease
  // lapses and the server hands its job to another worker.
  std::unique_ptr<RedisQueue> redis;
  while (!stopping_) {
    try {
      if (!redis) redis = std::make_unique<RedisQueue>(options_.queue_url);
      for (const std::string& id : ids_) redis->renew_lease(id, options_.lease);
    } catch (const std::exception& e) {
      std::fprintf(stderr, "drape serve: worker heartbeat: %s\n", e.what());
      redis.reset();
    }
    for (auto slept = std::chrono::milliseconds(0); slept < options_.lease / 3 && !stopping_;
         slept += std::chrono::milliseconds(50))
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
}

void RedisWorkers::work(const std::string& worker) {
  const int cores = std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
  omp_set_num_threads(std::max(1, cores / static_cast<int>(std::max<size_t>(ids_.size(), 1))));
  std::unique_ptr<RedisQueue> redis;
  while (!stopping_) {
    std::optional<RedisJob> job;
    try {
      if (!redis) redis = std::make_unique<RedisQueue>(options_.queue_url);
      job = redis->take(worker, kTakeWait);
    } catch (const std::exception& e) {
      std::fprintf(stderr, "drape serve: worker: %s\n", e.what());
      redis.reset();
      std::this_thread::sleep_for(std::chrono::seconds(1));
      continue;
    }
    if (!job) {
      // Nothing queued: the next warm-up dressing, if this process warms up and no other worker of
      // it is dressing one.
      if (warm_up_)
        if (const std::optional<WarmUp::Job> warm = warm_up_->take()) warm_up_->dress(*warm);
      continue;
    }
    ++running_;
    RedisResult result;
    result.tryon = job->tryon;
    const std::filesystem::path staged =
        options_.data_dir / "work" / (is_id(job->tryon) ? job->tryon : random_id());
    std::optional<Body> body;  // and what passed on it, kept once the result is handed back
    TryOnOutcome outcome;
    try {
      const CatalogueEntry* garment = catalogue_.find(job->garment);
      const std::optional<std::string> glb = is_id(job->body) ? redis->body(job->body) : std::nullopt;
      if (!is_id(job->tryon)) {
        result.error = "not a try-on";
      } else if (!garment) {
        result.error = fmt::format("no garment '{}' in this worker's catalogue", job->garment);
      } else if (!glb) {
        result.error = "the body is gone (deleted or expired)";
      } else {
        redis->set_progress(job->tryon, 0.0, options_.keep);
        body = body_from_upload(Upload{"body.glb", *glb, "m", "y"}, options_.max_upload_triangles);
        double shown = 0;
        outcome = run_tryon(
            *body, *garment, job->size, options_.dress,
            [&](double p) {
              // Throttled: a few hundred updates per try-on at most.
              if (p < shown + 0.01) return;
              shown = p;
              redis->set_progress(job->tryon, std::min(p, 0.99), options_.keep);
            },
            staged, &transfers_);
        result.done = true;
        result.size = outcome.size;
        result.report = outcome.report;
        for (const char* name : kTryOnFiles) result.files.emplace_back(name, read_file(staged / name));
      }
    } catch (const InputError& e) {
      result.error = fmt::format("{} could not be dressed on this body: {}", job->garment, e.what());
    } catch (const RequestError& e) {
      result.error = e.what();
    } catch (const std::exception& e) {
      std::fprintf(stderr, "drape serve: a try-on failed: %s\n", e.what());
      result.error = "the dressing failed on the server; please try again or pick another size";
    }
    remove_inside(options_.data_dir / "work", staged);
    try {
      redis->finish(worker, *job, result, options_.keep);
    } catch (const std::exception& e) {
      // The job stays in this worker's list; if the worker goes, another takes it up.
      std::fprintf(stderr, "drape serve: worker could not hand back a result: %s\n", e.what());
      redis.reset();
    }
    try {
      if (body && result.done) keep_transfers(transfers_, *body, outcome.passed);
    } catch (const std::exception& e) {
      std::fprintf(stderr, "drape serve: a try-on's drape was not kept as a start: %s\n", e.what());
    }
    --running_;
  }
}

}  // namespace drape::web

namespace drape {

struct QueueWorkers::Impl {
  ServeOptions options;
  web::Catalogue catalogue;
  web::RedisWorkers workers;
  explicit Impl(ServeOptions o)
      : options(std::move(o)),
        catalogue(options.catalogue_dir),
        workers(
            options, catalogue,
            static_cast<size_t>(options.workers > 0 ? options.workers
                                                    : std::max(1u, std::thread::hardware_concurrency()))) {}
};

QueueWorkers::QueueWorkers(ServeOptions options) {
  if (options.queue_url.empty())
    throw InputError("--queue", "a worker-only process needs the shared queue's URL");
  impl_ = std::make_unique<Impl>(std::move(options));
}

QueueWorkers::~QueueWorkers() {
  stop();
}

void QueueWorkers::stop() {
  if (impl_) impl_->workers.stop();
}

}  // namespace drape
