#include "export/report.h"

#include <cstdio>
#include <sstream>

namespace lacuna {

nlohmann::json box_json(const Box3& box) {
  if (box.empty()) return nullptr;
  return {{"min", {box.min.x, box.min.y, box.min.z}}, {"max", {box.max.x, box.max.y, box.max.z}}};
}

nlohmann::json check_report_json(const MeshCheckReport& r) {
  nlohmann::json checks = {
      {"valid", r.valid()},
      {"closed", r.closed()},
      {"edge_manifold", r.non_manifold_edges == 0},
      {"vertex_manifold", r.vertex_manifold_checked && r.non_manifold_vertices == 0},
      {"consistently_oriented", r.misoriented_edges == 0},
      {"outward_oriented", r.outward()},
      {"self_intersection_free", r.self_intersections_checked && !r.self_intersecting},
      {"self_intersections_checked", r.self_intersections_checked},
      {"no_degenerate_faces", r.degenerate_faces == 0},
      {"finite_coordinates", r.non_finite_vertices == 0},
      {"positive_volume", r.volume_mm3 > 0},
      {"problems", r.problems()},
  };
  return {
      {"triangles", r.triangles},
      {"vertices", r.vertices},
      {"edges", r.edges},
      {"volume_mm3", r.volume_mm3},
      {"surface_area_mm2", r.area_mm2},
      {"bounding_box_mm", box_json(r.bounding_box)},
      {"components", r.components},
      {"genus", r.genus},
      {"boundary_edges", r.boundary_edges},
      {"non_manifold_edges", r.non_manifold_edges},
      {"non_manifold_vertices", r.non_manifold_vertices},
      {"misoriented_edges", r.misoriented_edges},
      {"inward_components", r.inward_components},
      {"degenerate_faces", r.degenerate_faces},
      {"non_finite_vertices", r.non_finite_vertices},
      {"bad_indices", r.bad_indices},
      {"checks", checks},
  };
}

std::string check_report_text(const MeshCheckReport& r) {
  std::ostringstream out;
  char line[256];
  std::snprintf(line, sizeof line, "  triangles %llu, vertices %llu, components %llu, genus %lld\n",
                (unsigned long long)r.triangles, (unsigned long long)r.vertices, (unsigned long long)r.components,
                (long long)r.genus);
  out << line;
  std::snprintf(line, sizeof line, "  volume %.6g mm3, surface area %.6g mm2\n", r.volume_mm3, r.area_mm2);
  out << line;
  if (!r.bounding_box.empty()) {
    std::snprintf(line, sizeof line, "  bounding box [%.4g, %.4g, %.4g] .. [%.4g, %.4g, %.4g] mm\n", r.bounding_box.min.x,
                  r.bounding_box.min.y, r.bounding_box.min.z, r.bounding_box.max.x, r.bounding_box.max.y,
                  r.bounding_box.max.z);
    out << line;
  }
  auto mark = [&](const char* name, bool ok) { out << "  " << (ok ? "ok    " : "FAILED") << " " << name << "\n"; };
  mark("closed", r.closed());
  mark("edge-manifold", r.non_manifold_edges == 0);
  mark("vertex-manifold", r.vertex_manifold_checked && r.non_manifold_vertices == 0);
  mark("outward-oriented", r.outward());
  mark("no self-intersections", r.self_intersections_checked && !r.self_intersecting);
  mark("no degenerate faces", r.degenerate_faces == 0);
  mark("finite coordinates", r.non_finite_vertices == 0 && r.bad_indices == 0);
  mark("positive volume", r.volume_mm3 > 0);
  for (const std::string& p : r.problems()) out << "  - " << p << "\n";
  out << (r.valid() ? "  valid\n" : "  INVALID\n");
  return out.str();
}

}  // namespace lacuna
