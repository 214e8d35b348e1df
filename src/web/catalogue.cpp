#include "web/catalogue.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "drape/error.hpp"
#include "drape/render.hpp"

namespace drape::web {
namespace {

bool valid_name(const std::string& name) {
  if (name.empty() || name.size() > 40) return false;
  return std::all_of(name.begin(), name.end(), [](char c) {
    return (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '_' || c == '-';
  });
}

Vec3f colour_linear(const std::string& hex) {
  const auto channel = [&](size_t at) { return std::stoi(hex.substr(at, 2), nullptr, 16); };
  return srgb8(channel(1), channel(3), channel(5));
}

// The panels of the garment's base size laid out flat in rows (a shelf packing to a roughly square
// picture), drawn from the front in the fabric's colour.
std::string render_thumbnail(const CatalogueEntry& entry) {
  const Garment garment = garment_in_size(entry.spec);
  const GarmentMesh meshed = mesh_garment(garment, MeshOptions{Mesher::grid, 0.02});
  double area = 0;
  for (const PanelMesh& p : meshed.panels) {
    const Bounds b = bounds(p.mesh.positions);
    area += static_cast<double>(b.size().x()) * static_cast<double>(b.size().y());
  }
  const float row_width = static_cast<float>(1.3 * std::sqrt(area));
  const float gap = 0.04f;
  std::vector<Mesh> panels;
  float x = 0, y = 0, row_height = 0;
  for (const PanelMesh& p : meshed.panels) {
    const Bounds b = bounds(p.mesh.positions);
    if (x > 0 && x + b.size().x() > row_width) {
      x = 0;
      y -= row_height + gap;
      row_height = 0;
    }
    Mesh m = p.mesh;
    for (Vec3f& v : m.positions) v += Vec3f(x - b.min.x(), y - b.max.y(), 0.0f);
    m.normals.clear();
    panels.push_back(std::move(m));
    x += b.size().x() + gap;
    row_height = std::max(row_height, b.size().y());
  }
  std::vector<RenderItem> items;
  for (const Mesh& m : panels) {
    RenderItem item;
    item.mesh = &m;
    item.color = colour_linear(entry.colour);
    items.push_back(item);
  }
  RenderOptions options;
  options.width = options.height = 256;
  options.views = {{"", 0.0f}};
  options.elevation_degrees = 0.0f;
  options.floor_shadow = false;
  options.ambient_occlusion = false;
  options.view_labels = false;
  options.supersample = 2;
  options.background_top = options.background_bottom = srgb8(250, 248, 245);
  const std::vector<uint8_t> png = encode_png(render_views(items, options));
  return std::string(png.begin(), png.end());
}

}  // namespace

std::string fabric_colour(const std::string& fabric) {
  // Colours a shopper associates with the cloth, dark enough to stand out against skin.
  if (fabric == "denim") return "#3b5878";
  if (fabric == "silk") return "#a8463c";
  if (fabric == "jersey") return "#5d7f5a";
  if (fabric == "wool") return "#7a5e4e";
  return "#3a5e8c";  // cotton
}

Catalogue::Catalogue(const std::filesystem::path& folder) {
  const auto add = [&](GarmentSpec spec, const std::string& name, const std::string& description,
                       bool builtin) {
    CatalogueEntry e;
    e.name = name;
    e.description = description.empty() ? spec.description : description;
    e.fabric = spec.fabric;
    e.colour = fabric_colour(spec.fabric);
    e.builtin = builtin;
    e.spec = std::move(spec);
    entries_.push_back(std::move(e));
  };
  for (const BuiltinGarment& b : builtin_garments())
    if (std::optional<GarmentSpec> spec = builtin_garment(b.name))
      add(std::move(*spec), b.name, b.description, true);
  if (folder.empty()) return;
  if (!std::filesystem::is_directory(folder)) throw InputError(folder.string(), "no such catalogue folder");
  std::vector<std::filesystem::path> files;
  for (const auto& f : std::filesystem::directory_iterator(folder)) {
    std::string ext = f.path().extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(),
                   [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    if (f.is_regular_file() && (ext == ".json" || ext == ".dxf")) files.push_back(f.path());
  }
  std::sort(files.begin(), files.end());
  for (const std::filesystem::path& file : files) {
    const std::string name = file.stem().string();
    if (!valid_name(name) || find(name)) {
      std::fprintf(stderr, "drape serve: %s: left out of the catalogue: '%s' is %s\n", file.string().c_str(),
                   name.c_str(), valid_name(name) ? "taken" : "not a name of a-z, 0-9, _ and - (at most 40)");
      continue;
    }
    try {
      GarmentSpec spec = read_garment(file);
      for (const std::string& size : spec.sizes) garment_in_size(spec, size);
      add(std::move(spec), name, {}, false);
    } catch (const InputError& e) {
      std::fprintf(stderr, "drape serve: left out of the catalogue: %s\n", e.what());
    }
  }
}

const CatalogueEntry* Catalogue::find(const std::string& name) const {
  for (const CatalogueEntry& e : entries_)
    if (e.name == name) return &e;
  return nullptr;
}

std::shared_ptr<const std::string> Catalogue::thumbnail(const CatalogueEntry& entry) {
  // One lock for all thumbnails: each is drawn once per process (a fraction of a second), then is a
  // map lookup; drawn, not read from disk, so a changed garment file never shows a stale picture.
  std::lock_guard lock(mutex_);
  if (auto it = thumbnails_.find(entry.name); it != thumbnails_.end()) return it->second;
  std::string png = render_thumbnail(entry);
  auto shared = std::make_shared<const std::string>(std::move(png));
  thumbnails_[entry.name] = shared;
  return shared;
}

}  // namespace drape::web
