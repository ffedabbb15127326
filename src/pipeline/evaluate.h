// The CSG interpreter: a recipe's needed inputs voxelized and its operations applied in order, each
// n-ary operation folding its operands from the first, with the memory refused before anything
// large is allocated.
#pragma once

#include <cstdint>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "pipeline/build_inputs.h"
#include "pipeline/plan.h"
#include "recipe/recipe.h"
#include "solids/volume.h"
#include "util/progress.h"

namespace lacuna {

struct EvaluateOptions {
  uint64_t max_memory_bytes = 0;     // 0: half the memory available to the process
  ProgressSink* progress = nullptr;  // null: the sink current on this thread
};

// The level sets the outputs mesh, and what the run needs to report about them.
struct Evaluation {
  std::map<std::string, Volume> volumes;          // objects not yet read for the last time
  std::map<std::string, int> uses;                // the reads each of them has left
  std::map<std::string, double> hull_volume_mm3;  // infill operations: their hull's volume
  uint64_t memory_estimate_bytes = 0;
  uint64_t memory_budget_bytes = 0;
  std::vector<std::pair<std::string, double>> stage_seconds;  // timed so far; write_outputs adds its own after them

  // The object's level set for one of its reads; released here after its last.
  Volume take(const std::string& name);
};

// Voxelizes the planned inputs and evaluates the planned operations. Throws ResourceLimit, before
// allocating, when the part reaches too far from the origin for float32 output at this voxel size or
// when the estimated memory exceeds the budget (the message names a voxel size that fits), and
// InvalidInput naming the recipe and JSON path of a piece that cannot be voxelized.
Evaluation evaluate(const Recipe& recipe, const Plan& plan, const BuiltInputs& inputs, const EvaluateOptions& options = {});

}  // namespace lacuna
