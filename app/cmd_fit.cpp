// `drape fit`: dresses a body in every size of a garment (two sizes at a time), judges each by the
// quality gates and the fit per region, recommends one and writes DIR/report.json, fitmap.png,
// sizes.png and fit.glb (DESIGN.md, docs/fit.md). Exit 2 on bad input (nothing written), 3 when no
// size closes, stays on and passes every gate (outputs written; report.json says why).
#include <fmt/format.h>
#include <omp.h>

#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>

#include "commands.hpp"
#include "drape/error.hpp"
#include "drape/size_advice.hpp"

namespace drape::app {
namespace {

struct FitArgs {
  std::string body = "female";
  std::string measurements;
  std::string garment;
  std::string out = "out";
  std::string solver = std::string(to_string(DressOptions{}.solver));
  int threads = 0;
  LoadOptions load;
};

void run_fit(const FitArgs& a) {
  // Everything the user gave is checked before the (long) dressing starts.
  const GarmentSpec spec = load_garment(a.garment.empty() ? default_garment_name() : a.garment);
  for (const std::string& size : spec.sizes) garment_in_size(spec, size);
  const Body body = load_command_body(a.body, a.measurements, a.load);
  if (a.threads > 0) omp_set_num_threads(a.threads);

  std::fprintf(stderr, "fitting %s in %zu sizes on a %.2f m body (bust %.3f, waist %.3f, hips %.3f m)\n",
               spec.name.c_str(), spec.sizes.size(), static_cast<double>(body.measurements.height),
               static_cast<double>(body.measurements.bust), static_cast<double>(body.measurements.waist),
               static_cast<double>(body.measurements.hips));
  DressOptions options;
  options.solver = a.solver == "explicit" ? Solver::Explicit : Solver::Implicit;
  const SizeAdvice advice = advise_size(body, spec, options, [](size_t done, size_t total) {
    std::fprintf(stderr, "  %zu of %zu sizes dressed\n", done, total);
  });
  write_fit_outputs(a.out, body, advice);

  for (const SizeTrial& t : advice.sizes) {
    std::fprintf(stderr, "%-4s %s %s\n", t.size.c_str(), t.result.passed() ? "passes every check," : "fails a check,   ",
                 t.verdict.c_str());
    std::string pattern;
    for (const RegionFit& r : t.pattern)
      if (r.girth) pattern += fmt::format("{}{} {:+.1f} cm ({})", pattern.empty() ? "" : ", ", r.region, 100 * r.ease_m, to_string(r.verdict));
    if (!pattern.empty()) std::fprintf(stderr, "     on the pattern, before draping: %s\n", pattern.c_str());
    if (advice.chart_from_pattern) {
      std::string cut_for;
      for (const PatternGirth& g : t.pattern_girths)
        cut_for += fmt::format("{}{} {:.2f} m ({:.2f} m at {}, less {:.0f} cm ease)", cut_for.empty() ? "" : ", ", g.key,
                               g.body_m(), g.girth_m, g.line, 100 * g.ease_m);
      if (!cut_for.empty()) std::fprintf(stderr, "     cut for a body with %s\n", cut_for.c_str());
    }
  }
  if (advice.chart_from_pattern)
    std::fprintf(stderr, "%s has no size chart: its pattern made one (girths at its own lines less its ease)\n", spec.name.c_str());
  if (advice.has_recommendation()) std::fprintf(stderr, "\n%s", fit_table(advice.sizes[advice.recommended].fit).c_str());
  std::fprintf(stderr, "\n");
  for (const std::string& line : advice.reasons) std::fprintf(stderr, "%s\n", line.c_str());
  std::fprintf(stderr, "wrote %s/report.json, fitmap.png, sizes.png, fit.glb\n", a.out.c_str());
  if (!advice.has_recommendation() || !advice.sizes[advice.recommended].result.passed()) {
    std::fprintf(stderr, "drape: fit: no size of %s closes, stays on and passes every check on this body\n",
                 spec.name.c_str());
    std::exit(kExitQualityGate);
  }
}

}  // namespace

void add_fit_command(CLI::App& app) {
  auto args = std::make_shared<FitArgs>();
  CLI::App* cmd = app.add_subcommand(
      "fit", "Dress a body in every size of a garment, map where it pulls and where it is loose, recommend a size");
  cmd->add_option("--body", args->body, "female, male (built-in bodies) or a body file (OBJ, PLY, glTF, GLB)")
      ->capture_default_str();
  cmd->add_option("--measurements", args->measurements,
                  "build the body from measurements in metres, e.g. height=1.70,bust=0.92,waist=0.74,hips=0.98");
  cmd->add_option("--garment", args->garment,
                  "built-in garment name (see `drape garments`) or garment file; default: the shirt");
  cmd->add_option("--solver", args->solver,
                  "implicit (Newton on the incremental potential) or explicit (the paper's explicit Euler with "
                  "velocity modification); see drape dress --help")
      ->capture_default_str()->check(CLI::IsMember({"implicit", "explicit"}));
  cmd->add_option("--threads", args->threads, "OpenMP threads (0: all cores); sizes are dressed two at a time")
      ->check(CLI::Range(0, 1024));
  cmd->add_option("--out", args->out, "output directory (report.json, fitmap.png, sizes.png, fit.glb)")
      ->capture_default_str();
  add_load_options(*cmd, args->load);
  cmd->callback([args] { run_fit(*args); });
}

}  // namespace drape::app
