#include "pipeline/mesh_object.h"

#include <tbb/global_control.h>

#include <algorithm>
#include <memory>
#include <utility>

#include "errors.h"
#include "pipeline/build_inputs.h"
#include "pipeline/detail/memory.h"
#include "pipeline/evaluate.h"
#include "pipeline/plan.h"
#include "solids/components.h"
#include "solids/extract.h"
#include "solids/simplify.h"
#include "util/system.h"

namespace lacuna {
namespace {

std::unique_ptr<tbb::global_control> thread_limit(int threads) {
  if (threads <= 0) return nullptr;
  return std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism, size_t(threads));
}

uint64_t budget_of(uint64_t max_memory_bytes) {
  return max_memory_bytes ? max_memory_bytes : available_memory_bytes() / 2;
}

}  // namespace

Recipe recipe_for_object(const Recipe& recipe, const std::string& object) {
  Recipe only = recipe;
  std::vector<std::string> names;
  for (const RecipeInput& in : recipe.inputs) names.push_back(in.name);
  for (const RecipeOperation& op : recipe.operations) names.push_back(op.name);
  const std::string name = object.empty() && !recipe.outputs.empty() ? recipe.outputs.front().object : object;
  if (std::find(names.begin(), names.end(), name) == names.end())
    throw InvalidInput(recipe.file + ": \"" + name + "\" is not an input or operation");
  RecipeOutput out;
  out.object = name;
  out.file = name + ".stl";
  out.format = "stl";
  out.part_name = name;
  out.json_path = "outputs[0]";
  for (const RecipeOutput& o : recipe.outputs)
    if (o.object == name && o.group.empty()) out.simplify_mm = o.simplify_mm;
  only.outputs = {out};
  return only;
}

namespace {

Volume evaluate_only(const Recipe& only, const ObjectOptions& options) {
  const uint64_t budget = budget_of(options.max_memory_bytes);
  const BuiltInputs inputs = build_inputs(only, budget);
  const Plan p = plan(only);
  EvaluateOptions evaluate_options;
  evaluate_options.max_memory_bytes = budget;
  Evaluation evaluation = evaluate(only, p, inputs, evaluate_options);
  return evaluation.take(only.outputs.front().object);
}

}  // namespace

Volume evaluate_object(const Recipe& recipe, const std::string& object, const ObjectOptions& options) {
  ProgressSinkScope progress(options.progress ? options.progress : current_progress_sink());
  const auto threads = thread_limit(options.threads);
  return evaluate_only(recipe_for_object(recipe, object), options);
}

ObjectMesh mesh_volume(const Volume& volume, double simplify_mm, const std::string& what, uint64_t max_memory_bytes) {
  const VolumeOptions& vopt = volume.options();
  detail::require_mesh_memory(volume, budget_of(max_memory_bytes), what, vopt);
  throw_if_cancelled(current_progress_sink());
  ObjectMesh result = extract_object_surface(volume, simplify_mm);
  if (result.mesh.triangles.empty()) throw InvalidInput(what + " is empty: nothing is left to mesh");
  return result;
}

ObjectMesh extract_object_surface(const Volume& volume, double simplify_mm) {
  ObjectMesh result;
  result.voxels = volume.active_voxel_count();
  result.simplify_mm = simplify_mm;
  if (simplify_mm > 0) {
    SimplifyOptions simplify;
    simplify.max_deviation_mm = simplify_mm;
    SimplifyStats stats;
    result.mesh = extract_simplified_surface(volume, simplify, &stats);
    result.extracted_triangles = stats.input_triangles;
  } else {
    result.mesh = extract_surface(volume);
    result.extracted_triangles = result.mesh.triangles.size();
  }
  const double h = volume.voxel_size_mm();
  const SmallShells removed = remove_small_shells(result.mesh, h * h * h);
  result.subvoxel_cavities_filled = removed.cavities;
  result.subvoxel_specks_removed = removed.specks;
  return result;
}

ObjectMesh mesh_object(const Recipe& recipe, const std::string& object, const ObjectOptions& options) {
  ProgressSinkScope progress(options.progress ? options.progress : current_progress_sink());
  const auto threads = thread_limit(options.threads);
  Recipe only = recipe_for_object(recipe, object);
  if (options.simplify_mm >= 0) {
    only.simplify_mm = options.simplify_mm;
    only.outputs.front().simplify_mm.reset();
  }
  const double deviation = simplify_deviation_mm(only, only.outputs.front());
  Volume volume = evaluate_only(only, options);
  return mesh_volume(volume, deviation, recipe.file + ": \"" + only.outputs.front().object + "\"",
                     options.max_memory_bytes);
}

}  // namespace lacuna
