#include "web/warm_up.hpp"

#include <algorithm>
#include <cstdio>

#include "drape/dress.hpp"
#include "web/starts.hpp"

namespace drape::web {

WarmUp::WarmUp(const Catalogue& catalogue, const ServeOptions& options, GarmentTransferStore& transfers)
    : catalogue_(catalogue), options_(options), transfers_(transfers) {
  for (const Sex sex : {Sex::Female, Sex::Male}) bodies_.push_back(std::make_shared<const Body>(default_body(sex)));
  // Per garment and body, the size its chart picks for the body: warmed first, for every garment,
  // then the sizes one away from it, two away, and so on (the sizes shoppers like them ask for most).
  struct Plan {
    const CatalogueEntry* entry;
    size_t body;
    long chart;  // index into the entry's sizes
  };
  std::vector<Plan> plans;
  size_t most = 1;
  for (const CatalogueEntry& e : catalogue_.entries())
    for (size_t b = 0; b < bodies_.size(); ++b) {
      const std::vector<std::string>& sizes = e.spec.sizes;
      const std::string chart = choose_size(e.spec, bodies_[b]->measurements).size;
      const auto at = std::find(sizes.begin(), sizes.end(), chart);
      if (at == sizes.end()) {
        jobs_.push_back({e.name, chart, b});  // a garment of one size, not listed
        continue;
      }
      plans.push_back({&e, b, static_cast<long>(at - sizes.begin())});
      most = std::max(most, sizes.size());
    }
  for (long d = 0; d < static_cast<long>(most); ++d)
    for (const Plan& p : plans) {
      const std::vector<std::string>& sizes = p.entry->spec.sizes;
      for (const long at : {p.chart - d, p.chart + d}) {
        if (at >= 0 && at < static_cast<long>(sizes.size()))
          jobs_.push_back({p.entry->name, sizes[static_cast<size_t>(at)], p.body});
        if (d == 0) break;
      }
    }
  // Those an earlier run kept in the data folder are starts at once.
  const double edge = static_cast<double>(options_.dress.mesh.edge_length);
  std::erase_if(jobs_, [&](const Job& job) {
    std::optional<KeptStart> kept = load_start(file(job), *bodies_[job.body], edge);
    if (!kept) return false;
    if (!kept->fits) return true;  // dressed before: the size does not fit the body
    if (kept->transfer.garment != job.garment || kept->transfer.size != job.size) return false;
    transfers_.add(std::make_shared<const GarmentTransfer>(std::move(kept->transfer)));
    ++kept_;
    return true;
  });
  std::fprintf(stderr, "drape serve: warming up: %zu starts kept in %s, %zu dressings to go while no shopper waits\n",
               kept_, (options_.data_dir / "starts").string().c_str(), jobs_.size());
}

std::filesystem::path WarmUp::file(const Job& job) const {
  return start_file(options_.data_dir, job.garment, job.size, job.body == 0 ? "female" : "male");
}

bool WarmUp::ready() const {
  std::lock_guard lock(mutex_);
  return !jobs_.empty() && !dressing_;
}

std::optional<WarmUp::Job> WarmUp::take() {
  std::lock_guard lock(mutex_);
  if (jobs_.empty() || dressing_) return std::nullopt;
  Job job = jobs_.front();
  jobs_.pop_front();
  dressing_ = true;
  return job;
}

size_t WarmUp::left() const {
  std::lock_guard lock(mutex_);
  return jobs_.size() + (dressing_ ? 1u : 0u);
}

size_t WarmUp::kept() const {
  std::lock_guard lock(mutex_);
  return kept_;
}

void WarmUp::dress(const Job& job) {
  const Body& body = *bodies_.at(job.body);
  bool passed = false;
  try {
    const CatalogueEntry* entry = catalogue_.find(job.garment);
    if (!entry) throw std::invalid_argument("not in the catalogue");
    const double edge = static_cast<double>(options_.dress.mesh.edge_length);
    DressResult r = drape::dress(body, {GarmentRequest{entry->spec, job.size}}, options_.dress);
    if (r.passed()) {
      auto kept = std::make_shared<const GarmentTransfer>(make_garment_transfer(body, r.garments.at(0)));
      transfers_.add(kept);
      save_start(file(job), kept.get(), kept->body_mesh, edge);
      passed = true;
    } else {
      // A size that does not fit the body is no start for anyone's: remembered, not dressed again.
      save_start(file(job), nullptr, mesh_fingerprint(body.mesh), edge);
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "drape serve: warming up %s %s on the default %s body: %s\n", job.garment.c_str(),
                 job.size.c_str(), job.body == 0 ? "female" : "male", e.what());
  }
  std::lock_guard lock(mutex_);
  dressing_ = false;
  if (passed) ++kept_;
  if (jobs_.empty()) std::fprintf(stderr, "drape serve: warmed up: %zu starts kept for shoppers' try-ons\n", kept_);
}

}  // namespace drape::web
