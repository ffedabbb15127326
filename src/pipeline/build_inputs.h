// The one build step of every recipe input: its options (recipe/inputs.h) into geometry, running
// the generator, importing the mesh file or measuring the input it is fitted to. Large inputs come
// out as streams of batches (a CIFS attractor's pieces).
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "bcifs/plate.h"
#include "geometry.h"
#include "pipeline/report.h"
#include "recipe/recipe.h"

namespace lacuna {

namespace fill {
struct WallpaperFill;
}

// An input built: its geometry and what building it found.
struct BuiltInput {
  GeometrySet geometry;
  InputReport report;
  // What the report page draws of it (pipeline/input_figures.h): a lacunar plate's rule set and
  // realization, a lacunar volume's sections and measures, a wallpaper pattern's fundamental region.
  std::shared_ptr<const bcifs::Plate> plate;
  std::shared_ptr<const BcifsVolumeInput> volume;
  std::shared_ptr<const fill::WallpaperFill> pattern;
};

// Every input of a recipe built, in the recipe's order.
struct BuiltInputs {
  std::vector<std::string> names;
  std::vector<BuiltInput> inputs;  // one per name

  // The input of that name; throws InternalError for an unknown name.
  const BuiltInput& at(const std::string& name) const;
};

// What building an input may use besides its options.
struct BuildContext {
  const Recipe* recipe = nullptr;      // its file (for messages and relative paths) and voxel size
  const BuiltInputs* built = nullptr;  // the inputs built so far (those it depends on among them)
  uint64_t max_memory_bytes = 0;       // reading a mesh needing more is refused; 0: the reader's default
};

// Builds one input of context.recipe. Throws InvalidInput, IoError or ResourceLimit naming the
// recipe file and the input's JSON path, as reading it would have.
BuiltInput build_input(const RecipeInput& input, const BuildContext& context);

// Builds every input of the recipe: those without dependencies in the recipe's order, then those
// built from other inputs (which must not themselves be built from others), then checks every
// geometry (finite, positive sizes). `max_memory_bytes` bounds mesh imports (0: half the memory
// available, a run's default budget).
BuiltInputs build_inputs(const Recipe& recipe, uint64_t max_memory_bytes = 0);

// A plate's rule set built from its faces, refused (ResourceLimit naming `file` and `path`.level) when its
// level has more than 2 000 000 sub-faces, and realized at level 0 to check that shared edges match.
bcifs::Plate build_plate(const BcifsPlateInput& input, const std::string& file, const std::string& path);

}  // namespace lacuna
