// Benchmark (not a test): N capsules along a random-walk polyline, rasterized directly and through
// meshToLevelSet of a tube triangle soup, then the whole recipe path to a checked STL.
//
//   lacuna_capsules_bench --count N [--soup] [--full] [--box MM] [--step MM] [--radius MM] [--out DIR]
//
// Each run is one process, so its peak memory is its own. bench/run_capsules.sh runs the table.
#include <tbb/global_control.h>

#include <CLI/CLI.hpp>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "pipeline/pipeline.h"
#include "solids/check.h"
#include "solids/extract.h"
#include "solids/mesh_distance.h"
#include "solids/simplify.h"
#include "solids/rasterize.h"
#include "solids/volume.h"
#include "solids/voxelize.h"
#include "util/system.h"
#include "export/mesh_io.h"

namespace lacuna {
namespace {

constexpr double kPi = 3.14159265358979323846;

// SplitMix64: a portable generator, so the walk is the same everywhere.
struct Random {
  uint64_t state;
  uint64_t next() {
    uint64_t z = (state += 0x9e3779b97f4a7c15ull);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return z ^ (z >> 31);
  }
  double uniform(double lo, double hi) { return lo + (hi - lo) * double(next() >> 11) * 0x1.0p-53; }
};

// A persistent random walk of `count` steps reflected inside a cube of side `box` centred at 0.
std::vector<Vec3d> random_walk(size_t count, double step, double box, uint64_t seed) {
  Random rng{seed};
  Vec3d p{0, 0, 0}, d{1, 0, 0};
  std::vector<Vec3d> points{p};
  const double half = 0.5 * box;
  for (size_t i = 0; i < count; ++i) {
    d = d + Vec3d{rng.uniform(-0.6, 0.6), rng.uniform(-0.6, 0.6), rng.uniform(-0.6, 0.6)};
    d = d / norm(d);
    Vec3d q = p + d * step;
    for (int k = 0; k < 3; ++k)
      if (std::fabs(q[k]) > half) {
        d[k] = -d[k];
        q[k] = p[k] + d[k] * step;
      }
    p = q;
    points.push_back(p);
  }
  return points;
}

// Closed triangle meshes for every capsule: a 16-sided prism with end caps, and a 80-triangle
// icosphere at every polyline point to round the joints (the soup a mesh-based pipeline builds).
TriMesh tube_soup(const std::vector<Vec3d>& points, double r, int sides = 16) {
  TriMesh soup;
  // Icosphere level 1 (80 faces), unit radius.
  const double t = (1 + std::sqrt(5.0)) / 2;
  std::vector<Vec3d> ico = {{-1, t, 0}, {1, t, 0}, {-1, -t, 0}, {1, -t, 0}, {0, -1, t}, {0, 1, t},
                            {0, -1, -t}, {0, 1, -t}, {t, 0, -1}, {t, 0, 1}, {-t, 0, -1}, {-t, 0, 1}};
  std::vector<std::array<uint32_t, 3>> faces = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11},
                                                {1, 5, 9},  {5, 11, 4}, {11, 10, 2}, {10, 7, 6}, {7, 1, 8},
                                                {3, 9, 4},  {3, 4, 2},  {3, 2, 6},   {3, 6, 8},  {3, 8, 9},
                                                {4, 9, 5},  {2, 4, 11}, {6, 2, 10},  {8, 6, 7},  {9, 8, 1}};
  for (Vec3d& v : ico) v = v / norm(v);
  {
    std::vector<std::array<uint32_t, 3>> finer;
    for (const auto& f : faces) {
      uint32_t m[3];
      for (int k = 0; k < 3; ++k) {
        Vec3d mid = (ico[f[k]] + ico[f[(k + 1) % 3]]) * 0.5;
        ico.push_back(mid / norm(mid));
        m[k] = uint32_t(ico.size() - 1);
      }
      finer.push_back({f[0], m[0], m[2]});
      finer.push_back({f[1], m[1], m[0]});
      finer.push_back({f[2], m[2], m[1]});
      finer.push_back({m[0], m[1], m[2]});
    }
    faces = finer;
  }
  auto add_sphere = [&](const Vec3d& c) {
    uint32_t base = uint32_t(soup.positions_mm.size());
    for (const Vec3d& v : ico) soup.positions_mm.push_back(c + v * r);
    for (const auto& f : faces) soup.triangles.push_back({base + f[0], base + f[1], base + f[2]});
  };
  for (size_t i = 0; i < points.size(); ++i) add_sphere(points[i]);
  for (size_t i = 0; i + 1 < points.size(); ++i) {
    Vec3d a = points[i], b = points[i + 1], axis = b - a;
    double len = norm(axis);
    if (len == 0) continue;
    axis = axis / len;
    Vec3d u = std::fabs(axis.x) < 0.9 ? cross(axis, Vec3d{1, 0, 0}) : cross(axis, Vec3d{0, 1, 0});
    u = u / norm(u);
    Vec3d w = cross(axis, u);
    uint32_t base = uint32_t(soup.positions_mm.size());
    for (int end = 0; end < 2; ++end)
      for (int s = 0; s < sides; ++s) {
        double phi = 2 * kPi * s / sides;
        soup.positions_mm.push_back((end ? b : a) + (u * std::cos(phi) + w * std::sin(phi)) * r);
      }
    soup.positions_mm.push_back(a);
    soup.positions_mm.push_back(b);
    uint32_t ca = base + 2 * sides, cb = ca + 1;
    for (int s = 0; s < sides; ++s) {
      uint32_t a0 = base + s, a1 = base + (s + 1) % sides, b0 = a0 + sides, b1 = a1 + sides;
      soup.triangles.push_back({a0, a1, b1});
      soup.triangles.push_back({a0, b1, b0});
      soup.triangles.push_back({ca, a1, a0});
      soup.triangles.push_back({cb, b0, b1});
    }
  }
  return soup;
}

