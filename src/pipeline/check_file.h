// A mesh file checked as a printable solid (`lacuna check`): the validity of the mesh as read, and
// optionally the printability of the solid it bounds, analysed on a level set of it.
#pragma once

#include <nlohmann/json_fwd.hpp>
#include <string>

#include "geometry.h"
#include "solids/check.h"
#include "solids/printability.h"

namespace lacuna {

struct CheckFileOptions {
  bool printability = false;       // also analyse printability (the mesh must be closed)
  double min_wall_mm = 0;          // 0: not checked
  double min_hole_mm = 0;          // 0: not checked
  Vec3d build_direction{0, 0, 1};  // pointing up from the build plate
  double critical_angle_deg = 45;  // down-facing surface flatter than this is overhang
  double voxel_size_mm = 0;        // of the analysis; 0: a quarter of the smallest size asked about (at most
                                   // the part's diagonal / 100), else the part's diagonal / 300
  uint64_t max_memory_bytes = 0;   // the analysis's budget; 0: half the memory available
};

struct FileCheck {
  std::string file;
  MeshCheckReport check;
  bool printability_analysed = false;
  double voxel_size_mm = 0;         // of the printability analysis
  PrintabilityReport printability;  // when analysed
  // A valid solid, and printable when that was analysed.
  bool valid() const { return check.valid() && (!printability_analysed || printability.ok()); }
};

// Reads and checks the mesh file (STL, OBJ, PLY, 3MF). Throws IoError or InvalidInput naming the
// file when it cannot be read, InvalidInput when printability is asked of a mesh that is not closed or
// with sizes that are not finite lengths (or a voxel size outside 0.0001 to 1000 mm), ResourceLimit
// (before allocating) when the analysis would not fit the memory budget.
FileCheck check_file(const std::string& path, const CheckFileOptions& options = {});

// The same for a mesh in memory; `label` stands for the file in the report and in messages.
FileCheck check_solid(const TriMesh& mesh, const std::string& label, const CheckFileOptions& options = {});

// The check as JSON: check_report_json() with "file", and with the printability findings both under
// "printability" and (trapped_voids, thin_walls, small_holes) at the top level.
nlohmann::json to_json(const FileCheck& check);

}  // namespace lacuna
