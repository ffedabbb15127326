// Benchmark (not a test): superimposed Sierpinski curves on a torus as tubes, mapped (adaptive
// chords) and rasterized at a fine voxel size; prints segments, times, active voxels and memory.
//
//   lacuna_curves_bench [--orders 1..7] [--scale 20] [--radius 0.15] [--voxel 0.03]
#include <CLI/CLI.hpp>
#include <chrono>
#include <cstdio>
#include <nlohmann/json.hpp>

#include "curves/curves.h"
#include "curves/sweep.h"
#include "solids/voxelize.h"
#include "util/system.h"

int run_bench(int argc, char** argv) {
  using namespace lacuna;
  CLI::App app{"Space-filling curves on a torus: mapping and rasterization"};
  int first = 1, last = 7;
  double scale = 20, radius = 0.15, voxel = 0.03;
  app.add_option("--first-order", first, "Lowest order");
  app.add_option("--last-order", last, "Highest order");
  app.add_option("--scale", scale, "mm per unit: the torus has major radius 1.5 scale, minor radius scale");
  app.add_option("--radius", radius, "Tube radius (mm)");
  app.add_option("--voxel", voxel, "Voxel size (mm)");
  CLI11_PARSE(app, argc, argv);
  curves::SweepOptions options;
  options.kind = curves::SweepOptions::Kind::kSierpinski;
  options.orders.clear();
  for (int k = first; k <= last; ++k) options.orders.push_back(k);
  options.radii_mm = {radius};
  options.map.scale = scale;
  options.map.tolerance_mm = 0.1 * radius;
  nlohmann::json result = {{"orders", options.orders}, {"scale_mm", scale}, {"radius_mm", radius}, {"voxel_size_mm", voxel}};
  auto t0 = std::chrono::steady_clock::now();
  curves::Sweep sweep = curves::sweep_curves(options, curves::torus_map());
  result["map_seconds"] = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  result["mapped_segments"] = sweep.segments;
  GeometrySet set;
  set.tubes = std::move(sweep.tubes);
  t0 = std::chrono::steady_clock::now();
  Volume v = voxelize(set, VolumeOptions{voxel, 3.0});
  result["rasterize_seconds"] = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  result["active_voxels"] = v.active_voxel_count();
  result["grid_bytes"] = v.memory_bytes();
  result["peak_memory_bytes"] = peak_memory_bytes();
  std::printf("%s\n", result.dump().c_str());
  return 0;
}
