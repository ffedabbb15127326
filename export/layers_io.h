// Layer files for printers: PNG stacks (greyscale layer images with a manifest, in a folder or a
// zip) and CLI files (Common Layer Interface 2.0, ASCII or binary: closed polylines per layer).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "layers/layers.h"

namespace lacuna {

// Where the layers of a part lie: layer k spans z0 + k * layer_mm .. z0 + (k + 1) * layer_mm and is
// cut at its centre; its pixels are those of `grid`.
struct LayerStack {
  std::string name;  // the object's
  double layer_mm = 0.05;
  double z0_mm = 0;
  size_t layers = 0;
  LayerGrid grid;
};

// An 8-bit greyscale PNG of a layer image (row j = 0 of the grid, the lowest y, is the PNG's bottom
// row: seen from above with x to the right and y up).
std::string encode_layer_png(const std::vector<uint8_t>& image, const LayerGrid& grid);

// The PNG of an image given top row first (as a printer's display is).
std::string encode_grey_png(int width, int height, const std::vector<uint8_t>& rows_top_first);

// The layer images' file names: layer_00000.png, ...
std::string layer_file_name(size_t layer);

// manifest.json of a PNG stack: layer height, pixel size, origin (the corner of pixel (0, 0) at the
// bottom of layer 0), layer count, image size and the files.
std::string layer_manifest(const LayerStack& stack);

// A CLI file of the contours of every layer: units of 1 mm, the layer's top height above z0, outer
// contours counter-clockwise (direction 1) and holes clockwise (0), each closed by repeating its
// first point. ASCII writes 6 decimals; binary uses the long commands (127, 130) with float32.
std::string cli_file(const LayerStack& stack, const std::vector<Contours>& layers, bool binary);

// A resin printer as PrusaSlicer describes it in an SL1 archive (the defaults: the Original Prusa
// SL1's display and exposures, as PrusaSlicer 2.5 writes them).
struct Sl1Printer {
  double display_width_mm = 120, display_height_mm = 68;
  int display_pixels_x = 2560, display_pixels_y = 1440;
  double exposure_s = 10, initial_exposure_s = 15;
  int faded_layers = 10;
  double area_fill_percent = 50;           // layers covering more of the display tilt slowly
  double fast_tilt_s = 5, slow_tilt_s = 8;
  // PrusaSlicer 2.5 rasterizes a portrait display with the image's rows along the bed's x at
  // display_height / display_pixels_y mm and its columns along y at display_width / display_pixels_x.
  double row_step_mm() const { return display_height_mm / display_pixels_y; }
  double column_step_mm() const { return display_width_mm / display_pixels_x; }
};

// What an SL1 archive's config.ini reports of a job.
struct Sl1Job {
  std::string name;      // jobDir and the layer files' prefix
  double layer_mm = 0.05;
  size_t layers = 0;
  size_t slow_layers = 0;   // layers over area_fill (slow tilt)
  double used_ml = 0;       // resin: the layers' areas times their height
  double print_s = 0;       // estimated print time
};

// The name of layer k in an SL1 archive: NAME00000.png, ...
std::string sl1_layer_name(const std::string& job, size_t layer);

// config.ini and prusaslicer.ini of an SL1 archive, with PrusaSlicer 2.5's keys in its order.
std::string sl1_config_ini(const Sl1Job& job, const Sl1Printer& printer);
std::string sl1_prusaslicer_ini(const Sl1Job& job, const Sl1Printer& printer);

// Lacuna's print-time estimate for an SL1 job: per layer its exposure (the first faded_layers at the
// initial exposure), its tilt (slow over area_fill) and 5 s per mm of layer height (fitted to
// PrusaSlicer 2.5's estimates: 1650 s against its 1624 s on the tests' hollow sphere, +1.6 %).
double sl1_print_seconds(const std::vector<double>& layer_areas_mm2, double layer_mm, const Sl1Printer& printer,
                         size_t* slow_layers);

}  // namespace lacuna
