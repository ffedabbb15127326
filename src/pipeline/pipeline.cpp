#include "pipeline/pipeline.h"

#include <tbb/global_control.h>

#include <cmath>
#include <memory>
#include <utility>

#include "errors.h"
#include "util/system.h"

namespace lacuna {
namespace {

// The stages after reading: the recipe's time to read (and its inputs' to build) is `read`.
RunReport run_read(Recipe recipe, const RunOptions& options, StageTimer& read) {
  apply_run_options(recipe, options);
  const uint64_t budget = options.max_memory_bytes ? options.max_memory_bytes : available_memory_bytes() / 2;
  WriteOptions write_options;
  write_options.output_dir = options.output_dir;
  write_options.write_report = options.write_report;
  // Held for the whole run, so that a second run into the same folder is refused at once rather than
  // after its work; a folder created here is removed again unless the run succeeds.
  const std::unique_ptr<OutputFolder> folder = hold_output_folder(recipe, write_options);
  write_options.folder = folder.get();
  const BuiltInputs inputs = build_inputs(recipe, budget);
  const Plan p = plan(recipe);
  read.stop();
  EvaluateOptions evaluate_options;
  evaluate_options.max_memory_bytes = budget;
  Evaluation evaluation = evaluate(recipe, p, inputs, evaluate_options);
  evaluation.stage_seconds.insert(evaluation.stage_seconds.begin(), read.seconds().begin(), read.seconds().end());
  return write_outputs(recipe, p, std::move(evaluation), inputs, write_options);
}

std::unique_ptr<tbb::global_control> thread_limit(int threads) {
  if (threads <= 0) return nullptr;
  return std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism, size_t(threads));
}

}  // namespace

void check_run_options(const RunOptions& options) {
  if (options.voxel_size_mm != 0 &&
      !(options.voxel_size_mm >= kMinVoxelSizeMm && options.voxel_size_mm <= kMaxVoxelSizeMm))
    throw InvalidInput("voxel size: expected 0.0001 to 1000 mm (or 0: the recipe's), got " +
                       message_number(options.voxel_size_mm) + " mm");
  if (std::isnan(options.simplify_mm) || options.simplify_mm == HUGE_VAL)
    throw InvalidInput("simplification deviation: expected a finite length of at least 0 mm, got " +
                       message_number(options.simplify_mm) + " mm");
  if (options.threads < 0) throw InvalidInput("threads: expected 0 (every core) or more, got " + std::to_string(options.threads));
  if (options.output_dir.find('\0') != std::string::npos)
    throw InvalidInput("output folder: a path may not hold a NUL character");
}

void apply_run_options(Recipe& recipe, const RunOptions& options) {
  if (options.voxel_size_mm > 0) recipe.voxel_size_mm = options.voxel_size_mm;
  if (options.simplify_mm >= 0) {
    recipe.simplify_mm = options.simplify_mm;
    for (RecipeOutput& out : recipe.outputs) out.simplify_mm.reset();
  }
}

RunReport run(const std::string& recipe_path, const RunOptions& options) {
  check_run_options(options);
  ProgressSinkScope progress(options.progress ? options.progress : current_progress_sink());
  const auto threads = thread_limit(options.threads);
  StageTimer read;
  read.start("read");
  return run_read(load_recipe(recipe_path), options, read);
}

RunReport run(Recipe recipe, const RunOptions& options) {
  check_run_options(options);
  ProgressSinkScope progress(options.progress ? options.progress : current_progress_sink());
  const auto threads = thread_limit(options.threads);
  StageTimer read;
  read.start("read");
  return run_read(std::move(recipe), options, read);
}

}  // namespace lacuna
