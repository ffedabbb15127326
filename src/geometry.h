// The plain value types that flow between Lacuna's stages: generators produce them, solids
// consume them. No library types appear here; all lengths are millimetres.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace lacuna {

// The voxel sizes Lacuna works with (mm): below, OpenVDB's transforms lose their scale (a voxel's
// volume nears double's epsilon) and no printer resolves it; above, no part is resolved at all.
constexpr double kMinVoxelSizeMm = 1e-4;
constexpr double kMaxVoxelSizeMm = 1000;

struct Vec3d {
  double x = 0, y = 0, z = 0;

  constexpr double operator[](int i) const { return i == 0 ? x : (i == 1 ? y : z); }
  double& operator[](int i) { return i == 0 ? x : (i == 1 ? y : z); }
  constexpr Vec3d operator+(const Vec3d& o) const { return {x + o.x, y + o.y, z + o.z}; }
  constexpr Vec3d operator-(const Vec3d& o) const { return {x - o.x, y - o.y, z - o.z}; }
  constexpr Vec3d operator-() const { return {-x, -y, -z}; }
  constexpr Vec3d operator*(double s) const { return {x * s, y * s, z * s}; }
  constexpr Vec3d operator/(double s) const { return {x / s, y / s, z / s}; }
  Vec3d& operator+=(const Vec3d& o) { x += o.x; y += o.y; z += o.z; return *this; }
  Vec3d& operator-=(const Vec3d& o) { x -= o.x; y -= o.y; z -= o.z; return *this; }
  constexpr bool operator==(const Vec3d& o) const { return x == o.x && y == o.y && z == o.z; }
  constexpr bool operator!=(const Vec3d& o) const { return !(*this == o); }
};

