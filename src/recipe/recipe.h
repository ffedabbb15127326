// A recipe: the JSON file that describes a part. Read into plain data here; the runner
// (src/cli/run_recipe.h) calls the stages in order. The keys are documented in README.md.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "curves/curves.h"
#include "geometry.h"
#include "recipe/json_fields.h"

namespace lacuna {

// What the runner offers inputs that depend on other inputs (lattices fitted to a hull, grades by
// depth inside it), once every mesh is imported.
struct RecipeContext {
  std::function<Box3(const std::string& input)> box_of;  // bounding box of another input (mm)
  // Distance inside another input's solid (mm, 0 outside), exact up to `max_depth_mm`.
  std::function<std::function<double(const Vec3d&)>(const std::string& input, double max_depth_mm)> depth_in;
  // Signed distance to another input's surface (mm, negative inside), exact from -inside_mm to
  // outside_mm.
  std::function<std::function<double(const Vec3d&)>(const std::string& input, double inside_mm, double outside_mm)>
      signed_distance_in;
  // Volume of another input's solid (mm^3).
  std::function<double(const std::string& input)> volume_of;
  // A disk-like mesh patch (a file) flattened onto the square (-1, 1)^2; `where` prefixes errors.
  std::function<curves::SurfaceMap(const std::string& file, const std::string& where)> surface_of_mesh;
};

// Explicit repairs of an imported hull (none by default: a broken hull is an error).
struct MeshRepair {
  double weld_mm = 0;
  bool reorient = false;
  double close_gaps_mm = 0;
  bool allow_overlaps = false;  // accept self-intersecting or overlapping shells (resolved as a union)
  bool any() const { return weld_mm > 0 || reorient || close_gaps_mm > 0; }
};

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
  MeshRepair repair;
  std::vector<std::string> depends_on;  // inputs this one is built from
  std::function<void(RecipeInput& self, const RecipeContext& context)> resolve;  // fills geometry
  nlohmann::json report;            // what building it found (a fill's count, fill fraction, stop reason)
};

struct RecipeOperation {
  enum class Kind { kUnion, kDifference, kIntersection, kOffset, kShell, kInfill };
  std::string name;
  std::string json_path;
  Kind kind = Kind::kUnion;
  std::vector<std::string> operands;  // names of inputs or earlier operations (infill: hull, structure)
  double distance_mm = 0;             // offset: > 0 grows, < 0 shrinks; infill: fusing depth (< 0: a voxel)
  double thickness_mm = 0;            // shell: wall thickness inward; infill: skin thickness
};

// Printability checks applied to every exported object, and what to do when one fails.
struct PrintabilitySettings {
  bool enabled = false;
  double min_wall_mm = 0;
  double min_hole_mm = 0;
  Vec3d build_direction{0, 0, 1};
  double critical_angle_deg = 45;
  enum class OnFailure { kError, kFix, kReport } on_failure = OnFailure::kError;
  double drain_hole_mm = 2.0;      // fix: diameter of the holes drilled from trapped voids
  bool drain_down = false;         // fix: drill along -build_direction instead of the shortest way
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
  std::string object;     // the input or operation to export (of a group: the first)
  // A 3MF with one object per name (two or more inputs or operations), each named after its input or
  // operation; empty for a single object.
  std::vector<std::string> group;
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
  PrintabilitySettings printability;
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
