#include "web/tryon_job.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "drape/files.hpp"
#include "drape/io.hpp"
#include "drape/render.hpp"
#include "drape/size_advice.hpp"

namespace drape::web {
namespace {

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
    const auto byte = [](float v) {
      return static_cast<int>(std::lround(255.0f * linear_to_srgb(std::clamp(v, 0.0f, 1.0f))));
    };
    stops.push_back(fmt::format("#{:02x}{:02x}{:02x}", byte(c.x()), byte(c.y()), byte(c.z())));
  }
  return {{"title", legend.title}, {"lo", legend.lo}, {"hi", legend.hi}, {"stops", stops}};
}

}  // namespace

TryOnOutcome run_tryon(const Body& body, const CatalogueEntry& entry, const std::string& size,
                       const DressOptions& options, const std::function<void(double)>& set_progress,
                       const std::filesystem::path& staged, GarmentTransferStore* transfers,
                       PreviewOutput preview) {
  DressOptions o = options;
  if (transfers)
    for (const std::string& s : entry.spec.sizes)
      if (size == "auto" || s == size)
        for (auto& t : transfers->for_body(entry.spec.name, s, body)) o.transfers.push_back(std::move(t));
  std::vector<DressedGarment> passed;
  const auto keep = [&](DressResult& r) {
    if (transfers && r.passed())
      for (DressedGarment& g : r.garments) passed.push_back(std::move(g));
  };
  DressResult result;
  FitAnalysis fit;
  nlohmann::json report;
  if (size == "auto") {
    SizeAdvice advice = advise_size(body, entry.spec, o, [&](size_t done, size_t total) {
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
    report = nlohmann::json::parse(report_with_fit(dress_report_json(body, trial.result, o), trial.fit));
    report["size_advice"] = nlohmann::json::parse(size_advice_json(body, advice));
    report["size_advice"]["reasons"] = advice.reasons;
    for (size_t i = 0; i < advice.sizes.size(); ++i)
      if (i != shown) keep(advice.sizes[i].result);
    result = std::move(trial.result);
    fit = std::move(trial.fit);
  } else {
    const std::vector<GarmentRequest> requests{{entry.spec, size}};
    // As `drape dress` shows it: sewing is the first half, draping the second.
    result = dress(body, requests, o, [&](const DressProgress& p) {
      const std::string_view phase(p.phase);
      const double frac =
          p.phase_limit_seconds > 0 ? std::min(1.0, p.simulated_seconds / p.phase_limit_seconds) : 0.0;
      set_progress(0.5 * ((phase.ends_with("draping") ? 1.0 : 0.0) + frac));
    });
    const std::vector<Garment> made{garment_in_size(entry.spec, result.garments.at(0).size)};
    fit = analyse_dress_fit(body, result, made);
    report = nlohmann::json::parse(report_with_fit(dress_report_json(body, result, o), fit));
  }
  // fit.glb: the garments by strain, the body by the pressure on the skin.
  report["legends"] = {{"garment", legend_json(strain_legend())},
                       {"body", legend_json(pressure_legend(fit))}};
  std::filesystem::remove_all(staged);
  write_dress_outputs(staged, body, result, o, preview);
  write_file_atomic(staged / "report.json", report.dump(2));
  write_scene(staged / "fit.glb", fit_scene(body, result, fit));
  TryOnOutcome outcome{result.garments.at(0).size, shopper_report(report), std::nullopt, {}};
  if (preview == PreviewOutput::Leave) outcome.preview = dress_preview(body, result);
  keep(result);
  outcome.passed = std::move(passed);
  return outcome;
}

void keep_transfers(GarmentTransferStore& transfers, const Body& body, const std::vector<DressedGarment>& passed) {
  for (const DressedGarment& g : passed) transfers.add(std::make_shared<GarmentTransfer>(make_garment_transfer(body, g)));
}

}  // namespace drape::web
