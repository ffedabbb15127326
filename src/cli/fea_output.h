// Tetrahedral outputs: a checked surface into a verified tetrahedral mesh, for recipes and for
// `lacuna fea`.
#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "geometry.h"
#include "recipe/recipe.h"
#include "solids/check.h"
#include "solids/tetrahedralize.h"

namespace lacuna {

struct FeaResult {
  MeshCheckReport surface;       // the surface handed to TetGen
  TetMesh mesh;
  TetReport report;
  std::vector<std::string> problems;  // empty when the surface and the tetrahedra passed
  bool valid() const { return problems.empty(); }
};

// Checks the surface (it must be a valid solid), tetrahedralizes it with the settings, and
// verifies the tetrahedra: every one positive, their volume equal to the surface's within 1e-6
// (1e-5 when TetGen was allowed to refine), none above the volume bound.
FeaResult make_fea_mesh(const TriMesh& surface, const FeaSettings& settings,
                        const std::vector<Vec3d>& region_seeds = {});

// The report entry of a tetrahedral output.
nlohmann::json fea_report_json(const FeaResult& result);

}  // namespace lacuna
