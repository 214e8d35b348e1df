#pragma once
// One try-on dressed: the work a worker does, wherever it runs (a thread of the server, or a
// `drape serve --worker-only` process fed through Redis).
#include <filesystem>
#include <functional>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "drape/body.hpp"
#include "drape/dress.hpp"
#include "web/catalogue.hpp"

namespace drape::web {

struct TryOnOutcome {
  std::string size;       // the size dressed (for "auto", the recommended one)
  nlohmann::json report;  // what the page shows: passed, quality, gates, fit, size_advice, legends
  std::optional<DressPreview> preview;  // preview.png's scene, when it was left to be drawn later
  // The garments that passed their gates, for keep_transfers once the shopper is answered.
  std::vector<DressedGarment> passed;
};

// Dresses `body` in the garment at `size` (a size of it, or "auto": every size dressed and one
// recommended, docs/fit.md) and writes dressed.glb, fit.glb, preview.png and report.json into
// `dir` (made empty first); with PreviewOutput::Leave, preview.png is not drawn and the outcome
// holds its scene instead (encode_preview_png). `progress` receives 0..1. Throws InputError when the garment cannot be
// dressed on this body, std::exception for anything else. With `transfers`, each size starts from
// the same garment dressed before on the nearest body of this body's mesh, where there is one
// (drape/garment_transfer.hpp); each size that passes its gates is in the outcome's `passed`, for
// the caller to keep there for the next (keep_transfers) after answering.
TryOnOutcome run_tryon(const Body& body, const CatalogueEntry& garment, const std::string& size,
                       const DressOptions& options, const std::function<void(double)>& progress,
                       const std::filesystem::path& dir, GarmentTransferStore* transfers = nullptr,
                       PreviewOutput preview = PreviewOutput::Write);

// Keeps each of `passed`, dressed on `body`, in `transfers` as a start for the try-ons to come.
// (Making a transfer finds each particle's nearest body triangle: a few hundredths of a second the
// shopper need not wait for.)
void keep_transfers(GarmentTransferStore& transfers, const Body& body, const std::vector<DressedGarment>& passed);

// The files a finished try-on has, in the order they are written.
inline constexpr const char* kTryOnFiles[] = {"dressed.glb", "fit.glb", "preview.png", "report.json"};

}  // namespace drape::web
