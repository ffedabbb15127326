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

}  // namespace lacuna
