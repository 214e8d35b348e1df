#pragma once
// The warm-up (ServeOptions::warm_up, docs/web.md): every garment of the catalogue dressed in each
// size on the default female and male bodies, the chart's sizes first, then the sizes one away from
// them, two away, ...; each drape that passes its gates kept as a start for shoppers' try-ons and
// in data_dir/starts/ (web/starts.hpp), which a server started again loads at once. One dressing
// at a time, taken by a worker that has nothing a shopper waits for. Thread-safe.
#include <cstddef>
#include <deque>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "drape/body.hpp"
#include "drape/garment_transfer.hpp"
#include "drape/web.hpp"
#include "web/catalogue.hpp"

namespace drape::web {

class WarmUp {
 public:
  // Plans the dressings and loads what an earlier run kept (said on stderr).
  WarmUp(const Catalogue& catalogue, const ServeOptions& options, GarmentTransferStore& transfers);

  struct Job {
    std::string garment, size;
    size_t body = 0;  // 0: the default female body, 1: the male
  };
  // The next dressing, when there is one and none is being dressed.
  std::optional<Job> take();
  bool ready() const;  // take() would give one
  // Dresses a taken job, keeps what passes (and saves it), and lets the next be taken.
  void dress(const Job& job);
  size_t left() const;  // dressings to go, the one being dressed included
  size_t kept() const;  // starts kept (loaded or dressed)

 private:
  std::filesystem::path file(const Job& job) const;

  const Catalogue& catalogue_;
  const ServeOptions& options_;
  GarmentTransferStore& transfers_;
  std::vector<std::shared_ptr<const Body>> bodies_;
  mutable std::mutex mutex_;
  std::deque<Job> jobs_;
  bool dressing_ = false;
  size_t kept_ = 0;
};

}  // namespace drape::web
