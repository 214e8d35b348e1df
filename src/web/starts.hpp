#pragma once
// The warm-up's drapes kept in the data folder (data_dir/starts/), so that a server started again
// has its starts at once instead of dressing the catalogue anew. Each is a garment in one size as
// dressed on a default body (no shopper's data): the garment transfer (drape/garment_transfer.hpp)
// as JSON, with the drape version and the cloth's edge length it was dressed with; a file of
// another version, edge length or body mesh is left unused and dressed again.
#include <filesystem>
#include <optional>
#include <string>

#include "drape/body.hpp"
#include "drape/garment_transfer.hpp"

namespace drape::web {

// data_dir/starts/GARMENT-SIZE-BODY.json, the size hex-encoded (any text a garment file names).
std::filesystem::path start_file(const std::filesystem::path& data_dir, const std::string& garment,
                                 const std::string& size, const std::string& body_name);

// Writes the start `t` (made on `body` from a garment dressed at `edge_m`) to `file` atomically; or,
// with `t` null, that the size did not pass its gates on the body (a warm-up not to repeat).
void save_start(const std::filesystem::path& file, const GarmentTransfer* t, uint64_t body_mesh, double edge_m);

// What `file` keeps for `body`: a start (its measurements are the body's), or that the size does
// not fit the body (`fits` false). nullopt when there is no file, or it is of another drape
// version, edge length or body mesh, or does not read (named on stderr): dressed again and written
// anew.
struct KeptStart {
  bool fits = false;
  GarmentTransfer transfer;  // when it fits
};
std::optional<KeptStart> load_start(const std::filesystem::path& file, const Body& body, double edge_m);

}  // namespace drape::web
