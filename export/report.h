// Reports as JSON: the validity report of a mesh, and the record of a recipe run.
#pragma once

#include <nlohmann/json.hpp>

#include "solids/check.h"

namespace lacuna {

// The check report as JSON: counts, measures, and a "checks" object of booleans with "valid" and
// "problems".
nlohmann::json check_report_json(const MeshCheckReport& report);

// A bounding box as {"min": [x, y, z], "max": [x, y, z]} in mm (null when empty).
nlohmann::json box_json(const Box3& box);

// Human-readable lines of a check report for the terminal.
std::string check_report_text(const MeshCheckReport& report);

}  // namespace lacuna