constexpr Vec3d operator*(double s, const Vec3d& v) { return v * s; }
constexpr double dot(const Vec3d& a, const Vec3d& b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
constexpr Vec3d cross(const Vec3d& a, const Vec3d& b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
inline double norm(const Vec3d& v) { return std::sqrt(dot(v, v)); }
// A coordinate the output formats store exactly: the nearest float32 (binary STL keeps float32;
// 3MF files are written with the shortest text that reads back to the same float32). Through a
// volatile: GCC 12 at -O3 with -frounding-math (which CGAL requires) was seen to drop a plain
// double(float(v)) on some lanes of a Vec3d.
inline double round_to_output(double v) {
  volatile float f = float(v);
  return double(f);
}
inline Vec3d round_to_output(const Vec3d& v) { return {round_to_output(v.x), round_to_output(v.y), round_to_output(v.z)}; }
inline bool is_finite(const Vec3d& v) {
  return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}
// The axis along which n is largest in magnitude (ties to the lower axis): dropping it projects a
// plane with normal n onto the coordinate plane it is least foreshortened on.
inline int dominant_axis(const Vec3d& n) {
  const double x = std::fabs(n.x), y = std::fabs(n.y), z = std::fabs(n.z);
  return x >= y && x >= z ? 0 : (y >= z ? 1 : 2);
}
// The squared distance from p to the closed segment ab (to a when b == a).
inline double point_segment_distance2(const Vec3d& p, const Vec3d& a, const Vec3d& b) {
  const Vec3d ab = b - a, ap = p - a;
  const double len2 = dot(ab, ab);
  const double t = len2 > 0 ? std::clamp(dot(ap, ab) / len2, 0.0, 1.0) : 0.0;
  const Vec3d r = ap - ab * t;
  return dot(r, r);
}

struct Vec2d {
  double x = 0, y = 0;
  constexpr Vec2d operator+(const Vec2d& o) const { return {x + o.x, y + o.y}; }
  constexpr Vec2d operator-(const Vec2d& o) const { return {x - o.x, y - o.y}; }
  constexpr Vec2d operator*(double s) const { return {x * s, y * s}; }
  constexpr bool operator==(const Vec2d& o) const { return x == o.x && y == o.y; }
};

inline double cross2(const Vec2d& a, const Vec2d& b) { return a.x * b.y - a.y * b.x; }
// The distance from p to the closed segment ab (to a when b == a).
inline double point_segment_distance(const Vec2d& p, const Vec2d& a, const Vec2d& b) {
  const Vec2d ab = b - a, ap = p - a;
  const double len2 = ab.x * ab.x + ab.y * ab.y;
  const double t = len2 > 0 ? std::clamp((ap.x * ab.x + ap.y * ab.y) / len2, 0.0, 1.0) : 0.0;
  const Vec2d r = ap - ab * t;
  return std::hypot(r.x, r.y);
}
// Shoelace area of a closed polygon (the last point is not repeated): positive when counter-clockwise.
double signed_area(const std::vector<Vec2d>& polygon);
// Whether the closed segments ab and cd share a point (exact orientation signs of the double inputs).
bool segments_intersect(const Vec2d& a, const Vec2d& b, const Vec2d& c, const Vec2d& d);

// An axis-aligned box; empty when min > max on any axis.
struct Box3 {
  Vec3d min{HUGE_VAL, HUGE_VAL, HUGE_VAL};
  Vec3d max{-HUGE_VAL, -HUGE_VAL, -HUGE_VAL};

  bool empty() const { return min.x > max.x || min.y > max.y || min.z > max.z; }
  void expand(const Vec3d& p) {
    min = {std::fmin(min.x, p.x), std::fmin(min.y, p.y), std::fmin(min.z, p.z)};
    max = {std::fmax(max.x, p.x), std::fmax(max.y, p.y), std::fmax(max.z, p.z)};
  }
  void expand(const Box3& b) {
    if (!b.empty()) { expand(b.min); expand(b.max); }
  }
  Vec3d size() const { return empty() ? Vec3d{} : max - min; }
};

// An indexed triangle mesh. Closed meshes are read as solids, open ones as surfaces.
struct TriMesh {
  std::vector<Vec3d> positions_mm;                 // millimetres
  std::vector<std::array<uint32_t, 3>> triangles;  // counter-clockwise seen from outside
};

// One tube: a polyline swept by a ball whose radius is given per point (round cones between
// consecutive points, exact distance).
struct Tube {
  std::vector<Vec3d> points_mm;   // at least one point
  std::vector<double> radii_mm;   // one per point, or a single value for the whole tube
};

struct TubeSet {
  std::vector<Tube> tubes;
};

struct SphereSet {
  std::vector<Vec3d> centers_mm;
  std::vector<double> radii_mm;   // one per centre, or a single value for all
};

// Planar regions (polygons with holes, even-odd rule) extruded along the normal of their plane.
// The plane is origin + u * axis_u + v * axis_v; the extrusion spans [0, height] along axis_u x axis_v.
struct Region2 {
  std::vector<std::vector<Vec2d>> loops_mm;  // closed loops, the last point is not repeated
  Vec3d origin_mm{0, 0, 0};
  Vec3d axis_u{1, 0, 0};                     // unit vectors, orthogonal
  Vec3d axis_v{0, 1, 0};
  double height_mm = 1.0;
};

// Analytic solids that recipes name directly; rasterized from their exact distance functions.
struct Shape {
  enum class Kind { kBox, kCylinder, kTorus };
  Kind kind = Kind::kBox;
  Vec3d center_mm;
  Vec3d axis{0, 0, 1};       // cylinder and torus axis (unit)
  Vec3d half_size_mm;        // box half extents
  double radius_mm = 0;      // cylinder radius, torus major radius
  double height_mm = 0;      // cylinder height (along axis, centred)
  double minor_radius_mm = 0;  // torus tube radius
};

// An open (or closed) surface thickened into a shell: every point within thickness/2 of it.
struct ThickSurface {
  TriMesh surface;
  double thickness_mm = 1.0;
};

// Convex polyhedra sharing one face layout (all hexahedra, all tetrahedra, ...): the cells of a
// volume attractor. Faces list corner indices; their orientation is not trusted (mirrored cells
// are common), the solid stage orients them from the cell's centroid.
struct ConvexCells {
  int corners_per_cell = 8;
  std::vector<std::vector<int>> faces;  // indices 0 .. corners_per_cell - 1
  std::vector<Vec3d> corners_mm;        // corners_per_cell per cell, cell after cell
  size_t size() const { return corners_per_cell > 0 ? corners_mm.size() / size_t(corners_per_cell) : 0; }
};

struct GeometrySet;
// A source that hands its pieces over in batches, so that millions of them are never all in
// memory: emit() calls the sink once per batch, the same batches every time it is called.
struct GeometryStream {
  std::function<void(const std::function<void(const GeometrySet&)>& sink)> emit;
};

// What a generator or a recipe input hands to the solid stage: a union of pieces of any kind.
struct GeometrySet {
  TubeSet tubes;
  SphereSet spheres;
  std::vector<Shape> shapes;
  std::vector<ThickSurface> surfaces;
  std::vector<TriMesh> solids;      // closed meshes, each bounding a solid
  std::vector<Region2> regions;     // extruded planar regions
  std::vector<ConvexCells> cells;   // convex polyhedra
  std::vector<GeometryStream> streams;  // batches of any of the above (streams inside ignored)
};

// A tetrahedral mesh for finite elements: every tetrahedron positively oriented (corner 3 on the
// side the right-hand normal of corners 0, 1, 2 points to).
struct TetMesh {
  std::vector<Vec3d> nodes_mm;
  std::vector<std::array<uint32_t, 4>> tets;
  std::vector<int> regions;  // material region of each tetrahedron; empty when there is one
};

// Mesh statistics that depend only on the triangle list.
Box3 bounding_box(const TriMesh& mesh);
double signed_volume(const TriMesh& mesh);   // mm^3, divergence theorem, exact for closed meshes
double surface_area(const TriMesh& mesh);    // mm^2

}  // namespace lacuna
