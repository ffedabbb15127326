#include "pipeline/input_figures.h"

#include <algorithm>
#include <cstdio>

#include "bcifs/realize.h"
#include "bcifs/topology.h"
#include "fill/wallpaper.h"

namespace lacuna {
namespace {

// Rows bottom-up (the raster) to top-down (PNG).
std::vector<uint8_t> flip_rows(const std::vector<uint8_t>& rgb, int width, int height) {
  std::vector<uint8_t> out(rgb.size());
  const size_t row = size_t(3 * width);
  for (int y = 0; y < height; ++y)
    std::copy(rgb.begin() + long(size_t(y) * row), rgb.begin() + long(size_t(y + 1) * row),
              out.begin() + long(size_t(height - 1 - y) * row));
  return out;
}

std::string as_string(const std::vector<uint8_t>& bytes) { return std::string(bytes.begin(), bytes.end()); }

}  // namespace

PlateImages plate_images(const PlateMeasures& measures, int mask_px) {
  constexpr int kSide = 1024;
  bcifs::Raster raster = bcifs::square_raster(measures.polygons, kSide);
  bcifs::rasterize(measures.polygons, raster);
  const std::vector<uint8_t> mask = bcifs::mask_of(raster);
  const std::vector<uint8_t> density = bcifs::density_colours(bcifs::density_map(mask, kSide, kSide, mask_px));
  PlateImages images;
  images.density_png = bcifs::encode_png(kSide, kSide, flip_rows(density, kSide, kSide), 6);
  // R_i of the plate's first face.
  const std::vector<double> ratio = measures.faces.empty() ? std::vector<double>{} : measures.faces[0].ratio;
  const double limit = measures.faces.empty() ? 0 : measures.faces[0].limit;
  images.plot_png = bcifs::encode_png(1200, 400, bcifs::plot_measures(measures.geometry, measures.boundary, ratio, limit, 1200, 400), 6);
  return images;
}

VolumeImages volume_images(const VolumeCellMeasures& measures, int mask_px) {
  VolumeImages images;
  for (size_t axis = 0; axis < 3; ++axis) {
    const std::vector<uint8_t> density =
        bcifs::density_colours(bcifs::density_map(measures.sections[axis], kSectionPixels, kSectionPixels, mask_px));
    images.section_png[axis] =
        bcifs::encode_png(kSectionPixels, kSectionPixels, flip_rows(density, kSectionPixels, kSectionPixels), 6);
  }
  bcifs::GeometricMeasures g;
  g.area = measures.geometry.volume;
  g.perimeter = measures.geometry.surface;
  const std::vector<double> ratio = measures.cells.empty() ? std::vector<double>{} : measures.cells[0].ratio;
  const double limit = measures.cells.empty() ? 0 : measures.cells[0].limit;
  bcifs::PlotLabels labels;
  labels.first = "VOLUME";
  labels.second = "SURFACE";
  labels.first_symbol = "V";
  labels.second_symbol = "S";
  images.plot_png =
      bcifs::encode_png(1200, 400, bcifs::plot_measures(g, measures.region, ratio, limit, 1200, 400, labels), 6);
  return images;
}

std::vector<InputFigure> input_figures(const BuiltInputs& inputs) {
  std::vector<InputFigure> figures;
  for (size_t i = 0; i < inputs.names.size(); ++i) {
    const std::string& name = inputs.names[i];
    const BuiltInput& input = inputs.inputs[i];
    if (input.plate) {
      const int level = std::min(input.plate->options.level, kMaxGeometryLevel);
      PlateMeasures measures = measure_plate(*input.plate, 0, level);
      // The counts to level 10 at least (they need no geometry), so R_i nears its limit.
      for (size_t f = 0; f < measures.faces.size(); ++f)
        measures.faces[f] = bcifs::lacunarity(input.plate->rules, input.plate->rules.roots[f], std::max(level, 10));
      const PlateImages images = plate_images(measures);
      const std::string levels = "levels 0 to " + std::to_string(level) + ", R_i to " + std::to_string(std::max(level, 10));
      figures.push_back({name + ": density at level " + std::to_string(level) + " (windows of 31 of 1024 pixels)",
                         "image/png", as_string(images.density_png)});
      figures.push_back({name + ": area and perimeter, box counting (" + levels + ")", "image/png",
                         as_string(images.plot_png)});
    }
    if (input.volume) {
      // Drawn at its level, or the deepest below with at most 50 000 cells, so that the pictures cost little
      // beside the run (the whole run's peak memory is taken before them).
      const bcifs::VolumeRules rules = bcifs::build_volume_rules(input.volume->spec);
      int drawn = input.volume->level;
      while (drawn > 0 && bcifs::volume_cells(rules, drawn) > 50000) --drawn;
      const VolumeCellMeasures measures = measure_volume(input.volume->spec, input.volume->options, drawn);
      VolumeImages images = volume_images(measures);
      const std::string level = std::to_string(measures.geometry_last);
      for (size_t axis = 0; axis < 3; ++axis) {
        char at[32];
        std::snprintf(at, sizeof at, "%.4g", measures.section_mm[axis]);
        figures.push_back({name + ": density of the section " + "xyz"[axis] + " = " + at + " mm at level " + level +
                               " (windows of 31 of 1024 pixels)",
                           "image/png", as_string(images.section_png[axis])});
      }
      figures.push_back({name + ": volume and surface, 3D box counting (levels 0 to " + level + "), R_i", "image/png",
                         as_string(images.plot_png)});
    }
    if (input.pattern)
      figures.push_back({name + ": the wallpaper pattern over 3 x 3 cells, its fundamental region in red",
                         "image/svg+xml", fill::wallpaper_svg(*input.pattern, 3)});
  }
  return figures;
}

}  // namespace lacuna
