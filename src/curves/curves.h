// Space-filling curves in the square (-1, 1)^2 and the cube (-1, 1)^3, their superpositions, the fill
// rate of their strokes, and their mapping onto surfaces (../shared/spec/space-filling-curves.md).
// Curve coordinates are unitless (the square has side 2); mapped points are in millimetres once scaled.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "geometry.h"

namespace lacuna {
namespace curves {

// A polyline; a closed one has a segment from its last point back to its first, which is not repeated.
struct Polyline2 {
  std::vector<Vec2d> points;
  bool closed = false;
};

struct Polyline3 {
  std::vector<Vec3d> points;  // millimetres once mapped
  bool closed = false;
};

enum class CurveKind { kHilbert, kSierpinski };

// One member of a superposition: the curve of one order.
struct Curve2 {
  int order = 0;
  Polyline2 polyline;
};

struct Curve3 {
  int order = 0;
  Polyline3 polyline;
};

// H_k: open, the 4^k centres of the 2^k x 2^k cells of the square, consecutive ones one cell (1 / 2^(k-1))
// apart; starts at (1 - 1/2^k, 1 - 1/2^k), ends at (1 - 1/2^k, -(1 - 1/2^k)). Coordinates are exact
// (dyadic). Throws InvalidInput unless 1 <= order <= 12.
Polyline2 hilbert(int order);

// S_k: closed, 4^(k+1) points and as many segments (the closing one included), diagonal steps of length
// h sqrt 2 and axis-parallel ones of length 2h, h = 1/2^(k+1); the first point is
// (-1 + 1/2^k, 1 - 1/2^(k+1)). Coordinates are exact. Throws InvalidInput unless 1 <= order <= 11.
Polyline2 sierpinski(int order);

// hilbert(order) or sierpinski(order).
Polyline2 curve(CurveKind kind, int order);

// The curves of the given orders drawn in the same square (H_(1,n) is orders 1 .. n), in the order given.
// Throws InvalidInput for an empty list, a repeated order or an order out of range.
std::vector<Curve2> superposition(CurveKind kind, const std::vector<int>& orders);

// The polylines of a superposition, without their orders.
std::vector<Polyline2> polylines_of(const std::vector<Curve2>& curves);

// The 3D Hilbert curve of order k: open, the 8^k centres of the 2^k x 2^k x 2^k cells of the cube
// (-1, 1)^3, consecutive ones one cell (2 / 2^k) apart along one axis. Built by Skilling's transpose
// algorithm ("Programming the Hilbert curve", 2004): point i is the cell whose Hilbert index is i. It starts
// at the cell at (-1, -1, -1) and ends at the cell at (1, -1, -1). Throws InvalidInput unless 1 <= order <= 8.
Polyline3 hilbert3d(int order);

// The 3D curves of the given orders in the same cube. Throws as superposition().
std::vector<Curve3> superposition3d(const std::vector<int>& orders);

// The stroke of a segment of width w is the rectangle of width w around it, extended by w/2 beyond each
// end (square caps): for an axis-parallel segment, the segment swept by an axis-aligned w x w square.
// Each stroke contains the disk of radius w/2 around each end, so consecutive strokes meet without gaps at
// any joint angle. Returns one counter-clockwise rectangle per segment (closing segments included);
// a zero-length segment gives a w x w square. Throws InvalidInput unless stroke_width > 0.
std::vector<std::vector<Vec2d>> strokes(const std::vector<Polyline2>& curves, double stroke_width);

// The exact area of the union of convex polygons (either orientation, at least 3 points; fewer are
// ignored) clipped to the box [clip_min, clip_max], overlaps counted once. Polygons are binned into a uniform
// grid of cells; in each cell they are clipped to it and swept along x between the critical abscissas (the
// vertices and the crossings of edges of different polygons), where every cross-section length is linear in
// x, so the midpoint rule is exact per slab. A cell inside one polygon counts whole. Time grows with the
// number of polygons overlapping one cell (cubically): meant for strokes that overlap a few times, not
// hundreds. Throws InvalidInput for an empty or non-finite box.
double convex_union_area(const std::vector<std::vector<Vec2d>>& polygons, const Vec2d& clip_min, const Vec2d& clip_max);

// The simple estimate: total length x stroke width / 4 (the square's area). It ignores the caps and counts
// overlaps twice: for one Hilbert curve with w below its step it is w^2 / 4 below the exact rate (the two
// end caps), for a superposition with crossings it is above. Throws as strokes().
double fill_rate_estimate(const std::vector<Polyline2>& curves, double stroke_width);

// The exact fill rate: the area of the union of the strokes clipped to the square, divided by 4.
// Throws as strokes().
double fill_rate_exact(const std::vector<Polyline2>& curves, double stroke_width);

// A map from the square onto a surface: point(X, Y) for (X, Y) in [-1, 1]^2.
struct SurfaceMap {
  std::string name;
  std::function<Vec3d(double X, double Y)> point;
  std::function<Vec3d(double X, double Y)> normal;  // unit, outwards; empty: from finite differences
};

// Riemann sphere (inverse stereographic, the spec's formula): the unit sphere; the square covers the
// part with z <= 1/3.
SurfaceMap sphere_map();
// Cylinder x = sin(pi X), y = Y, z = cos(pi X): radius 1 about the y axis; X = -1 and X = 1 meet.
SurfaceMap cylinder_map();
// Torus x = cos(pi Y)(sin(pi X) - 1.5), y = sin(pi Y)(sin(pi X) - 1.5), z = cos(pi X): major radius 1.5
// about the z axis, minor radius 1; X and Y both wrap around.
SurfaceMap torus_map();
// Cone x = r sin(pi X), y = Y, z = r cos(pi X) with r = (1 - Y) / 2: the lateral surface of the cone with
// base radius 1 at y = -1 and apex (0, 1, 0), the angle from X as on the cylinder (X = -1 and X = 1 meet),
// the height from Y, the apex at Y = 1. Implicit: x^2 + z^2 = ((1 - y) / 2)^2.
SurfaceMap cone_map();

// A tensor-product B-spline patch with clamped uniform knots (degree + 1 equal knots at each end, interior
// knots evenly spaced), parameters (u, v) in [0, 1]^2.
struct BSplinePatch {
  int degree_u = 3, degree_v = 3;
  int count_u = 0, count_v = 0;       // control points along u and along v, each > its degree
  std::vector<Vec3d> control_points;  // count_u * count_v, u fastest: point (i, j) at i + count_u * j
};

// The patch as a map: u = (X + 1) / 2, v = (Y + 1) / 2. Its normal comes from finite differences along
// dP/du x dP/dv. Throws InvalidInput for a degree < 1, too few or non-finite control points.
SurfaceMap bspline_map(const BSplinePatch& patch);

// The chart of face f (0 .. 5) of the cube [-1, 1]^3: point = n_f + X a_f + Y b_f, isometric, with
// n_f the face's outward normal. The faces follow a closed tour along the cube's Petrie hexagon of
// corners V_0 .. V_5 = (1,-1,-1), (1,1,-1), (-1,1,-1), (-1,1,1), (-1,-1,1), (1,-1,1): face f has outward
// normal +x, -z, +y, -x, +z, -y, and its chart puts V_f at (1, 1) and V_(f+1) at (1, -1) (indices mod 6):
// its edge X = 1 is V_f V_(f+1), its edge Y = 1 is V_(f-1) V_f, the previous face's X = 1 edge.
// Throws InvalidInput for another face.
SurfaceMap cube_face_map(int face);

// The unit outward normal of `map` at (X, Y): its own normal, or else the normalized cross product of
// central differences (one-sided at the square's border); zero where the map is degenerate.
Vec3d surface_normal(const SurfaceMap& map, double X, double Y);

// The footprint of tubes of `radius` along polylines: the points within `radius` (3D distance) of a
// segment, found through a bucket grid of the segments' boxes (at most 256 cells a side). Throws
// InvalidInput unless radius > 0.
class TubeFootprint {
 public:
  TubeFootprint(const std::vector<Polyline3>& lines, double radius);
  bool covers(const Vec3d& p) const;

