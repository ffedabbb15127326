// The lacunar plate and cell inputs (bcifs).
#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "errors.h"
#include "bcifs/volume.h"
#include "recipe/input_parsers.h"

namespace lacuna {
namespace {

using namespace bcifs;

constexpr double kPi = 3.14159265358979323846;

FaceType parse_face(const JsonObject& f) {
  f.allow_only({"boundary", "params", "algorithm", "delay", "control_mm", "bends_mm"});
  FaceType face;
  try {
    face.boundary = parse_boundary(f.string("boundary"));
  } catch (const InvalidInput& e) {
    f.fail("boundary", e.what());
  }
  try {
    face.edges = parse_edge_set(f.string_or("params", "C2 B2 B2"));
  } catch (const InvalidInput& e) {
    f.fail("params", e.what());
  }
  try {
    face.algorithm = parse_algorithm(f.string_or("algorithm", "A1"));
  } catch (const InvalidInput& e) {
    f.fail("algorithm", e.what());
  }
  const uint64_t delay = f.unsigned_integer_or("delay", 1);
  if (delay < 1 || delay > 16) f.fail("delay", "expected a delay from 1 to 16");
  face.delay = int(delay);
  try {
    validate(face);
  } catch (const InvalidInput& e) {
    f.fail("", e.what());
  }
  return face;
}

std::vector<Vec2d> parse_control(const JsonObject& f, size_t edges, double radius) {
  std::vector<Vec2d> control;
  if (!f.has("control_mm")) {
    if (radius <= 0) f.fail("control_mm", "expected one [x, y] per boundary edge (or \"radius_mm\" for a regular polygon)");
    for (size_t j = 0; j < edges; ++j) {
      const double a = 2 * kPi * double(j) / double(edges);
      control.push_back({radius * std::cos(a), radius * std::sin(a)});
    }
    return control;
  }
  control = f.vec2_list(f.required("control_mm"), f.path_of("control_mm"));
  if (control.size() != edges)
    f.fail("control_mm", "expected " + std::to_string(edges) + " points (one per boundary edge), got " +
                             std::to_string(control.size()));
  if (!(signed_area(control) > 0)) f.fail("control_mm", "expected a counter-clockwise polygon of positive area");
  return control;
}

// "bends_mm": one entry per edge, null for a straight edge or [x, y], the middle control point of the edge's
// quadratic Bézier.
std::vector<Bend> parse_bends(const JsonObject& f, size_t edges) {
  std::vector<Bend> bends;
  if (!f.has("bends_mm")) return bends;
  const nlohmann::json& list = f.required("bends_mm");
  if (!list.is_array() || list.size() != edges)
    f.fail("bends_mm", "expected " + std::to_string(edges) + " entries (one per edge): null or [x, y]");
  for (size_t j = 0; j < edges; ++j) {
    if (list[j].is_null()) {
      bends.emplace_back();
      continue;
    }
    if (!list[j].is_array() || list[j].size() != 2 || !list[j][0].is_number() || !list[j][1].is_number())
      f.fail("bends_mm", "entry " + std::to_string(j) + ": expected null or [x, y]");
    bends.emplace_back(Vec2d{list[j][0].get<double>(), list[j][1].get<double>()});
  }
  return bends;
}

double fraction(const JsonObject& o, const char* key, double fallback) {
  const double v = o.number_or(key, fallback);
  if (!(v > 0 && v < 1)) o.fail(key, "expected a fraction strictly between 0 and 1");
  return v;
}

// The face geometry of an input: the named "realization" (default "default"), then any of its three options given
// explicitly; `lacuna_key` names the key of the faces' lacuna scale.
GeometryOptions face_geometry(const JsonObject& o, const char* lacuna_key = "lacuna_scale") {
  GeometryOptions g;
  try {
    g = realization_preset(o.string_or("realization", "default"));
  } catch (const InvalidInput& e) {
    o.fail("realization", e.what());
  }
  g.gap_fraction = fraction(o, "gap_fraction", g.gap_fraction);
  g.lacuna_scale = fraction(o, lacuna_key, g.lacuna_scale);
  g.notch_depth = fraction(o, "notch_depth", g.notch_depth);
  return g;
}

}  // namespace

BcifsPlateInput parse_bcifs_plate_input(const JsonObject& o) {
  BcifsPlateInput in;
  bcifs::PlateOptions& spec = in.plate;
  if (o.has("face") == o.has("faces")) o.fail("", "give either \"face\" (one lacunar face) or \"faces\" (an assembly)");
  const double radius = o.has("radius_mm") ? o.positive_length("radius_mm") : 0.0;
  if (o.has("face")) {
    if (o.has("shared")) o.fail("shared", "shared edges need \"faces\"");
    const JsonObject f = o.object("face");
    spec.assembly.faces.push_back(parse_face(f));
    spec.controls.push_back(parse_control(f, spec.assembly.faces[0].boundary.size(), radius));
    spec.bends.push_back(parse_bends(f, spec.assembly.faces[0].boundary.size()));
  } else {
    const nlohmann::json& list = o.required("faces");
    if (!list.is_array() || list.empty()) o.fail("faces", "expected a list of faces");
    for (size_t i = 0; i < list.size(); ++i) {
      const JsonObject f(list[i], o.file(), o.path_of("faces") + "[" + std::to_string(i) + "]");
      spec.assembly.faces.push_back(parse_face(f));
      spec.controls.push_back(parse_control(f, spec.assembly.faces.back().boundary.size(), list.size() == 1 ? radius : 0));
      spec.bends.push_back(parse_bends(f, spec.assembly.faces.back().boundary.size()));
    }
    if (o.has("shared")) {
      const nlohmann::json& shared = o.required("shared");
      if (!shared.is_array()) o.fail("shared", "expected a list of {face_a, edge_a, face_b, edge_b} (0-based)");
      for (size_t i = 0; i < shared.size(); ++i) {
        const JsonObject s(shared[i], o.file(), o.path_of("shared") + "[" + std::to_string(i) + "]");
        s.allow_only({"face_a", "edge_a", "face_b", "edge_b"});
        auto index = [&](const char* key) {
          if (!s.has(key)) s.fail(key, "expected a 0-based index");
          return int(std::min<uint64_t>(s.unsigned_integer_or(key, 0), 1u << 30));
        };
        SharedEdge e;
        e.face_a = index("face_a");
        e.edge_a = index("edge_a");
        e.face_b = index("face_b");
        e.edge_b = index("edge_b");
        spec.assembly.shared.push_back(e);
      }
    }
  }
  try {
    validate(spec.assembly);
  } catch (const InvalidInput& e) {
    o.fail(o.has("shared") ? "shared" : "", e.what());
  }
  const uint64_t level = o.unsigned_integer_or("level", 3);
  if (level > 8) o.fail("level", "expected a level from 0 to 8");
  spec.level = int(level);
  spec.thickness_mm = o.positive_length_or("thickness_mm", 1.0);
  spec.origin_mm = o.vec3_or("origin_mm", Vec3d{});
  spec.options.defaults = face_geometry(o);
  in.faces_listed = o.has("faces");
  return in;
}

BcifsCellInput parse_bcifs_cell_input(const JsonObject& o) {
  BcifsCellInput in;
  in.edge_mm = o.positive_length("edge_mm");
  try {
    in.cell = cell_kind_from_name(o.string("cell"));
  } catch (const InvalidInput& e) {
    o.fail("cell", e.what());
  }
  in.thickness_mm = o.positive_length("thickness_mm");
  if (in.thickness_mm >= in.edge_mm / 4) o.fail("thickness_mm", "expected a wall thinner than a quarter of edge_mm");
  in.center_mm = o.vec3_or("center_mm", Vec3d{});
  const uint64_t level = o.unsigned_integer_or("level", 2);
  if (level > 6) o.fail("level", "expected a level from 0 to 6");
  in.level = int(level);
  try {
    in.edge = parse_edge(o.string_or("edge", "C2"));
  } catch (const InvalidInput& e) {
    o.fail("edge", e.what());
  }
  try {
    in.params = parse_edge_set(o.string_or("params", "C2 B2 B2"));
  } catch (const InvalidInput& e) {
    o.fail("params", e.what());
  }
  try {
    in.algorithm = parse_algorithm(o.string_or("algorithm", "A1"));
  } catch (const InvalidInput& e) {
    o.fail("algorithm", e.what());
  }
  RealizeOptions& options = in.options;
  options.defaults = face_geometry(o);
  return in;
}

namespace {

template <class T>
T parsed(const JsonObject& o, const char* key, const std::string& fallback, T (*parse)(const std::string&)) {
  try {
    return parse(o.string_or(key, fallback));
  } catch (const InvalidInput& e) {
    o.fail(key, e.what());
  }
}

// One cell of a bcifs_volume: a regular cell (cell, edge_mm, center_mm) or any convex polyhedron (corners_mm and
// faces, corner loops counter-clockwise seen from outside), and its delay.
CellSpec parse_volume_cell(const JsonObject& o, const FaceType& face, bool plain) {
  CellSpec cell;
  if (o.has("corners_mm")) {
    if (o.has("cell") || o.has("edge_mm")) o.fail("corners_mm", "give either corners_mm and faces or cell and edge_mm");
    cell.shape.corners_mm = o.vec3_list("corners_mm");
    if (cell.shape.corners_mm.size() < 4 || cell.shape.corners_mm.size() > 1000)
      o.fail("corners_mm", "expected 4 to 1000 corners");
    const nlohmann::json& faces = o.required("faces");
    if (!faces.is_array() || faces.size() < 4 || faces.size() > 1000)
      o.fail("faces", "expected 4 to 1000 faces, each a list of 0-based corner indices");
    for (size_t f = 0; f < faces.size(); ++f) {
      const std::string at = o.path_of("faces") + "[" + std::to_string(f) + "]";
      if (!faces[f].is_array() || faces[f].size() < 3 || faces[f].size() > 64)
        throw InvalidInput(o.file() + ": " + at + ": expected a list of 3 to 64 corner indices");
      std::vector<int> loop;
      for (const auto& k : faces[f]) {
        if (!k.is_number_unsigned() || k.get<uint64_t>() >= cell.shape.corners_mm.size())
          throw InvalidInput(o.file() + ": " + at + ": expected corner indices from 0 to " +
                             std::to_string(cell.shape.corners_mm.size() - 1));
        loop.push_back(int(k.get<uint64_t>()));
      }
      cell.shape.faces.push_back(std::move(loop));
    }
  } else {
    CellKind kind = CellKind::kHexahedron;
    try {
      kind = cell_kind_from_name(o.string_or("cell", "hexahedron"));
    } catch (const InvalidInput& e) {
      o.fail("cell", e.what());
    }
    cell.shape = regular_cell(kind, o.positive_length("edge_mm"), o.vec3_or("center_mm", Vec3d{}));
  }
  const uint64_t delay = o.unsigned_integer_or("delay", 1);
  if (delay < 1 || delay > 8) o.fail("delay", "expected a delay from 1 to 8");
  cell.delay = int(delay);
  set_uniform_faces(cell, face, plain);
  return cell;
}

}  // namespace

namespace {

// The keys a bcifs_volume and a bcifs_infill share: the walls' face rule, the interior faces, the geometry.
struct VolumeKeys {
  FaceType face;  // its boundary holds one edge: the type of every edge
  bool plain = false;
  InteriorFaces interior;
  VolumeGeometryOptions options;
  int level = 2;
};

VolumeKeys parse_volume_keys(const JsonObject& o, uint64_t max_level) {
  VolumeKeys k;
  const std::string walls = o.string_or("walls", "lacunar");
  if (walls != "lacunar" && walls != "plain") o.fail("walls", "expected \"lacunar\" or \"plain\"");
  k.plain = walls == "plain";
  k.face.boundary = {parsed(o, "edge", "C2", parse_edge)};
  k.face.edges = parsed(o, "params", "C2 B2 B2", parse_edge_set);
  k.face.algorithm = parsed(o, "algorithm", "A1", parse_algorithm);
  const std::string interior = o.string_or("interior", "lacunar");
  if (interior != "lacunar" && interior != "plain") o.fail("interior", "expected \"lacunar\" or \"plain\"");
  k.interior.plain = interior == "plain";
  k.interior.radial = parsed(o, "radial", "B2", parse_edge);
  k.interior.edges = o.has("interior_params") ? parsed(o, "interior_params", "", parse_edge_set) : k.face.edges;
  k.interior.algorithm =
      o.has("interior_algorithm") ? parsed(o, "interior_algorithm", "", parse_algorithm) : k.face.algorithm;
  const uint64_t level = o.unsigned_integer_or("level", 2);
  if (level > max_level) o.fail("level", "expected a level from 0 to " + std::to_string(max_level));
  k.level = int(level);
  k.options.lacuna_scale = fraction(o, "lacuna_scale", k.options.lacuna_scale);
  k.options.faces = face_geometry(o, "face_lacuna_scale");
  return k;
}

}  // namespace

BcifsVolumeInput parse_bcifs_volume_input(const JsonObject& o) {
  BcifsVolumeInput in;
  const VolumeKeys k = parse_volume_keys(o, 6);
  in.spec.interior = k.interior;
  in.level = k.level;
  in.options = k.options;
  if (o.has("cells")) {
    if (o.has("cell") || o.has("edge_mm") || o.has("corners_mm") || o.has("delay"))
      o.fail("cells", "give the cells either as a list in \"cells\" or as one cell, not both");
    const nlohmann::json& list = o.required("cells");
    if (!list.is_array() || list.empty() || list.size() > 1000) o.fail("cells", "expected a list of 1 to 1000 cells");
    for (size_t i = 0; i < list.size(); ++i) {
      const JsonObject c(list[i], o.file(), o.path_of("cells") + "[" + std::to_string(i) + "]");
      c.allow_only({"cell", "edge_mm", "center_mm", "corners_mm", "faces", "delay"});
      in.spec.cells.push_back(parse_volume_cell(c, k.face, k.plain));
    }
  } else {
    in.spec.cells.push_back(parse_volume_cell(o, k.face, k.plain));
  }
  try {
    in.shared_faces = shared_faces(in.spec).size();
  } catch (const InvalidInput& e) {
    o.fail(o.has("cells") ? "cells" : "", e.what());
  }
  return in;
}

BcifsInfillInput parse_bcifs_infill_input(const JsonObject& o) {
  BcifsInfillInput in;
  in.hull = o.string("hull");
  const VolumeKeys k = parse_volume_keys(o, 4);
  in.face = k.face;
  in.plain = k.plain;
  in.interior = k.interior;
  in.options = k.options;
  in.level = k.level;
  if (in.level < 1) o.fail("level", "expected a level from 1 to 4");
  in.skin_mm = o.number_or("skin_mm", 1.0);
  if (!(in.skin_mm >= 0 && std::isfinite(in.skin_mm))) o.fail("skin_mm", "expected a skin of 0 mm or more");
  in.cell_mm = o.positive_length_or("cell_mm", 10.0);
  in.equal_lacunas = o.boolean_or("equal_lacunas", true);
  if (o.has("grade")) {
    const JsonObject g = o.object("grade");
    g.allow_only({"levels", "field", "axis", "from_mm", "to_mm", "points_mm", "falloff_mm", "depth_mm"});
    in.grade = parse_grade_field(g, "");
    if (in.level < 2) o.fail("grade", "a grade lowers the level somewhere: it needs level 2 or more");
    const uint64_t levels = g.unsigned_integer_or("levels", uint64_t(in.level - 1));
    if (levels < 1 || levels >= uint64_t(in.level))
      g.fail("levels", "expected 1 to level - 1 = " + std::to_string(in.level - 1) +
                           " levels the field may take away (every cell subdivides at least once)");
    in.grade_levels = int(levels);
  }
  if (o.has("cell_grade")) {
    const JsonObject g = o.object("cell_grade");
    g.allow_only({"min_cell_mm", "field", "axis", "from_mm", "to_mm", "points_mm", "falloff_mm", "depth_mm"});
    in.cell_grade = parse_grade_field(g, "");
    in.min_cell_mm = g.positive_length("min_cell_mm");
    // Each third of an octave is one more bisection of every cell there (and of neighbours, to conform).
    if (!(in.min_cell_mm < in.cell_mm) || in.cell_mm / in.min_cell_mm > 8)
      g.fail("min_cell_mm", "expected a cell size below cell_mm (" + message_number(in.cell_mm) +
                                " mm) and at least an eighth of it");
  }
  return in;
}

}  // namespace lacuna
