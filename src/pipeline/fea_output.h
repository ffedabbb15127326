// Tetrahedral outputs: a checked surface into a verified tetrahedral mesh, for recipes and for
// `lacuna fea`.
#pragma once

#include <nlohmann/json_fwd.hpp>
#include <string>
#include <vector>

#include "export/fea.h"
#include "geometry.h"
#include "recipe/recipe.h"
#include "solids/check.h"
#include "solids/tetrahedralize.h"

namespace lacuna {

// What verifying a tetrahedral mesh and its surface found.
struct TetCheck {
  MeshCheckReport surface;            // the surface handed to TetGen
  TetReport report;                   // the tetrahedra
  std::vector<std::string> problems;  // empty when the surface and the tetrahedra passed
  bool valid() const { return problems.empty(); }
};

struct FeaResult {
  TetMesh mesh;
  TetCheck check;
};

// Checks the surface (it must be a valid solid), tetrahedralizes it with the settings, and
// verifies the tetrahedra: every one positive, their volume equal to the surface's within 1e-6
// (1e-5 when TetGen was allowed to refine), none above the volume bound.
FeaResult make_fea_mesh(const TriMesh& surface, const FeaSettings& settings,
                        const std::vector<Vec3d>& region_seeds = {});

// Tetrahedralizes the closed mesh in the file `mesh_path` (simplified with guards to `simplify_mm`
// first when it is > 0) and, when the surface and the tetrahedra pass their checks, writes them to
// `output_path` (the format from its extension) through a temporary file; nothing is written otherwise.
TetCheck write_tetrahedra(const std::string& mesh_path, const std::string& output_path, const FeaSettings& settings,
                          double simplify_mm = 0);

// The same for a surface in memory (not simplified here; `deviation_mm`: how far it was simplified,
// which the node sets allow for).
TetCheck write_tetrahedra(const TriMesh& surface, const std::string& output_path, const FeaSettings& settings,
                          double deviation_mm = 0);

// How a tetrahedral output's settings ask for it to be written (Gmsh version, element order), for
// a surface simplified to `deviation_mm` (the node sets take in the nodes that near the box's planes).
FeaWriteOptions fea_write_options(const FeaSettings& settings, double deviation_mm);

// The report entry of a tetrahedral output.
nlohmann::json fea_report_json(const TetCheck& check);

}  // namespace lacuna
