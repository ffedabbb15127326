// The `bcifs_plate` recipe input: a lacunar face, or an assembly of faces sharing edges, realized at a level
// and extruded into a plate. parse_plate is shared with `lacuna bcifs measure`, which reads the same objects.
#pragma once

#include <string>
#include <vector>

#include "bcifs/realize.h"
#include "bcifs/topology.h"
#include "geometry.h"

namespace lacuna {
class JsonObject;
namespace bcifs {

struct PlateSpec {
  Assembly assembly;                         // one face and no shared edges for a single face
  std::vector<std::vector<Vec2d>> controls;  // per face, mm, one point per boundary edge (vertex j starts edge j)
  std::vector<std::vector<Bend>> bends;      // per face: one per edge (curved edges), or empty
  RuleSet rules;                             // built from the faces (roots in face order)
  RealizeOptions options;
  int level = 3;
  double thickness_mm = 1;
  Vec3d origin_mm;
};

// Reads a `bcifs_plate` object: "face" {boundary, params, algorithm, delay, control_mm, bends_mm} or "faces" [...] with
// "shared" [{face_a, edge_a, face_b, edge_b}], "level", "thickness_mm", "radius_mm" (a face without control_mm
// is the regular polygon of that circumradius), "gap_fraction", "lacuna_scale", "notch_depth", "origin_mm".
// Fails (InvalidInput naming the file and key) on anything malformed.
PlateSpec parse_plate(const JsonObject& o);

// The union of the leaves of every face at `level`, as closed loops (mm): the outer boundaries
// counter-clockwise and the lacunas clockwise, for the even-odd rule.
std::vector<std::vector<Vec2d>> plate_loops(const PlateSpec& spec, int level);

// The boundary of a union of counter-clockwise polygons that meet only along shared edges (identical end
// points), as closed loops: the edges without their reverse, chained.
std::vector<std::vector<Vec2d>> union_loops(const std::vector<std::vector<Vec2d>>& polygons);

// The faces of a polyhedral cell centred at the origin, each counter-clockwise seen from outside:
// "hexahedron" (a cube of edge `edge_mm`) or "truncated_tetrahedron" (4 triangles and 4 hexagons, all edges
// `edge_mm`). Throws InvalidInput for another name.
std::vector<std::vector<Vec3d>> cell_faces(const std::string& cell, double edge_mm);

void register_recipe_inputs();

}  // namespace bcifs
}  // namespace lacuna
