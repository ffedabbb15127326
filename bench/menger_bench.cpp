// Benchmark (not a test): the Menger sponge at level L, 27 mm, rasterized from its 20^L cells
// streamed in batches, at a voxel size of 1/3^6 of its side (or --divisions); optionally the whole
// recipe path to a checked STL at a voxel size that fits the memory budget.
//
//   lacuna_menger_bench --level L [--divisions 729] [--full-divisions 243] [--out DIR]
#include <CLI/CLI.hpp>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "cifs/library.h"
#include "cifs/solid_input.h"
#include "cifs/tessellate.h"
#include "pipeline/pipeline.h"
#include "recipe/cifs_system.h"
#include "solids/voxelize.h"
#include "util/system.h"

int run_bench(int argc, char** argv) {
  using namespace lacuna;
  CLI::App app{"Menger sponge benchmark"};
  int level = 4, divisions = 729, full_divisions = 0;
  std::string out_dir = "menger-bench-out";
  app.add_option("--level", level, "Sponge level");
  app.add_option("--divisions", divisions, "Voxels along the side for the rasterization (729 = 3^6)");
  app.add_option("--full-divisions", full_divisions, "Voxels along the side for the whole recipe (0: skip)");
  app.add_option("--out", out_dir, "Folder for the recipe run");
  CLI11_PARSE(app, argc, argv);
  const double side = 27.0;
  nlohmann::json result = {{"level", level}, {"side_mm", side}};
  {
    const double h = side / divisions;
    nlohmann::json spec = {{"library", "menger_sponge"}, {"scale", side}, {"translate_mm", {h / 2, h / 2, h / 2}}};
    cifs::Cifs c = cifs::parse_system(spec, "bench", "system");
    result["cells"] = cifs::count_pieces(c.automaton, level);
    result["voxel_size_mm"] = h;
    auto t0 = std::chrono::steady_clock::now();
    Volume v = voxelize(cifs::attractor_geometry(c, level, {}), VolumeOptions{h, 3.0});
    result["rasterize_seconds"] = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    result["active_voxels"] = v.active_voxel_count();
    result["grid_bytes"] = v.memory_bytes();
    result["rasterize_peak_memory_bytes"] = peak_memory_bytes();
  }
  if (full_divisions > 0) {
    namespace fs = std::filesystem;
    const double h = side / full_divisions;
    fs::create_directories(out_dir);
    nlohmann::json recipe = {
        {"name", "menger"},
        {"voxel_size_mm", h},
        {"inputs",
         {{"sponge",
           {{"type", "cifs"},
            {"level", level},
            {"system", {{"library", "menger_sponge"}, {"scale", side}, {"translate_mm", {h / 2, h / 2, h / 2}}}}}}}},
        {"outputs", {{{"of", "sponge"}, {"file", "menger.stl"}}}}};
    std::string path = (fs::path(out_dir) / "menger.json").string();
    std::ofstream(path) << recipe.dump();
    RunOptions run_options;
    run_options.output_dir = (fs::path(out_dir) / "out").string();
    auto t0 = std::chrono::steady_clock::now();
    const nlohmann::json r = to_json(run(path, run_options));
    result["recipe_voxel_size_mm"] = h;
    result["recipe_seconds"] = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    result["recipe_stage_seconds"] = r["stage_seconds"];
    result["recipe_triangles"] = r["outputs"][0]["triangles"];
    result["recipe_voxels"] = r["outputs"][0]["voxels"];
    result["recipe_genus"] = r["outputs"][0]["genus"];
    result["recipe_valid"] = r["valid"];
  }
  result["peak_memory_bytes"] = peak_memory_bytes();
  std::printf("%s\n", result.dump().c_str());
  return 0;
}
