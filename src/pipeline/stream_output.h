// A recipe's meshes streamed slab by slab (`lacuna run --stream`): each object evaluated one slab
// at a time along z, its surface extracted and simplified as the slabs come
// (solids/simplify.h, StreamedSurface) and written to one binary STL as it goes, then the written
// file checked chunk by chunk (solids/check.h, ChunkedCheck). Memory follows the slab height, not
// the part; the file is the one a whole-grid run writes, byte for byte, where that fits.
#pragma once

#include <cstdint>
#include <nlohmann/json_fwd.hpp>
#include <string>
#include <utility>
#include <vector>

#include "pipeline/pipeline.h"
#include "pipeline/ranks.h"
#include "recipe/recipe.h"
#include "solids/check.h"

namespace lacuna {

struct StreamOptions {
  // Slab height (mm, rounded up to whole blocks of 32 voxels); 0: the whole part at once when its
  // level set fits the budget, otherwise the highest slabs that do.
  double slab_mm = 0;
  RunOptions run;  // output folder, voxel size, simplification, budget, threads, progress, report
  // A job over several processes (the same call in each, `mpirun -np K lacuna run --stream`): each
  // streams a block of the slabs into a part beside the output (a file system they share), the
  // first joins the parts, checks the file and writes; the file is the same bytes as one process's.
  // Null or one alone: this process does everything. Only the first's report has figures.
  JobRanks* ranks = nullptr;
};

struct StreamedOutput {
  std::string file;     // as written
  std::string object;
  uint64_t triangles = 0;            // written
  uint64_t extracted_triangles = 0;  // of the marching-tetrahedra surface, before simplification
  size_t specks_removed = 0, cavities_filled = 0;  // shells below a voxel's volume, as a whole run removes them
  size_t slabs = 1;
  double slab_mm = 0, halo_mm = 0;   // 0: the whole part at once
  uint64_t memory_estimate_bytes = 0;  // the largest slab's level set (or the whole part's)
  uint64_t bytes = 0;
  size_t check_chunks = 0;           // the file was checked in this many chunks, two at a time
  double simplify_mm = 0;
  MeshCheckReport check;
};

struct StreamReport {
  std::string recipe, output_dir;
  double voxel_size_mm = 0;
  std::vector<StreamedOutput> outputs;
  std::vector<std::pair<std::string, double>> stage_seconds;
  bool valid = false;  // every file passed its checks; otherwise nothing was written
};

// Streams every output of the recipe: each must be an STL of one object with a positive
// simplification deviation and no render, printability or FEA settings (those need the whole
// mesh); InvalidInput names the output otherwise. Throws as run() does; when a written file fails
// its checks the report is not valid and nothing is left on disk.
StreamReport stream_recipe(const std::string& recipe_path, const StreamOptions& options);
StreamReport stream_recipe(Recipe recipe, const StreamOptions& options);

nlohmann::json to_json(const StreamReport& report);

}  // namespace lacuna