double seconds_since(std::chrono::steady_clock::time_point t) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
}

}  // namespace
}  // namespace lacuna

int run_bench(int argc, char** argv) {
  using namespace lacuna;
  CLI::App app{"Capsule benchmark: direct rasterization vs meshToLevelSet of a tube soup, and the whole recipe"};
  size_t count = 1000;
  double radius = 0.5, step = 0.5, box = 0;
  bool soup = false, full = false, only_recipe = false;
  double recipe_simplify_mm = -1, reference_voxel_mm = 0;
  double simplify_mm = 0, merge_fraction = -1;
  bool skip_plain = false;
  bool hausdorff = false;
  int threads = 0;
  std::string out_dir = "capsules-bench-out";
  app.add_option("--count", count, "Number of capsules (segments of the walk)");
  app.add_option("--radius", radius, "Tube radius in mm");
  app.add_option("--step", step, "Walk step (segment length) in mm");
  app.add_option("--box", box, "Side of the cube the walk is reflected in, mm (default 20 (N/1000)^(1/3): constant density)");
  app.add_flag("--soup", soup, "Also convert a tube triangle soup with meshToLevelSet");
  app.add_flag("--full", full, "Also run the whole recipe (rasterize, mesh, write STL, re-read, check)");
  app.add_option("--threads", threads, "Worker threads (default all)");
  app.add_flag("--hausdorff", hausdorff, "With --simplify: the sampled one-sided Hausdorff distances both ways");
  app.add_option("--simplify", simplify_mm, "Also time extraction with simplification to this deviation (mm), and its check");
  app.add_option("--merge-fraction", merge_fraction, "With --simplify: the share of the deviation the cubes' merge may use (default: the library's)");
  app.add_flag("--skip-plain", skip_plain, "With --simplify and without --hausdorff: do not extract the plain surface first");
  app.add_option("--out", out_dir, "Folder for the recipe run's output");
  app.add_flag("--only-recipe", only_recipe, "With --full: skip the direct rasterization, so the peak memory is the recipe's");
  app.add_option("--recipe-simplify", recipe_simplify_mm, "With --full: the recipe's simplify_mm (default: the recipe default)");
  app.add_option("--reference-voxel", reference_voxel_mm,
                 "With --full: also the volume at this finer voxel size (compact mesh at a fifth of it), and the recipe's difference");
  CLI11_PARSE(app, argc, argv);
  std::unique_ptr<tbb::global_control> limit;
  if (threads > 0) limit = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism, threads);

  if (!(box > 0)) box = 20.0 * std::cbrt(double(count) / 1000.0);
  const VolumeOptions options{radius / 6.0, 3.0};
  std::vector<Vec3d> points = random_walk(count, step, box, 7);
  GeometrySet set;
  set.tubes.tubes.push_back(Tube{points, {radius}});
  nlohmann::json result = {{"capsules", count}, {"radius_mm", radius}, {"step_mm", step}, {"box_mm", box},
                           {"voxel_size_mm", options.voxel_size_mm}};

  auto t0 = std::chrono::steady_clock::now();
  Volume direct = only_recipe ? Volume() : rasterize_primitives(set, options);
  double direct_s = seconds_since(t0);
  result["direct_seconds"] = direct_s;
  result["direct_active_voxels"] = direct.active_voxel_count();
  result["direct_voxels_per_second"] = double(direct.active_voxel_count()) / direct_s;
  result["direct_volume_mm3"] = direct.voxel_volume_mm3();

  if (soup) {
    TriMesh mesh = tube_soup(points, radius);
    auto t1 = std::chrono::steady_clock::now();
    Volume via_soup = mesh_to_volume(mesh, options);
    double soup_s = seconds_since(t1);
    result["soup_triangles"] = mesh.triangles.size();
    result["soup_seconds"] = soup_s;
    result["soup_active_voxels"] = via_soup.active_voxel_count();
    result["soup_volume_mm3"] = via_soup.voxel_volume_mm3();
    result["soup_over_direct_time"] = soup_s / direct_s;
  }
  if (simplify_mm > 0) {
    auto t3 = std::chrono::steady_clock::now();
    TriMesh plain = skip_plain && !hausdorff ? TriMesh() : extract_surface(direct);
    result["extract_seconds"] = seconds_since(t3);
    result["extract_triangles"] = plain.triangles.size();
    if (!plain.triangles.empty()) result["extract_volume_mm3"] = check_mesh(plain).volume_mm3;
    if (!hausdorff) plain = TriMesh();
    SimplifyOptions so;
    so.max_deviation_mm = simplify_mm;
    if (merge_fraction >= 0) so.merge_fraction = merge_fraction;
    SimplifyStats stats;
    auto t4 = std::chrono::steady_clock::now();
    TriMesh compact = extract_simplified_surface(direct, so, &stats);
    result["extract_simplified_seconds"] = seconds_since(t4);
    result["simplified_triangles"] = compact.triangles.size();
    result["simplify_regions"] = stats.regions;
    result["simplify_input_triangles"] = stats.input_triangles;
    result["simplify_merged_triangles"] = stats.merged_triangles;
    result["simplify_regions_redone"] = stats.regions_redone;
    result["simplify_regions_guarded"] = stats.regions_guarded;
    result["simplify_collapses"] = stats.collapses;
    result["simplify_thread_seconds"] = {{"extract", stats.extract_thread_seconds},
                                         {"run", stats.run_thread_seconds},
                                         {"verify", stats.verify_thread_seconds},
                                         {"redo", stats.redo_thread_seconds}};
    result["simplify_wall_seconds"] = {
        {"blocks", stats.blocks_seconds}, {"assemble", stats.assemble_seconds}, {"pass", stats.pass_seconds}};
    auto t5 = std::chrono::steady_clock::now();
    MeshCheckReport check = check_mesh(compact);
    result["simplified_check_seconds"] = seconds_since(t5);
    result["simplified_valid"] = check.valid();
    result["simplified_genus"] = check.genus;
    result["simplified_volume_mm3"] = check.volume_mm3;
    if (hausdorff) {
      Vec3d at1, at2;
      result["hausdorff_simplified_to_extracted_mm"] = sampled_hausdorff_mm(compact, plain, 0, &at1);
      result["hausdorff_extracted_to_simplified_mm"] = sampled_hausdorff_mm(plain, compact, 0, &at2);
      result["hausdorff_simplified_to_extracted_at"] = {at1.x, at1.y, at1.z};
      result["hausdorff_extracted_to_simplified_at"] = {at2.x, at2.y, at2.z};
      if (getenv("LACUNA_DUMP")) {
        write_stl("/tmp/plain.stl", plain, "plain");
        write_stl("/tmp/compact.stl", compact, "compact");
      }
    }
  }
  direct = Volume();

  if (full) {
    namespace fs = std::filesystem;
    fs::create_directories(out_dir);
    nlohmann::json polyline = {{"points_mm", nlohmann::json::array()}, {"radius_mm", radius}};
    for (const Vec3d& p : points) polyline["points_mm"].push_back({p.x, p.y, p.z});
    nlohmann::json recipe = {{"name", "capsules"},
                             {"voxel_size_mm", options.voxel_size_mm},
                             {"inputs", {{"walk", {{"type", "tubes"}, {"polylines", {polyline}}}}}},
                             {"outputs", {{{"of", "walk"}, {"file", "capsules.stl"}}}}};
    if (recipe_simplify_mm >= 0) recipe["simplify_mm"] = recipe_simplify_mm;
    std::string recipe_path = (fs::path(out_dir) / "capsules.json").string();
    std::ofstream(recipe_path) << recipe.dump();
    RunOptions run_options;
    run_options.output_dir = (fs::path(out_dir) / "out").string();
    auto t2 = std::chrono::steady_clock::now();
    const nlohmann::json r = to_json(run(recipe_path, run_options));
    result["recipe_seconds"] = seconds_since(t2);
    result["recipe_exit_code"] = r["valid"].get<bool>() ? 0 : 4;
    result["recipe_stage_seconds"] = r["stage_seconds"];
    result["recipe_triangles"] = r["outputs"][0]["triangles"];
    result["recipe_valid"] = r["valid"];
    result["recipe_memory_estimate_bytes"] = r["memory_estimate_bytes"];
    result["recipe_peak_memory_bytes"] = r["peak_memory_bytes"];
    result["recipe_volume_mm3"] = r["outputs"][0]["volume_mm3"];
    result["recipe_extracted_triangles"] = r["outputs"][0]["extracted_triangles"];
    result["recipe_stl_bytes"] = fs::file_size(fs::path(out_dir) / "out" / "capsules.stl");
    if (reference_voxel_mm > 0) {
      SimplifyOptions fine;
      fine.max_deviation_mm = 0.2 * reference_voxel_mm;
      const double reference =
          check_mesh(extract_simplified_surface(rasterize_primitives(set, VolumeOptions{reference_voxel_mm, 3.0}), fine))
              .volume_mm3;
      result["reference_voxel_mm"] = reference_voxel_mm;
      result["reference_volume_mm3"] = reference;
      result["recipe_volume_error"] = (r["outputs"][0]["volume_mm3"].get<double>() - reference) / reference;
    }
  }
  result["peak_memory_bytes"] = peak_memory_bytes();
  std::printf("%s\n", result.dump().c_str());
  return 0;
}
