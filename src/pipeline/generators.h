// The generator commands as functions: what `lacuna cifs tessellate`, `curve points|fill-rate`,
// `voronoi rules|cells` and `bcifs measure` compute, as plain data, for the command line and the
// Python module. Names given as text (kinds, surfaces, groups) are parsed by each front end, which
// names its own option in messages.
#pragma once

#include <array>
#include <cstdint>
#include <nlohmann/json_fwd.hpp>
#include <optional>
#include <string>
#include <vector>

#include "bcifs/plate.h"
#include "bcifs/realize.h"
#include "bcifs/topology.h"
#include "bcifs/volume.h"
#include "cifs/automaton.h"
#include "curves/curves.h"
#include "geometry.h"
#include "voronoi/rules.h"
#include "voronoi/walls.h"

namespace lacuna {

// A system's pieces at a level: curves as polylines, surfaces as triangles, volumes as cells.
struct CifsTessellation {
  int dimension = 1;    // of the pieces: 1, 2 or 3
  uint64_t pieces = 0;  // accepted words of the level
  std::vector<Vec3d> points_mm;
  std::vector<std::vector<uint32_t>> cells;  // polylines, triangles or cells, as indices into points_mm
  std::vector<std::vector<uint32_t>> faces;  // volumes: every cell's faces, as indices into points_mm
};

// The most pieces a tessellation is listed with; beyond, a recipe builds the solid as a stream.
constexpr uint64_t kMaxListedPieces = 20'000'000;

// Tessellates the system (its primitives completed) at `level`. Throws ResourceLimit beyond
// kMaxListedPieces pieces, before enumerating them.
CifsTessellation tessellate_system(cifs::Cifs system, int level);

// One NURBS piece evaluated through its automaton: 2^level + 1 points and their parameters.
struct NurbsCurvePoints {
  std::vector<Vec3d> points_mm;
  std::vector<double> parameters;
  // Levels up to 16: the unit tangent at every point along increasing parameter, from the automaton
  // (the limit frame of the sub-piece the point starts, or ends for the last point).
  std::vector<Vec3d> tangents;
};

// The piece of `degree` with its 2 degree knots and control points (a JSON list of degree + 1 points
// [x, y, z], or [x, y, z, w] for a rational curve) at `level` (0 to 24). Throws InvalidInput naming
// `file` for bad knots or points, and for a level out of range.
NurbsCurvePoints nurbs_curve_points(int degree, const std::vector<double>& knots, const nlohmann::json& control_points,
                                    int level, const std::string& file);

// The surfaces curves are drawn on by curve_points().
enum class CurveSurface { kPlane, kSphere, kCylinder, kTorus, kCone, kCube };

// One drawn polyline: its order, whether it closes, its points in drawing order.
struct DrawnCurve {
  int order = 0;
  bool closed = false;
  std::vector<Vec3d> points;
};

// The superimposed curves of `orders` in the square (-1, 1)^2 (z = 0) or mapped onto a unit surface
// with chords within `tolerance` of it; `hilbert3d` draws the 3D Hilbert curves in the cube (-1, 1)^3
// and takes the plane or the cube as its surface. Throws InvalidInput for a 3D curve on another
// surface, ResourceLimit beyond 20 000 000 points.
std::vector<DrawnCurve> curve_points(curves::CurveKind kind, bool hilbert3d, const std::vector<int>& orders,
                                     CurveSurface surface, double tolerance);
// The same on a surface the caller gives as a map of the square (a B-spline patch from
// curves::bspline_map, a mesh patch from mesh_patch_map): the 2D curves only.
std::vector<DrawnCurve> curve_points(curves::CurveKind kind, const std::vector<int>& orders,
                                     const curves::SurfaceMap& surface, double tolerance);

// The fraction of the square (-1, 1)^2 the strokes of width `width` along the curves cover.
struct CurveFillRate {
  std::vector<int> orders;
  uint64_t segments = 0;
  double length = 0;            // of every polyline, units of the square
  double fill_rate = 0;         // the area of the union of the strokes over the square's
  double fill_rate_simple = 0;  // length x width / 4
};

// Throws InvalidInput unless width > 0.
CurveFillRate curve_fill_rate(curves::CurveKind kind, const std::vector<int>& orders, double width);

// y = a e^(b x), fitted by least squares to ln y (the form of the source's fill-rate fits).
struct ExponentialFit {
  double a = 0, b = 0;
};
// Throws InvalidInput unless there are at least two points, of equal count, with distinct x and every y > 0.
ExponentialFit exponential_fit(const std::vector<double>& x, const std::vector<double>& y);

// The growing superpositions of `orders` (n_1 < n_2 < ...): entry k is curve_fill_rate of n_1 .. n_k, and the
// exponential fits of their rates in percent against n_k (the source fits 100 x rate = a e^(b n) for
// H_(1,n) and S_(1,n)). Throws as curve_fill_rate, and InvalidInput for fewer than two orders.
struct FillRateSeries {
  std::vector<CurveFillRate> rates;
  ExponentialFit exact_fit, simple_fit;  // of 100 fill_rate, 100 fill_rate_simple
};
FillRateSeries curve_fill_rate_series(curves::CurveKind kind, const std::vector<int>& orders, double width);

// The fraction of a unit surface's area that tubes of diameter `width` along the curves drawn on it
// (curve_points(), chords within `tolerance`) cover: curves::surface_coverage on samples x samples
// cells of the square (each of the cube's six faces), rows in parallel, summed in order (identical for
// any thread count); samples 0: eight cells across a tube.
struct SurfaceFillRate {
  std::vector<int> orders;
  double area = 0;              // of the surface
  double covered_area = 0;      // of the tubes' footprint on it
  double fill_rate = 0;         // covered_area / area
  double length = 0;            // of the mapped polylines
  double fill_rate_simple = 0;  // length x width / area
  int samples = 0;              // per side of the square (per face)
};

// Throws InvalidInput unless width > 0 and samples is 0 or 16 .. 20000, and as curve_points().
SurfaceFillRate curve_surface_fill_rate(curves::CurveKind kind, const std::vector<int>& orders, double width,
                                        CurveSurface surface, int samples, double tolerance);
// The same on a surface the caller gives as a map of the square (a B-spline or mesh patch): its area
// and the footprint integrated over the square as for the built-in surfaces.
SurfaceFillRate curve_surface_fill_rate(curves::CurveKind kind, const std::vector<int>& orders, double width,
                                        const curves::SurfaceMap& surface, int samples, double tolerance);

// A fractal Voronoi level's cell measures per colour and, with scaled children, its walls.
struct VoronoiCells {
  voronoi::Level level;
  std::vector<double> measures;         // area (2D) or volume (3D) of each colour's cells, torus units
  std::optional<voronoi::Walls> walls;  // with scaled children
};

// The rules' level `level`, measured. Throws InvalidInput for a level out of 0 to 12.
VoronoiCells voronoi_cells(const voronoi::Rules& rules, int level, bool scaled_children);

// What `bcifs measure` finds for one plate between two levels.
struct PlateMeasures {
  std::vector<bcifs::Lacunarity> faces;      // per face of the assembly, its counts at levels 0 .. last (to 12)
  std::vector<int> face_types;               // per face, its type in the rule set
  bcifs::GeometricMeasures geometry;         // areas and perimeters of levels first .. min(last, 8)
  bcifs::BoxCount region;                    // box counting of the region at the last level
  bcifs::BoxCount boundary;                  // and of its boundary
  std::vector<std::vector<Vec2d>> polygons;  // the sub-faces of the last level (mm)
};

// The deepest levels measured: the counts N^C_i, N^L_i, R_i need only the rules; areas, perimeters and
// box counting realize every sub-face.
constexpr int kMaxTopologyLevel = 12;
constexpr int kMaxGeometryLevel = 8;

// Measures the plate: its counts from level 0 to `last`, its geometry from `first` to min(last, 8)
// (0 <= first <= 8, first <= last <= 12). Throws InvalidInput for other levels.
PlateMeasures measure_plate(const bcifs::Plate& plate, int first, int last);

// What `bcifs measure` finds for one lacunar volume.
struct VolumeCellMeasures {
  std::vector<bcifs::Lacunarity> cells;  // per cell of the assembly, its counts N^C, N^L, R at levels 0 .. last
  std::vector<int> cell_types;           // per cell, its type in the rules
  size_t cell_type_count = 0, face_type_count = 0;
  bcifs::VolumeMeasures geometry;        // volumes, surfaces, tunnels, genus of levels 0 .. geometry_last
  int geometry_last = 0;                 // min(last, the deepest level with at most kMaxMeasuredCells cells)
  // Level geometry_last's solid sampled at the centres of a kVolumeBoxGrid^3 grid over its bounding cube: box
  // counts in 3D of the solid (region) and of its boundary voxels, and its sections by the three planes through
  // the middle of its box (x, y, z), kSectionPixels^2 masks over the cube's square (bcifs::section_mask).
  bcifs::BoxCount region, boundary;
  std::array<std::vector<uint8_t>, 3> sections;
  std::array<double, 3> section_mm{};    // where each section's plane lies
  double grid_fill = 0;                  // the set voxels' share of the grid
};

constexpr int kVolumeBoxGrid = 256;
constexpr int kSectionPixels = 1024;

// The most cells `bcifs measure` realizes for a volume's geometry (a few hundred MB).
constexpr double kMaxMeasuredCells = 300000;

// Measures a lacunar volume (a bcifs_volume input's cells and geometry options) from level 0 to `last` (at most
// 12). Throws InvalidInput for a bad level or spec.
VolumeCellMeasures measure_volume(const bcifs::VolumeSpec& spec, const bcifs::VolumeGeometryOptions& options, int last);

}  // namespace lacuna
