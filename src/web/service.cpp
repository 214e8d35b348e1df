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
#include "web/request_error.hpp"

namespace drape::web {
namespace {

using Clock = std::chrono::steady_clock;

// What the page shows of a dressing's report.json: the gates, the quality and the fit in words.
nlohmann::json shopper_report(const nlohmann::json& full) {
  nlohmann::json out = nlohmann::json::object();
  for (const char* key : {"quality", "gates", "fit", "size_advice", "legends"})
    if (full.contains(key)) out[key] = full[key];
  out["passed"] = full.contains("gates") && full["gates"].value("passed", false);
  if (full.contains("garments") && !full["garments"].empty())
    out["size_reason"] = full["garments"][0].value("size_reason", "");
  return out;
}

// A fit map's colour scale as the page draws it: sRGB stops of drape's own colour map, ends and title.
nlohmann::json legend_json(const Legend& legend) {
  nlohmann::json stops = nlohmann::json::array();
  for (int i = 0; i <= 8; ++i) {
    const Vec3f c = colormap(legend.map, static_cast<float>(i) / 8.0f);
    const auto byte = [](float v) { return static_cast<int>(std::lround(255.0f * linear_to_srgb(std::clamp(v, 0.0f, 1.0f)))); };
    stops.push_back(fmt::format("#{:02x}{:02x}{:02x}", byte(c.x()), byte(c.y()), byte(c.z())));
  }
  return {{"title", legend.title}, {"lo", legend.lo}, {"hi", legend.hi}, {"stops", stops}};
}

// Removes what a previous run left: the bodies it held in memory are gone, so their files could
// never be reached or deleted through the API again.
void clear_unreachable(const std::filesystem::path& dir) {
  std::error_code ec;
  if (!std::filesystem::is_directory(dir, ec)) return;
  for (const auto& entry : std::filesystem::directory_iterator(dir, ec))
    if (is_id(entry.path().filename().string())) std::filesystem::remove_all(entry.path(), ec);
}

}  // namespace

const char* to_string(TryOnState state) {
  switch (state) {
    case TryOnState::Queued: return "queued";
    case TryOnState::Running: return "running";
    case TryOnState::Done: return "done";
    case TryOnState::Failed: return "failed";
  }
  return "failed";
}

TryOnService::TryOnService(const ServeOptions& options, Catalogue& catalogue)
    : options_(options), catalogue_(catalogue) {
  const int cores = std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
  workers_count_ = static_cast<size_t>(options.workers > 0 ? options.workers : cores);
  capacity_ = options.queue_capacity > 0 ? options.queue_capacity : 4 * workers_count_;
  // The cores are shared between the workers: each dressing's OpenMP loops get the rest.
  omp_threads_per_worker_ = std::max(1, cores / static_cast<int>(workers_count_));
  std::filesystem::create_directories(options_.data_dir / "bodies");
  clear_unreachable(options_.data_dir / "bodies");
  clear_unreachable(options_.data_dir / "work");
  for (size_t i = 0; i < workers_count_; ++i) workers_.emplace_back([this] { worker_loop(); });
  sweeper_ = std::thread([this] { sweeper_loop(); });
}

TryOnService::~TryOnService() { stop(); }

void TryOnService::stop() {
  {
    std::lock_guard lock(mutex_);
    if (stopping_ && workers_.empty()) return;
    stopping_ = true;
  }
  queue_cv_.notify_all();
  sweeper_cv_.notify_all();
  for (std::thread& t : workers_) t.join();
  workers_.clear();
  if (sweeper_.joinable()) sweeper_.join();
  // Bodies live in this process's memory: once it stops, their files could never be reached or
  // deleted through the API, so they go now.
  std::lock_guard lock(mutex_);
  while (!bodies_.empty()) remove_body_locked(bodies_.begin()->first);
}

std::filesystem::path TryOnService::body_dir(const std::string& id) const {
  return options_.data_dir / "bodies" / id;
}

BodyView TryOnService::add_body(Body body) {
  BodyView view;
  view.id = random_id();
  view.measurements = measurements_json(body.measurements);
  view.height_m = std::round(1e4 * static_cast<double>(body.measurements.height)) / 1e4;
  // The file is written before the id is handed out, so a body that exists has its file.
  write_scene(body_dir(view.id) / "body.glb", body_scene(body));
  std::lock_guard lock(mutex_);
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

std::optional<std::filesystem::path> TryOnService::body_file(const std::string& id, const std::string& name) const {
  if (name != "body.glb") return std::nullopt;
  std::lock_guard lock(mutex_);
  if (!is_id(id) || !bodies_.count(id)) return std::nullopt;
  return body_dir(id) / name;
}

void TryOnService::remove_body_locked(const std::string& id) {
  const auto it = bodies_.find(id);
  if (it == bodies_.end()) return;
  for (const std::string& t : it->second.tryons) {
    const auto tr = tryons_.find(t);
    if (tr == tryons_.end()) continue;
    cache_.erase(tr->second.cache_key);
    tryons_.erase(tr);
    queue_.erase(std::remove(queue_.begin(), queue_.end(), t), queue_.end());
  }
  bodies_.erase(it);
  std::error_code ec;
  std::filesystem::remove_all(body_dir(id), ec);
  if (ec) std::fprintf(stderr, "drape serve: could not remove a body's files: %s\n", ec.message().c_str());
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
  if (queue_.size() >= capacity_) {
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
  tryons_[id] = std::move(record);
  cache_[key] = id;
  body->second.tryons.push_back(id);
  queue_.push_back(id);
  queue_cv_.notify_one();
  return {id, false};
}

std::optional<TryOnView> TryOnService::tryon(const std::string& id) const {
  std::lock_guard lock(mutex_);
  const auto it = tryons_.find(id);
  if (it == tryons_.end()) return std::nullopt;
  return it->second.view;
}

std::optional<std::filesystem::path> TryOnService::tryon_file(const std::string& id, const std::string& name) const {
  if (name != "dressed.glb" && name != "fit.glb" && name != "preview.png" && name != "report.json") return std::nullopt;
  std::lock_guard lock(mutex_);
  const auto it = tryons_.find(id);
  if (it == tryons_.end() || it->second.view.state != TryOnState::Done) return std::nullopt;
  return body_dir(it->second.view.body) / "tryons" / id / name;
}

ServiceStats TryOnService::stats() const {
  std::lock_guard lock(mutex_);
  return {queue_.size(), running_, capacity_, workers_count_, done_, failed_, rejected_};
}

int TryOnService::retry_after_seconds() const {
  std::lock_guard lock(mutex_);
  const double mean = done_ + failed_ > 0 ? dress_seconds_total_ / static_cast<double>(done_ + failed_) : 10.0;
  const double wait = mean * static_cast<double>(queue_.size() + 1) / static_cast<double>(workers_count_);
  return std::clamp(static_cast<int>(std::ceil(wait)), 1, 600);
}

void TryOnService::worker_loop() {
  omp_set_num_threads(omp_threads_per_worker_);
  for (;;) {
    std::string id;
    {
      std::unique_lock lock(mutex_);
      queue_cv_.wait(lock, [&] { return stopping_ || !queue_.empty(); });
      if (stopping_) return;
      id = queue_.front();
      queue_.pop_front();
      ++running_;
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
    const CatalogueEntry& entry = *catalogue_.find(garment_name);
    const DressOptions& o = options_.dress;
    DressResult result;
    FitAnalysis fit;
    nlohmann::json report;
    if (size == "auto") {
      SizeAdvice advice = advise_size(*body, entry.spec, o, [&](size_t done, size_t total) {
        set_progress(static_cast<double>(done) / static_cast<double>(std::max<size_t>(total, 1)));
      });
      // The recommended size is shown; when none closes and stays on, the chart's (else the base
      // size), and the report says that none fits.
      size_t shown = advice.recommended;
      if (!advice.has_recommendation()) {
        shown = 0;
        for (size_t i = 0; i < advice.sizes.size(); ++i)
          if (advice.sizes[i].size == advice.chart_size) shown = i;
      }
      SizeTrial& trial = advice.sizes.at(shown);
      report = nlohmann::json::parse(report_with_fit(dress_report_json(*body, trial.result, o), trial.fit));
      report["size_advice"] = nlohmann::json::parse(size_advice_json(*body, advice));
      report["size_advice"]["reasons"] = advice.reasons;
      result = std::move(trial.result);
      fit = std::move(trial.fit);
    } else {
      const std::vector<GarmentRequest> requests{{entry.spec, size}};
      // As `drape dress` shows it: sewing is the first half, draping the second.
      result = dress(*body, requests, o, [&](const DressProgress& p) {
        const std::string_view phase(p.phase);
        const double frac = p.phase_limit_seconds > 0 ? std::min(1.0, p.simulated_seconds / p.phase_limit_seconds) : 0.0;
        set_progress(0.5 * ((phase.ends_with("draping") ? 1.0 : 0.0) + frac));
      });
      const std::vector<Garment> made{garment_in_size(entry.spec, result.garments.at(0).size)};
      fit = analyse_dress_fit(*body, result, made);
      report = nlohmann::json::parse(report_with_fit(dress_report_json(*body, result, o), fit));
    }
    // fit.glb: the garments by strain, the body by the pressure on the skin.
    report["legends"] = {{"garment", legend_json(strain_legend())}, {"body", legend_json(pressure_legend(fit))}};
    std::filesystem::remove_all(staged);
    write_dress_outputs(staged, *body, result, o);
    write_file_atomic(staged / "report.json", report.dump(2));
    write_scene(staged / "fit.glb", fit_scene(*body, result, fit));
    finish(id, TryOnState::Done, result.garments.at(0).size, {}, shopper_report(report), staged);
  } catch (const InputError& e) {
    // A garment file the catalogue took in every size still failed to mesh or place on this body.
    finish(id, TryOnState::Failed, {}, fmt::format("{} could not be dressed on this body: {}", garment_name, e.what()),
           {}, staged);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "drape serve: a try-on failed: %s\n", e.what());
    finish(id, TryOnState::Failed, {}, "the dressing failed on the server; please try again or pick another size", {},
           staged);
  }
}

void TryOnService::finish(const std::string& id, TryOnState state, const std::string& size, const std::string& error,
                          nlohmann::json report, const std::filesystem::path& staged) {
  std::error_code ec;
  std::lock_guard lock(mutex_);
  const auto it = tryons_.find(id);
  if (it == tryons_.end()) {  // deleted or expired meanwhile: nothing of it may stay
    std::filesystem::remove_all(staged, ec);
    return;
  }
  TryOnView& view = it->second.view;
  if (state == TryOnState::Done) {
    const std::filesystem::path dir = body_dir(view.body) / "tryons" / id;
    std::filesystem::create_directories(dir.parent_path(), ec);
    if (!ec) std::filesystem::rename(staged, dir, ec);
    if (ec) {
      std::fprintf(stderr, "drape serve: could not keep a try-on's files: %s\n", ec.message().c_str());
      state = TryOnState::Failed;
    }
  }
  std::filesystem::remove_all(staged, ec);
  view.state = state;
  if (state == TryOnState::Done) {
    view.progress = 1.0;
    view.size = size;
    view.report = std::move(report);
    ++done_;
  } else {
    view.error = error.empty() ? "the try-on's results could not be kept on the server" : error;
    // A failed try-on is not the cached answer: asking again tries again.
    cache_.erase(it->second.cache_key);
    ++failed_;
  }
}

void TryOnService::sweeper_loop() {
  // Checks a few times per keep period (at most every minute), so nothing outlives it by much.
  const auto interval = std::clamp<std::chrono::milliseconds>(options_.keep / 4, std::chrono::milliseconds(20),
                                                              std::chrono::minutes(1));
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
