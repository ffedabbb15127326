// Lacunar fractal faces, geometry (../shared/spec/bcifs-lacunar.md, "Geometric realization"): every face type's
// rule becomes a barycentric map set (cifs.md): each sub-face vertex is a fixed affine combination of the parent's
// control points (one per boundary vertex; vertex j is the start of boundary edge j). Then the leaves of a level,
// their area and the perimeter of their union, rasterization, box counting, density maps and PNG output.
//
// Geometry of a rule, for a parent polygon P (N vertices, edge i from P[i] to P[i+1]):
// - Edges are straight. A Bézier edge Bn splits at parameters k/n. A Cantor edge Cn keeps n sub-edges of length
//   (1 - g)/n separated by n - 1 gaps of g/(n - 1) (g = gap_fraction of the edge, the gaps together). A delayed
//   edge keeps its end points. Every point on an edge is w_a P[i] + w_b P[i+1] with w_a = v/(u+v), w_b = u/(u+v),
//   u and v the lengths before and after it, each summed as (sub-edges) * L + (gaps) * G, so the neighbour across
//   a shared edge, walking it the other way, computes the same doubles: shared vertices are bitwise identical.
// - Lacuna copy: Q[k] = (1 - s) c + s P[k], c the vertex average of P, s = lacuna_scale.
// - An adjacency edge at a corner k goes to Q[k]; one at the point after sub-edge k of edge i goes to the point of
//   lacuna edge i (Q[i] to Q[i+1]) with the same weights (for a Cantor gap: the weights of the gap's midpoint).
//   The lacuna is the polygon through these feet (its El edges are straight): under A1, where no adjacency edge
//   leaves a corner, the El edge cuts the corner of the copy Q, and that corner belongs to the sub-face.
// - Notch apex in a Cantor gap: (1 - t) m + t f, m the gap's midpoint, f the foot of its adjacency edge (for a
//   delayed face, the foot it would have), t = notch_depth.
// - Curved edges: a root face's edge j may carry a bend, the middle control point B of the quadratic Bézier
//   (P[j], B, P[j+1]). Its points then lie on the curve at the same splits (t = u / (u + v)), and a sub-edge
//   of it carries the blossom of its two parameters as its own bend, so every sub-face edge on the curve is the
//   exact piece of the curve. Interior edges stay straight. Curves are evaluated with their end points in a
//   fixed order, so a shared curved edge gives both sides the same doubles. Outlines flatten each curved edge
//   into kCurveSegments chords of equal parameter steps.
#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "bcifs/topology.h"
#include "geometry.h"

