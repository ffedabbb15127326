#include "pipeline/check_file.h"

#include <algorithm>
#include <cmath>
#include <nlohmann/json.hpp>

#include "errors.h"
#include "export/mesh_io.h"
#include "export/report.h"
#include "solids/budget.h"
#include "solids/volume.h"
#include "util/system.h"

namespace lacuna {

FileCheck check_file(const std::string& path, const CheckFileOptions& options) {
  return check_solid(read_mesh(path), path, options);
}

FileCheck check_solid(const TriMesh& mesh, const std::string& path, const CheckFileOptions& options) {
  FileCheck result;
  result.file = path;
  result.check = check_mesh(mesh);
  if (!options.printability) return result;
  auto finite_length = [&](double v, const char* what) {
    if (!(v >= 0 && std::isfinite(v)))
      throw InvalidInput(path + ": " + what + ": expected a finite length of at least 0 mm, got " + message_number(v));
  };
  finite_length(options.min_wall_mm, "minimum wall");
  finite_length(options.min_hole_mm, "minimum hole");
  finite_length(options.voxel_size_mm, "voxel size");
  if (!result.check.closed()) throw InvalidInput(path + ": printability needs a closed mesh");
  // Resolve the smallest size asked about by four voxels (the part by 100 at least), else the part by 300.
  const double diagonal = norm(result.check.bounding_box.size());
  double h = options.voxel_size_mm;
  const char* chosen = "the voxel size";
  if (!(h > 0)) {
    double smallest = HUGE_VAL;
    for (double v : {options.min_wall_mm, options.min_hole_mm})
      if (v > 0) smallest = std::min(smallest, v / 4);
    h = std::isfinite(smallest) ? std::min(smallest, diagonal / 100) : diagonal / 300;
    chosen = "the analysis's voxel size (a quarter of the smallest size asked about)";
  }
  if (!(h >= kMinVoxelSizeMm && h <= kMaxVoxelSizeMm))
    throw InvalidInput(path + ": " + chosen + " would be " + message_number(h) + " mm; expected 0.0001 to 1000 mm");
  // The analysis's level sets, refused before they are made: the opening and closing widen the band
  // by half the sizes asked about, the closing grows the box by as much.
  const uint64_t budget = options.max_memory_bytes ? options.max_memory_bytes : available_memory_bytes() / 2;
  const VolumeOptions plain{h, 3.0};
  // (An erosion deeper than half the part's smallest side is not made: everything is a thin wall.)
  const Vec3d size = result.check.bounding_box.size();
  const double hole_reach = 0.5 * options.min_hole_mm;
  const double reach = std::max(std::min(0.5 * options.min_wall_mm, 0.5 * std::min({size.x, size.y, size.z})), hole_reach);
  VolumeOptions wide = plain;
  wide.half_band_voxels += reach / h;
  Box3 box = result.check.bounding_box;
  box.min -= Vec3d{hole_reach, hole_reach, hole_reach};
  box.max += Vec3d{hole_reach, hole_reach, hole_reach};
  const double area = surface_area(mesh);
  const MemoryEstimate grids = estimate_from_voxels(band_voxels(area, box, wide), wide);
  const MemoryEstimate surface = estimate_from_voxels(band_voxels(area, result.check.bounding_box, plain), plain);
  const double need = 3.0 * double(grids.grid_bytes) + double(surface.mesh_bytes) + double(current_memory_bytes());
  if (!(need <= double(budget)))
    throw ResourceLimit(path + ": the printability analysis at a voxel size of " + message_number(h) + " mm needs about " +
                        (need < 1e18 ? format_bytes(uint64_t(need)) : std::string("more than 1000000000 GB")) +
                        ", more than the budget of " + format_bytes(budget) +
                        "; use a larger voxel size or a smaller minimum hole");
  PrintabilityOptions analysis;
  analysis.min_wall_mm = options.min_wall_mm;
  analysis.min_hole_mm = options.min_hole_mm;
  analysis.build_direction = options.build_direction;
  analysis.critical_angle_deg = options.critical_angle_deg;
  result.printability = analyze_printability(mesh_to_volume(mesh, VolumeOptions{h, 3.0}), analysis);
  result.printability_analysed = true;
  result.voxel_size_mm = h;
  return result;
}

nlohmann::json to_json(const FileCheck& c) {
  nlohmann::json j = check_report_json(c.check);
  j["file"] = c.file;
  if (!c.printability_analysed) return j;
  const PrintabilityReport& pr = c.printability;
  j["printability"] = {{"voxel_size_mm", c.voxel_size_mm},
                       {"trapped_voids", nlohmann::json::array()},
                       {"thin_walls", nlohmann::json::array()},
                       {"small_holes", nlohmann::json::array()},
                       {"overhang_area_mm2", pr.overhang_area_mm2},
                       {"down_facing_area_mm2", pr.down_facing_area_mm2}};
  auto list = [&](const char* key, const std::vector<PrintFeature>& features) {
    for (const PrintFeature& f : features)
      j["printability"][key].push_back(
          {{"volume_mm3", f.volume_mm3}, {"location", {f.location_mm.x, f.location_mm.y, f.location_mm.z}}});
  };
  list("trapped_voids", pr.trapped_voids);
  list("thin_walls", pr.thin_walls);
  list("small_holes", pr.small_holes);
  // Copies at the top level, where scripts look first.
  j["trapped_voids"] = j["printability"]["trapped_voids"];
  j["thin_walls"] = j["printability"]["thin_walls"];
  j["small_holes"] = j["printability"]["small_holes"];
  return j;
}

}  // namespace lacuna
