// Inputs built from generators of lattices, CIFS attractors and space-filling curves.
#include <algorithm>
#include <string>
#include <vector>

#include "errors.h"
#include "recipe/cifs_system.h"
#include "recipe/input_parsers.h"

namespace lacuna {
namespace {

using curves::SweepOptions;

// "orders": [1, 2, 5] or "1..5".
std::vector<int> parse_orders(const JsonObject& o, int most) {
  const nlohmann::json& v = o.required("orders");
  std::vector<int> orders;
  auto check = [&](int64_t k) {
    if (k < 1 || k > most) o.fail("orders", "expected orders from 1 to " + std::to_string(most) + ", got " + std::to_string(k));
    return int(k);
  };
  if (v.is_string()) {
    std::vector<int> given;
    try {
      given = curves::parse_orders(v.get<std::string>());
    } catch (const InvalidInput& e) {
      o.fail("orders", e.what());
    }
    for (int k : given) orders.push_back(check(k));
  } else if (v.is_array()) {
    for (size_t i = 0; i < v.size(); ++i) {
      if (!v[i].is_number_integer()) o.fail("orders", "expected whole numbers, got " + describe_json_type(v[i]) + " at " + std::to_string(i));
      orders.push_back(check(v[i].get<int64_t>()));
    }
  } else {
    o.fail("orders", "expected \"FROM..TO\" or a list of orders, got " + describe_json_type(v));
  }
  if (orders.empty()) o.fail("orders", "expected at least one order");
  for (size_t i = 0; i < orders.size(); ++i)
    for (size_t j = 0; j < i; ++j)
      if (orders[i] == orders[j]) o.fail("orders", "order " + std::to_string(orders[i]) + " is given twice");
  return orders;
}

}  // namespace

curves::BSplinePatch parse_bspline_patch(const JsonObject& p) {
  p.allow_only({"degree_u", "degree_v", "count_u", "count_v", "control_points_mm"});
  curves::BSplinePatch patch;
  patch.degree_u = int(p.unsigned_integer_or("degree_u", 3));
  patch.degree_v = int(p.unsigned_integer_or("degree_v", 3));
  patch.count_u = int(p.unsigned_integer_or("count_u", 0));
  patch.count_v = int(p.unsigned_integer_or("count_v", 0));
  patch.control_points = p.vec3_list("control_points_mm");
  if (patch.degree_u < 1 || patch.degree_v < 1) p.fail("degree_u", "expected degrees of at least 1");
  if (patch.count_u <= patch.degree_u) p.fail("count_u", "expected more control points along u than the degree");
  if (patch.count_v <= patch.degree_v) p.fail("count_v", "expected more control points along v than the degree");
  if (patch.control_points.size() != size_t(patch.count_u) * size_t(patch.count_v))
    p.fail("control_points_mm", "expected count_u x count_v = " + std::to_string(patch.count_u * patch.count_v) +
                                    " points (u fastest), got " + std::to_string(patch.control_points.size()));
  return patch;
}

GradeField parse_grade_field(const JsonObject& g, const std::string& no_depth) {
  GradeField f;
  std::string field = g.string("field");
  if (field == "ramp") {
    f.kind = GradeField::Kind::kRamp;
    f.axis = g.direction_or("axis", Vec3d{0, 0, 1});
    f.from_mm = g.number("from_mm");
    f.to_mm = g.number("to_mm");
    if (f.from_mm == f.to_mm) g.fail("to_mm", "expected a value different from from_mm");
  } else if (field == "points") {
    f.kind = GradeField::Kind::kPoints;
    f.points_mm = g.vec3_list("points_mm");
    if (f.points_mm.empty()) g.fail("points_mm", "expected at least one point");
    f.falloff_mm = g.positive_length("falloff_mm");
  } else if (field == "depth") {
    f.kind = GradeField::Kind::kDepth;
    f.depth_mm = g.positive_length("depth_mm");
    if (!no_depth.empty()) g.fail("field", no_depth);
  } else {
    g.fail("field", "expected \"ramp\", \"points\" or \"depth\", got \"" + field + "\"");
  }
  return f;
}

LatticeInput parse_lattice_input(const JsonObject& o) {
  LatticeInput in;
  LatticeOptions& options = in.lattice;
  std::string cell = o.string_or("cell", "cubic");
  if (cell == "cubic") options.cell = LatticeOptions::Cell::kCubic;
  else if (cell == "bcc") options.cell = LatticeOptions::Cell::kBodyCentred;
  else o.fail("cell", "expected \"cubic\" or \"bcc\", got \"" + cell + "\"");
  options.period_mm = o.positive_length("period_mm");
  const bool fitted = o.has("fit_to");
  if (fitted == (o.has("min_mm") || o.has("max_mm"))) o.fail("", "give either \"fit_to\" or \"min_mm\" and \"max_mm\"");
  const std::string layout = o.string_or("layout", "tiled");
  if (layout == "tiled") options.layout = LatticeOptions::Layout::kTiled;
  else if (layout == "scaled") options.layout = LatticeOptions::Layout::kScaled;
  else if (layout == "conforming") options.layout = LatticeOptions::Layout::kConforming;
  else o.fail("layout", "expected \"tiled\", \"scaled\" or \"conforming\", got \"" + layout + "\"");
  const bool conforming = options.layout == LatticeOptions::Layout::kConforming;
  if (conforming && !fitted) o.fail("layout", "a conforming lattice needs \"fit_to\": the hull it conforms to");
  if (o.has("inset_mm")) {
    if (!conforming) o.fail("inset_mm", "only a conforming lattice has an inset");
    options.conform_inset_mm = o.number("inset_mm");
    if (!(options.conform_inset_mm >= 0)) o.fail("inset_mm", "expected a depth of at least 0 mm");
  }
  bool radius_given = true;
  if (o.has("grade")) {
    JsonObject g = o.object("grade");
    g.allow_only({"parameter", "radius_min_mm", "radius_max_mm", "levels", "field", "axis", "from_mm", "to_mm",
                  "points_mm", "falloff_mm", "depth_mm"});
    const std::string parameter = g.string_or("parameter", "radius");
    if (parameter == "radius") {
      options.graded = LatticeOptions::Graded::kRadius;
      options.radius_min_mm = g.positive_length("radius_min_mm");
      options.radius_max_mm = g.positive_length("radius_max_mm");
      radius_given = false;
    } else if (parameter == "level") {
      options.graded = LatticeOptions::Graded::kLevel;
      const uint64_t levels = g.unsigned_integer_or("levels", 1);
      if (levels < 1 || levels > 6) g.fail("levels", "expected 1 to 6 splits of a cell");
      options.levels = int(levels);
    } else {
      g.fail("parameter", "expected \"radius\" or \"level\", got \"" + parameter + "\"");
    }
    options.grade = parse_grade_field(g, fitted ? "" : "a depth grade needs \"fit_to\": the hull it is measured in");
  }
  if (radius_given) options.radius_mm = o.positive_length("strut_radius_mm");
  else if (o.has("strut_radius_mm")) o.fail("strut_radius_mm", "give the radii in \"grade\" when grading the radius");
  if (!fitted) {
    in.box.expand(o.vec3("min_mm"));
    in.box.expand(o.vec3("max_mm"));
    Vec3d lo = o.vec3("min_mm"), hi = o.vec3("max_mm");
    if (!(hi.x > lo.x && hi.y > lo.y && hi.z > lo.z)) o.fail("max_mm", "expected max_mm > min_mm on every axis");
    return in;
  }
  in.fit_to = o.string("fit_to");
  return in;
}

namespace {

// The tree under a cifs shell: the keys of `so` (the "support" object, or a cifs_support input itself);
// `o` names the input in messages.
void read_support(const JsonObject& o, const JsonObject& so, const char* key, CifsInput& in) {
  if (in.solid.as != cifs::SolidOptions::As::kDefault && in.solid.as != cifs::SolidOptions::As::kShell)
    o.fail(key, "a support stands under a shell: leave \"as\" out or give \"shell\"");
  for (const cifs::State& s : in.system.automaton.states)
    if (s.primitive != cifs::Primitive::kQuad)
      o.fail(key, "a support stands under a tensor surface (quad pieces); state \"" + s.name + "\" is a " +
                      cifs::primitive_name(s.primitive));
  cifs::SupportOptions support;
  support.base_center_mm = so.vec3("base_mm");
  if (so.has("base_size_mm")) support.base_size_mm = so.positive_length("base_size_mm");
  support.fork = so.number_or("fork", support.fork);
  if (!(support.fork > 0 && support.fork < 1)) so.fail("fork", "expected a number strictly between 0 and 1");
  support.shrink = so.number_or("shrink", support.shrink);
  if (!(support.shrink > 0 && support.shrink <= 1)) so.fail("shrink", "expected a number in (0, 1]");
  in.support = support;
}

}  // namespace

CifsInput parse_cifs_input(const JsonObject& o) {
  CifsInput in;
  in.system = cifs::parse_system(o.required("system"), o.file(), o.path_of("system"));
  uint64_t level = o.unsigned_integer_or("level", 3);
  if (level > 24) o.fail("level", "expected a level from 0 to 24");
  in.level = int(level);
  cifs::SolidOptions& options = in.solid;
  std::string as = o.string_or("as", "");
  if (as == "tubes") options.as = cifs::SolidOptions::As::kTubes;
  else if (as == "shell") options.as = cifs::SolidOptions::As::kShell;
  else if (as == "cells") options.as = cifs::SolidOptions::As::kCells;
  else if (as == "edges") options.as = cifs::SolidOptions::As::kEdges;
  else if (!as.empty()) o.fail("as", "expected \"tubes\", \"shell\", \"cells\" or \"edges\", got \"" + as + "\"");
  if (o.has("radius_mm")) options.radius_mm = o.positive_length("radius_mm");
  if (o.has("thickness_mm")) options.thickness_mm = o.positive_length("thickness_mm");
  if (o.has("fit_to")) in.fit_to = o.string("fit_to");
  if (o.has("support")) {
    JsonObject so = o.object("support");
    so.allow_only({"base_mm", "base_size_mm", "fork", "shrink"});
    read_support(o, so, "support", in);
  }
  return in;
}

CifsInput parse_cifs_support_input(const JsonObject& o) {
  CifsInput in = parse_cifs_input(o);
  in.solid.as = cifs::SolidOptions::As::kShell;
  read_support(o, o, "system", in);
  return in;
}

CurveInput parse_curve_input(const JsonObject& o) {
  CurveInput in;
  SweepOptions& options = in.sweep;
  const std::string kind = o.string("kind");
  if (kind == "hilbert") options.kind = SweepOptions::Kind::kHilbert;
  else if (kind == "sierpinski") options.kind = SweepOptions::Kind::kSierpinski;
  else if (kind == "hilbert3d") options.kind = SweepOptions::Kind::kHilbert3d;
  else o.fail("kind", "expected \"hilbert\", \"sierpinski\" or \"hilbert3d\", got \"" + kind + "\"");
  options.orders = parse_orders(o, options.kind == SweepOptions::Kind::kHilbert3d ? 8 : options.kind == SweepOptions::Kind::kHilbert ? 12 : 11);
  if (o.has("radius_mm") && o.json().at("radius_mm").is_array()) {
    options.radii_mm = o.positive_length_list("radius_mm");
    if (options.radii_mm.size() != options.orders.size())
      o.fail("radius_mm", "expected one radius per order (" + std::to_string(options.orders.size()) + "), got " +
                              std::to_string(options.radii_mm.size()));
  } else {
    options.radii_mm = {o.positive_length("radius_mm")};
  }
  const double smallest = *std::min_element(options.radii_mm.begin(), options.radii_mm.end());
  const std::string surface = o.string_or("surface", options.kind == SweepOptions::Kind::kHilbert3d ? "cube" : "plane");
  const bool mesh = surface == "mesh";
  options.map.scale = mesh ? o.positive_length_or("scale_mm", 1) : o.positive_length("scale_mm");
  options.map.offset_mm = o.number_or("offset_mm", 0);
  options.map.tolerance_mm = o.positive_length_or("tolerance_mm", 0.1 * smallest);
  options.center_mm = o.vec3_or("center_mm", Vec3d{});
  options.base_thickness_mm = o.has("base_mm") ? o.positive_length("base_mm") : 0;
  if (o.has("patch") && surface != "bspline") o.fail("patch", "a patch is only read with \"surface\": \"bspline\"");
  if (o.has("mesh") && !mesh) o.fail("mesh", "a mesh patch is only read with \"surface\": \"mesh\"");
  if (options.kind == SweepOptions::Kind::kHilbert3d) {
    if (surface != "cube") o.fail("surface", "a 3D Hilbert curve fills the cube; it takes no surface");
    if (options.base_thickness_mm > 0) o.fail("base_mm", "a 3D Hilbert curve has no base surface");
  }
  using Surface = CurveInput::Surface;
  if (surface == "plane") in.surface = Surface::kPlane;
  else if (surface == "sphere") in.surface = Surface::kSphere;
  else if (surface == "cylinder") in.surface = Surface::kCylinder;
  else if (surface == "torus") in.surface = Surface::kTorus;
  else if (surface == "cone") in.surface = Surface::kCone;
  else if (surface == "cube") in.surface = Surface::kCube;
  else if (surface == "bspline") {
    in.surface = Surface::kBspline;
    in.patch = parse_bspline_patch(o.object("patch"));
  } else if (!mesh) {
    o.fail("surface", "expected \"plane\", \"sphere\", \"cylinder\", \"torus\", \"cone\", \"cube\", \"bspline\" or \"mesh\", got \"" + surface + "\"");
  }
  if (!mesh) return in;
  in.surface = Surface::kMesh;
  in.mesh_file = o.string("mesh");
  if (in.mesh_file.empty()) o.fail("mesh", "expected a file name");
  return in;
}

}  // namespace lacuna
