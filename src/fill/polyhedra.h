// Random fractal filling with convex polyhedra (../shared/spec/random-fractal-fill.md): the 3D volume rule
// V_i = V / (zeta(c, N) (N + i)^c) of fill_spheres(), with a convex polyhedron motif scaled to V_i and
// optionally turned by a uniformly random rotation. Lengths are millimetres.
#pragma once

#include <array>
#include <string>
#include <vector>

#include "fill/fill.h"
#include "geometry.h"

namespace lacuna {
namespace fill {

// A convex polyhedron in its own frame: volume 1, centroid at the origin.
struct Motif3 {
  std::vector<Vec3d> vertices;           // unit-volume frame
  std::vector<std::vector<int>> faces;   // vertex indices, counter-clockwise seen from outside, planar
  double bounding_radius = 0;            // largest distance of a vertex from the centroid
};

// The cube, regular tetrahedron and regular octahedron of volume 1, centred on the origin (the cube
// axis-aligned with edge 1; the tetrahedron with vertices along (1,1,1), (1,-1,-1), (-1,1,-1), (-1,-1,1);
// the octahedron with vertices on the axes).
Motif3 cube_motif();
Motif3 tetrahedron_motif();
Motif3 octahedron_motif();

// Where one motif goes: vertex p of the motif lands at center_mm + scale * rotation * p.
struct Placement3 {
  Vec3d center_mm;
  double volume_mm3 = 0;  // scale^3 (the motif has volume 1)
  double scale = 0;       // linear
  std::array<std::array<double, 3>, 3> rotation{{{1, 0, 0}, {0, 1, 0}, {0, 0, 1}}};  // proper rotation, row-major
};

// The motif's vertices under the placement, in the motif's order.
std::vector<Vec3d> placed_vertices(const Motif3& motif, const Placement3& placement);

// Whether two placed convex motifs come closer than gap_mm, by separating axes (the face normals of both and
// the cross products of their edge directions): they count as apart when the projections on one unit axis
// are at least gap_mm apart. That separation is a lower bound on their distance, so "apart" is exact, while a
// pair farther apart than gap_mm but no axis showing it (corners facing) counts as overlapping: conservative.
// With gap 0, touching motifs do not overlap.
bool polyhedra_overlap(const Motif3& a, const Placement3& pa, const Motif3& b, const Placement3& pb, double gap_mm);

struct FillResult3P {
  std::vector<Placement3> motifs;  // in placement order: ever smaller
  double fill_fraction = 0;        // sum_{i < count} 1 / (zeta(c, N) (N + i)^c), summed in that order
  std::string stop_reason;         // "max_count", "min_volume" or "max_trials: motif i could not be placed in T trials"
};

// Places motif i, of volume volume_mm3 / (zeta(c, N) (N + i)^c), at the first of at most max_trials uniformly
// random centres in `box` (which must contain the region), turned by a uniformly random rotation when
// random_rotation is set, where it lies inside with the boundary gap and keeps the gap from every motif placed
// before (polyhedra_overlap(), only neighbours on a hierarchical grid of bounding spheres are tested).
// Inside means signed_distance <= -boundary_gap_mm at the centre, every vertex, edge midpoint and face
// centroid. For a convex region that is exact (the points at least the gap inside form a convex set, so the
// vertices suffice); for a non-convex region the skin can still pass between those points and cross an edge
// or face. volume_mm3 is the region's volume. Throws InvalidInput as fill_spheres(), and for a motif that is
// not a convex polyhedron of volume 1 centred on the origin (to 1e-9).
FillResult3P fill_polyhedra(const SignedDistance3& signed_distance_mm, const Box3& box, double volume_mm3,
                            const Motif3& motif, const FillOptions3& options = {}, bool random_rotation = false);

}  // namespace fill
}  // namespace lacuna
