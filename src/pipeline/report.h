// What a run found, as values: per input what building it found, per output what its checks found,
// and the run's figures. to_json() gives the form report.json holds.
#pragma once

#include <cstdint>
#include <nlohmann/json_fwd.hpp>
#include <optional>
#include <string>
#include <utility>
#include <variant>
#include <vector>

#include "pipeline/draco_output.h"
#include "pipeline/fea_output.h"
#include "solids/check.h"
#include "solids/printability.h"

namespace lacuna {

// A curve input: its tubes and the segments of the mapped polylines.
struct CurveReport {
  size_t tubes = 0;
  uint64_t segments = 0;
};

// A filling of a region or a wallpaper pattern with motifs.
struct MotifFillReport {
  size_t motifs = 0;                                // placed (every image, for a pattern)
  std::optional<size_t> fundamental_region_motifs;  // a pattern: placed in its fundamental region
  double fill_fraction = 0;
  std::string stop_reason;
};

// A filling of a volume with spheres or polyhedra.
struct VolumeFillReport {
  bool polyhedra = false;  // polyhedra rather than spheres
  size_t placed = 0;
  double fill_fraction = 0;
  std::string stop_reason;
};

// Spheres on the generators of a Voronoi level.
struct VoronoiSpheresReport {
  size_t points = 0;   // generators in the level
  size_t spheres = 0;  // of the kept colours, over every tile
};

// The walls of a Voronoi level (tiles and foams), and a tiling's pieces.
struct VoronoiWallsReport {
  int dimension = 3;
  size_t points = 0;               // generators in the level
  size_t boundary_generators = 0;  // generators with a neighbour of another colour
  size_t wall_facets = 0;
  double wall_measure = 0;            // wall length (2D, mm) or area (3D, mm^2) in one period
  std::optional<size_t> pieces;       // tiles: convex pieces
  std::optional<double> clearance_mm; // tiles: the gap between colours
  std::vector<int> tiles_per_level;   // foam with `refine`: tiles kept at each refinement level 0 .. refine levels
};

// One face of a lacunar plate at its level.
struct BcifsFaceReport {
  int type = 0;  // its face type in the rule set
  double subfaces = 0;
  double lacunas = 0;
  double r_limit = 0;
};

// A lacunar plate: its faces, and the loops of its region.
struct BcifsPlateReport {
  int level = 0;
  size_t face_types = 0;
  std::vector<BcifsFaceReport> faces;
  size_t loops = 0;
  size_t holes = 0;
  double area_mm2 = 0;
};

// A lacunar cell: its faces' regions.
struct BcifsCellReport {
  size_t faces = 0;
  size_t face_types = 0;
  size_t holes = 0;
  double face_area_mm2 = 0;
};

struct BcifsVolumeReport {
  int level = 0;
  size_t cells = 0;         // sub-cells at the level (N^C)
  double lacunas = 0;       // N^L at the level
  double r_limit = 0;       // lim R of the first cell
  size_t cell_types = 0;
  size_t face_types = 0;
  size_t shared_faces = 0;  // faces two cells of the assembly share
  size_t pieces = 0;        // convex pieces handed to the rasterizer
  double volume_mm3 = 0;    // the cells' volume, exact (the solid is this less what the voxels round off)
  // bcifs_infill only: the hull's tetrahedra, their sizes (edge of the regular tetrahedron of their volume)
  // and the largest delay given to the small ones.
  size_t tetrahedra = 0;
  double min_cell_mm = 0, max_cell_mm = 0;
  int max_delay = 0;
  double min_lacuna_mm = 0, max_lacuna_mm = 0;        // the lacunas the last level makes, each one
  double min_lacuna_scale = 0, max_lacuna_scale = 0;  // their scales
  int min_level = 0, max_level = 0;                   // the levels a grade leaves (both `level` without one)
};

// What building an input found; most inputs have nothing to report.
using InputReport = std::variant<std::monostate, CurveReport, MotifFillReport, VolumeFillReport, VoronoiSpheresReport,
                                 VoronoiWallsReport, BcifsPlateReport, BcifsCellReport,
                                 BcifsVolumeReport>;

// An object's printability, analysed before it was meshed (again after the fixes, when asked for).
struct PrintabilityFindings {
  std::vector<PrintFeature> trapped_voids;
  std::vector<PrintFeature> thin_walls;
  std::vector<PrintFeature> small_holes;
  double overhang_area_mm2 = 0;
  double down_facing_area_mm2 = 0;
  size_t drain_holes = 0;             // drilled by "fix"
  size_t thickened_walls = 0;         // grown by "fix"
  std::vector<PrintFeature> loose_pieces;  // separate bodies below min_piece_mm3 (kept: "error", "report")
  size_t loose_pieces_removed = 0;         // by "fix"
  double loose_volume_removed_mm3 = 0;
  std::vector<std::string> problems;  // what fails the output (none with "report")
};

// A layer output (.cli, a zipped PNG stack): what cutting and checking its layers found.
struct LayerOutputReport {
  size_t layers = 0;
  double layer_mm = 0, pixel_mm = 0, tolerance_mm = 0;
  double z0_mm = 0;                   // the bottom of layer 0
  int width = 0, height = 0;          // pixels per layer
  double max_area_difference_mm2 = 0; // between a layer's image and its contours
  size_t contours = 0;                // over every layer
  uint64_t bytes = 0;
  std::vector<std::string> problems;  // what failed (nothing written then)
};

// One written file and what its checks found.
struct OutputReport {
  std::string file;    // final path
  std::string format;  // "stl", "3mf", "drc", "msh", "inp", "vtu", "mesh", "cli", "png_layers"
  std::string object;  // the input or operation (of a group: the first)
  std::string part_name;              // surface outputs: the object's name in the file
  std::vector<std::string> group;     // a 3MF of several objects: the objects asked for ...
  std::vector<std::string> objects;   // ... and those read back from the package, in order
  uint64_t voxels = 0;                // active voxels of the object's level set
  size_t subvoxel_cavities_filled = 0;
  size_t subvoxel_specks_removed = 0;
  double simplify_mm = 0;             // deviation the surface was simplified to (mm; 0: not simplified)
  uint64_t extracted_triangles = 0;   // of the surface before simplification
  std::optional<MeshCheckReport> check;  // surface outputs: the file as read back
  std::optional<DracoFigures> draco;     // .drc outputs: quantization and size
  std::string picture;                   // the PNG rendered of it ("render"), final path; empty: none
  std::optional<TetCheck> tetrahedra;    // tetrahedral outputs
  std::optional<LayerOutputReport> layers;  // layer outputs (no mesh)
  std::optional<PrintabilityFindings> printability;
  std::optional<double> hull_volume_mm3;  // infill objects: the hull's volume, for the relative density

