// Random fractal filling (../shared/spec/random-fractal-fill.md): ever smaller motifs placed at random
// positions in a region, their areas (volumes in 3D) following the inverse power law
// A_i = A / (zeta(c, N) (N + i)^c), so that they would fill the region completely in the limit.
// Lengths are millimetres. Periodic patterns (the 17 wallpaper groups) are in fill/wallpaper.h.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "geometry.h"
#include "util/random.h"

namespace lacuna {
namespace fill {

// The Hurwitz zeta function zeta(s, q) = sum_{k >= 0} (q + k)^-s, to full double precision. Throws InvalidInput
// unless s > 1 and q > 0 (both finite).
double hurwitz_zeta(double s, double q);

// The project's own generator (util/random.h).
using ::lacuna::Random;

// A motif in its own frame: centroid at the origin, area 1.
struct Motif2 {
  enum class Kind { kCircle, kPolygon };
  Kind kind = Kind::kCircle;
  std::vector<Vec2d> outline;              // polygon: counter-clockwise, simple; circle: empty
  int rotation_order = 0;                  // n-fold about the centroid (1: none); 0 for a circle (every angle)
  std::vector<double> mirror_angles_rad;   // directions of the mirror lines through the centroid, in [0, pi),
                                           // ascending; empty for a circle, whose every direction is one
  double bounding_radius = 0.5641895835477563;  // largest distance from the centroid (circle: 1 / sqrt(pi))
  bool convex = true;
  Vec2d interior_point;                    // a point strictly inside: the centroid when it is inside
};

// The circle of area 1.
Motif2 circle_motif();
// The regular n-gon of area 1 with a vertex on the +x axis: rotation order n, n mirrors at multiples of pi/n.
// Throws InvalidInput unless 3 <= n <= 100000.
Motif2 regular_polygon_motif(int n);
// A simple polygon (either orientation, the last point not repeated), made counter-clockwise, moved to its
// centroid and scaled to area 1; repeated and collinear points are dropped. Its rotation order and mirror
// lines are detected to 1e-9 of its bounding radius. Throws InvalidInput for fewer than 3 distinct points,
// non-finite coordinates, zero area or a self-touching outline.
Motif2 polygon_motif(const std::vector<Vec2d>& points);

// Where one motif goes: point p of the motif lands at center + scale * R(angle) * (p.x, mirrored ? -p.y : p.y).
struct Placement2 {
  Vec2d center_mm;
  double area_mm2 = 0;       // the motif's whole area, scale^2
  double scale = 0;          // linear: the unit-area outline times scale has area area_mm2
  double angle_rad = 0;      // counter-clockwise rotation about the centre
  bool mirrored = false;     // reflected across the motif's x axis before the rotation (wallpaper images)
  int stabilizer_order = 1;  // wallpaper snap: how many group elements map it onto itself; 1 / this counts
};

// The outline (or, for a circle, 64 points on the circle) of a placed motif, counter-clockwise.
std::vector<Vec2d> placed_outline(const Motif2& motif, const Placement2& placement);

// The region a fill covers.
struct FillRegion2 {
  enum class Kind { kRectangle, kDisk, kPolygon };
  Kind kind = Kind::kRectangle;
  Vec2d min_mm, max_mm;            // rectangle corners
  Vec2d center_mm;                 // disk
  double radius_mm = 0;            // disk
  std::vector<Vec2d> polygon_mm;   // a simple polygon, counter-clockwise
};

// Validating constructors: they throw InvalidInput for an empty rectangle, a non-positive radius, a polygon
// that is not simple (as polygon_motif()) or non-finite numbers.
FillRegion2 rectangle_region(const Vec2d& min_mm, const Vec2d& max_mm);
FillRegion2 disk_region(const Vec2d& center_mm, double radius_mm);
FillRegion2 polygon_region(const std::vector<Vec2d>& points_mm);

double area(const FillRegion2& region);  // mm^2
// Whether the placed motif lies inside the region with every point at least clearance_mm from its boundary.
bool contains(const FillRegion2& region, const Motif2& motif, const Placement2& placement, double clearance_mm);

// The most motifs (or spheres) one fill places; recipes and the command line refuse more.
constexpr size_t kMaxFillCount = 10'000'000;

struct FillOptions {
  double c = 1.3;              // exponent of the area law, > 1; the fractal dimension is 2 / c
  double N = 2;                // offset of the area law, > 1
  size_t max_count = 1000;     // most motifs
  double min_area_mm2 = 0;     // stop before the first motif smaller than this
  size_t max_trials = 100000;  // random positions tried per motif before giving up
  double gap_mm = 0;           // least distance between two motifs
  double boundary_gap_mm = 0;  // least distance between a motif and the region's boundary
  uint64_t seed = 1;
  bool random_rotation = false;  // turn each motif by a random angle in [0, 2 pi / rotation order)
};

struct FillResult2 {
  std::vector<Placement2> motifs;  // in placement order: ever smaller
  double fill_fraction = 0;        // sum_{i < count} 1 / (zeta(c, N) (N + i)^c), summed in that order
  std::string stop_reason;         // "max_count", "min_area" or "max_trials: motif i could not be placed in T trials"
};

// Places motif i, of area A / (zeta(c, N) (N + i)^c) with A the region's area, at the first of at most
// max_trials uniformly random positions (and angles) where it lies in the region with the boundary gap and
// keeps the gap from every motif placed before. Overlaps are exact (circles by distance, convex polygons by
// separating axes, others by edge crossings and containment, gaps by the distance between outlines), and
// only motifs near the trial position are tested. Throws InvalidInput for c <= 1, N <= 1, negative gaps or
// zero trials.
FillResult2 fill_region(const FillRegion2& region, const Motif2& motif, const FillOptions& options = {});

// 3D: spheres by the volume rule V_i = V / (zeta(c, N) (N + i)^c), fractal dimension 3 / c.
struct FillOptions3 {
  double c = 1.3;               // exponent of the volume law, > 1
  double N = 2;                 // offset of the volume law, > 1
  size_t max_count = 1000;      // most spheres
  double min_volume_mm3 = 0;    // stop before the first sphere smaller than this
  size_t max_trials = 100000;   // random centres tried per sphere before giving up
  double gap_mm = 0;            // least distance between two spheres
  double boundary_gap_mm = 0;   // least distance between a sphere and the region's boundary
  uint64_t seed = 1;
};

struct FillResult3 {
  std::vector<Vec3d> centers_mm;  // in placement order
  std::vector<double> radii_mm;   // one per centre, ever smaller
  double fill_fraction = 0;       // sum_{i < count} 1 / (zeta(c, N) (N + i)^c), summed in that order
  std::string stop_reason;        // "max_count", "min_volume" or "max_trials: sphere i could not be placed in T trials"
};

// Negative inside, millimetres: the exact distance to the boundary, or a bound that never exceeds it.
using SignedDistance3 = std::function<double(const Vec3d&)>;

// Places sphere i, of volume volume_mm3 / (zeta(c, N) (N + i)^c), at the first of at most max_trials uniform
// random centres in `box` (which must contain the region) where signed_distance(center) <= -(r + boundary gap)
// and it keeps the gap from every sphere placed before (only neighbours on a hierarchical grid are tested).
// volume_mm3 is the region's volume. Throws InvalidInput as fill_region(), for an empty box, a missing
// distance function or a non-positive volume.
FillResult3 fill_spheres(const SignedDistance3& signed_distance_mm, const Box3& box, double volume_mm3,
                         const FillOptions3& options = {});

// The exact signed distance of an axis-aligned box, negative inside. Throws InvalidInput for an empty box.
SignedDistance3 box_region_distance(const Box3& box);
// The exact signed distance of a ball. Throws InvalidInput unless radius_mm > 0.
SignedDistance3 sphere_region_distance(const Vec3d& center_mm, double radius_mm);

// Box counting of what circles leave uncovered in the square [0, side]^2: for eps = side / 2^k,
// k = first .. last, the boxes of side eps not inside one circle (a box lies in a circle when its
// four corners do); the dimension is the least-squares slope of log N against log(1 / eps) (2 / c
// by the area law). `circles` are placements of the circle motif (radius sqrt(area / pi)).
struct UncoveredBoxCount {
  std::vector<double> eps_mm;
  std::vector<uint64_t> boxes;
  double dimension = 0;
};
UncoveredBoxCount uncovered_box_count(const std::vector<Placement2>& circles, double side_mm, int first, int last);

}  // namespace fill
}  // namespace lacuna
