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
  std::function<double(const Vec3d&)> depth_of;  // depth: distance inside the hull (mm), set by the runner

  // The field's value at p, in [0, 1].
  double at(const Vec3d& p) const;
};

struct LatticeOptions {
  enum class Cell { kCubic, kBodyCentred };
  Cell cell = Cell::kCubic;
  double period_mm = 5;            // cell size; nodes at integer multiples (tiles line up)
  double radius_mm = 0.5;          // strut radius without a grade
  double radius_min_mm = 0;        // with a grade: radius where the field is 0 ...
  double radius_max_mm = 0;        // ... and where it is 1
  GradeField grade;
};

// The struts of the cells covering `box`, each split into pieces of at most a quarter period so
// the radius can follow the field. Throws InvalidInput for non-positive sizes or more than 10^7
// struts.
TubeSet lattice_tubes(const Box3& box, const LatticeOptions& options);

}  // namespace lacuna
