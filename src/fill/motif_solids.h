// Placed motifs of a random fractal filling turned into solids: prisms for lacunar panels, flat or
// wrapped around a cylinder.
#pragma once

#include <vector>

#include "fill/fill.h"
#include "geometry.h"

namespace lacuna {
namespace fill {

// Where placed motifs become solids: prisms of `height_mm` standing on z = base_z_mm, or, when
// wrap_radius_mm > 0, radial prisms of that depth centred on the cylinder of that radius about the z
// axis, the pattern's x measured along its circumference from angle 0 and its y along z.
struct MotifSolidOptions {
  double height_mm = 1;
  double base_z_mm = 0;
  double wrap_radius_mm = 0;
};

// Circles become cylinders (exact); polygons become extruded regions, grouped into layers in which
// no two motifs' bounding circles meet (so overlapping images under the "allow" policy stay a union).
GeometrySet motif_solids(const Motif2& motif, const std::vector<Placement2>& placements, const MotifSolidOptions& options);

}  // namespace fill
}  // namespace lacuna
