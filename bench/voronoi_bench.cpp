// Benchmark (not a test): a 3D fractal Voronoi foam at scale. m = 4 random starting points, d = 2, level K
// (4 (2^3)^K points: 16 384 at K = 4, 131 072 at K = 5): the time of the rules, the points, the Voronoi
// cells, the walls and the foam solid (the walls thickened into a level set and meshed), and peak memory;
// the walls once more from every generator's own clipped cell, to show what reusing the m cell shapes and
// skipping the generators inside one colour saves.
//
//   lacuna_voronoi_bench [--level 4] [--period-mm 40] [--wall-mm 0.25] [--voxel-mm 0.1] [--reference]
#include <CLI/CLI.hpp>
#include <chrono>
#include <cstdio>
#include <iostream>
#include <nlohmann/json.hpp>

#include "solids/extract.h"
#include "solids/voxelize.h"
#include "util/system.h"
#include "voronoi/rules.h"
#include "voronoi/walls.h"

int run_bench(int argc, char** argv) {
  using namespace lacuna;
  CLI::App app{"Fractal Voronoi foam benchmark"};
  int level = 4;
  double period = 40, wall = 0.25, voxel = 0.1;
  bool reference = false, mesh = true;
  app.add_option("--level", level, "Level K of the partition");
  app.add_option("--period-mm", period, "Period of the foam (mm)");
  app.add_option("--wall-mm", wall, "Wall thickness (mm)");
  app.add_option("--voxel-mm", voxel, "Voxel size (mm)");
  app.add_flag("--reference", reference, "Also compute the walls from every generator's own cell");
  app.add_option("--mesh", mesh, "Mesh the foam's level set (default true)");
  CLI11_PARSE(app, argc, argv);

  using clock = std::chrono::steady_clock;
  auto seconds_since = [](clock::time_point t0) { return std::chrono::duration<double>(clock::now() - t0).count(); };
  nlohmann::json result = {{"dimension", 3}, {"d", 2}, {"m", 4}, {"level", level}, {"period_mm", period},
                           {"wall_mm", wall}, {"voxel_mm", voxel}};
  auto t = clock::now();
  voronoi::RulesOptions options;
  options.children = voronoi::RulesOptions::Children::kScaled;
  const voronoi::Rules rules = voronoi::make_rules(3, 2, voronoi::random_points(3, 4, 2026), options);
  result["rules_s"] = seconds_since(t);
  result["graph_condition"] = rules.graph_connected_condition;
  t = clock::now();
  const voronoi::Level points = voronoi::generate_level(rules, level);
  result["points_s"] = seconds_since(t);
  result["points"] = points.points.size();
  t = clock::now();
  const voronoi::Walls walls = voronoi::extract_walls(rules, points);
  result["cells_and_walls_s"] = seconds_since(t);
  result["boundary_generators"] = walls.boundary_generators;
  result["wall_facets"] = walls.facets.size();
  result["wall_area_mm2"] = walls.measure * period * period;
  if (reference) {
    t = clock::now();
    const voronoi::Walls slow = voronoi::walls_by_clipping(points);
    result["walls_by_clipping_every_cell_s"] = seconds_since(t);
    result["walls_by_clipping_facets"] = slow.facets.size();
  }
  t = clock::now();
  GeometrySet foam;
  ThickSurface surface;
  surface.thickness_mm = wall;
  surface.surface = voronoi::wall_triangles(walls, period, Vec3d{}, {0, 0, 0}, {1, 1, 1});
  result["wall_triangles"] = surface.surface.triangles.size();
  foam.surfaces.push_back(std::move(surface));
  Volume v = voxelize(foam, VolumeOptions{voxel, 3.0});
  result["foam_level_set_s"] = seconds_since(t);
  result["active_voxels"] = v.active_voxel_count();
  if (mesh) {
    t = clock::now();
    const TriMesh m = extract_surface(v);
    result["foam_mesh_s"] = seconds_since(t);
    result["foam_mesh_triangles"] = m.triangles.size();
  }
  result["peak_memory_bytes"] = peak_memory_bytes();
  std::cout << result.dump(1) << "\n";
  return 0;
}
