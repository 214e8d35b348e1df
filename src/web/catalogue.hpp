#pragma once
// The garments a shop offers: the built-ins and the garment files of the catalogue folder, each
// with its sizes, fabric, the colour the page draws it in, and a thumbnail drawn by drape's own
// renderer (the pattern's panels laid out flat), made when first asked for and kept in memory.
#include <filesystem>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "drape/garment.hpp"

namespace drape::web {

struct CatalogueEntry {
  std::string name;  // the key in URLs: [a-z0-9_-], at most 40 characters
  std::string description;
  std::string fabric;
  std::string colour;  // sRGB "#rrggbb": the fabric's colour on the page
  bool builtin = false;
  GarmentSpec spec;
};

class Catalogue {
 public:
  // Built-ins, then every *.json and *.dxf file in `folder` (empty: none) named by its stem. A file
  // that does not load, or whose stem is not a valid name or is taken, is named on stderr and left out.
  explicit Catalogue(const std::filesystem::path& folder);

  const CatalogueEntry* find(const std::string& name) const;
  const std::vector<CatalogueEntry>& entries() const { return entries_; }
  // PNG bytes of the garment's thumbnail (its base size's panels), rendered once and kept.
  std::shared_ptr<const std::string> thumbnail(const CatalogueEntry& entry);

 private:
  std::vector<CatalogueEntry> entries_;
  std::mutex mutex_;
  std::map<std::string, std::shared_ptr<const std::string>> thumbnails_;
};

// The colour the page and the thumbnails give a fabric (sRGB "#rrggbb").
std::string fabric_colour(const std::string& fabric);

}  // namespace drape::web
