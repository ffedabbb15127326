// Lacunar volumes (../shared/spec/bcifs-lacunar.md, "Lacunar volumes"): cells whose faces are lacunar faces,
// subdivided in 3D around a central lacuna, to a level; their rules, closure and measures, and their geometry.
//
// The subdivision of a cell C (a convex polyhedron, or a sub-cell made by an earlier level):
// - Its lacuna is C scaled by `lacuna_scale` about its apex c (the average of its corners).
// - Every face f of C subdivides by its own face rule (topology.h, realize.h), in its own plane. Each sub-face g
//   becomes one sub-cell: the frustum between g and its copy g' on the lacuna, {c + t (p - c) : p in g,
//   t in [s, 1]}. The frusta of f's sub-faces fill the pyramid frustum of f except where f's rule leaves holes:
//   the face's central lacuna and its Cantor notches become tunnels from f to C's lacuna, so the void is connected
//   to whatever lies beyond f. A plain face (no rule) is one sub-face, itself: the sub-cell is its whole frustum.
//   With plain faces a hexahedron subdivides into six hexahedra, each spanning from one of its faces to the
//   matching face of the lacuna (the spec's example); with lacunar faces its walls are opened where the face
//   rules put lacunas.
// - A sub-cell's faces: its outer face g (the sub-face's type), its inner face g' (the same type: the lacuna's
//   wall shows the same pattern, scaled), and one side face per edge of g: the quad between that edge and its
//   copy, a new interior face of type <X, R, X, R> (X the edge's type, R the radial edge type, with the
//   interior faces' E and algorithm), or plain. Two sub-cells that share an edge of their outer faces (an Ea edge
//   inside one face, or a sub-edge of an edge of C) share that side face.
// - Consistency: a face shared by two cells (an interior side face, or a face two cells of an assembly share)
//   is one face object with one control polygon; both cells subdivide it by the same rule from the same points,
//   so its sub-faces are bitwise equal from both sides (realize_volume counts the faces shared at every level).
// - Delays: a cell with delay d >= 2 makes no lacuna and subdivides into one sub-cell of delay d - 1 with the
//   same region; its faces are delayed with it (every face of the cell gets a delay of at least d, so each has
//   one sub-face, its boundary subdivided and notched). A face two cells share gets the larger delay of the two.
// Cell types are known by their faces: a cell type is its delay and the multiset of its faces' types (plain
// faces by their number of sides), which is all its children depend on.
//
// Geometry: every sub-face vertex is the fixed affine combination of its face's control points that the face
// rule names (realize.h, applied to each coordinate), and every lacuna corner the fixed combination
// (1 - s) c + s p, so a cell is free-form from its corners.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "bcifs/plate.h"
#include "bcifs/realize.h"
#include "bcifs/topology.h"
#include "geometry.h"

