// Benchmark (not a test): the stages a mesh goes through after extraction, timed one by one on a
// mesh file: read (with welding), check (every validity check), and simplification when asked;
// --hausdorff-to measures the sampled one-sided Hausdorff distances both ways between the (simplified)
// mesh and another file (a plain run's surface against a compact run's, say).
//
//   lacuna_mesh_bench MESH [--simplify MM] [--threads N] [--out FILE.stl] [--hausdorff-to OTHER]
#include <tbb/global_control.h>

#include <CLI/CLI.hpp>
#include <chrono>
#include <cstdio>
#include <memory>
#include <nlohmann/json.hpp>

#include "export/mesh_io.h"
#include "solids/check.h"
#include "solids/mesh_distance.h"
#include "solids/simplify.h"
#include "util/system.h"

namespace {

double seconds_since(std::chrono::steady_clock::time_point t) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
}

}  // namespace

int run_bench(int argc, char** argv) {
  using namespace lacuna;
  CLI::App app{"Mesh stages benchmark: read, check"};
  std::string path;
  int threads = 0;
  double simplify_mm = 0;
  std::string out_path, other_path;
  app.add_option("mesh", path, "Mesh file (STL, OBJ, PLY, 3MF)")->required();
  app.add_option("--simplify", simplify_mm, "Simplify to this deviation (mm) before the check");
  app.add_option("--out", out_path, "Write the (simplified) mesh to this STL");
  app.add_option("--threads", threads, "Worker threads (default all)");
  app.add_option("--hausdorff-to", other_path, "Sampled one-sided Hausdorff distances (mm) both ways to this mesh");
  CLI11_PARSE(app, argc, argv);
  std::unique_ptr<tbb::global_control> limit;
  if (threads > 0) limit = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism, threads);

  nlohmann::json result;
  auto t0 = std::chrono::steady_clock::now();
  TriMesh mesh = read_mesh(path);
  result["read_seconds"] = seconds_since(t0);
  result["triangles"] = mesh.triangles.size();
  if (simplify_mm > 0) {
    SimplifyOptions options;
    options.max_deviation_mm = simplify_mm;
    SimplifyStats stats;
    auto ts = std::chrono::steady_clock::now();
    mesh = simplify_mesh(mesh, options, &stats);
    const double simplify_s = seconds_since(ts);
    result["simplify_seconds"] = simplify_s;
    result["simplify_input_triangles_per_second"] = double(stats.input_triangles) / simplify_s;
    result["simplified_triangles"] = mesh.triangles.size();
    result["collapses"] = stats.collapses;
    result["rejected_by_intersection"] = stats.rejected_by_intersection;
    result["regions"] = stats.regions;
    result["regions_redone"] = stats.regions_redone;
    result["regions_guarded"] = stats.regions_guarded;
    result["simplify_thread_seconds"] = {
        {"run", stats.run_thread_seconds}, {"verify", stats.verify_thread_seconds}, {"redo", stats.redo_thread_seconds}};
  }
  if (!other_path.empty()) {
    const TriMesh other = read_mesh(other_path);
    Vec3d at_other, at_mesh;
    result["hausdorff_mesh_to_other_mm"] = sampled_hausdorff_mm(mesh, other, 0, &at_other);
    result["hausdorff_other_to_mesh_mm"] = sampled_hausdorff_mm(other, mesh, 0, &at_mesh);
    result["hausdorff_mesh_to_other_at"] = {at_other.x, at_other.y, at_other.z};
    result["hausdorff_other_to_mesh_at"] = {at_mesh.x, at_mesh.y, at_mesh.z};
  }
  if (!out_path.empty()) write_stl(out_path, mesh, "lacuna mesh bench");
  auto t1 = std::chrono::steady_clock::now();
  MeshCheckReport report = check_mesh(mesh);
  const double check_s = seconds_since(t1);
  result["check_seconds"] = check_s;
  result["check_triangles_per_second"] = double(mesh.triangles.size()) / check_s;
  result["valid"] = report.valid();
  result["genus"] = report.genus;
  result["components"] = report.components;
  result["volume_mm3"] = report.volume_mm3;
  result["peak_memory_bytes"] = peak_memory_bytes();
  std::printf("%s\n", result.dump().c_str());
  return 0;
}
