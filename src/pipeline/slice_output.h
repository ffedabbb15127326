// A recipe's object as layers for printers (`lacuna slice`): its level set cut at the centre of every
// layer, with no mesh, into a PNG stack (a folder or a zip) or a CLI file; every layer checked before
// anything is written (contours closed, simple, disjoint, oriented; the image's area against the
// contours'), and all or nothing on disk.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "export/layers_io.h"
#include "export/zip_archive.h"
#include "layers/layers.h"
#include "pipeline/pipeline.h"
#include "pipeline/ranks.h"
#include "recipe/recipe.h"
#include "solids/volume.h"
#include "util/progress.h"

namespace lacuna {

enum class LayerFormat { kPng, kPngZip, kCli, kCliBinary, kSl1 };

// The format a path asks for: .cli (ASCII unless `binary`), .zip (a zipped PNG stack), .sl1 (an SL1
// archive for resin printers, as PrusaSlicer writes them), anything else a folder of PNGs. Throws
// InvalidInput for other archive kinds it cannot write.
LayerFormat layer_format_from_path(const std::string& path, bool binary);

struct SliceOptions {
  std::string object;         // the recipe's object (default: its first output's)
  double layer_mm = 0;        // layer height; 0: the voxel size
  double pixel_mm = 0;        // the pixels the level set is sampled on (images and contours); 0: the voxel size
  double tolerance_mm = -1;   // CLI contours simplified this far; < 0: a quarter pixel; 0: not simplified
  bool binary = false;        // CLI: binary rather than ASCII
  // Streaming: the object is evaluated slab by slab, this high (mm, rounded up to whole leaves of
  // 8 voxels), each with the halo its operations need; 0: the whole part at once when its level
  // set fits the memory budget, otherwise the highest slab that does.
  double slab_mm = 0;
  // A job over several processes (the same call in each): their ranks; null or one alone: this
  // process does everything. The files are the same bytes as one process's.
  JobRanks* ranks = nullptr;
  RunOptions run;             // voxel size, budget, threads, progress
};

struct LayerFigures {
  double z_mm = 0;               // where the layer is cut
  double image_area_mm2 = 0;     // the image's pixel sum
  double contour_area_mm2 = 0;   // the contours' area
  double contour_length_mm = 0;
  size_t contours = 0;
  bool simplified = true;        // false: the simplified contours failed their checks, the plain ones were kept
};

struct SliceReport {
  std::string output;  // the folder or file written
  LayerFormat format = LayerFormat::kPng;
  std::string object;
  double layer_mm = 0, pixel_mm = 0, tolerance_mm = 0, voxel_size_mm = 0;
  double z0_mm = 0;    // the bottom of layer 0: the solid's lowest point
  int width = 0, height = 0;
  std::vector<LayerFigures> layers;
  uint64_t bytes = 0;  // written
  size_t slabs = 1;    // evaluated one after another (1: the whole part at once)
  double slab_mm = 0;  // their height (0: the whole part), each with halo_mm more below and above
  double halo_mm = 0;
  uint64_t memory_estimate_bytes = 0;  // the largest slab's (or the whole part's) estimate
  std::vector<std::pair<std::string, double>> stage_seconds;
  bool valid = false;  // every layer passed; otherwise nothing was written
  std::vector<std::string> problems;
};

// How to cut one solid into layers.
struct LayerSettings {
  LayerFormat format = LayerFormat::kPng;
  std::string name;            // the object's, in the files
  double layer_mm = 0;         // 0: the voxel size
  double pixel_mm = 0;         // 0: the voxel size
  double tolerance_mm = -1;    // CLI simplification; < 0: a quarter pixel
  Sl1Printer printer;          // SL1: the display (its pixels replace pixel_mm) and exposures
};

// A solid cut into layers, checked, not written: the report's figures and problems, and the layers.
struct SlicedLayers {
  SliceReport report;              // output, object and bytes unset
  LayerStack stack;
  std::vector<std::string> pngs;   // PNG formats and SL1: one image per layer
  Sl1Job job;                      // SL1: what config.ini reports
  Sl1Printer printer;
  std::vector<Contours> contours;  // CLI formats: per layer, as they will be written
};

// Cuts a solid into layers as its level set comes, part by part, bottom to top. The pixel grid (and
// the layers' top) come from a box known to hold the solid; the layers start at the solid's lowest
// point. `what` names the solid in messages. Throws InvalidInput for bad sizes, ResourceLimit past a
// million layers, 2^28 pixels per layer or the budget (0: half the memory available).
class LayerSlicer {
 public:
  LayerSlicer(const LayerSettings& settings, double voxel_size_mm, std::string what, uint64_t max_memory_bytes = 0);
  // The pixel grid over `box` (xy; its top ends the layers) and layer 0's bottom at z0_mm.
  void start(const Box3& box, double z0_mm);
  bool started() const { return started_; }
  // Where layer k is cut.
  double layer_z_mm(size_t k) const;
  // Images go to `write` (layer, PNG bytes; called from worker threads) as they are made rather
  // than staying in memory (SlicedLayers::pngs then holds empty strings).
  void spool_images(std::function<void(size_t, const std::string&)> write) { spool_ = std::move(write); }
  // Samples, from `volume`, every layer not sampled yet whose plane lies below z_end_mm.
  void sample(const Volume& volume, double z_end_mm);
  // Before sampling: the layers below z_mm are another process's.
  void skip_to(double z_mm);
  // The layers sampled here (figures, problems, contours) for another process to unpack(); unpack()
  // takes them in and returns the texts appended to them (length-prefixed, 8-byte length).
  std::string pack() const;
  std::vector<std::string> unpack(const std::string& bytes);
  // Every layer sampled: the checked layers (the report is not valid when a layer failed).
  SlicedLayers finish();

