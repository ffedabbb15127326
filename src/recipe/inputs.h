// The options of every recipe input type, as plain data: what a recipe says, before anything is
// built. The pipeline's build step (pipeline/build_inputs.h) turns each into geometry.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <variant>
#include <vector>

#include "bcifs/plate.h"
#include "bcifs/realize.h"
#include "bcifs/topology.h"
#include "bcifs/volume.h"
#include "cifs/automaton.h"
#include "cifs/solid_input.h"
#include "cifs/support.h"
#include "curves/curves.h"
#include "curves/sweep.h"
#include "fill/fill.h"
#include "fill/motif_solids.h"
#include "fill/wallpaper.h"
#include "geometry.h"
#include "infill/lattice.h"

namespace lacuna {

// "sphere": one ball.
struct SphereInput {
  Vec3d center_mm;
  double radius_mm = 1;
};

// "spheres": balls with one radius for all or one per centre.
struct SpheresInput {
  std::vector<Vec3d> centers_mm;
  std::vector<double> radii_mm;  // one, or one per centre
};

// "capsule": a round cone between two points (a cylinder with round ends when the radii agree).
struct CapsuleInput {
  Vec3d a_mm, b_mm;
  double radius_mm = 1;    // at a
  double radius_b_mm = 1;  // at b
};

// "tubes": polylines swept by balls.
struct TubesInput {
  std::vector<Tube> polylines;
};

// "box": an axis-aligned box.
struct BoxInput {
  Vec3d center_mm;
  Vec3d half_size_mm{0.5, 0.5, 0.5};
};

// "cylinder": centred on its axis.
struct CylinderInput {
  Vec3d center_mm;
  Vec3d axis{0, 0, 1};  // unit
  double radius_mm = 1;
  double height_mm = 1;
};

// "torus": about its axis through its centre.
struct TorusInput {
  Vec3d center_mm;
  Vec3d axis{0, 0, 1};  // unit
  double major_radius_mm = 2;
  double minor_radius_mm = 1;  // less than the major radius
};

// "region": planar polygons with holes (even-odd), extruded.
struct RegionInput {
  Region2 region;
};

// Explicit repairs of an imported hull (none by default: a broken hull is an error).
struct MeshRepair {
  double weld_mm = 0;
  bool reorient = false;
  double close_gaps_mm = 0;
  bool allow_overlaps = false;  // accept self-intersecting or overlapping shells (resolved as a union)
  bool any() const { return weld_mm > 0 || reorient || close_gaps_mm > 0; }
};

// A mesh given as a file (STL, OBJ, PLY, 3MF) or inline, scaled then moved.
struct MeshSource {
  std::string file;          // as written in the recipe, relative to the recipe's folder; empty: inline
  TriMesh inline_mesh;       // when `file` is empty
  double scale = 1.0;        // applied first
  Vec3d translate_mm;        // applied after the scale
};

// "mesh": a closed hull, which must be a valid solid unless repairs are asked for.
struct MeshInput {
  MeshSource source;
  MeshRepair repair;
};

// "surface": an open (or closed) surface thickened into a shell centred on it.
struct SurfaceInput {
  MeshSource source;
  double thickness_mm = 1;
};

// "lattice": a test lattice of tubes in a box, or fitted to another input's box.
struct LatticeInput {
  LatticeOptions lattice;
  Box3 box;                           // without fit_to
  std::optional<std::string> fit_to;  // the input whose box it fills (depth grades and conforming layouts use it too)
};

// "cifs": the attractor of a CIFS at a level, as tubes, a shell or cells.
struct CifsInput {
  cifs::Cifs system;
  int level = 3;
  cifs::SolidOptions solid;
  std::optional<std::string> fit_to;  // scaled uniformly and centred in that input's box
  std::optional<cifs::SupportOptions> support;  // a shell stood on its own fractal tree (cifs/support.h)
};

// "curve": space-filling curves on a surface as tubes, with an optional base shell.
struct CurveInput {
  enum class Surface { kPlane, kSphere, kCylinder, kTorus, kCone, kCube, kBspline, kMesh };
  curves::SweepOptions sweep;
  Surface surface = Surface::kPlane;
  curves::BSplinePatch patch;  // kBspline
  std::string mesh_file;       // kMesh: a disk-like patch, relative to the recipe's folder
};

// "fill_motifs": a random fractal filling of a region or a wallpaper pattern, as prisms.
struct FillMotifsInput {
  fill::Motif2 motif;
  fill::FillOptions fill;
  fill::MotifSolidOptions solid;  // the wrap radius is set from the pattern when wrap_depth_mm > 0
  bool wallpaper = false;         // a periodic pattern instead of `region`
  fill::FillRegion2 region;       // without a wallpaper
  fill::Group group = fill::Group::p1;
  fill::Lattice lattice;
  int cells_u = 1, cells_v = 1;   // unit cells of the pattern along a and b
  fill::BoundaryPolicy policy = fill::BoundaryPolicy::kReject;
  double wrap_depth_mm = 0;       // > 0: wrapped around the cylinder the pattern's width goes round, this deep
  // "color_class": only the motifs (with all their images) of colour `keep` among `classes`, coloured as
  // `fill pattern --colors` does (fill::motif_colors with the fill's seed): inputs that differ only in
  // `keep` split one pattern into disjoint objects, e.g. for the parts of a multi-material 3MF. Without
  // `keep` the recipe splits the input itself into one object per class (see Recipe::display_colors).
  struct ColorClass {
    fill::Coloring by = fill::Coloring::kSize;
    int classes = 2;
    int keep = -1;                     // -1: every class, one object each
    std::vector<std::string> palette;  // "#rrggbb" per class, the display colours of the split objects
  };
  std::optional<ColorClass> color_class;
};

// "fill_spheres": a random fractal filling of a volume with spheres or convex polyhedra.
struct FillSpheresInput {
  enum class Motif { kSphere, kCube, kTetrahedron, kOctahedron };
  enum class Region { kBox, kSphere, kFitTo };
  fill::FillOptions3 fill;
  Motif motif = Motif::kSphere;
  bool random_rotation = false;  // polyhedra only
  Region region = Region::kBox;
  Box3 box;                      // kBox
  Vec3d sphere_center_mm;        // kSphere
  double sphere_radius_mm = 1;   // kSphere
  std::string fit_to;            // kFitTo: a closed input
};

// The partition every fractal Voronoi input starts from: rules with scaled children, one level.
struct VoronoiPartition {
  int dimension = 3;                          // 2 or 3
  int d = 2;                                  // lacunarity
  std::vector<std::vector<double>> points;    // starting points in [0, 1)^dimension; empty: random ones
  int random_points = 0;                      // how many random starting points when `points` is empty
  uint64_t seed = 1;                          // of the random starting points
  int level = 2;
  double period_mm = 1;
  Vec3d origin_mm;
  // Starting points (colours) in total.
  size_t colour_count() const { return points.empty() ? size_t(random_points) : points.size(); }
};

// "voronoi_spheres": a sphere on every generator of the kept colours.
struct VoronoiSpheresInput {
  VoronoiPartition partition;
  double radius_mm = 1;
  std::vector<int> colours;        // 1-based; empty: every colour
  std::array<int, 3> tiles{1, 1, 1};  // periods along each axis
};

// "voronoi_tiles": each kept colour's compact tile, with a clearance to the others.
struct VoronoiTilesInput {
  VoronoiPartition partition;
  std::vector<int> colours;  // 1-based; empty: every colour
  double clearance_mm = 0;
  double thickness_mm = 0;   // 2D: the plate's thickness
  // `refine` as for the foam: the kept colours' fractal cells split into their refined tiles, each its own
  // piece with the clearance to its neighbours.
  GradeField refine;
  int refine_levels = 0;
};

// "voronoi_foam": the walls between colours, thickened, over whole periods.
struct VoronoiFoamInput {
  VoronoiPartition partition;
  double wall_mm = 0.1;
  double thickness_mm = 0;            // 2D: the plate's thickness
  std::array<int, 3> tiles{1, 1, 1};  // periods along each axis, without `cover`
  std::optional<std::string> cover;   // instead of tiles: every period meeting that input's box
  // `refine`: starting from the partition's fractal cells, a tile of level l < refine_levels is replaced by its
  // children while the field at its generator (mm, the period at origin_mm) exceeds (l + 1) / (refine_levels + 1);
  // every tile drawn with `level` levels of detail (walls of level + refine_levels). kind kNone: no refinement.
  GradeField refine;
  int refine_levels = 0;
};

// "bcifs_plate": a lacunar face, or an assembly of faces, extruded into a plate.
struct BcifsPlateInput {
  bcifs::PlateOptions plate;
  bool faces_listed = false;  // given as "faces" (an assembly) rather than "face", for messages
};

// "bcifs_cell": a polyhedral cell whose faces are lacunar faces, its walls extruded inwards.
struct BcifsCellInput {
  bcifs::CellKind cell = bcifs::CellKind::kHexahedron;
  double edge_mm = 10;
  Vec3d center_mm;
  bcifs::EdgeType edge;    // every edge's type
  bcifs::EdgeSet params;
  bcifs::Algorithm algorithm = bcifs::Algorithm::kA1;
  int level = 2;
  double thickness_mm = 1;  // less than a quarter of the edge
  bcifs::RealizeOptions options;
};

// "bcifs_volume": one cell, or an assembly of cells sharing faces, subdivided in 3D around lacunas to a level.
struct BcifsVolumeInput {
  bcifs::VolumeSpec spec;
  int level = 2;
  bcifs::VolumeGeometryOptions options;
  size_t shared_faces = 0;
};

// "bcifs_infill": another input's hull, inset by a skin, divided into tetrahedra that conform to it (a Kuhn grid of
// cell_mm, its outside corners moved onto the inset), every tetrahedron a lacunar cell, delayed by its size and
// every last lacuna scaled down to the smallest one's size (equal_lacunas).
struct BcifsInfillInput {
  std::string hull;
  double skin_mm = 1;
  double cell_mm = 10;
  int level = 2;
  bool equal_lacunas = true;
  // Grading: a field over the hull (depth measured in `hull`) lowers the level where it is at most
  // grade_levels / (grade_levels + 1): a cell is lowered by grade_levels - #{k < grade_levels : field at its centre >
  // (k + 1) / (grade_levels + 1)} levels (as a lattice's level grade), added to its delay by size and capped at
  // `level` (every cell subdivides at least once), so faces between levels stay consistent.
  GradeField grade;     // kind kNone: no grading
  int grade_levels = 0;
  // Graded cell size: where cell_grade is 1 the cells are min_cell_mm, where it is 0 cell_mm, geometrically
  // between (in steps of a third of an octave: Kuhn tetrahedra bisected, Maubach's way, which keeps them
  // conforming). kind kNone: every cell from the grid of cell_mm.
  GradeField cell_grade;
  double min_cell_mm = 0;
  bcifs::FaceType face;  // one edge in its boundary: the type of every edge
  bool plain = false;
  bcifs::InteriorFaces interior;
  bcifs::VolumeGeometryOptions options;
};

// One input's options, by type.
using InputSpec =
    std::variant<SphereInput, SpheresInput, CapsuleInput, TubesInput, BoxInput, CylinderInput, TorusInput, RegionInput,
                 MeshInput, SurfaceInput, LatticeInput, CifsInput, CurveInput, FillMotifsInput, FillSpheresInput,
                 VoronoiSpheresInput, VoronoiTilesInput, VoronoiFoamInput, BcifsPlateInput, BcifsCellInput,
                 BcifsVolumeInput, BcifsInfillInput>;

// The other inputs this one is built from (fit_to, cover), in no particular order.
std::vector<std::string> dependencies(const InputSpec& spec);

// Whether the input can only be built once other inputs (or files) are: it depends on other inputs,
// or it is a curve on a mesh patch.
bool built_after_others(const InputSpec& spec);

}  // namespace lacuna
