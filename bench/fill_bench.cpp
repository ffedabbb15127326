// Benchmark (not a test): random fractal fills at scale. 100 000 circles in the fundamental region of
// p6m, and 50 000 spheres in an imported hull (its signed distance from a level set); prints
// placements per second, stop reasons and peak memory.
//
//   lacuna_fill_bench [--circles 100000] [--spheres 50000] [--hull samples/meshes/egg_hull.stl] [--scale 2.5]
#include <CLI/CLI.hpp>
#include <chrono>
#include <cstdio>
#include <nlohmann/json.hpp>

#include "export/mesh_io.h"
#include "fill/fill.h"
#include "fill/wallpaper.h"
#include "solids/volume.h"
#include "util/system.h"

int run_bench(int argc, char** argv) {
  using namespace lacuna;
  CLI::App app{"Random fractal fill benchmark"};
  size_t circles = 100000, spheres = 50000, dimension_circles = 0;
  std::string hull_path = "samples/meshes/egg_hull.stl";
  double scale = 2.5, c2 = 1.05, c3 = 1.05;
  app.add_option("--circles", circles, "Circles in p6m (0: skip)");
  app.add_option("--spheres", spheres, "Spheres in the hull (0: skip)");
  app.add_option("--hull", hull_path, "Closed mesh to fill with spheres");
  app.add_option("--scale", scale, "Scale applied to the hull");
  app.add_option("--c2", c2, "Exponent of the area rule for the circles");
  app.add_option("--c3", c3, "Exponent of the volume rule for the spheres");
  app.add_option("--dimension-circles", dimension_circles,
                 "Circles (c = 1.3) in a 100 mm square whose uncovered set is box-counted (0: skip)");
  CLI11_PARSE(app, argc, argv);
  nlohmann::json result;
  if (circles > 0) {
    fill::FillOptions f;
    f.c = c2;
    f.N = 2;
    f.max_count = circles;
    f.max_trials = 1000000;
    f.seed = 7;
    const fill::Lattice hex{{100, 0}, {50, 86.60254037844386}};
    auto t0 = std::chrono::steady_clock::now();
    const fill::WallpaperFill w = fill::fill_wallpaper(fill::Group::p6m, hex, fill::circle_motif(), f);
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    result["p6m"] = {{"circles", w.fundamental.motifs.size()}, {"c", c2}, {"seconds", seconds},
                     {"placements_per_second", double(w.fundamental.motifs.size()) / seconds},
                     {"fill_fraction", w.fundamental.fill_fraction}, {"stop_reason", w.fundamental.stop_reason},
                     {"peak_memory_bytes", peak_memory_bytes()}};
  }
  if (spheres > 0) {
    TriMesh hull = read_mesh(hull_path);
    for (Vec3d& p : hull.positions_mm) p = p * scale;
    const double h = 0.1 * scale;
    VolumeOptions wide{h, 40};  // exact 4 mm deep at scale 1: deeper than the largest sphere's reach
    auto t0 = std::chrono::steady_clock::now();
    const Volume v = mesh_to_volume(hull, wide);
    const double field_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    const double volume = signed_volume(hull);
    fill::FillOptions3 f;
    f.c = c3;
    f.N = 2;
    f.max_count = spheres;
    f.max_trials = 1000000;
    f.gap_mm = 0.05 * scale;
    f.boundary_gap_mm = 0.2 * scale;
    f.seed = 7;
    t0 = std::chrono::steady_clock::now();
    const fill::FillResult3 r = fill::fill_spheres([&](const Vec3d& p) { return v.distance_at(p); }, bounding_box(hull), volume, f);
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    result["hull"] = {{"spheres", r.centers_mm.size()}, {"c", c3}, {"hull_volume_mm3", volume}, {"field_seconds", field_seconds},
                      {"seconds", seconds}, {"placements_per_second", double(r.centers_mm.size()) / seconds},
                      {"fill_fraction", r.fill_fraction}, {"stop_reason", r.stop_reason},
                      {"smallest_radius_mm", r.radii_mm.empty() ? 0.0 : r.radii_mm.back()}};
  }
  if (dimension_circles > 0) {
    // Box counting of the set the circles leave uncovered: N(eps) boxes of side eps not inside one
    // circle (a box lies in a circle when its four corners do), for eps = 100 mm / 2^k; the slope of
    // log N against log(1 / eps) estimates the dimension, 2 / c by the spec.
    fill::FillOptions f;
    f.c = 1.3;
    f.N = 2;
    f.max_count = dimension_circles;
    f.max_trials = 1000000;
    f.seed = 3;
    const double side = 100;
    auto t0 = std::chrono::steady_clock::now();
    const fill::FillResult2 r = fill::fill_region(fill::rectangle_region({0, 0}, {side, side}), fill::circle_motif(), f);
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    // Over eps = 100/32 .. 100/512 mm.
    const fill::UncoveredBoxCount boxes = fill::uncovered_box_count(r.motifs, side, 5, 9);
    nlohmann::json counts = nlohmann::json::array();
    for (size_t i = 0; i < boxes.eps_mm.size(); ++i) counts.push_back({{"eps_mm", boxes.eps_mm[i]}, {"uncovered_boxes", boxes.boxes[i]}});
    result["box_counting"] = {{"circles", r.motifs.size()}, {"c", f.c}, {"expected_dimension", 2 / f.c},
                              {"measured_dimension", boxes.dimension}, {"fill_seconds", seconds},
                              {"fill_fraction", r.fill_fraction}, {"stop_reason", r.stop_reason}, {"counts", counts}};
  }
  result["peak_memory_bytes"] = peak_memory_bytes();
  std::printf("%s\n", result.dump().c_str());
  return 0;
}