 private:
  std::vector<std::pair<Vec3d, Vec3d>> segments_;
  std::vector<std::vector<uint32_t>> buckets_;
  Vec3d lo_, hi_;
  double cell_ = 0, radius_ = 0;
  int dims_[3] = {1, 1, 1};
  int cell_of(double v, int k) const;
};

// What the footprint covers of a surface (the image of the square), integrated in parameter space: the
// square's n x n cells, one point in each at a fixed pseudo-random place (stratified, so that the samples
// do not alias with the curves' lattice), weighted by the map's area element there (central differences
// of its points), covered when its surface point is in the footprint. This sums the rows
// [row_begin, row_end) (callers split the rows over threads and add them in order). Exact in the limit
// of fine cells; where the map is an isometry up to scale (the cylinder, the cube's faces) it is the
// planar rate of the unrolled strokes with round ends. Throws InvalidInput unless 16 <= n <= 20000 and
// for a map without points.
struct SurfaceCoverage {
  double area = 0;          // of the surface
  double covered_area = 0;  // of the tubes' footprint on it
  uint64_t samples = 0;
  double fill_rate() const { return area > 0 ? covered_area / area : 0; }
};
SurfaceCoverage surface_coverage(const SurfaceMap& map, const TubeFootprint& footprint, int n, int row_begin,
                                 int row_end);

struct MapOptions {
  double scale = 1;            // multiplies the surface's points: millimetres per unit
  double offset_mm = 0;        // along the unit normal after scaling, positive outwards
  double tolerance_mm = 0.01;  // largest distance from a chord's midpoint to the image of its square midpoint
  int max_depth = 20;          // most halvings of one segment of the square
  uint64_t max_points = 50'000'000;  // most points of one mapped polyline (a memory bound)
};

// The image of a polyline of the square on a surface, each segment halved in the square (recursively,
// at most max_depth times) until the distance between the midpoint of the mapped chord and the mapped
// square midpoint is at most tolerance_mm. The result has the input's points (mapped) plus the inserted
// ones, and the same closed flag. Throws InvalidInput for a map without point function, a non-positive
// scale or tolerance, or max_depth outside 0 .. 40; ResourceLimit past max_points points (counted as
// they are made).
Polyline3 map_polyline(const Polyline2& polyline, const SurfaceMap& map, const MapOptions& options = {});

// The curve of one order drawn on all six faces of the cube [-1, 1]^3 through cube_face_map(), scaled
// and offset (tolerance and depth unused: faces are flat and charts affine). The curves pass through cell
// centres and never reach a face's border, so:
// - Hilbert: one closed polyline through the six faces in tour order. On face f, H_k ends at chart
//   (1 - d, -1 + d), d = 1/2^k, next to corner V_(f+1); on face f + 1 it starts at (1 - d, 1 - d), the
//   mirror image of that end across their shared edge V_f V_(f+1). One joint point on that edge, at
//   distance d from V_(f+1), joins them with two half steps perpendicular to the edge (one on each face):
//   6 * 4^k + 6 points, every step one cell (2d) on a face or half a cell (d) across an edge. (As seen from
//   outside, odd faces carry the mirror image of even faces' chart, but H_k is symmetric under that
//   mirror traversed backwards, so every face shows the same pattern.)
// - Sierpinski: six closed polylines, one per face, which never meet.
// With an offset, face points move along their face's normal and joint points along the sum of both
// faces' normals: all points lie on the box of half-size scale + offset_mm.
// Throws InvalidInput as hilbert() / sierpinski() and for a non-positive scale.
std::vector<Polyline3> cube_curve(CurveKind kind, int order, const MapOptions& options = {});

}  // namespace curves
}  // namespace lacuna