 private:
  LayerSettings settings_;
  std::string what_;
  uint64_t budget_ = 0;
  SlicedLayers out_;
  std::vector<std::vector<std::string>> problems_;
  std::function<void(size_t, const std::string&)> spool_;
  size_t first_ = 0, next_ = 0;  // the layers sampled here: [first_, next_)
  std::vector<uint8_t> done_;     // every layer sampled here or unpacked
  bool started_ = false;
  std::unique_ptr<Progress> bar_;
};


// Cuts `volume` into layers and checks them (the report is not valid when a layer failed), the
// pixel grid over `planned_box` when given (an evaluation's ObjectExtent, as `lacuna slice` uses),
// otherwise over the solid's box. Throws as LayerSlicer does and InvalidInput for an empty solid.
SlicedLayers slice_volume(const Volume& volume, const LayerSettings& settings, const std::string& what,
                          uint64_t max_memory_bytes = 0, const Box3* planned_box = nullptr);

// The one file of a zipped PNG stack or a CLI file; `where` names it in messages.
std::string layers_file(const SlicedLayers& sliced, const std::string& where);

// The entries of a zipped PNG stack or an SL1 archive: the texts (kept alive in `texts`) and the
// images, from `sliced.pngs` or, when given, from the files they were spooled to (one per layer).
std::vector<ZipEntry> layer_archive_entries(const SlicedLayers& sliced, std::vector<std::string>& texts,
                                            const std::vector<std::string>* image_files = nullptr);

// Slices the recipe's object into `output`. Throws as run() does (InvalidInput, IoError,
// ResourceLimit, Cancelled) and InvalidInput for bad sizes or an empty object; when a layer fails its
// checks the report is not valid and nothing is written.
SliceReport slice_recipe(const std::string& recipe_path, const std::string& output, const SliceOptions& options);
// The same for a recipe already loaded (the Python module's).
SliceReport slice_recipe(Recipe recipe, const std::string& output, const SliceOptions& options);

// The report as JSON (per layer figures under "layers").
nlohmann::json to_json(const SliceReport& report);

}  // namespace lacuna
