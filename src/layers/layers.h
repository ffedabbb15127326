// Layers for printers, from a solid's signed distance sampled on a layer's pixel grid: anti-aliased
// greyscale images (resin printers), closed contours (powder-bed machines, CLI files), their
// simplification, and the checks every layer passes before it is written. Plain math on the
// samples; solids/slice.h samples a level set.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "geometry.h"

namespace lacuna {

// A layer's pixel grid: pixel (i, j) has its centre at origin + (i * pixel_mm, j * pixel_y_mm()).
struct LayerGrid {
  Vec2d origin_mm;
  double pixel_mm = 0.05;
  double pixel_height_mm = 0;  // along y, for displays whose pixels are not square; 0: pixel_mm
  int width = 0, height = 0;
  size_t pixels() const { return size_t(width) * size_t(height); }
  double pixel_y_mm() const { return pixel_height_mm > 0 ? pixel_height_mm : pixel_mm; }
};

// Closed polylines (mm), the first point not repeated: outer boundaries counter-clockwise, holes
// clockwise (the solid on the left).
using Contours = std::vector<std::vector<Vec2d>>;

// The 8-bit coverage of every pixel, row j = 0 first: 255 * clamp(1/2 - d2 / pixel, 0, 1) where d2 is
// the distance to the section's boundary within the layer's plane, estimated from the signed distance
// d (mm, negative inside) at the pixel's centre as d / |horizontal gradient of d|; a pixel the
// boundary crosses through its centre is half grey.
std::vector<uint8_t> coverage_image(const std::vector<float>& distance, const LayerGrid& grid);

// The area (mm^2) the image covers: its sum / 255 * pixel^2.
double image_area_mm2(const std::vector<uint8_t>& image, const LayerGrid& grid);

// The zero contour of the samples (marching squares, the crossings interpolated linearly along the
// grid's edges but kept 1/100 pixel off the samples, saddles decided by the cell's mean). Samples on
// the grid's border must be outside (> 0), so every contour closes. The contours are simple, disjoint
// and oriented as above.
Contours contour_layer(const std::vector<float>& distance, const LayerGrid& grid);

// Every contour reduced (Douglas-Peucker, each closed loop split at its two farthest vertices) so
// that no removed vertex lies further than tolerance_mm from what replaces it; loops that would
// fall under 4 vertices stay as they are.
Contours simplify_contours(const Contours& contours, double tolerance_mm);

// Sum of the signed areas (mm^2): the region's area when the contours are oriented as above.
double contours_area_mm2(const Contours& contours);
// Total length (mm).
double contours_length_mm(const Contours& contours);

// What checking a layer's contours found.
struct ContourCheck {
  bool closed = true;       // every loop has at least 3 points and finite coordinates
  bool simple = true;       // no loop crosses or touches itself
  bool disjoint = true;     // no two loops cross or touch
  bool oriented = true;     // counter-clockwise at even nesting depth, clockwise at odd
  size_t loops = 0;
  std::vector<std::string> problems;
  bool valid() const { return closed && simple && disjoint && oriented; }
};

// Checks the contours: segment pairs through a grid of buckets, nesting depth by counting the
// crossings of a ray from each loop's lowest vertex.
ContourCheck check_contours(const Contours& contours);

}  // namespace lacuna
