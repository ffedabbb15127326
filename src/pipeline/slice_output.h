// A recipe's object as layers for printers (`lacuna slice`): its level set cut at the centre of every
// layer, with no mesh, into a PNG stack (a folder or a zip) or a CLI file; every layer checked before
// anything is written (contours closed, simple, disjoint, oriented; the image's area against the
// contours'), and all or nothing on disk.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "export/layers_io.h"
#include "layers/layers.h"
#include "pipeline/pipeline.h"
#include "solids/volume.h"

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

// Cuts `volume` into layers and checks them (the report is not valid when a layer failed). `what`
// names the solid in messages. Throws InvalidInput for bad sizes or an empty solid, ResourceLimit past
// a million layers, 2^28 pixels per layer or the budget (0: half the memory available).
SlicedLayers slice_volume(const Volume& volume, const LayerSettings& settings, const std::string& what,
                          uint64_t max_memory_bytes = 0);

// The one file of a zipped PNG stack or a CLI file; `where` names it in messages.
std::string layers_file(const SlicedLayers& sliced, const std::string& where);

// Slices the recipe's object into `output`. Throws as run() does (InvalidInput, IoError,
// ResourceLimit, Cancelled) and InvalidInput for bad sizes or an empty object; when a layer fails its
// checks the report is not valid and nothing is written.
SliceReport slice_recipe(const std::string& recipe_path, const std::string& output, const SliceOptions& options);

// The report as JSON (per layer figures under "layers").
nlohmann::json to_json(const SliceReport& report);

}  // namespace lacuna
