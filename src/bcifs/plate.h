// Lacunar plates and cells: faces realized at a level as planar regions to extrude, and the faces of
// polyhedral cells. The recipe's "bcifs_plate" and "bcifs_cell" inputs and `lacuna bcifs measure` use them.
#pragma once

#include <string>
#include <vector>

#include "bcifs/realize.h"
#include "bcifs/topology.h"
#include "geometry.h"

namespace lacuna {
namespace bcifs {

// A lacunar face, or an assembly of faces sharing edges, placed and extruded into a plate.
struct PlateOptions {
  Assembly assembly;                         // one face and no shared edges for a single face
  std::vector<std::vector<Vec2d>> controls;  // per face, mm, one point per boundary edge (vertex j starts edge j)
  std::vector<std::vector<Bend>> bends;      // per face: one per edge (curved edges), or empty
  RealizeOptions options;
  int level = 3;
  double thickness_mm = 1;
  Vec3d origin_mm;                           // where the plate's plane z = 0 is moved to
};

// A plate with the rule set of its faces (roots in face order).
struct Plate {
  PlateOptions options;
  RuleSet rules;
};

// The most sub-faces a plate may have at its level; more is refused before realizing them.
constexpr double kMaxPlateLeaves = 2e6;

// The sub-faces of every face of the plate at its level, summed (they grow by the spectral radius).
double plate_leaves(const Plate& plate);

// The union of the leaves of every face at `level`, as closed loops (mm): the outer boundaries
// counter-clockwise and the lacunas clockwise, for the even-odd rule.
std::vector<std::vector<Vec2d>> plate_loops(const Plate& plate, int level);

// The boundary of a union of counter-clockwise polygons that meet only along shared edges (identical end
// points), as closed loops: the edges without their reverse, chained.
std::vector<std::vector<Vec2d>> union_loops(const std::vector<std::vector<Vec2d>>& polygons);

enum class CellKind { kHexahedron, kTruncatedTetrahedron, kTetrahedron, kPrism };

// "hexahedron", "truncated_tetrahedron", "tetrahedron" or "prism"; throws InvalidInput for another name.
CellKind cell_kind_from_name(const std::string& name);

// The faces of a polyhedral cell centred at the origin, each counter-clockwise seen from outside:
// a hexahedron (a cube of edge `edge_mm`), a truncated tetrahedron (4 triangles and 4 hexagons), a regular
// tetrahedron or a prism (an equilateral triangle extruded along z by its edge), every edge `edge_mm`.
std::vector<std::vector<Vec3d>> cell_faces(CellKind cell, double edge_mm);

}  // namespace bcifs
}  // namespace lacuna