namespace lacuna {
namespace bcifs {

struct GeometryOptions {
  double gap_fraction = 0.2;  // of a Cantor edge's length taken by its n - 1 gaps together, in (0, 1)
  double lacuna_scale = 0.35;  // lacuna = control polygon scaled about its vertex average, in (0, 1)
  double notch_depth = 0.3;    // notch apex: this fraction of the way from the gap midpoint to the lacuna, in (0, 1)
};

struct RealizeOptions {
  GeometryOptions defaults;
  // Per face-type id. Two types that share an edge (an Ea, or an assembly edge) must agree on gap_fraction, or
  // the two sides no longer coincide.
  std::map<int, GeometryOptions> per_type;
};

// Throws InvalidInput unless every option is in (0, 1).
void validate(const GeometryOptions& options);

// Named realizations, for any face type:
// - "default": the GeometryOptions defaults above.
// - "paper": lacuna_scale 0.55, gap_fraction 0.2, notch_depth 0.7, calibrated so that F0 on the regular hexagon
//   reproduces the source's measures (F_A 0.76, F_P 1.97 as geometric means over levels 0-5, D_box 1.65 by box
//   counting at level 5): it gives F_A 0.751, F_P 1.980, D_box 1.673, each within 1.4 %. The calibration swept
//   the three options (scaling the lacuna alone reaches all three; F_A and D_box move together, so no choice
//   gets both below 1 %). tests/bcifs_test.cpp measures it.
// Throws InvalidInput for any other name, listing these.
GeometryOptions realization_preset(const std::string& name);
const std::vector<std::string>& realization_names();

// An edge's bend: the middle control point of its quadratic Bézier; none for a straight edge.
using Bend = std::optional<Vec2d>;

// Chords per curved edge in an outline.
constexpr int kCurveSegments = 16;

// The point a VertexRef names, for the rule's face with control polygon `control` (rule.face.boundary order)
// and the bends of its edges (empty: all straight). Throws InvalidInput when control does not have one point
// per boundary edge, or bends is neither empty nor one per edge.
Vec2d vertex_position(const FaceRule& rule, const std::vector<Vec2d>& control, const VertexRef& vertex,
                      const GeometryOptions& options = {}, const std::vector<Bend>& bends = {});

// The polygon of each sub-face, vertex j = start of its edge j as written in the rule.
std::vector<std::vector<Vec2d>> subface_polygons(const FaceRule& rule, const std::vector<Vec2d>& control,
                                                 const GeometryOptions& options = {},
                                                 const std::vector<Bend>& bends = {});

// The bends of each sub-face's edges (as written in the rule): the piece of the parent's curve for an edge on
// a curved parent edge, none otherwise. Empty lists when the parent has no bends.
std::vector<std::vector<Bend>> subface_bends(const FaceRule& rule, const std::vector<Vec2d>& control,
                                             const GeometryOptions& options, const std::vector<Bend>& bends);

// The central lacuna (counter-clockwise), empty for a delayed face.
std::vector<Vec2d> lacuna_polygon(const FaceRule& rule, const std::vector<Vec2d>& control,
                                  const GeometryOptions& options = {});

struct Leaf {
  std::vector<Vec2d> polygon;  // one vertex per boundary edge of `type`, in its canonical order
  int type = -1;
  std::vector<Bend> bends;     // one per edge, or empty when every edge is straight
};

// The leaf's outline: its polygon with every curved edge flattened into kCurveSegments chords.
std::vector<Vec2d> outline(const Leaf& leaf);

// The leaves (material) of face type `type` after `levels` subdivisions; control in the type's canonical order.
// Throws InvalidInput for a bad type, levels < 0 or a control polygon of the wrong size, ResourceLimit past
// 20 000 000 leaves.
// `bends`: one per control edge (or empty: all straight), in the same order as control.
std::vector<Leaf> realize(const RuleSet& rules, int type, const std::vector<Vec2d>& control, int levels,
                          const RealizeOptions& options = {}, const std::vector<Bend>& bends = {});

// The leaves of every face of an assembly; controls[f] follows faces[f].boundary as written (vertex j = start of
// edge j). Throws InvalidInput when validate(assembly) does, when a face is not in `rules`, or when the two sides
// of a shared edge do not have the same end points (reversed) or the same bend. bends[f], when given, follows
// controls[f].
std::vector<std::vector<Leaf>> realize_assembly(const RuleSet& rules, const Assembly& assembly,
                                                const std::vector<std::vector<Vec2d>>& controls, int levels,
                                                const RealizeOptions& options = {},
                                                const std::vector<std::vector<Bend>>& bends = {});

// The leaf sub-edges (start, end) along edge `edge` (canonical index) of face type `type` after `levels`
// subdivisions, in order, found through the rules' incidences.
std::vector<std::pair<Vec2d, Vec2d>> edge_segments(const RuleSet& rules, int type, const std::vector<Vec2d>& control,
                                                   int edge, int levels, const RealizeOptions& options = {});

// No two edges meet except consecutive ones at their common vertex, and no edge has zero length.
bool is_simple(const std::vector<Vec2d>& polygon);

// The edges of the union's boundary: every leaf edge whose reverse (identical end points) is not a leaf edge.
std::vector<std::pair<Vec2d, Vec2d>> boundary_segments(const std::vector<std::vector<Vec2d>>& polygons);
double union_perimeter(const std::vector<std::vector<Vec2d>>& polygons);
std::vector<std::vector<Vec2d>> polygons_of(const std::vector<Leaf>& leaves);  // their outlines

struct GeometricMeasures {
  std::vector<double> area;       // A_i, i = 0..levels: sum of leaf areas
  std::vector<double> perimeter;  // P_i: length of the union's boundary
  double area_factor = 0;         // F_A = (A_levels / A_0)^(1 / levels): geometric mean of A_(i+1) / A_i
  double perimeter_factor = 0;    // F_P likewise
  int first_level = 0;            // the level of area[0]
};

GeometricMeasures geometric_measures(const RuleSet& rules, int type, const std::vector<Vec2d>& control, int levels,
                                     const RealizeOptions& options = {});

// The same from any level-0 leaves (the faces of an assembly, say), measured at levels first..last (A_0, P_0
// above then stand for level `first`; the factors span last - first levels). `last_polygons`, when given,
// receives the leaves of level `last`. Throws InvalidInput unless 0 <= first <= last.
GeometricMeasures geometric_measures(const RuleSet& rules, std::vector<Leaf> leaves, int first, int last,
                                     const RealizeOptions& options = {},
                                     std::vector<std::vector<Vec2d>>* last_polygons = nullptr);

// A pixel grid over the plane: pixel (x, y) has its centre at origin + ((x + 0.5) p, (y + 0.5) p), row y = 0 at
// the bottom.
struct Raster {
  Vec2d origin;
  double pixel = 1;
  int width = 0, height = 0;
  std::vector<uint16_t> count;  // how many polygons contain each pixel centre (saturating)
};

// The bounding square of the polygons (side = the larger extent, centred on their box) as size x size pixels.
Raster square_raster(const std::vector<std::vector<Vec2d>>& polygons, int size);
// Adds each polygon's pixel centres (even-odd, a centre on a left edge is in, on a right edge out, so that two
// polygons sharing an edge never both count a centre).
void rasterize(const std::vector<std::vector<Vec2d>>& polygons, Raster& raster);
// Pixels whose centre lies in at least one polygon, 0 or 1, row-major.
std::vector<uint8_t> mask_of(const Raster& raster);

// Perimeter of a mask's set by the Cauchy-Crofton formula over the four pixel directions (0, 45, 90, 135 degrees):
// L = pi/8 * sum over directions of (transitions along lines) * (line spacing). For a segment at any angle the
// estimate lies within [0.948, 1.026] of the length.
double crofton_perimeter(const Raster& raster);

struct BoxCount {
  std::vector<double> log_inverse_size;  // ln(1/eps), eps = 1/16 .. 1/1024 of the bounding square
  std::vector<double> log_count;         // ln N_eps
  double dimension = 0;                  // least-squares slope
};

// Box counts of a 1024 x 1024 mask, aggregated from the pixels (a box meets the set when one of its pixels is set).
// Throws InvalidInput unless the mask is 1024 x 1024.
BoxCount box_count(const std::vector<uint8_t>& mask, int size);
// The filled region: pixel centres of the union of the polygons on their bounding square.
BoxCount box_count_region(const std::vector<std::vector<Vec2d>>& polygons);
// Curves: every pixel a segment passes through (sampled at a quarter pixel) on the segments' bounding square.
BoxCount box_count_segments(const std::vector<std::pair<Vec2d, Vec2d>>& segments);

// Fraction of set pixels in the window x window square centred on each pixel (clipped at the image border).
std::vector<double> density_map(const std::vector<uint8_t>& mask, int width, int height, int window);
// RGB, 3 bytes per pixel: (255 f, 0, 255 (1 - f)) rounded, blue at 0 and red at 1.
std::vector<uint8_t> density_colours(const std::vector<double>& density);

uint32_t crc32(const uint8_t* data, size_t size);
uint32_t adler32(const uint8_t* data, size_t size);
// An 8-bit RGB PNG: stored (uncompressed) deflate blocks at `level` 0, zlib's deflate at levels 1-9.
// Throws InvalidInput when rgb.size() != 3 w h.
std::vector<uint8_t> encode_png(int width, int height, const std::vector<uint8_t>& rgb, int level = 0);
// Throws IoError when the file cannot be written.
void write_png(const std::string& path, int width, int height, const std::vector<uint8_t>& rgb, int level = 0);

// A three-panel plot, RGB width x height (at least 300 x 150), each panel titled, its axes labelled
// with their ranges and a legend: left ln(A_i/A_first) (red) and ln(P_i/P_first) (blue) against the
// level; middle the box-counting points (black) and their fitted line (green, D); right R_i (purple)
// against the level, to level ratio.size() - 1, and its limit R (grey, dashed).
// `labels` names the two measures (a volume's plot shows volume V and surface S in their place).
struct PlotLabels {
  std::string first = "AREA", second = "PERIMETER";  // upper case: the plot's font has no lower case
  std::string first_symbol = "A", second_symbol = "P";
};
std::vector<uint8_t> plot_measures(const GeometricMeasures& measures, const BoxCount& boxes,
                                   const std::vector<double>& ratio, double ratio_limit, int width, int height,
                                   const PlotLabels& labels = {});

}  // namespace bcifs
}  // namespace lacuna
