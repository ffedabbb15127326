// A recipe: the JSON file that describes a part, read into plain data (no JSON, no callbacks) that
// the pipeline (pipeline/pipeline.h) runs. The keys are documented in README.md.
#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <variant>
#include <vector>

#include "geometry.h"
#include "recipe/inputs.h"

namespace lacuna {

// A named input and its options, as the recipe gives them.
struct RecipeInput {
  std::string name;
  std::string json_path;  // "inputs.ball", for messages
  InputSpec spec;
};

// A CSG operation on two or more objects, applied in order: their union, the first minus the
// others, their intersection.
struct CsgOperation {
  enum class Kind { kUnion, kDifference, kIntersection };
  Kind kind = Kind::kUnion;
  std::vector<std::string> of;  // inputs or earlier operations
};

// An object grown (distance > 0) or shrunk (distance < 0) by a distance.
struct OffsetOperation {
  std::string of;
  double distance_mm = 0;
};

// An object hollowed into a wall of a thickness inward.
struct ShellOperation {
  std::string of;
  double thickness_mm = 0;
};

// A hull filled with a structure inside a skin: (H minus erode(H, skin)) union (S inside erode(H, skin)),
// the structure fused into the skin by fuse_mm.
struct InfillOperation {
  std::string hull;
  std::string structure;
  double skin_mm = 1;
  double fuse_mm = -1;  // < 0: a voxel, at most half the skin
};

using OperationSpec = std::variant<CsgOperation, OffsetOperation, ShellOperation, InfillOperation>;

// The objects an operation reads, in order.
std::vector<std::string> operands(const OperationSpec& op);

struct RecipeOperation {
  std::string name;
  std::string json_path;  // "operations[2]", for messages
  OperationSpec spec;
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
  // Meshed outputs: separate bodies enclosing less than this (mm^3) are loose pieces, debris in the powder
  // or resin; "fix" removes them (0: not checked).
  double min_piece_mm3 = 0;
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
  uint64_t max_memory_bytes = 0;      // TetGen's memory limit; 0: half the memory available (a run sets its budget)
};

struct RecipeOutput {
  std::string object;     // the input or operation to export (of a group: the first)
  // A 3MF with one object per name (two or more inputs or operations), each named after its input or
  // operation; empty for a single object.
  std::vector<std::string> group;
  std::string file;       // a plain file name inside the output folder
  std::string format;     // "stl", "3mf", "drc", a tetrahedral format "msh", "inp", "vtu", "mesh", or layers "cli", "sl1", "png_layers"
  std::string part_name;  // object name inside the file (3MF)
  // Deviation of this output's compact mesh (mm; 0: the plain marching-tetrahedra surface);
  // unset: the recipe's. `decimate_mm` is its older name.
  std::optional<double> simplify_mm;
  // .drc: the most any vertex may move by quantization (mm); unset: a tenth of the voxel size.
  std::optional<double> quantize_mm;
  // A picture of the output's surface beside it (PNG), with markers at printability findings.
  struct Render {
    std::string file;                     // a plain .png file name in the output folder
    int width = 1200, height = 900;       // pixels
    std::vector<std::string> views{"iso"};  // "iso", "front", "top", "side"
    std::optional<double> section;          // cut at this fraction of the height (0 to 1, along z)
  };
  std::optional<Render> render;
  // Layers cut from the level set (format "cli", "sl1" or "png_layers", a zipped PNG stack): no mesh is made.
  struct Layers {
    double layer_mm = 0;       // 0: the voxel size
    double pixel_mm = 0;       // 0: the voxel size
    double tolerance_mm = -1;  // CLI contours simplified this far; < 0: a quarter pixel
    bool binary = false;       // CLI: binary rather than ASCII
  };
  std::optional<Layers> layers;
  FeaSettings fea;        // for tetrahedral formats
  std::string json_path;
};

struct Recipe {
  std::string file;            // the recipe's path, for messages
  std::string name;            // defaults to the file's stem
  std::string description;
  double voxel_size_mm = 0.1;
  double band_voxels = 3.0;
  // Deviation of the compact meshes written (mm; 0: the plain marching-tetrahedra surface); unset:
  // kDefaultSimplifyVoxels voxels.
  std::optional<double> simplify_mm;
  uint64_t seed = 0;
  std::vector<RecipeInput> inputs;
  std::vector<RecipeOperation> operations;
  std::vector<RecipeOutput> outputs;
  PrintabilitySettings printability;
  // Objects a recipe split itself into, with their display colours ("#rrggbb") in a 3MF: a fill_motifs
  // input NAME coloured without "keep" becomes NAME-0 ... NAME-(K-1), one colour class each, and the
  // union operation NAME of them (first in `operations`); a .3mf of NAME holds the K parts as objects.
  std::map<std::string, std::string> display_colors;
};

// The default deviation of compact meshes, in voxels. Measured on the constant-density capsule
// walk of 1 000 capsules (lacuna_capsules_bench --simplify D --hausdorff): at 0.1 / 0.2 / 0.3 voxel
// the sampled one-sided Hausdorff distances stay within the deviation both ways (worst 0.75 / 0.79 /
// 0.73 of it), with 1.43 / 1.08 / 0.90 times the triangles of a 16-sided mesh union and volumes within
// 0.03 % of the unsimplified surface; 0.2 keeps the deviation a fifth of what the voxels resolve.
constexpr double kDefaultSimplifyVoxels = 0.2;

// The deviation an output's mesh is simplified to (mm; 0: not simplified).
double simplify_deviation_mm(const Recipe& recipe, const RecipeOutput& output);

// Reads and validates a recipe file. Throws IoError if it cannot be read, InvalidInput naming the
// file and JSON path for anything malformed: unknown keys (with a suggestion), wrong types,
// non-positive sizes, unknown or forward references, duplicate names. Nothing is generated while
// reading: the pipeline builds the inputs (pipeline/build_inputs.h).
Recipe load_recipe(const std::string& path);
Recipe parse_recipe(const std::string& text, const std::string& path);

// The input types a recipe can name, sorted.
std::vector<std::string> input_type_names();

}  // namespace lacuna
