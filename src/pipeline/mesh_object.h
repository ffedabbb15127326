// One object of a recipe (an input or an operation) built, evaluated and meshed in memory, without
// writing files: what the Python module's solids and benchmarks call. The surface is made as the
// output transaction makes it (pipeline/write_outputs.h): extracted, simplified, sub-voxel cavities
// filled and specks removed; it is not checked.
#pragma once

#include <cstdint>
#include <string>

#include "geometry.h"
#include "recipe/recipe.h"
#include "solids/volume.h"
#include "util/progress.h"

namespace lacuna {

struct ObjectOptions {
  double simplify_mm = -1;           // >= 0 overrides the recipe's simplification deviation (0: not simplified)
  uint64_t max_memory_bytes = 0;     // 0: half the memory available to the process
  int threads = 0;                   // worker threads for the call; 0: every core
  ProgressSink* progress = nullptr;  // null: the sink current on this thread
};

// An object's surface and what making it found.
struct ObjectMesh {
  TriMesh mesh;
  uint64_t voxels = 0;               // active voxels of the level set it was meshed from
  double simplify_mm = 0;            // deviation it was simplified to (mm; 0: not simplified)
  uint64_t extracted_triangles = 0;  // before simplification
  size_t subvoxel_cavities_filled = 0;
  size_t subvoxel_specks_removed = 0;
};

// The recipe with one output, the object `object` (default: the first output's), so that a plan
// builds what it needs and nothing else. Throws InvalidInput for an unknown object.
Recipe recipe_for_object(const Recipe& recipe, const std::string& object);

// The level set of the recipe's object `object` (default: the first output's), with only what it
// needs built. Throws InvalidInput for an unknown object and whatever building and evaluating throw
// (InvalidInput, IoError, ResourceLimit before allocating beyond the budget, Cancelled).
Volume evaluate_object(const Recipe& recipe, const std::string& object, const ObjectOptions& options = {});

// The surface of `volume`: marching tetrahedra, simplified block by block to simplify_mm when it
// is > 0, with sub-voxel cavities filled and specks removed. No memory check and no check for an
// empty result: the callers say what they mesh.
ObjectMesh extract_object_surface(const Volume& volume, double simplify_mm);

// The surface of a level set simplified to `simplify_mm` (0: the plain marching-tetrahedra surface),
// with cavities and specks of less than a voxel's volume removed. Throws ResourceLimit before meshing
// when the mesh would not fit `max_memory_bytes` (0: half the memory available), InvalidInput when
// nothing is left; `what` names the object in messages.
ObjectMesh mesh_volume(const Volume& volume, double simplify_mm, const std::string& what,
                       uint64_t max_memory_bytes = 0);

// evaluate_object() then mesh_volume() at the recipe's deviation for its voxel size (or the
// options').
ObjectMesh mesh_object(const Recipe& recipe, const std::string& object, const ObjectOptions& options = {});

}  // namespace lacuna