  // Whether every check passed: the file's (or the tetrahedra's), the group's objects, printability.
  bool valid() const;
};

struct RunReport {
  std::string lacuna_version;
  std::string recipe;  // the recipe's path
  std::string name;
  double voxel_size_mm = 0;
  double band_voxels = 0;
  uint64_t seed = 0;
  bool valid = false;  // every output passed; otherwise nothing was written
  std::vector<OutputReport> outputs;
  std::vector<std::pair<std::string, double>> stage_seconds;  // in the order the stages ran (a stage may recur)
  uint64_t peak_memory_bytes = 0;
  uint64_t peak_memory_children_bytes = 0;
  uint64_t memory_estimate_bytes = 0;
  uint64_t memory_budget_bytes = 0;
  size_t threads = 0;
  std::vector<std::pair<std::string, InputReport>> inputs;  // by input name, those with something to report
  std::vector<std::string> written;  // final paths of every file written, report.html then report.json last; empty when invalid
};

// The JSON of an input's report (null when there is nothing to report).
nlohmann::json to_json(const InputReport& report);

// An output's entry in report.json.
nlohmann::json to_json(const OutputReport& report);

// A .drc output's figures: quantization bits, the bound on vertex moves, sizes and their ratio.
nlohmann::json to_json(const DracoFigures& figures);

// report.json: the run's figures, every output's entry, the inputs' reports; a stage that ran more
// than once is given its last time, total_seconds sums them all.
nlohmann::json to_json(const RunReport& report);

}  // namespace lacuna
