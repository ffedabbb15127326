// Printability of a solid: walls thinner than a minimum, holes and channels narrower than a
// minimum, voids with no way out (trapped powder or resin), overhanging surface; and the fixes:
// drain holes drilled to the outside.
#pragma once

#include <vector>

#include "geometry.h"
#include "solids/volume.h"

namespace lacuna {

struct PrintabilityOptions {
  double min_wall_mm = 0;             // 0: not checked
  double min_hole_mm = 0;             // 0: not checked
  Vec3d build_direction{0, 0, 1};     // unit, pointing up from the build plate
  double critical_angle_deg = 45;     // down-facing surface flatter than this is overhang
};

// A region found by an analysis: its volume and where it is (its centroid), with its box.
struct PrintFeature {
  double volume_mm3 = 0;
  Vec3d location_mm;
  Box3 box;
};

struct PrintabilityReport {
  std::vector<PrintFeature> thin_walls;     // material thinner than min_wall_mm
  std::vector<PrintFeature> small_holes;    // gaps and channels narrower than min_hole_mm
  std::vector<PrintFeature> trapped_voids;  // cavities with no path to the outside
  double overhang_area_mm2 = 0;             // down-facing surface below the critical angle
  double down_facing_area_mm2 = 0;          // all surface facing down
  TriMesh thin_wall_surface;                // the surfaces of the thin-wall regions (for thickening)
  bool ok() const { return thin_walls.empty() && small_holes.empty() && trapped_voids.empty(); }
};

// Analyses the solid. Thin walls are the parts of the solid an opening by min_wall/2 removes
// (erode, then dilate), holes the parts of the outside a closing by min_hole/2 fills; from both
// the slivers an opening cuts off convex edges (and a closing adds in concave corners) are left
// out: a region counts when its volume to surface ratio is at least a quarter of the radius, as a
// slab thinner than the limit has and an edge sliver (ratio 0.08 of the radius) has not. Trapped
// voids are the inward-facing shells of the solid's surface (cavities), with the volume they
// enclose. Overhang from the surface's down-facing triangles.
PrintabilityReport analyze_printability(const Volume& part, const PrintabilityOptions& options);

// The solid with every thin-wall region grown by half the minimum wall, so it is at least that
// thick; the rest of the solid is untouched.
Volume thicken_thin_walls(const Volume& part, const PrintabilityReport& report, double min_wall_mm);

// The solid with a drain hole of the given diameter drilled from every trapped void to the
// outside: a straight channel from the void's centroid to the nearest point of the outer surface,
// or along -build direction when `downwards` is set.
Volume drill_drain_holes(const Volume& part, const std::vector<PrintFeature>& voids, double diameter_mm,
                         const PrintabilityOptions& options, bool downwards);

}  // namespace lacuna
