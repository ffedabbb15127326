// Figures of a run's inputs for its report page: a lacunar plate's density map and measure plot (as
// `lacuna bcifs measure` draws them), a wallpaper pattern's picture.
#pragma once

#include <array>

#include <cstdint>
#include <string>
#include <vector>

#include "pipeline/build_inputs.h"
#include "pipeline/generators.h"

namespace lacuna {

struct PlateImages {
  std::vector<uint8_t> density_png;  // 1024 x 1024: the last level's local density in windows of mask_px
  std::vector<uint8_t> plot_png;     // 1200 x 400: ln A_i, ln P_i against i, the box counting, R_i of the first face
};

// The density map and measure plot of a plate's measures.
PlateImages plate_images(const PlateMeasures& measures, int mask_px = 31);

struct VolumeImages {
  std::array<std::vector<uint8_t>, 3> section_png;  // 1024 x 1024: the sections' local density (x, y, z planes)
  std::vector<uint8_t> plot_png;  // 1200 x 400: ln V_i, ln S_i against i, the 3D box counting, R_i of the first cell
};

// The section density maps (windows of mask_px pixels) and measure plot of a volume's measures.
VolumeImages volume_images(const VolumeCellMeasures& measures, int mask_px = 31);

struct InputFigure {
  std::string caption;
  std::string type;   // "image/png" or "image/svg+xml"
  std::string bytes;  // the file's
};

// Per lacunar plate (its geometry measured from level 0 to its own, at most 8, its counts to 10 or
// its own level) its density map and plot; per
// wallpaper pattern its picture over 3 x 3 cells; in the recipe's order.
std::vector<InputFigure> input_figures(const BuiltInputs& inputs);

}  // namespace lacuna
