// Benchmark (not a test): TetGen on a checked surface mesh, optionally simplified first.
//
//   lacuna_tet_bench --mesh FILE [--simplify MM] [--max-tet-volume MM3] [--quality Q]
#include <CLI/CLI.hpp>
#include <chrono>
#include <cstdio>
#include <nlohmann/json.hpp>

#include "export/mesh_io.h"
#include "solids/check.h"
#include "solids/simplify.h"
#include "solids/tetrahedralize.h"
#include "util/system.h"

int run_bench(int argc, char** argv) {
  using namespace lacuna;
  CLI::App app{"TetGen benchmark"};
  std::string path;
  double deviation = 0;
  TetOptions options;
  app.add_option("--mesh", path, "Closed surface mesh (STL, OBJ, PLY, 3MF)")->required();
  app.add_option("--simplify", deviation, "Simplify (guarded) to this deviation in mm first");
  app.add_option("--max-tet-volume", options.max_tet_volume_mm3, "Largest tetrahedron in mm3");
  app.add_option("--quality", options.max_radius_edge_ratio, "Radius-edge ratio bound");
  CLI11_PARSE(app, argc, argv);
  auto seconds = [](auto t0) { return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(); };
  nlohmann::json result = {{"mesh", path}};
  TriMesh surface = read_mesh(path);
  result["input_triangles"] = surface.triangles.size();
  if (deviation > 0) {
    auto t0 = std::chrono::steady_clock::now();
    SimplifyOptions simplify;
    simplify.max_deviation_mm = deviation;
    surface = simplify_mesh(surface, simplify);
    result["simplify_seconds"] = seconds(t0);
  }
  auto t1 = std::chrono::steady_clock::now();
  MeshCheckReport check = check_mesh(surface);
  result["check_seconds"] = seconds(t1);
  result["surface_triangles"] = surface.triangles.size();
  result["surface_valid"] = check.valid();
  auto t2 = std::chrono::steady_clock::now();
  TetMesh tets = tetrahedralize(surface, options);
  const double tet_seconds = seconds(t2);
  TetReport r = tet_report(tets);
  result["tetrahedralize_seconds"] = tet_seconds;
  result["tets"] = r.tets;
  result["nodes"] = r.nodes;
  result["tets_per_second"] = double(r.tets) / tet_seconds;
  result["volume_relative_error"] = (r.volume_mm3 - check.volume_mm3) / check.volume_mm3;
  result["peak_memory_bytes"] = peak_memory_bytes();                // this process
  result["tetgen_peak_memory_bytes"] = peak_child_memory_bytes();   // TetGen runs in a child
  std::printf("%s\n", result.dump().c_str());
  return 0;
}
