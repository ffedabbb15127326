// Runs a recipe: imports, voxelizes, combines, meshes, writes, re-reads and checks, all or
// nothing. The stages are free functions elsewhere; this file only calls them in order.
#pragma once

#include <cstdint>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "recipe/recipe.h"

namespace lacuna {

struct RunOptions {
  std::string output_dir;         // empty: "<recipe name>-out" in the working folder
  double voxel_size_mm = 0;       // > 0 overrides the recipe's voxel size
  uint64_t max_memory_bytes = 0;  // 0: half the memory available to the process
  // When not empty, these outputs replace the recipe's (an empty `object` names the recipe's
  // first output's object); used by `lacuna fea`.
  std::vector<RecipeOutput> replace_outputs;
  bool write_report = true;       // report.json next to the outputs
};

struct RunResult {
  int exit_code = 0;                 // 0, or 4 when an output failed its checks
  nlohmann::json report;             // what report.json holds
  std::vector<std::string> written;  // final paths of every file written, report.json last
};

// Runs the recipe at `recipe_path`. Throws InvalidInput/IoError (exit 2) for bad recipes and
// input meshes, ResourceLimit (exit 3) before allocating when the memory budget would be
// exceeded. When a written file fails its checks nothing is left on disk and exit_code is 4.
RunResult run_recipe(const std::string& recipe_path, const RunOptions& options);

}  // namespace lacuna
