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
#include "solids/budget.h"
#include "solids/volume.h"
#include "solids/voxelize.h"
#include "util/progress.h"

namespace lacuna {

struct EvaluateOptions {
  uint64_t max_memory_bytes = 0;     // 0: half the memory available to the process
  ProgressSink* progress = nullptr;  // null: the sink current on this thread
  // A streamed run's slab: the inputs are built only there (see voxelize()), the operations act on
  // what that leaves, and the memory is estimated for the slab. Every object then equals the whole
  // run's bit for bit at least its halo inside the slab (object_extents()).
  const ZSlab* slab = nullptr;
  // A streamed run's inputs' closed meshes, converted in the first slab and kept for the others.
  std::map<std::string, Volume>* converted_meshes = nullptr;
  // A streamed run's offsets of inputs' own meshes (offset, shell and infill operations on an input
  // that is one closed mesh), by operation: made whole in the first slab, clipped in each.
  std::map<std::string, std::vector<Volume>>* mesh_offsets = nullptr;
  // The plan's estimator, made once for every slab (null: made here).
  const class MemoryEstimator* estimator = nullptr;
};

// Where an object can be, known before any voxel is made.
struct ObjectExtent {
  Box3 box;            // holds the solid: the inputs' geometry, grown by unions and outward offsets
  double halo_mm = 0;  // evaluated in a slab, the object equals the whole run's this far inside it
};

// The extent of every object the plan builds (inputs and operations).
std::map<std::string, ObjectExtent> object_extents(const Recipe& recipe, const Plan& plan, const BuiltInputs& inputs);

// The level sets the outputs mesh, and what the run needs to report about them.
struct Evaluation {
  std::map<std::string, Volume> volumes;          // objects not yet read for the last time
  std::map<std::string, int> uses;                // the reads each of them has left
  std::map<std::string, double> hull_volume_mm3;  // infill operations: their hull's volume
  uint64_t memory_estimate_bytes = 0;
  uint64_t memory_budget_bytes = 0;
  std::vector<std::pair<std::string, double>> stage_seconds;  // timed so far; write_outputs adds its own after them
  std::map<std::string, ObjectExtent> extents;    // every object's, known before evaluating

  // The object's level set for one of its reads; released here after its last.
  Volume take(const std::string& name);
};

// The memory evaluate() estimates for a plan, before building anything; what voxelizing each input
// needs is worked out once (a streamed input is walked for it), so slabs of many heights can be tried.
struct MemoryNeed {
  uint64_t grid_bytes = 0;  // every level set the plan keeps (conservatively, all at once)
  uint64_t mesh_bytes = 0;  // the largest surface it meshes and checks (or distances again)
  uint64_t voxels = 0;
  uint64_t triangles = 0;
  uint64_t bytes() const { return grid_bytes + mesh_bytes; }
};

// Operations that distance an input's own closed mesh, by name, each with that mesh.
using MeshOffsetOperations = std::map<std::string, const TriMesh*>;

class MemoryEstimator {
 public:
  MemoryEstimator(const Recipe& recipe, const Plan& plan, const BuiltInputs& inputs);
  // What evaluating the plan (in the slab, when given) needs.
  MemoryNeed need(const ZSlab* slab = nullptr) const;
  // The most any of the slabs needs, or the whole part when there are none.
  uint64_t bytes(const std::vector<ZSlab>& slabs = {}) const;
  const std::map<std::string, ObjectExtent>& extents() const { return extents_; }
  // The offset, shell and infill operations that distance an input's own closed mesh (mesh_offsets),
  // each with that mesh.
  const MeshOffsetOperations& mesh_offset_operations() const { return from_mesh_; }

 private:
  const Recipe& recipe_;
  const Plan& plan_;
  MeshOffsetOperations from_mesh_;
  std::map<std::string, ObjectExtent> extents_;
  std::map<std::string, MemoryEstimate> inputs_;
};

// Voxelizes the planned inputs and evaluates the planned operations. Throws ResourceLimit, before
// allocating, when the part reaches too far from the origin for float32 output at this voxel size or
// when the estimated memory exceeds the budget (the message names a voxel size that fits), and
// InvalidInput naming the recipe and JSON path of a piece that cannot be voxelized.
Evaluation evaluate(const Recipe& recipe, const Plan& plan, const BuiltInputs& inputs, const EvaluateOptions& options = {});

}  // namespace lacuna
