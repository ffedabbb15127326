#include "pipeline/check_file.h"

#include <algorithm>
#include <cmath>
#include <nlohmann/json.hpp>

#include "errors.h"
#include "export/mesh_io.h"
#include "export/report.h"
#include "solids/volume.h"

namespace lacuna {

FileCheck check_file(const std::string& path, const CheckFileOptions& options) {
  return check_solid(read_mesh(path), path, options);
}

FileCheck check_solid(const TriMesh& mesh, const std::string& path, const CheckFileOptions& options) {
  FileCheck result;
  result.file = path;
  result.check = check_mesh(mesh);
  if (!options.printability) return result;
  if (!result.check.closed()) throw InvalidInput(path + ": printability needs a closed mesh");
  // Resolve the smallest size asked about by four voxels, else the part by 300.
  double h = options.voxel_size_mm;
  if (!(h > 0)) {
    double smallest = HUGE_VAL;
    for (double v : {options.min_wall_mm, options.min_hole_mm})
      if (v > 0) smallest = std::min(smallest, v / 4);
    h = std::isfinite(smallest) ? smallest : norm(result.check.bounding_box.size()) / 300;
  }
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
