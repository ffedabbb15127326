#include "bcifs/recipe_input.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <string>
#include <utility>

#include "errors.h"
#include "recipe/json_fields.h"
#include "recipe/recipe.h"

namespace lacuna {
namespace bcifs {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kMaxLeaves = 2e6;

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

}  // namespace

PlateSpec parse_plate(const JsonObject& o) {
  PlateSpec spec;
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
  spec.options.defaults.gap_fraction = fraction(o, "gap_fraction", spec.options.defaults.gap_fraction);
  spec.options.defaults.lacuna_scale = fraction(o, "lacuna_scale", spec.options.defaults.lacuna_scale);
  spec.options.defaults.notch_depth = fraction(o, "notch_depth", spec.options.defaults.notch_depth);
  try {
    spec.rules = build_rules(spec.assembly.faces);
  } catch (const InvalidInput& e) {
    o.fail("", e.what());
  } catch (const ResourceLimit& e) {
    throw ResourceLimit(o.file() + ": " + o.path() + ": " + e.what());
  }
  // Leaves grow by the spectral radius per level; refuse before building millions.
  double leaves = 0;
  for (int root : spec.rules.roots) leaves += lacunarity(spec.rules, root, spec.level).subfaces.back();
  if (leaves > kMaxLeaves)
    throw ResourceLimit(o.file() + ": " + o.path_of("level") + ": level " + std::to_string(spec.level) + " has " +
                        std::to_string(int64_t(leaves)) + " sub-faces, more than 2 000 000; use a lower level");
  // The shared edges must have the same end points (reversed) on both sides.
  try {
    realize_assembly(spec.rules, spec.assembly, spec.controls, 0, spec.options, spec.bends);
  } catch (const InvalidInput& e) {
    o.fail(o.has("faces") ? "faces" : "face", e.what());
  }
  return spec;
}

std::vector<std::vector<Vec2d>> plate_loops(const PlateSpec& spec, int level) {
  std::vector<std::vector<Vec2d>> polygons;
  for (const auto& face : realize_assembly(spec.rules, spec.assembly, spec.controls, level, spec.options, spec.bends))
    for (auto& outline : polygons_of(face)) polygons.push_back(std::move(outline));
  return union_loops(polygons);
}

std::vector<std::vector<Vec2d>> union_loops(const std::vector<std::vector<Vec2d>>& polygons) {
  // Chained by following, from each end point, an unused edge that starts there (in-degree equals out-degree
  // at every vertex, so every chain closes).
  const auto segments = boundary_segments(polygons);
  auto key = [](const Vec2d& p) { return std::make_pair(p.x, p.y); };
  std::multimap<std::pair<double, double>, size_t> starts;
  for (size_t i = 0; i < segments.size(); ++i) starts.emplace(key(segments[i].first), i);
  std::vector<char> used(segments.size(), 0);
  std::vector<std::vector<Vec2d>> loops;
  for (size_t first = 0; first < segments.size(); ++first) {
    if (used[first]) continue;
    std::vector<Vec2d> loop;
    size_t s = first;
    for (;;) {
      used[s] = 1;
      loop.push_back(segments[s].first);
      const Vec2d end = segments[s].second;
      if (end == segments[first].first) break;
      size_t next = segments.size();
      auto range = starts.equal_range(key(end));
      for (auto it = range.first; it != range.second; ++it)
        if (!used[it->second]) {
          next = it->second;
          break;
        }
      if (next == segments.size()) throw std::logic_error("bcifs: the boundary of the leaves does not close");
      s = next;
    }
    loops.push_back(std::move(loop));
  }
  return loops;
}

std::vector<std::vector<Vec3d>> cell_faces(const std::string& cell, double edge_mm) {
  std::vector<std::vector<Vec3d>> faces;
  if (cell == "hexahedron") {
    const double h = edge_mm / 2;
    auto corner = [&](int i) { return Vec3d{i & 1 ? h : -h, i & 2 ? h : -h, i & 4 ? h : -h}; };
    for (const auto& f : std::vector<std::array<int, 4>>{
             {0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}})
      faces.push_back({corner(f[0]), corner(f[1]), corner(f[2]), corner(f[3])});
    return faces;
  }
  if (cell != "truncated_tetrahedron")
    throw InvalidInput("expected \"hexahedron\" or \"truncated_tetrahedron\", got \"" + cell + "\"");
  // The regular tetrahedron (1,1,1), (1,-1,-1), (-1,1,-1), (-1,-1,1) (edge 2 sqrt 2) with each corner cut a
  // third of the way along its edges: 12 vertices, edges 2 sqrt(2) / 3.
  const std::array<Vec3d, 4> t = {Vec3d{1, 1, 1}, Vec3d{1, -1, -1}, Vec3d{-1, 1, -1}, Vec3d{-1, -1, 1}};
  const double scale = edge_mm / (2 * std::sqrt(2.0) / 3);
  auto cut = [&](int i, int j) { return (t[size_t(i)] * (2.0 / 3) + t[size_t(j)] * (1.0 / 3)) * scale; };
  for (int i = 0; i < 4; ++i) {
    // The triangle cut off corner i, and the hexagon opposite it (the face of the other three corners).
    std::vector<int> others;
    for (int j = 0; j < 4; ++j)
      if (j != i) others.push_back(j);
    std::vector<Vec3d> triangle, hexagon;
    for (int j : others) triangle.push_back(cut(i, j));
    for (size_t k = 0; k < 3; ++k) {
      const int a = others[k], b = others[(k + 1) % 3];
      hexagon.push_back(cut(a, b));
      hexagon.push_back(cut(b, a));
    }
    for (auto* f : {&triangle, &hexagon}) {
      // Orient counter-clockwise seen from outside (the centre is the origin).
      Vec3d n{0, 0, 0}, c{0, 0, 0};
      for (size_t k = 0; k < f->size(); ++k) {
        n += cross((*f)[k], (*f)[(k + 1) % f->size()]);
        c += (*f)[k];
      }
      if (dot(n, c) < 0) std::reverse(f->begin(), f->end());
      faces.push_back(*f);
    }
  }
  return faces;
}

void register_recipe_inputs() {
  register_input_type(
      {"bcifs_plate",
       {"face", "faces", "shared", "level", "thickness_mm", "radius_mm", "gap_fraction", "lacuna_scale", "notch_depth",
        "origin_mm"},
       [](const JsonObject& o, RecipeInput& in) {
         const PlateSpec spec = parse_plate(o);
         Region2 region;
         region.loops_mm = plate_loops(spec, spec.level);
         region.height_mm = spec.thickness_mm;
         region.origin_mm = spec.origin_mm;
         double area = 0;
         size_t holes = 0;
         for (const auto& loop : region.loops_mm) {
           const double a = signed_area(loop);
           area += a;
           holes += a < 0;
         }
         nlohmann::json faces = nlohmann::json::array();
         for (size_t f = 0; f < spec.assembly.faces.size(); ++f) {
           const int type = spec.rules.roots[f];
           const Lacunarity l = lacunarity(spec.rules, type, spec.level);
           faces.push_back({{"type", type}, {"subfaces", l.subfaces.back()}, {"lacunas", l.lacunas.back()},
                            {"r_limit", l.limit}});
         }
         in.report = {{"level", spec.level}, {"face_types", spec.rules.rules.size()}, {"faces", faces},
                      {"loops", region.loops_mm.size()}, {"holes", holes}, {"area_mm2", area}};
         in.geometry.regions.push_back(std::move(region));
       }});

  // A polyhedral cell whose faces are lacunar faces: every face realized in its own plane (its corners as the
  // control polygon) and extruded inwards by thickness_mm. All edges have one type, so neighbouring faces
  // subdivide their shared edge the same way and their notches meet.
  register_input_type(
      {"bcifs_cell",
       {"cell", "edge_mm", "center_mm", "edge", "params", "algorithm", "level", "thickness_mm", "gap_fraction",
        "lacuna_scale", "notch_depth"},
       [](const JsonObject& o, RecipeInput& in) {
         const double edge_mm = o.positive_length("edge_mm");
         std::vector<std::vector<Vec3d>> faces;
         try {
           faces = cell_faces(o.string("cell"), edge_mm);
         } catch (const InvalidInput& e) {
           o.fail("cell", e.what());
         }
         const double thickness = o.positive_length("thickness_mm");
         if (thickness >= edge_mm / 4) o.fail("thickness_mm", "expected a wall thinner than a quarter of edge_mm");
         const Vec3d center = o.vec3_or("center_mm", Vec3d{});
         const uint64_t level = o.unsigned_integer_or("level", 2);
         if (level > 6) o.fail("level", "expected a level from 0 to 6");
         EdgeType edge;
         EdgeSet params;
         Algorithm algorithm = Algorithm::kA1;
         try {
           edge = parse_edge(o.string_or("edge", "C2"));
         } catch (const InvalidInput& e) {
           o.fail("edge", e.what());
         }
         try {
           params = parse_edge_set(o.string_or("params", "C2 B2 B2"));
         } catch (const InvalidInput& e) {
           o.fail("params", e.what());
         }
         try {
           algorithm = parse_algorithm(o.string_or("algorithm", "A1"));
         } catch (const InvalidInput& e) {
           o.fail("algorithm", e.what());
         }
         RealizeOptions options;
         options.defaults.gap_fraction = fraction(o, "gap_fraction", options.defaults.gap_fraction);
         options.defaults.lacuna_scale = fraction(o, "lacuna_scale", options.defaults.lacuna_scale);
         options.defaults.notch_depth = fraction(o, "notch_depth", options.defaults.notch_depth);
         std::vector<FaceType> types;
         for (const auto& f : faces) types.push_back({std::vector<EdgeType>(f.size(), edge), params, algorithm, 1});
         RuleSet rules;
         try {
           rules = build_rules(types);
         } catch (const InvalidInput& e) {
           o.fail("", e.what());
         }
         double area = 0;
         size_t holes = 0;
         for (size_t k = 0; k < faces.size(); ++k) {
           const auto& f = faces[k];
           // The face's plane: origin at its first corner, u along its first edge, v = n x u.
           Vec3d n{0, 0, 0};
           for (size_t j = 0; j < f.size(); ++j) n += cross(f[j], f[(j + 1) % f.size()]);
           n = n / norm(n);
           const Vec3d u = (f[1] - f[0]) / norm(f[1] - f[0]);
           const Vec3d v = cross(n, u);
           std::vector<Vec2d> control;
           for (const Vec3d& p : f) control.push_back({dot(p - f[0], u), dot(p - f[0], v)});
           // The type's canonical rotation of a boundary with one edge type is the boundary itself.
           Region2 region;
           region.loops_mm = union_loops(polygons_of(realize(rules, rules.roots[k], control, int(level), options)));
           for (const auto& loop : region.loops_mm) {
             const double a = signed_area(loop);
             area += a;
             holes += a < 0;
           }
           region.origin_mm = center + f[0] - n * thickness;  // the slab spans [-thickness, 0] along n: inwards
           region.axis_u = u;
           region.axis_v = v;
           region.height_mm = thickness;
           in.geometry.regions.push_back(std::move(region));
         }
         in.report = {{"faces", faces.size()}, {"face_types", rules.rules.size()}, {"holes", holes},
                      {"face_area_mm2", area}};
       }});
}

}  // namespace bcifs
}  // namespace lacuna
