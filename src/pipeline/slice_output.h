// A recipe's object as layers for printers (`lacuna slice`): its level set cut at the centre of every
// layer, with no mesh, into a PNG stack (a folder or a zip) or a CLI file; every layer checked before
// anything is written (contours closed, simple, disjoint, oriented; the image's area against the
// contours'), and all or nothing on disk.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "pipeline/pipeline.h"

namespace lacuna {

enum class LayerFormat { kPng, kPngZip, kCli, kCliBinary };

// The format a path asks for: .cli (ASCII unless `binary`), .zip (a zipped PNG stack), anything
// else a folder of PNGs. Throws InvalidInput for .sl1 and other archive kinds it cannot write.
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

// Slices the recipe's object into `output`. Throws as run() does (InvalidInput, IoError,
// ResourceLimit, Cancelled) and InvalidInput for bad sizes or an empty object; when a layer fails its
// checks the report is not valid and nothing is written.
SliceReport slice_recipe(const std::string& recipe_path, const std::string& output, const SliceOptions& options);

// The report as JSON (per layer figures under "layers").
nlohmann::json to_json(const SliceReport& report);

}  // namespace lacuna
