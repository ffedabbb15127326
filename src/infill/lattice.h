// Test lattices of tubes for hull infill, with a radius that a scalar field can grade.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "geometry.h"

namespace lacuna {

// A scalar field over space mapped to [0, 1]: the parameter a graded structure follows.
struct GradeField {
  enum class Kind { kNone, kRamp, kPoints, kDepth };
  Kind kind = Kind::kNone;
  Vec3d axis{0, 0, 1};             // ramp: direction (unit)
  double from_mm = 0, to_mm = 1;   // ramp: 0 at `from` along the axis, 1 at `to`
  std::vector<Vec3d> points_mm;    // points: 1 at a point, falling off as exp(-(d / falloff)^2)
  double falloff_mm = 1;
  double depth_mm = 1;             // depth: 0 at the skin, 1 at this depth inside and beyond

  // The field's value at p, in [0, 1]; a depth field reads `depth_of` (0 when it is empty).
  double at(const Vec3d& p, const std::function<double(const Vec3d&)>& depth_of = {}) const;
};

struct LatticeOptions {
  enum class Cell { kCubic, kBodyCentred };
  Cell cell = Cell::kCubic;
  // kTiled: nodes at integer multiples of the period (tiles of neighbouring parts line up);
  // kScaled: the period rounded so a whole number of cells spans the box exactly, from its corner;
  // kConforming: tiled, then the nodes outside the hull's inset surface are moved onto it (see
  // signed_distance_mm), so the cells at the skin end on it instead of being cut.
  enum class Layout { kTiled, kScaled, kConforming };
  Layout layout = Layout::kTiled;
  double period_mm = 5;            // cell size (the coarsest, when the level is graded)
  double radius_mm = 0.5;          // strut radius without a radius grade
  // What the grade drives: the strut radius (radius_min_mm .. radius_max_mm), or the level: a
  // cell is split into 2 x 2 x 2 while the field at its centre exceeds (level + 1) / (levels + 1),
  // down to `levels` splits (motif size period / 2^level, radius_mm throughout).
  enum class Graded { kRadius, kLevel };
  Graded graded = Graded::kRadius;
  double radius_min_mm = 0;        // radius grade: radius where the field is 0 ...
  double radius_max_mm = 0;        // ... and where it is 1
  int levels = 1;                  // level grade: the most splits of a cell
  GradeField grade;
  double conform_inset_mm = 0;     // kConforming: how deep inside the hull the moved nodes lie
};

// Fields of the hull a lattice is fitted to, computed by the caller (from the hull's level set).
struct HullFields {
  std::function<double(const Vec3d&)> depth_mm;  // depth grades: distance inside the hull (mm, 0 outside)
  // kConforming: the hull's signed distance (mm, negative inside), valid from -conform_inset_mm -
  // period to a period outside. Nodes deeper than conform_inset_mm stay; the others within a
  // period of the hull move to the closest point at that depth; farther ones are dropped with
  // their struts.
  std::function<double(const Vec3d&)> signed_distance_mm;
};

// The struts of the cells covering `box`, each split into pieces of at most a quarter period so
// the radius can follow the field. Throws InvalidInput for non-positive sizes or more than 10^7
// struts, and for a conforming layout without the hull's signed distance.
TubeSet lattice_tubes(const Box3& box, const LatticeOptions& options, const HullFields& hull = {});

// The closest point to p where `signed_distance` is -inset (Newton steps along the field's
// gradient, by central differences of `step_mm`).
Vec3d project_to_level(const std::function<double(const Vec3d&)>& signed_distance, const Vec3d& p, double inset_mm,
                       double step_mm);

}  // namespace lacuna
