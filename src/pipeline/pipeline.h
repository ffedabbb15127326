// Lacuna's pipeline as a library: a recipe (plain data, recipe/recipe.h) is built into geometry,
// planned, evaluated into level sets and written as checked files, all or nothing. The command line,
// the benchmarks and the tests call these functions; run() chains them.
//
//   Recipe recipe = load_recipe(path);             // recipe/recipe.h: JSON into option structs
//   BuiltInputs inputs = build_inputs(recipe);     // pipeline/build_inputs.h: every input into geometry
//   Plan p = plan(recipe);                         // pipeline/plan.h: what is needed, in which order
//   Evaluation e = evaluate(recipe, p, inputs);    // pipeline/evaluate.h: level sets, memory refused first
//   RunReport r = write_outputs(recipe, p, std::move(e), inputs);  // pipeline/write_outputs.h
//   nlohmann::json j = to_json(r);                 // pipeline/report.h: what report.json holds
#pragma once

#include <cstdint>
#include <string>

#include "pipeline/build_inputs.h"
#include "pipeline/check_file.h"
#include "pipeline/evaluate.h"
#include "pipeline/fea_output.h"
#include "pipeline/plan.h"
#include "pipeline/report.h"
#include "pipeline/write_outputs.h"
#include "recipe/recipe.h"
#include "util/progress.h"

namespace lacuna {

struct RunOptions {
  std::string output_dir;            // empty: "<recipe name>-out" in the working folder
  double voxel_size_mm = 0;          // > 0 overrides the recipe's voxel size
  double simplify_mm = -1;           // >= 0 overrides the recipe's simplification deviation (0: off)
  uint64_t max_memory_bytes = 0;     // 0: half the memory available to the process
  int threads = 0;                   // worker threads for the call; 0: every core
  ProgressSink* progress = nullptr;  // receives the stages and may cancel them; null: the one current on this thread
  bool write_report = true;          // report.json and report.html next to the outputs
};

// Throws InvalidInput for options no run can use (NaN ignored silently would run something else).
void check_run_options(const RunOptions& options);
// The options' voxel size and simplification deviation, where given, in place of the recipe's (and
// of its outputs' own deviations).
void apply_run_options(Recipe& recipe, const RunOptions& options);

// Runs the recipe at `recipe_path`: reads it, builds its inputs, refuses what would not fit the
// memory budget before allocating it, evaluates, writes, re-reads and checks every output, all or
// nothing. Throws IoError or InvalidInput for bad recipes and input meshes, ResourceLimit beyond the
// budget, Cancelled when the progress sink asks to stop; nothing is left on disk then. When a written
// file fails its checks the report is not valid and nothing is left on disk either.
RunReport run(const std::string& recipe_path, const RunOptions& options);

// The same for a recipe already read (or made in code); its file names the folder mesh files are
// relative to.
RunReport run(Recipe recipe, const RunOptions& options);

}  // namespace lacuna