namespace lacuna {
namespace bcifs {

// A convex polyhedron: its corners and its faces as corner loops, counter-clockwise seen from outside.
struct Polyhedron {
  std::vector<Vec3d> corners_mm;
  std::vector<std::vector<int>> faces;
};

// The regular cell of `shape` (cell_faces in plate.h) centred at `center_mm`.
Polyhedron regular_cell(CellKind shape, double edge_mm, const Vec3d& center_mm = {});

// The faces a subdivision adds between sub-cells.
struct InteriorFaces {
  bool plain = false;                            // solid walls, never opened
  EdgeType radial{EdgeKind::kBezier, 2, 1};      // R: the edges from a face's corner to its copy on the lacuna
  EdgeSet edges;                                 // E of the quads <X, R, X, R>
  Algorithm algorithm = Algorithm::kA1;
};

// One cell of an assembly: its polyhedron, each face's type (faces[k]'s boundary edge j runs from corner
// faces[k][j] to the next) or none for a plain face, and its delay.
struct CellSpec {
  Polyhedron shape;
  std::vector<FaceType> face_types;  // one per face
  std::vector<char> plain;           // one per face: 1 = plain (its face type is ignored)
  int delay = 1;
};

struct VolumeSpec {
  std::vector<CellSpec> cells;
  InteriorFaces interior;
};

// Gives every face of the cell the face type `face` with every edge of type face.boundary[0] (so neighbouring faces
// agree on every edge), or makes every face plain.
void set_uniform_faces(CellSpec& cell, const FaceType& face, bool plain);

// Two cells with the same face (the same corners, in reverse order).
struct SharedFace {
  int cell_a = -1, face_a = -1;
  int cell_b = -1, face_b = -1;
};

// The faces cells share, found by their corners (faces of two cells that overlap without the same corners are
// not shared: each cell subdivides its own). Throws InvalidInput naming the cells and faces when a face is shared
// by more than two cells, when a cell is not closed, not convex, inside out, or has a face that is not planar,
// when the two sides of a shared face or of a cell's edge disagree on its type, when a cell has fewer than 4
// faces, a face fewer than 3 corners, or a face's type does not have one edge per side.
std::vector<SharedFace> shared_faces(const VolumeSpec& spec);

// A face of a cell type: its face-type id, or -1 with its number of sides for a plain face.
struct CellSlot {
  int type = -1;
  int sides = 0;
  bool operator<(const CellSlot& o) const { return type != o.type ? type < o.type : sides < o.sides; }
  bool operator==(const CellSlot& o) const { return type == o.type && sides == o.sides; }
};

struct CellType {
  int delay = 1;
  std::vector<CellSlot> faces;  // sorted
  bool operator<(const CellType& o) const { return delay != o.delay ? delay < o.delay : faces < o.faces; }
};

struct CellRule {
  CellType cell;
  std::vector<int> children;  // one cell-type id per sub-cell (a multiset: the order of the sorted face slots)
  double lacunas = 0;         // N^L_1: 1, or 0 for a delayed cell
};

struct VolumeRules {
  RuleSet faces;                 // every face type: the cells' faces (delays raised), the interior quads, closed
  InteriorFaces interior;
  std::vector<CellRule> cells;   // ids in breadth-first order from the roots
  std::vector<int> roots;        // the cell-type id of each cell of the spec
  std::vector<int> root_faces;   // per cell of the spec, per face: the face-type id (-1 plain), flattened
  std::vector<SharedFace> shared;
};

struct VolumeClosureOptions {
  int max_cell_types = 20000;  // ResourceLimit beyond
  int max_face_types = 10000;
};

// The rules of every cell type reachable from the spec's cells. Throws InvalidInput as shared_faces does or for
// an invalid face type or delay, ResourceLimit past the options' limits.
VolumeRules build_volume_rules(const VolumeSpec& spec, const VolumeClosureOptions& options = {});

// N^C_i (subfaces: the sub-cells), N^L_i, R_i and lim R of cell type `type` (lacunarity in topology.h).
Lacunarity volume_lacunarity(const VolumeRules& rules, int type, int levels);

// Sub-cells of the whole assembly at `level` (the sum over its cells), without realizing them.
double volume_cells(const VolumeRules& rules, int level);
// Lacunas (N^L) of the whole assembly at `level`, likewise.
double volume_lacunas(const VolumeRules& rules, int level);

struct VolumeGeometryOptions {
  double lacuna_scale = 0.5;  // the cell's lacuna: the cell scaled about its apex, in (0, 1)
  GeometryOptions faces;      // the faces' rules (gap_fraction, their own lacuna_scale, notch_depth)
  // Per cell of the spec, or empty: the size (mm) of every lacuna its descendants make in the last subdivision (the
  // one that makes the level realized), 0 for none. A cell of volume V subdividing then takes the scale
  // size / cbrt(V), kept within [lacuna_scale / 3, lacuna_scale] (lacunas only shrink, so no wall gets thinner than
  // lacuna_scale makes it); lacuna_scale before that step. A cell's own lacuna touches no face it shares with
  // another (its faces subdivide by their face rules alone), so every cell may take its own scale and the assembly
  // stays consistent.
  std::vector<double> last_lacuna_mm;
};

// Throws InvalidInput unless every option is in (0, 1).
void validate(const VolumeGeometryOptions& options);

// A face of a realized level, its polygon in its type's canonical order (any order for a plain face).
struct VolumeFace {
  std::vector<Vec3d> polygon;
  int type = -1;  // face-type id, -1 plain
};

// A cell of a realized level. Its region is a root polyhedron (root >= 0) or the frustum of `base` towards
// `base_apex`: {base_apex + t (p - base_apex) : p in base, t in [base_scale, 1]}.
struct VolumeCell {
  int type = -1;            // cell-type id
  int delay = 1;
  std::vector<int> faces;   // indices into VolumeLevel::faces
  int root = -1;
  int origin = -1;          // the cell of the spec it descends from
  std::vector<Vec3d> base;
  Vec3d base_apex;
  double base_scale = 0;
  Vec3d apex;               // the average of its region's corners: its lacuna's centre
};

struct VolumeLevel {
  int level = 0;
  std::vector<VolumeFace> faces;
  std::vector<VolumeCell> cells;
  std::vector<int> owners;  // per face, how many cells of this level have it (1, or 2 for a shared face)
};

// The most sub-cells a realization may hold; more is refused before realizing them.
constexpr double kMaxVolumeCells = 2e6;

// The cells of the spec subdivided `levels` times. Throws InvalidInput for a bad spec or options (as
// build_volume_rules and validate do), ResourceLimit past kMaxVolumeCells.
VolumeLevel realize_volume(const VolumeRules& rules, const VolumeSpec& spec, int levels,
                           const VolumeGeometryOptions& options = {});

// The volume of one cell's region (exact for planar faces).
double cell_volume(const VolumeCell& cell, const VolumeSpec& spec);

// The level's cells as convex pieces for the rasterizer: a root polyhedron as it is, a frustum over a convex
// base as one cell, one over a non-convex base as the frusta of its base's ear-clipped triangles. Every piece is
// grown by a relative 1e-9 about its corners' average, so that pieces sharing a face overlap and their union has
// no crack where the face lies on a voxel plane.
std::vector<ConvexCells> convex_pieces(const VolumeLevel& level, const VolumeSpec& spec);

// How much one level shrinks a cell: the geometric mean of cbrt(volume) over its level-1 sub-cells divided by
// that over its level-2 sub-cells, for cell `cell` of the spec subdivided alone without delay (between 3 and 4
// for a cube or a tetrahedron with Bezier B2 walls and lacuna scale 0.5).
double level_shrink(const VolumeSpec& spec, int cell, const VolumeGeometryOptions& options = {});

// Delays that give cells of different sizes lacunas of about one size: a cell of size L waits
// 1 + round(log(L_ref / L) / log(shrink)) levels (at least 1, at most `level`), L_ref the 90th percentile of the
// sizes (the largest cells but an outlier or two subdivide at once), shrink > 1 what one level does to a cell
// (level_shrink). Delays are whole levels, so a cell's lacunas are within sqrt(shrink) of the reference's and
// two cells' within shrink of each other (two sizes that round to one delay). Sizes must be > 0.
std::vector<int> delays_for_sizes(const std::vector<double>& sizes_mm, int level, double shrink);

// The lacuna scale a cell of volume `volume_mm3` takes in the last subdivision for a lacuna of `size_mm` (0: lacuna_scale).
double last_scale(double size_mm, double volume_mm3, double lacuna_scale);

// The lacunas the last subdivision makes (level - 1 to level), per cell of the spec: over its descendants that
// subdivide then, the geometric mean, the smallest and the largest of scale * cbrt(volume) (their scale as
// last_lacuna_mm gives it), and the range of those scales; 0 for a cell whose descendants are all still delayed.
struct LastLacunas {
  std::vector<double> mean_mm, smallest_mm, largest_mm;
  double min_scale = 0, max_scale = 0;  // over every cell
};
LastLacunas last_lacuna_sizes(const VolumeRules& rules, const VolumeSpec& spec, int level,
                              const VolumeGeometryOptions& options = {});

// Sampling a level's convex pieces (convex_pieces) for box counting and sections.
// A cube of size^3 voxels over the pieces' bounding box: its side the box's longest plus a margin of sqrt(2)/128 of
// it on each end, from the box's lowest corner less the margin (so that faces at fixed ratios of the box do not all
// sit at one offset from the voxel centres).
struct VoxelGrid {
  int size = 0;
  Vec3d origin_mm;
  double voxel_mm = 0;
};

// Throws InvalidInput unless size is a power of two from 4 to 1024 and there is a piece.
VoxelGrid voxel_grid(const std::vector<ConvexCells>& pieces, int size);

// The voxels of layers z_first <= z < z_last whose centre lies in a piece (on a face counts): 1, else 0, written
// to out (size^2 per layer, x fastest, then y). Layers are independent: callers may mark them in parallel.
void mark_voxels(const std::vector<ConvexCells>& pieces, const VoxelGrid& grid, int z_first, int z_last, uint8_t* out);

// Box counts of a size^3 mask (x fastest, then y, then z) on its cube: eps = 1/4 .. 1/size of the side, N_eps the
// boxes holding a voxel of the set, or with `boundary` a voxel of the set that has a 6-neighbour outside it or lies
// on the cube's border. Throws InvalidInput unless size is a power of two >= 8 and mask.size() = size^3.
BoxCount box_count_3d(const std::vector<uint8_t>& mask, int size, bool boundary);

// The section of the pieces by the plane where coordinate `axis` (0 x, 1 y, 2 z) equals `value`: pixel centres
// of a size x size square over the grid's cube in the other two coordinates (u = axis + 1, v = axis + 2, mod 3),
// 1 inside a piece; row-major, rows along v from the cube's low end.
std::vector<uint8_t> section_mask(const std::vector<ConvexCells>& pieces, const VoxelGrid& grid, int axis,
                                  double value, int size);

struct VolumeMeasures {
  std::vector<double> volume;   // V_i, i = 0..levels: the cells' volumes summed
  std::vector<double> surface;  // S_i: the area of the faces only one cell has (the union's boundary where
                                // neighbours subdivide shared faces alike; an upper bound where a plain face
                                // meets a lacunar one, whose sub-cells' sides split the edge the plain one keeps)
  double volume_factor = 0;     // F_V = (V_levels / V_0)^(1 / levels)
  double surface_factor = 0;    // F_S likewise
  // Tunnels made from level i - 1 to i: every face object of level i - 1 that its cells subdivide with a central
  // lacuna (lacunar, not delayed) opens one tunnel, whether one cell has it or two (the two halves meet).
  std::vector<double> tunnels;  // tunnels[0] = 0
  std::vector<double> lacunas;  // N^L_i over the whole assembly
  // The genus of the level's solid when every lacuna and tunnel joins one void (walls and interior faces
  // lacunar, Bézier edges only: Cantor notches join several voids at once and are not counted): every tunnel is
  // a void body touching two others, every lacuna one touching none of its own, so b_1 = sum of tunnels - N^L.
  std::vector<double> genus;
};

// `last`, when given, receives the realized level `levels` (what realize_volume would return).
VolumeMeasures volume_measures(const VolumeRules& rules, const VolumeSpec& spec, int levels,
                               const VolumeGeometryOptions& options = {}, VolumeLevel* last = nullptr);

}  // namespace bcifs
}  // namespace lacuna
