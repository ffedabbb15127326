// A recipe: the JSON file that describes a part. Read into plain data here; the runner
// (src/cli/run_recipe.h) calls the stages in order. The keys are documented in README.md.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "geometry.h"
#include "recipe/json_fields.h"

namespace lacuna {

// A named input: geometry given inline or produced by a generator, or a mesh file to import.
struct RecipeInput {
  enum class MeshRole { kNone, kSolid, kSurface };

  std::string name;
  std::string type;                // "sphere", "tubes", "mesh", ...
  std::string json_path;           // "inputs.ball", for messages
  GeometrySet geometry;            // everything given inline or generated
  std::string mesh_file;           // a mesh to import (resolved against the recipe's folder)
  MeshRole mesh_role = MeshRole::kNone;
  double surface_thickness_mm = 0; // for kSurface
  double mesh_scale = 1.0;         // applied to the imported mesh, then the translation
  Vec3d mesh_translate_mm;
};

struct RecipeOperation {
  enum class Kind { kUnion, kDifference, kIntersection, kOffset, kShell };
  std::string name;
  std::string json_path;
  Kind kind = Kind::kUnion;
  std::vector<std::string> operands;  // names of inputs or earlier operations
  double distance_mm = 0;             // offset: > 0 grows, < 0 shrinks
  double thickness_mm = 0;            // shell: wall thickness inward
};

// Settings of a tetrahedral (FEA) output.
struct FeaSettings {
  double max_tet_volume_mm3 = 0;      // 0: unbounded
  double quality = 0;                 // radius-edge ratio bound (> 1); 0: none
  double min_dihedral_deg = 0;        // with a quality bound; 0: TetGen's default
  bool preserve_surface = true;       // tetrahedra meet the surface's triangles exactly
  bool msh_version_2 = false;         // Gmsh 2.2 instead of 4.1
  bool quadratic = false;             // .inp with C3D10 elements
  std::vector<std::string> regions;   // objects whose insides are material regions 0, 1, ...
  double time_limit_s = 600;
};

struct RecipeOutput {
  std::string object;     // the input or operation to export
  std::string file;       // a plain file name inside the output folder
  std::string format;     // "stl", "3mf", or a tetrahedral format "msh", "inp", "vtu", "mesh"
  std::string part_name;  // object name inside the file (3MF)
  double decimate_mm = 0; // > 0: decimate the surface to this deviation first (re-checked)
  FeaSettings fea;        // for tetrahedral formats
  std::string json_path;
};

struct Recipe {
  std::string file;            // the recipe's path, for messages
  std::string name;            // defaults to the file's stem
  std::string description;
  double voxel_size_mm = 0.1;
  double band_voxels = 3.0;
  uint64_t seed = 0;
  std::vector<RecipeInput> inputs;
  std::vector<RecipeOperation> operations;
  std::vector<RecipeOutput> outputs;
};

// Reads and validates a recipe file. Throws IoError if it cannot be read, InvalidInput naming the
// file and JSON path for anything malformed: unknown keys (with a suggestion), wrong types,
// non-positive sizes, unknown or forward references, duplicate names.
Recipe load_recipe(const std::string& path);
Recipe parse_recipe(const std::string& text, const std::string& path);

// Generators register the input types they provide. `keys` are the keys allowed besides "type";
// `parse` fills input.geometry (or mesh_file) from the object.
struct InputType {
  std::string type;
  std::vector<std::string> keys;
  std::function<void(const JsonObject& object, RecipeInput& input)> parse;
};
void register_input_type(InputType type);
std::vector<std::string> input_type_names();

}  // namespace lacuna
