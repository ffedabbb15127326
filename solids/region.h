// Planar regions (polygons with holes, even-odd) extruded into closed triangle meshes.
#pragma once

#include "geometry.h"

namespace lacuna {

// The closed prism over the region: top and bottom faces triangulated with CGAL's constrained
// Delaunay triangulation, side walls as quads split in two. Outward oriented. Throws
// InvalidInput for loops with fewer than 3 points, non-finite points, or self-crossing loops.
TriMesh extrude_region(const Region2& region);

// Area of the region (mm^2), even-odd.
double region_area_mm2(const Region2& region);

}  // namespace lacuna
