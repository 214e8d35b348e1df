// Pictures of the fit (drape/size_advice.hpp): fitmap.png (garments by strain as a percentage of the
// fabric's limit, the body by pressure), sizes.png (every size from the front at one scale, each
// labelled with its verdict) and fit.glb (the same colours as glTF vertex colours).
#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "drape/files.hpp"
#include "drape/io.hpp"
#include "drape/size_advice.hpp"

namespace drape {
namespace {

// Stacks pictures of the same width top to bottom.
Image stack(const std::vector<Image>& rows) {
  int width = 0, height = 0;
  for (const Image& r : rows) {
    width = std::max(width, r.width);
    height += r.height;
  }
  Image out(width, height);
  int y0 = 0;
  for (const Image& r : rows) {
    for (int y = 0; y < r.height; ++y) std::copy_n(r.pixel(0, y), 3 * static_cast<size_t>(r.width), out.pixel(0, y0 + y));
    y0 += r.height;
  }
  return out;
}

// A round upper end for the pressure scale: 1, 2 or 5 times a power of ten.
float nice_ceiling(float v) {
  if (!(v > 0)) return 1.0f;
  const float p = std::pow(10.0f, std::floor(std::log10(v)));
  for (float m : {1.0f, 2.0f, 5.0f, 10.0f})
    if (v <= m * p) return m * p;
  return 10.0f * p;
}

// A garment coloured by its strain map (in its fabric's colour when it has none: a failed run).
RenderItem strain_item(const Mesh& mesh, const GarmentFit& fit, size_t index) {
  if (fit.strain_percent.size() != mesh.positions.size()) return garment_item(mesh, index);
  return scalar_item(mesh, fit.strain_percent, strain_legend());
}

}  // namespace

Legend strain_legend() { return Legend{"strain, % of limit", ColorMap::kViridis, 0.0f, 120.0f}; }

Legend pressure_legend(const FitAnalysis& fit) {
  // The scale ends at the 99th percentile of the pressed skin, so one hot vertex does not wash out the map.
  std::vector<float> pressed;
  for (float p : fit.pressure.pressure)
    if (p > 0) pressed.push_back(p);
  float top = 1.0f;
  if (!pressed.empty()) {
    const size_t k = std::min(pressed.size() - 1, static_cast<size_t>(0.99 * static_cast<double>(pressed.size())));
    std::nth_element(pressed.begin(), pressed.begin() + static_cast<std::ptrdiff_t>(k), pressed.end());
    top = nice_ceiling(pressed[k]);
  }
  return Legend{"pressure, N/m2", ColorMap::kViridis, 0.0f, top};
}

Image fit_map_picture(const Body& body, const DressResult& result, const FitAnalysis& fit, const std::string& title) {
  std::vector<Mesh> meshes;
  for (const DressedGarment& g : result.garments) meshes.push_back(g.mesh());
  RenderOptions o;
  o.width = 1200;
  o.height = 600;

  const Legend strain = strain_legend();
  std::vector<RenderItem> top{body_item(body.mesh)};
  for (size_t i = 0; i < meshes.size() && i < fit.garments.size(); ++i)
    top.push_back(strain_item(meshes[i], fit.garments[i], i));
  RenderOptions to = o;
  to.legend = strain;
  to.title = title + ": garment strain";
  const Image upper = render_views(top, to);

  // Ease: each garment vertex's distance to the skin, in cm.
  const Legend ease{"ease, cm", ColorMap::kViridis, 0.0f, 5.0f};
  std::vector<std::vector<float>> ease_cm(meshes.size());
  std::vector<RenderItem> middle{body_item(body.mesh)};
  for (size_t i = 0; i < meshes.size() && i < fit.garments.size(); ++i) {
    const std::vector<float>& d = fit.garments[i].contacts.distance;
    if (d.size() != meshes[i].positions.size()) {
      middle.push_back(garment_item(meshes[i], i));
      continue;
    }
    for (float v : d) ease_cm[i].push_back(std::isfinite(v) ? 100.0f * std::max(0.0f, v) : ease.hi);
    middle.push_back(scalar_item(meshes[i], ease_cm[i], ease));
  }
  RenderOptions mo = o;
  mo.legend = ease;
  mo.title = "ease: garment to body";
  const Image centre = render_views(middle, mo);

  const Legend pressure = pressure_legend(fit);
  std::vector<RenderItem> bottom{scalar_item(body.mesh, fit.pressure.pressure, pressure)};
  RenderOptions bo = o;
  bo.legend = pressure;
  bo.title = fmt::format("pressure on the body (peak {:.0f} N/m2)", fit.peak_pressure_pa);
  const Image lower = render_views(bottom, bo);
  return stack({upper, centre, lower});
}

Image sizes_picture(const Body& body, const SizeAdvice& advice) {
  // One scale for all sizes, so that lengths and widths compare.
  RenderOptions o;
  o.width = 360;
  o.height = 640;
  o.views = {{"front", 0.0f}};
  o.view_labels = false;
  o.pixels_per_metre = 0.88f * static_cast<float>(o.height - 40) / std::max(1.0f, 1.15f * body.measurements.height);
  std::vector<Image> pictures;
  std::vector<std::string> captions;
  const Legend strain = strain_legend();
  for (size_t k = 0; k < advice.sizes.size(); ++k) {
    const SizeTrial& t = advice.sizes[k];
    std::vector<Mesh> meshes;
    for (const DressedGarment& g : t.result.garments) meshes.push_back(g.mesh());
    std::vector<RenderItem> items{body_item(body.mesh)};
    for (size_t i = 0; i < meshes.size() && i < t.fit.garments.size(); ++i)
      items.push_back(strain_item(meshes[i], t.fit.garments[i], i));
    RenderOptions so = o;
    if (k + 1 == advice.sizes.size()) {
      so.legend = strain;
      so.width += 110;
    }
    pictures.push_back(render_views(items, so));
    // The verdict, shortened to its first clause so it fits above the picture.
    std::string verdict = !t.closes ? std::string("does not close") : !t.stays_on ? std::string("slides off") : t.verdict;
    verdict = verdict.substr(0, verdict.find(" ("));
    verdict = verdict.substr(0, verdict.find(';'));
    const std::string prefix = fmt::format("{}{}: ", t.size, k == advice.recommended ? " (recommended)" : "");
    // About 12 pixels a character in the captions: keep within the picture's width.
    const size_t room = static_cast<size_t>(std::max(8, static_cast<int>(pictures.back().width / 12) - static_cast<int>(prefix.size())));
    if (verdict.size() > room) verdict = verdict.substr(0, room - 3) + "...";
    captions.push_back(prefix + verdict);
  }
  return compose_side_by_side(pictures, captions);
}

Scene fit_scene(const Body& body, const DressResult& result, const FitAnalysis& fit) {
  Body coloured = body;
  coloured.mesh.colors = colorize(fit.pressure.pressure, ColorMap::kViridis, 0.0f, pressure_legend(fit).hi);
  Scene scene = body_scene(coloured);
  const Legend strain = strain_legend();
  for (size_t i = 0; i < result.garments.size() && i < fit.garments.size(); ++i) {
    Mesh m = result.garments[i].mesh();
    m.name = result.garments[i].name.empty() ? "garment" : result.garments[i].name;
    if (fit.garments[i].strain_percent.size() == m.positions.size())
      m.colors = colorize(fit.garments[i].strain_percent, strain.map, strain.lo, strain.hi);
    const std::string name = m.name;
    add_mesh_node(scene, std::move(m), name);
  }
  return scene;
}

void write_fit_outputs(const std::filesystem::path& dir, const Body& body, const SizeAdvice& advice) {
  const size_t shown = advice.has_recommendation() ? advice.recommended : 0;
  const SizeTrial& t = advice.sizes.at(shown);
  const std::string report = size_advice_json(body, advice);
  const std::vector<uint8_t> fitmap =
      encode_png(fit_map_picture(body, t.result, t.fit, fmt::format("{} {}{}", advice.garment, t.size,
                                                                    advice.has_recommendation() ? " (recommended)" : "")));
  const std::vector<uint8_t> sizes = encode_png(sizes_picture(body, advice));
  const std::vector<unsigned char> glb = encode_glb(fit_scene(body, t.result, t.fit));
  write_file_atomic(dir / "report.json", report);
  write_file_atomic(dir / "fitmap.png", fitmap);
  write_file_atomic(dir / "sizes.png", sizes);
  write_file_atomic(dir / "fit.glb", glb);
}

}  // namespace drape
