#include "pipeline/fea_output.h"

#include <cmath>
#include <nlohmann/json.hpp>

#include "errors.h"
#include "export/fea.h"
#include "export/mesh_io.h"
#include "export/output_files.h"
#include "export/report.h"
#include "solids/simplify.h"
#include "util/system.h"

namespace lacuna {

FeaResult make_fea_mesh(const TriMesh& surface, const FeaSettings& settings, const std::vector<Vec3d>& region_seeds) {
  FeaResult result;
  TetCheck& r = result.check;
  r.surface = check_mesh(surface);
  if (!r.surface.valid()) {
    for (const std::string& p : r.surface.problems()) r.problems.push_back("surface: " + p);
    return result;
  }
  TetOptions options;
  options.max_radius_edge_ratio = settings.quality;
  options.min_dihedral_deg = settings.min_dihedral_deg;
  options.max_tet_volume_mm3 = settings.max_tet_volume_mm3;
  options.preserve_surface = settings.preserve_surface;
  options.time_limit_s = settings.time_limit_s;
  options.max_memory_bytes = settings.max_memory_bytes ? settings.max_memory_bytes : available_memory_bytes() / 2;
  result.mesh = tetrahedralize(surface, options, region_seeds);
  r.report = tet_report(result.mesh);
  if (r.report.tets == 0) r.problems.push_back("TetGen produced no tetrahedra");
  if (r.report.inverted_tets) r.problems.push_back(std::to_string(r.report.inverted_tets) + " tetrahedra have no positive volume");
  // A preserved surface bounds exactly the same volume; when TetGen may refine, it can also
  // re-triangulate facets it takes as coplanar (its -T tolerance), which moves the volume by a few
  // parts per million.
  const double expected = r.surface.volume_mm3;
  const bool preserved = options.preserve_surface && options.max_radius_edge_ratio == 0 && options.max_tet_volume_mm3 == 0;
  const double tolerance = preserved ? 1e-6 : 1e-5;
  if (std::fabs(r.report.volume_mm3 - expected) > tolerance * expected)
    r.problems.push_back("the tetrahedra's volume " + message_number(r.report.volume_mm3) +
                         " mm3 differs from the surface's " + message_number(expected) + " mm3");
  if (settings.max_tet_volume_mm3 > 0 && r.report.max_tet_volume_mm3 > settings.max_tet_volume_mm3 * (1 + 1e-9))
    r.problems.push_back("a tetrahedron exceeds the volume bound");
  return result;
}

TetCheck write_tetrahedra(const std::string& mesh_path, const std::string& output_path, const FeaSettings& settings,
                          double simplify_mm) {
  TriMesh surface = read_mesh(mesh_path);
  if (simplify_mm > 0) {
    SimplifyOptions simplify;
    simplify.max_deviation_mm = simplify_mm;
    surface = simplify_mesh(surface, simplify);
  }
  return write_tetrahedra(surface, output_path, settings, std::max(0.0, simplify_mm));
}

TetCheck write_tetrahedra(const TriMesh& surface, const std::string& output_path, const FeaSettings& settings,
                          double deviation_mm) {
  FeaResult fea = make_fea_mesh(surface, settings);
  if (!fea.check.valid()) return fea.check;
  OutputTransaction transaction;
  try {
    write_fea(transaction.stage(output_path), fea_format_from_path(output_path), fea.mesh, fea_write_options(settings, deviation_mm));
    transaction.commit();
  } catch (const IoError& e) {
    // Named as the file asked for, not its hidden temporary.
    throw IoError(transaction.with_final_names(e.what()));
  }
  return fea.check;
}

FeaWriteOptions fea_write_options(const FeaSettings& settings, double deviation_mm) {
  FeaWriteOptions w;
  w.msh_version_2 = settings.msh_version_2;
  w.quadratic = settings.quadratic;
  w.node_set_tolerance_mm = deviation_mm;
  return w;
}

nlohmann::json fea_report_json(const TetCheck& r) {
  nlohmann::json histogram = nlohmann::json::array();
  for (size_t i = 0; i < r.report.ratio_counts.size(); ++i)
    histogram.push_back({{"below", i < r.report.ratio_bins.size() ? nlohmann::json(r.report.ratio_bins[i]) : nlohmann::json(nullptr)},
                         {"tets", r.report.ratio_counts[i]}});
  return {{"nodes", r.report.nodes},
          {"tets", r.report.tets},
          {"volume_mm3", r.report.volume_mm3},
          {"surface_volume_mm3", r.surface.volume_mm3},
          {"surface_triangles", r.surface.triangles},
          {"min_tet_volume_mm3", r.report.min_tet_volume_mm3},
          {"max_tet_volume_mm3", r.report.max_tet_volume_mm3},
          {"min_dihedral_deg", r.report.min_dihedral_deg},
          {"max_dihedral_deg", r.report.max_dihedral_deg},
          {"radius_edge_ratio_histogram", histogram},
          {"components", r.surface.components},
          {"genus", r.surface.genus},
          {"checks", {{"valid", r.valid()}, {"problems", r.problems}}}};
}

}  // namespace lacuna
