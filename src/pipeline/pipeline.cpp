#include "pipeline/pipeline.h"

#include <tbb/global_control.h>

#include <memory>
#include <utility>

#include "util/system.h"

namespace lacuna {
namespace {

// The stages after reading: the recipe's time to read (and its inputs' to build) is `read`.
RunReport run_read(Recipe recipe, const RunOptions& options, StageTimer& read) {
  if (options.voxel_size_mm > 0) recipe.voxel_size_mm = options.voxel_size_mm;
  if (options.simplify_mm >= 0) {
    recipe.simplify_mm = options.simplify_mm;
    for (RecipeOutput& out : recipe.outputs) out.simplify_mm.reset();
  }
  const uint64_t budget = options.max_memory_bytes ? options.max_memory_bytes : available_memory_bytes() / 2;
  const BuiltInputs inputs = build_inputs(recipe, budget);
  const Plan p = plan(recipe);
  read.stop();
  EvaluateOptions evaluate_options;
  evaluate_options.max_memory_bytes = budget;
  WriteOptions write_options;
  write_options.output_dir = options.output_dir;
  write_options.write_report = options.write_report;
  check_output_folder(recipe, write_options);
  Evaluation evaluation = evaluate(recipe, p, inputs, evaluate_options);
  evaluation.stage_seconds.insert(evaluation.stage_seconds.begin(), read.seconds().begin(), read.seconds().end());
  return write_outputs(recipe, p, std::move(evaluation), inputs, write_options);
}

std::unique_ptr<tbb::global_control> thread_limit(int threads) {
  if (threads <= 0) return nullptr;
  return std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism, size_t(threads));
}

}  // namespace

RunReport run(const std::string& recipe_path, const RunOptions& options) {
  ProgressSinkScope progress(options.progress ? options.progress : current_progress_sink());
  const auto threads = thread_limit(options.threads);
  StageTimer read;
  read.start("read");
  return run_read(load_recipe(recipe_path), options, read);
}

RunReport run(Recipe recipe, const RunOptions& options) {
  ProgressSinkScope progress(options.progress ? options.progress : current_progress_sink());
  const auto threads = thread_limit(options.threads);
  StageTimer read;
  read.start("read");
  return run_read(std::move(recipe), options, read);
}

}  // namespace lacuna
