#pragma once
// DESIGN.md's `quality` object as JSON, exactly its nine keys, non-finite numbers as null (JSON has
// no NaN): report.json's, and each animation frame's.
#include <nlohmann/json.hpp>

#include "drape/fit.hpp"

namespace drape {

nlohmann::ordered_json quality_json(const FitQuality& quality);

}  // namespace drape
