// lacuna.Solid: a recipe fragment built in Python (inputs with the recipe's keys as keyword
// arguments, CSG operators, offsets, shells, infills) and the calls that run it (mesh, voxelize),
// plus lacuna.run and lacuna.voxelize for whole recipes. A solid's keys are read by the recipe's own
// parser when it is made, so every check and message is the recipe's; meshing assembles the recipe
// and runs it through the pipeline.
#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include <atomic>
#include <filesystem>
#include <map>
#include <set>
#include <variant>

#include "export/mesh_io.h"
#include "pipeline/mesh_object.h"
#include "pipeline/pipeline.h"
#include "pipeline/slice_output.h"
#include "pipeline/stream_output.h"
#include "python/convert.h"
#include "python/objects.h"
#include "recipe/json_fields.h"
#include "recipe/recipe.h"

namespace lacuna {
namespace python {
namespace {

namespace fs = std::filesystem;

// One node of a solid's tree: an input of the recipe, or an operation on other nodes.
struct Node {
  enum class Kind { kInput, kOperation };
  Kind kind = Kind::kInput;
  std::string name;                               // in the recipes made from it
  std::string type;                               // input type, or operation ("union", "offset", ...)
  nlohmann::json object;                          // input: its recipe object; operation: keys besides name, op, of
  std::shared_ptr<const TriMesh> mesh;            // mesh and surface inputs given as arrays
  std::vector<std::shared_ptr<const Node>> refs;  // inputs it names (fit_to, cover)
  std::vector<std::shared_ptr<const Node>> of;    // operands (infill: hull, structure)
};

struct Solid {
  std::shared_ptr<const Node> node;
};

std::string next_name(const std::string& type) {
  static std::atomic<uint64_t> counter{0};
  return type + "_" + std::to_string(++counter);
}

const nlohmann::json kPlaceholderInput = {{"type", "sphere"}, {"radius_mm", 1}};

// Reads a fragment of a recipe as the recipe would (its checks and messages, `label` for the file).
Recipe parse_fragment(const std::string& label, nlohmann::json inputs, const nlohmann::json& operations,
                      const std::string& output_of) {
  nlohmann::json recipe = {{"inputs", std::move(inputs)}, {"outputs", {{{"of", output_of}, {"file", "solid.stl"}}}}};
  if (!operations.empty()) recipe["operations"] = operations;
  return parse_recipe(recipe.dump(), label);
}

// The tree under `root` as a recipe's inputs and operations, each node once, operands first.
struct Assembly {
  nlohmann::json inputs = nlohmann::json::object();
  nlohmann::json operations = nlohmann::json::array();
  std::set<const Node*> seen;
  std::vector<std::pair<std::string, std::shared_ptr<const TriMesh>>> meshes;

  void add(const Node& n, bool inline_meshes) {
    if (!seen.insert(&n).second) return;
    for (const auto& r : n.refs) add(*r, inline_meshes);
    for (const auto& o : n.of) add(*o, inline_meshes);
    if (n.kind == Node::Kind::kInput) {
      nlohmann::json object = n.object;
      if (n.mesh && inline_meshes) {
        object["positions_mm"] = nlohmann::json::array();
        for (const Vec3d& p : n.mesh->positions_mm) object["positions_mm"].push_back({p.x, p.y, p.z});
        object["triangles"] = n.mesh->triangles;
      } else if (n.mesh) {
        meshes.emplace_back(n.name, n.mesh);
      }
      inputs[n.name] = std::move(object);
      return;
    }
    nlohmann::json op = n.object;
    op["name"] = n.name;
    op["op"] = n.type;
    if (n.type == "infill") {
      op["hull"] = n.of[0]->name;
      op["structure"] = n.of[1]->name;
    } else if (n.type == "offset" || n.type == "shell") {
      op["of"] = n.of[0]->name;
    } else {
      op["of"] = nlohmann::json::array();
      for (const auto& o : n.of) op["of"].push_back(o->name);
    }
    operations.push_back(std::move(op));
  }
};

// The settings of the recipe a solid is run as.
struct Settings {
  std::string name = "solid";
  double voxel_size_mm = 0.1;
  double band_voxels = 3;
  uint64_t seed = 0;
  py::object simplify_mm = py::none();
};

nlohmann::json recipe_json(const Node& root, const Settings& s, bool inline_meshes, Assembly& a) {
  a.add(root, inline_meshes);
  nlohmann::json recipe = {{"lacuna_recipe", 1},           {"name", s.name}, {"voxel_size_mm", s.voxel_size_mm},
                           {"band_voxels", s.band_voxels}, {"seed", s.seed}, {"inputs", a.inputs}};
  if (!s.simplify_mm.is_none()) recipe["simplify_mm"] = s.simplify_mm.cast<double>();
  if (!a.operations.empty()) recipe["operations"] = a.operations;
  recipe["outputs"] = {{{"of", root.name}, {"file", s.name + ".stl"}}};
  return recipe;
}

// The recipe of a solid as plain data, its meshes given as arrays put in without copying them twice.
Recipe assemble(const Node& root, const Settings& s) {
  Assembly a;
  const nlohmann::json json = recipe_json(root, s, false, a);
  Recipe recipe = parse_recipe(json.dump(), s.name);
  for (const auto& [name, mesh] : a.meshes)
    for (RecipeInput& in : recipe.inputs) {
      if (in.name != name) continue;
      if (auto* m = std::get_if<MeshInput>(&in.spec)) m->source.inline_mesh = *mesh;
      if (auto* m = std::get_if<SurfaceInput>(&in.spec)) m->source.inline_mesh = *mesh;
    }
  return recipe;
}

// Keyword arguments as a recipe object: solids become the names of their nodes (collected in
// `refs`), relative file names absolute (a recipe made later reads them from the same place).
nlohmann::json keys_json(const std::string& type, const py::dict& keys,
                         std::vector<std::shared_ptr<const Node>>& refs) {
  const OtherValue solids = [&](const py::handle& value, nlohmann::json& out) {
    if (!py::isinstance<Solid>(value)) return false;
    const auto& node = value.cast<const Solid&>().node;
    if (node->kind != Node::Kind::kInput)
      throw InvalidInput("lacuna." + type +
                         ": a solid named here must be an input (lacuna.mesh(), lacuna.box(), ...), "
                         "not the result of an operation");
    refs.push_back(node);
    out = node->name;
    return true;
  };
  nlohmann::json object = to_json(keys, "lacuna." + type, solids);
  if (!object.is_object()) throw py::type_error("lacuna." + type + ": expected keyword arguments");
  const char* file_key = type == "mesh" || type == "surface" ? "file" : type == "curve" ? "mesh" : nullptr;
  if (file_key && object.contains(file_key) && object[file_key].is_string()) {
    const std::string file = object[file_key].get<std::string>();
    if (!file.empty() && fs::path(file).is_relative()) object[file_key] = fs::absolute(file).string();
  }
  return object;
}

Solid make_input(const std::string& type, nlohmann::json object, std::vector<std::shared_ptr<const Node>> refs,
                 std::shared_ptr<const TriMesh> mesh = nullptr) {
  if (object.contains("type")) throw InvalidInput("lacuna." + type + ": \"type\" is given by the constructor");
  object["type"] = type;
  nlohmann::json inputs = {{type, object}};
  for (const auto& r : refs) inputs[r->name] = kPlaceholderInput;
  parse_fragment("lacuna." + type, inputs, nlohmann::json::array(), type);
  auto node = std::make_shared<Node>();
  node->kind = Node::Kind::kInput;
  node->name = next_name(type);
  node->type = type;
  node->object = std::move(object);
  node->refs = std::move(refs);
  node->mesh = std::move(mesh);
  return Solid{node};
}

Solid make_operation(const std::string& op, std::vector<std::shared_ptr<const Node>> of, nlohmann::json keys,
                     const std::string& label) {
  // Checked as the recipe checks an operation, on stand-in operands.
  nlohmann::json inputs = nlohmann::json::object();
  nlohmann::json check = keys;
  check["name"] = op;
  check["op"] = op;
  std::vector<std::string> names;
  for (size_t i = 0; i < of.size(); ++i) {
    names.push_back("operand" + std::to_string(i + 1));
    inputs[names.back()] = kPlaceholderInput;
  }
  if (op == "infill") {
    check["hull"] = names[0];
    check["structure"] = names[1];
  } else if (op == "offset" || op == "shell") {
    check["of"] = names[0];
  } else {
    check["of"] = names;
  }
  parse_fragment(label, inputs, nlohmann::json::array({check}), op);
  auto node = std::make_shared<Node>();
  node->kind = Node::Kind::kOperation;
  node->name = next_name(op);
  node->type = op;
  node->object = std::move(keys);
  node->of = std::move(of);
  return Solid{node};
}

// a op b, flattening chains of the same n-ary operation (a | b | c is one union of three).
Solid combine(const std::string& op, const Solid& a, const py::handle& other) {
  if (!py::isinstance<Solid>(other))
    throw py::type_error("lacuna.Solid: expected a Solid on both sides of the operator");
  const Solid& b = other.cast<const Solid&>();
  std::vector<std::shared_ptr<const Node>> of;
  if (a.node->kind == Node::Kind::kOperation && a.node->type == op)
    of = a.node->of;
  else
    of.push_back(a.node);
  if (op != "difference" && b.node->kind == Node::Kind::kOperation && b.node->type == op)
    of.insert(of.end(), b.node->of.begin(), b.node->of.end());
  else
    of.push_back(b.node);
  return make_operation(op, std::move(of), nlohmann::json::object(), "lacuna.Solid");
}

Settings settings_of(double voxel_size_mm, double band_voxels, uint64_t seed, const py::object& simplify_mm) {
  Settings s;
  s.voxel_size_mm = voxel_size_mm;
  s.band_voxels = band_voxels;
  s.seed = seed;
  s.simplify_mm = simplify_mm;
  return s;
}

ObjectOptions object_options(const py::object& simplify_mm, const py::object& max_memory_gb,
                             const py::object& threads) {
  ObjectOptions o;
  o.simplify_mm = simplify_mm.is_none() ? -1.0 : simplify_mm.cast<double>();
  o.max_memory_bytes = budget_bytes(max_memory_gb);
  o.threads = threads.is_none() ? 0 : threads.cast<int>();
  if (o.threads < 0) throw py::value_error("threads: expected a positive number of threads (None: every core)");
  return o;
}

// The tubes of `points` (an N x 3 polyline, M x K x 3 polylines, or a list of polylines) with `radii`
// (one radius, one per point, or per polyline a radius or one per point).
nlohmann::json polylines_json(const py::handle& points, const py::handle& radii) {
  std::vector<py::object> lines;
  if (py::isinstance<py::list>(points) || py::isinstance<py::tuple>(points)) {
    for (auto p : points) lines.push_back(py::reinterpret_borrow<py::object>(p));
  } else {
    py::array a = py::array::ensure(points);
    if (!a) throw py::value_error("points: expected an N x 3 array, an M x K x 3 array or a list of N x 3 arrays (mm)");
    if (a.ndim() == 3) {
      for (py::ssize_t i = 0; i < a.shape(0); ++i) lines.push_back(a[py::int_(i)]);
    } else {
      lines.push_back(a);
    }
  }
  std::vector<py::object> per_line(lines.size());
  if (radii.is_none()) throw py::value_error("radii: expected a radius (mm) or radii with the points");
  py::array r = py::array::ensure(radii);
  if (!py::isinstance<py::list>(radii) && !py::isinstance<py::tuple>(radii) && r && r.ndim() == 0) {
    for (auto& p : per_line) p = py::float_(r.attr("item")());
  } else if (lines.size() == 1 && !py::isinstance<py::list>(points) && !py::isinstance<py::tuple>(points)) {
    per_line[0] = py::reinterpret_borrow<py::object>(radii);
  } else {
    py::sequence seq = py::reinterpret_borrow<py::sequence>(radii);
    if (py::len(seq) != lines.size())
      throw py::value_error("radii: expected one radius, or one entry per polyline (" + std::to_string(lines.size()) +
                            ")");
    for (size_t i = 0; i < lines.size(); ++i) per_line[i] = seq[i];
  }
  nlohmann::json out = nlohmann::json::array();
  for (size_t i = 0; i < lines.size(); ++i) {
    const std::string where = "points[" + std::to_string(i) + "]";
    nlohmann::json line = {{"points_mm", to_json(lines[i], where)}};
    py::array ri = py::array::ensure(per_line[i]);
    if (ri && ri.ndim() == 0)
      line["radius_mm"] = to_json(per_line[i], "radii");
    else
      line["radii_mm"] = to_json(per_line[i], "radii");
    out.push_back(std::move(line));
  }
  return out;
}

// The generic constructor every named one calls: positional arguments only where the issue's
// shorthand exists (tubes(points, radii), spheres(centers, radii), mesh(vertices, faces)).
Solid construct(const std::string& type, const py::args& args, py::dict keys) {
  std::vector<std::shared_ptr<const Node>> refs;
  std::shared_ptr<const TriMesh> mesh;
  auto take = [&](size_t i, const char* name) -> py::object {
    py::object value = i < args.size() ? py::reinterpret_borrow<py::object>(args[i]) : py::none();
    if (keys.contains(name)) {
      if (i < args.size()) throw py::type_error("lacuna." + type + ": " + name + " given twice");
      value = keys[name];
      PyDict_DelItemString(keys.ptr(), name);
    }
    return value;
  };
  nlohmann::json extra = nlohmann::json::object();
  if (type == "tubes") {
    if (args.size() > 2) throw py::type_error("lacuna.tubes: expected at most points and radii");
    py::object points = take(0, "points"), radii = take(1, "radii");
    if (!points.is_none())
      extra["polylines"] = polylines_json(points, radii);
    else if (!radii.is_none())
      throw py::value_error("lacuna.tubes: radii without points");
  } else if (type == "spheres") {
    if (args.size() > 2) throw py::type_error("lacuna.spheres: expected at most centers and radii");
    py::object centers = take(0, "centers"), radii = take(1, "radii");
    if (!centers.is_none()) {
      extra["centers_mm"] = to_json(centers, "centers");
      if (radii.is_none()) throw py::value_error("lacuna.spheres: expected radii (mm) with the centres");
      py::array r = py::array::ensure(radii);
      extra[r && r.ndim() == 0 ? "radius_mm" : "radii_mm"] = to_json(radii, "radii");
    }
  } else if (type == "mesh" || type == "surface") {
    if (args.size() > 2) throw py::type_error("lacuna." + type + ": expected at most vertices and faces");
    py::object vertices = take(0, "vertices"), faces = take(1, "faces");
    if (py::isinstance<Mesh>(vertices)) {
      if (!faces.is_none()) throw py::value_error("lacuna." + type + ": faces come with the Mesh");
      mesh = vertices.cast<const Mesh&>().data;
    } else if (!vertices.is_none() || !faces.is_none()) {
      if (vertices.is_none() || faces.is_none())
        throw py::value_error("lacuna." + type + ": expected vertices and faces");
      mesh = std::make_shared<const TriMesh>(mesh_from_arrays(vertices, faces));
    }
    if (mesh) {
      if (mesh->triangles.empty()) throw py::value_error("lacuna." + type + ": the mesh has no triangles");
      // A stand-in triangle for the parser; the mesh itself joins the recipe when it is assembled.
      extra["positions_mm"] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
      extra["triangles"] = {{0, 1, 2}};
    }
  } else if (!args.empty()) {
    throw py::type_error("lacuna." + type + "() takes the recipe's keys as keyword arguments only");
  }
  nlohmann::json object = keys_json(type, keys, refs);
  for (auto it = extra.begin(); it != extra.end(); ++it) {
    if (object.contains(it.key())) throw py::type_error("lacuna." + type + ": " + it.key() + " given twice");
    object[it.key()] = it.value();
  }
  return make_input(type, std::move(object), std::move(refs), std::move(mesh));
}

// A recipe given as a path, JSON text or a dict.
Recipe recipe_of(const py::handle& recipe) {
  if (py::isinstance<py::dict>(recipe) || py::isinstance<py::str>(recipe)) {
    nlohmann::json json;
    if (py::isinstance<py::dict>(recipe)) {
      json = to_json(recipe, "recipe");
    } else {
      const std::string text = recipe.cast<std::string>();
      const size_t first = text.find_first_not_of(" \t\r\n");
      if (first == std::string::npos || text[first] != '{') return load_recipe(text);
      json = parse_json_text(text, "recipe");
    }
    // Without a file, the part's name (and so its default output folder) is "recipe".
    if (json.is_object() && !json.contains("name")) json["name"] = "recipe";
    return parse_recipe(json.dump(), "recipe");
  }
  return load_recipe(path_of(recipe));
}

// lacuna.run's result: the report, and the meshes written, read back when first asked for.
struct RunResult {
  py::object report;
  std::vector<std::pair<std::string, std::string>> surfaces;  // output file name, path written
  py::object meshes_cache = py::none();
};

const char* kInputDocs[][2] = {
    {"sphere", "A ball: center_mm ([0, 0, 0]), radius_mm."},
    {"spheres",
     "A union of balls: spheres(centers, radii) with an N x 3 array of centres (mm) and one radius or N radii (mm), "
     "or the keys centers_mm, radius_mm / radii_mm."},
    {"capsule", "A round cone between two balls: a_mm, b_mm, radius_mm, radius_b_mm (= radius_mm)."},
    {"tubes",
     "Polylines swept by balls: tubes(points, radii) with an N x 3 array (one polyline), an M x K x 3 array or a list "
     "of N x 3 arrays (mm), and one radius, one per point, or per polyline (mm); or the key polylines: "
     "[{points_mm, radius_mm | radii_mm}]."},
    {"box", "An axis-aligned box: center_mm ([0, 0, 0]) and size_mm, or min_mm and max_mm."},
    {"cylinder", "A capped cylinder centred on center_mm ([0, 0, 0]): axis ([0, 0, 1]), radius_mm, height_mm."},
    {"torus", "A torus: center_mm ([0, 0, 0]), axis ([0, 0, 1]), major_radius_mm, minor_radius_mm (< major)."},
    {"region",
     "Planar loops extruded: loops_mm (loops of [x, y], even-odd: holes are loops inside loops), height_mm, origin_mm, "
     "axis_u, axis_v."},
    {"mesh",
     "The solid a closed mesh bounds: mesh(vertices, faces) with N x 3 positions (mm) and M x 3 indices, or "
     "mesh(a_lacuna_Mesh), or file (STL, OBJ, PLY, 3MF); scale (1), translate_mm, repair ({weld_mm, reorient, "
     "close_gaps_mm, allow_overlaps}). The mesh must pass every check unless repairs are asked for."},
    {"surface", "An open or closed surface thickened: as mesh, plus thickness_mm."},
    {"lattice",
     "A strut lattice: cell (cubic, bcc), period_mm, strut_radius_mm and/or grade, min_mm + max_mm or fit_to (an input "
     "solid), layout (tiled, scaled, conforming), inset_mm."},
    {"cifs",
     "The attractor of a controlled IFS: system (a shipped name or a system dict), level (3), as (tubes, shell, cells, "
     "edges), radius_mm, thickness_mm, fit_to (an input solid), support ({base_mm, base_size_mm, fork, shrink}: a "
     "shell on its own fractal tree)."},
    {"cifs_support",
     "A cifs shell on its own fractal tree: system, level, thickness_mm, fit_to, with base_mm, base_size_mm, fork "
     "(0.5), shrink (0.5)."},
    {"curve",
     "Superimposed space-filling curves as tubes: kind (hilbert, sierpinski, hilbert3d), orders (\"1..5\" or a list), "
     "radius_mm, scale_mm, surface (plane, sphere, cylinder, torus, cone, cube, bspline, mesh), patch, mesh, "
     "center_mm, "
     "offset_mm, tolerance_mm, base_mm."},
    {"fill_motifs",
     "Motifs placed by the area rule as prisms: motif, region or wallpaper ({group, a_mm, b_mm, cells, policy}), c "
     "(1.3), N (2), count (1000), min_area_mm2, max_trials, gap_mm, boundary_gap_mm, seed (1), random_rotation, "
     "height_mm, base_z_mm, wrap."},
    {"fill_spheres",
     "Spheres (or convex polyhedra) placed by the volume rule: fit_to (an input solid), box or sphere; motif, "
     "random_rotation, c, N, count, min_radius_mm, max_trials, gap_mm, boundary_gap_mm, seed."},
    {"voronoi_spheres",
     "Spheres on the generators of a fractal Voronoi level: dimension, d, points or random, seed, level, period_mm, "
     "origin_mm, radius_mm, colours, tiles."},
    {"voronoi_tiles",
     "The fractal Voronoi tiles of the kept colours: the partition keys, colours, clearance_mm, thickness_mm (2D)."},
    {"voronoi_foam",
     "The walls between colours of a fractal Voronoi level, thickened: the partition keys, wall_mm, tiles or cover (an "
     "input solid), thickness_mm (2D), refine (field ramp or points with its keys, levels: tiles split into their "
     "children where the field is high)."},
    {"bcifs_plate",
     "A lacunar face (or assembly) as a plate: face or faces + shared, level (3), thickness_mm (1), radius_mm, "
     "gap_fraction, lacuna_scale, notch_depth, realization (default, paper), origin_mm."},
    {"bcifs_cell",
     "A polyhedral cell with lacunar faces: cell (hexahedron, truncated_tetrahedron), edge_mm, thickness_mm, "
     "center_mm, edge, params, algorithm, level (2), gap_fraction, lacuna_scale, notch_depth, realization."},
    {"bcifs_volume",
     "Cells subdivided in 3D around lacunas: cell (hexahedron, tetrahedron, truncated_tetrahedron, prism), edge_mm, "
     "center_mm, delay, or corners_mm + faces, or cells (a list of those); walls (lacunar, plain), edge, params, "
     "algorithm, interior (lacunar, plain), radial, interior_params, interior_algorithm, level (2), lacuna_scale (0.5), "
     "face_lacuna_scale, gap_fraction, notch_depth, realization."},
    {"bcifs_infill",
     "A hull filled with lacunar cells: hull (another input), skin_mm (1), cell_mm (10), level (2), equal_lacunas "
     "(true), grade (field, levels), cell_grade (min_cell_mm, field), walls, edge, params, algorithm, interior, radial, interior_params, interior_algorithm, lacuna_scale, "
     "face_lacuna_scale, gap_fraction, notch_depth, realization."},
};

// `headline` and, a line each, every output's failed checks in a run's or a streamed run's report.
std::string with_output_problems(std::string headline, const nlohmann::json& report) {
  for (const auto& out : report["outputs"])
    for (const auto& problem : out["checks"]["problems"])
      headline += "\n  " + out["file"].get<std::string>() + ": " + problem.get<std::string>();
  return headline;
}

}  // namespace

void add_solids(py::module_& m) {
  py::class_<Solid>(m, "Solid",
                    "A solid described as a recipe fragment: inputs made by the constructors (lacuna.sphere, "
                    "lacuna.tubes, ...) with the recipe's keys, combined with | (union), - (difference), & "
                    "(intersection), offset(), shell() and infill(). Nothing is computed until mesh() or voxelize().")
      .def_property_readonly(
          "type", [](const Solid& s) { return s.node->type; },
          "The input type, or the operation (union, difference, intersection, offset, shell, infill).")
      .def_property_readonly(
          "name", [](const Solid& s) { return s.node->name; }, "Its name in the recipes made from it.")
      .def(
          "__or__", [](const Solid& a, const py::handle& b) { return combine("union", a, b); }, py::is_operator())
      .def(
          "__sub__", [](const Solid& a, const py::handle& b) { return combine("difference", a, b); }, py::is_operator())
      .def(
          "__and__", [](const Solid& a, const py::handle& b) { return combine("intersection", a, b); },
          py::is_operator())
      .def(
          "offset",
          [](const Solid& s, double distance_mm) {
            return make_operation("offset", {s.node}, {{"distance_mm", distance_mm}}, "Solid.offset");
          },
          py::arg("distance_mm"), "The Euclidean offset: > 0 grows (rounding convex edges), < 0 shrinks (mm, not 0).")
      .def(
          "shell",
          [](const Solid& s, double thickness_mm) {
            return make_operation("shell", {s.node}, {{"thickness_mm", thickness_mm}}, "Solid.shell");
          },
          py::arg("thickness_mm"), "The solid minus its inward offset: walls of thickness_mm (mm > 0), cavity sealed.")
      .def(
          "infill",
          [](const Solid& hull, const Solid& structure, double skin_mm, const py::object& fuse_mm) {
            nlohmann::json keys = {{"skin_mm", skin_mm}};
            if (!fuse_mm.is_none()) keys["fuse_mm"] = fuse_mm.cast<double>();
            return make_operation("infill", {hull.node, structure.node}, keys, "Solid.infill");
          },
          py::arg("structure"), py::arg("skin_mm"), py::arg("fuse_mm") = py::none(),
          "This solid as a hull with a skin of skin_mm (mm) and `structure` inside, reaching fuse_mm (mm; None: a "
          "voxel) into the skin so that they are one solid.")
      .def(
          "mesh",
          [](const Solid& s, double voxel_size_mm, const py::object& simplify_mm, double band_voxels, uint64_t seed,
             const py::object& max_memory_gb, const py::object& threads) {
            const Recipe recipe = assemble(*s.node, settings_of(voxel_size_mm, band_voxels, seed, simplify_mm));
            const ObjectOptions options = object_options(py::none(), max_memory_gb, threads);
            const std::string object = s.node->name;
            ObjectMesh r = released([&] { return mesh_object(recipe, object, options); });
            return make_mesh(std::move(r.mesh), object, recipe.voxel_size_mm);
          },
          py::arg("voxel_size_mm") = 0.1, py::arg("simplify_mm") = py::none(), py::arg("band_voxels") = 3.0,
          py::arg("seed") = 0, py::arg("max_memory_gb") = py::none(), py::arg("threads") = py::none(),
          "Builds, voxelizes (voxel edge voxel_size_mm, mm) and meshes the solid in memory: closed, manifold, outward, "
          "free of self-intersections; simplified to simplify_mm (mm; None: a fifth of the voxel, 0: not simplified). "
          "The memory is estimated first: beyond max_memory_gb (GB; None: half the machine's) ResourceLimitError is "
          "raised before allocating. threads: worker threads (None: every core). Ctrl-C cancels it.")
      .def(
          "voxelize",
          [](const Solid& s, double voxel_size_mm, double band_voxels, uint64_t seed, const py::object& max_memory_gb,
             const py::object& threads) {
            const Recipe recipe = assemble(*s.node, settings_of(voxel_size_mm, band_voxels, seed, py::none()));
            const ObjectOptions options = object_options(py::none(), max_memory_gb, threads);
            const std::string object = s.node->name;
            return Grid{released([&] { return evaluate_object(recipe, object, options); }), object};
          },
          py::arg("voxel_size_mm") = 0.1, py::arg("band_voxels") = 3.0, py::arg("seed") = 0,
          py::arg("max_memory_gb") = py::none(), py::arg("threads") = py::none(),
          "The solid's level set (a Grid) at voxel_size_mm (mm), without meshing it.")
      .def(
          "to_recipe",
          [](const Solid& s, const std::string& name, double voxel_size_mm, const py::object& simplify_mm,
             double band_voxels, uint64_t seed) {
            Settings settings = settings_of(voxel_size_mm, band_voxels, seed, simplify_mm);
            settings.name = name;
            Assembly a;
            return from_json(recipe_json(*s.node, settings, true, a));
          },
          py::arg("name") = "solid", py::arg("voxel_size_mm") = 0.1, py::arg("simplify_mm") = py::none(),
          py::arg("band_voxels") = 3.0, py::arg("seed") = 0,
          "The solid as a recipe dict with one output, <name>.stl: lacuna.run() runs it, json.dump() saves it.")
      .def("__repr__", [](const Solid& s) {
        std::string r = "<lacuna.Solid " + s.node->type;
        if (s.node->kind == Node::Kind::kOperation) r += " of " + std::to_string(s.node->of.size());
        return r + ">";
      });

  for (const auto& doc : kInputDocs) {
    const std::string type = doc[0];
    m.def(
        doc[0], [type](const py::args& args, const py::kwargs& keys) { return construct(type, args, py::dict(keys)); },
        (std::string(doc[1]) + " The keyword arguments are the recipe's keys for a \"" + type +
         "\" input (README.md, Inputs); bad keys raise ValueError with the recipe's message.")
            .c_str());
  }
  m.def(
      "solid",
      [](const std::string& type, const py::kwargs& keys) { return construct(type, py::args(), py::dict(keys)); },
      py::arg("type"),
      "An input of any recipe type with its keys as keyword arguments: solid(\"sphere\", radius_mm=2).");
  m.def("input_types", &input_type_names, "The input types a recipe (and lacuna.solid) can name, sorted.");

  py::class_<RunResult>(m, "RunResult", "What lacuna.run() did: the report and the meshes it wrote.")
      .def_readonly("report", &RunResult::report, "The report as a dict: what report.json holds.")
      .def_property_readonly(
          "files", [](const RunResult& r) { return r.report["written"]; }, "Every file written, report.html then report.json last.")
      .def_property_readonly(
          "meshes",
          [](RunResult& r) {
            if (r.meshes_cache.is_none()) {
              py::dict meshes;
              for (const auto& [name, path] : r.surfaces) {
                const std::string p = path;
                meshes[py::str(name)] = make_mesh(released([&] { return read_mesh(p); }), p);
              }
              r.meshes_cache = meshes;
            }
            return r.meshes_cache;
          },
          "The surface outputs (STL, 3MF, Draco) by file name, as Mesh objects read back from the files written (once, when "
          "first asked for).");

  m.def(
      "run",
      [](const py::handle& recipe, const py::object& output_dir, const py::object& voxel_size_mm,
         const py::object& max_memory_gb, const py::object& threads, const py::object& simplify_mm, bool write_report) {
        Recipe r = recipe_of(recipe);
        RunOptions options;
        options.output_dir = output_dir.is_none() ? std::string() : path_of(output_dir);
        if (!voxel_size_mm.is_none()) {
          options.voxel_size_mm = voxel_size_mm.cast<double>();
          if (!(options.voxel_size_mm > 0)) throw InvalidInput("voxel_size_mm: expected a positive length in mm");
        }
        const ObjectOptions o = object_options(simplify_mm, max_memory_gb, threads);
        options.simplify_mm = o.simplify_mm;
        options.max_memory_bytes = o.max_memory_bytes;
        options.threads = o.threads;
        options.write_report = write_report;
        const std::string label = r.file;
        const RunReport result = released([&] { return run(std::move(r), options); });
        nlohmann::json report = to_json(result);
        report["valid"] = result.valid;
        report["written"] = result.written;
        if (!result.valid) {
          raise(errors().check_failed,
                with_output_problems(label + ": an output failed its checks; nothing was written", report),
                from_json(report));
        }
        RunResult out;
        out.report = from_json(report);
        for (const OutputReport& o2 : result.outputs)
          if (o2.format == "stl" || o2.format == "3mf" || o2.format == "drc")
            out.surfaces.emplace_back(fs::path(o2.file).filename().string(), o2.file);
        return out;
      },
      py::arg("recipe"), py::arg("output_dir") = py::none(), py::arg("voxel_size_mm") = py::none(),
      py::arg("max_memory_gb") = py::none(), py::arg("threads") = py::none(), py::arg("simplify_mm") = py::none(),
      py::arg("write_report") = true,
      "Runs a recipe (a path, JSON text or a dict) as `lacuna run` does: every output written under a temporary name, "
      "read back and checked, then all renamed into output_dir (default <name>-out) with report.json and report.html "
      "(unless write_report is False), or nothing. "
      "voxel_size_mm (mm) and simplify_mm (mm) override the recipe's, max_memory_gb is the budget (GB, 10^9 bytes; "
      "None: half the machine's), threads the worker threads (None: every core). Returns a RunResult (report dict and "
      "meshes); raises CheckFailedError (with .report) when an output fails its checks, ResourceLimitError beyond "
      "the budget, ValueError for a bad recipe; Ctrl-C cancels the run and leaves nothing behind.");

  m.def(
      "slice",
      [](const py::handle& recipe, const py::object& output, const std::string& object, const py::object& layer_mm,
         const py::object& pixel_mm, const py::object& tolerance_mm, bool binary, const py::object& slab_mm,
         const py::object& voxel_size_mm, const py::object& max_memory_gb, const py::object& threads) {
        Recipe r = recipe_of(recipe);
        SliceOptions options;
        options.object = object;
        auto length = [](const py::object& v, const char* key, double none) {
          if (v.is_none()) return none;
          const double x = v.cast<double>();
          if (!(x >= 0) || !std::isfinite(x)) throw InvalidInput(std::string(key) + ": expected a length in mm, at least 0");
          return x;
        };
        options.layer_mm = length(layer_mm, "layer_mm", 0);
        options.pixel_mm = length(pixel_mm, "pixel_mm", 0);
        options.tolerance_mm = length(tolerance_mm, "tolerance_mm", -1);
        options.binary = binary;
        options.slab_mm = length(slab_mm, "slab_mm", 0);
        options.run.voxel_size_mm = length(voxel_size_mm, "voxel_size_mm", 0);
        const ObjectOptions o = object_options(py::none(), max_memory_gb, threads);
        options.run.max_memory_bytes = o.max_memory_bytes;
        options.run.threads = o.threads;
        const std::string path = path_of(output), label = r.file;
        const SliceReport result = released([&] { return slice_recipe(std::move(r), path, options); });
        const nlohmann::json report = to_json(result);
        if (!result.valid) {
          std::string message = label + ": layers failed their checks; nothing was written";
          for (const auto& problem : result.problems) message += "\n  " + problem;
          raise(errors().check_failed, message, from_json(report));
        }
        return from_json(report);
      },
      py::arg("recipe"), py::arg("output"), py::arg("object") = "", py::arg("layer_mm") = py::none(),
      py::arg("pixel_mm") = py::none(), py::arg("tolerance_mm") = py::none(), py::arg("binary") = false,
      py::arg("slab_mm") = py::none(), py::arg("voxel_size_mm") = py::none(), py::arg("max_memory_gb") = py::none(),
      py::arg("threads") = py::none(),
      "Cuts one object of a recipe (a path, JSON text or a dict; default: its first output's) into layers as "
      "`lacuna slice` does, with no mesh: output a folder (PNG layers and manifest.json), FILE.zip, FILE.sl1 or "
      "FILE.cli (binary: the binary CLI form); layer_mm, pixel_mm (default the voxel size), tolerance_mm (CLI "
      "simplification, default a quarter pixel), slab_mm (evaluate slab by slab; None: only when the whole part does "
      "not fit max_memory_gb). Every layer is checked first; returns the report dict (as `--json` prints it), raises "
      "CheckFailedError (with .report) when a layer fails and nothing is written.");

  m.def(
      "stream",
      [](const py::handle& recipe, const py::object& output_dir, const py::object& slab_mm, const py::object& voxel_size_mm,
         const py::object& max_memory_gb, const py::object& threads, const py::object& simplify_mm, bool write_report) {
        Recipe r = recipe_of(recipe);
        StreamOptions options;
        options.run.output_dir = output_dir.is_none() ? std::string() : path_of(output_dir);
        if (!slab_mm.is_none()) options.slab_mm = slab_mm.cast<double>();
        if (!voxel_size_mm.is_none()) {
          options.run.voxel_size_mm = voxel_size_mm.cast<double>();
          if (!(options.run.voxel_size_mm > 0)) throw InvalidInput("voxel_size_mm: expected a positive length in mm");
        }
        const ObjectOptions o = object_options(simplify_mm, max_memory_gb, threads);
        options.run.simplify_mm = o.simplify_mm;
        options.run.max_memory_bytes = o.max_memory_bytes;
        options.run.threads = o.threads;
        options.run.write_report = write_report;
        const std::string label = r.file;
        const StreamReport result = released([&] { return stream_recipe(std::move(r), options); });
        const nlohmann::json report = to_json(result);
        if (!result.valid) {
          raise(errors().check_failed,
                with_output_problems(label + ": a streamed output failed its checks; nothing was written", report),
                from_json(report));
        }
        return from_json(report);
      },
      py::arg("recipe"), py::arg("output_dir") = py::none(), py::arg("slab_mm") = py::none(),
      py::arg("voxel_size_mm") = py::none(), py::arg("max_memory_gb") = py::none(), py::arg("threads") = py::none(),
      py::arg("simplify_mm") = py::none(), py::arg("write_report") = true,
      "Streams a recipe's STL outputs as `lacuna run --stream` does: each object evaluated slab by slab (slab_mm "
      "high, rounded up to blocks of 32 voxels; None: the whole part when it fits max_memory_gb, otherwise the highest "
      "slabs that do), its surface simplified and written as it comes, then the file checked chunk by chunk; the same "
      "file as run() writes. Returns the report dict (as `--json` prints it); raises CheckFailedError (with .report) "
      "when a file fails its checks and nothing is written, ValueError for outputs a stream cannot write.");

  m.def(
      "voxelize",
      [](const py::handle& recipe, const std::string& object, const py::object& voxel_size_mm,
         const py::object& max_memory_gb, const py::object& threads) {
        Recipe r = recipe_of(recipe);
        if (!voxel_size_mm.is_none()) {
          r.voxel_size_mm = voxel_size_mm.cast<double>();
          if (!(r.voxel_size_mm > 0)) throw InvalidInput("voxel_size_mm: expected a positive length in mm");
        }
        const ObjectOptions options = object_options(py::none(), max_memory_gb, threads);
        const std::string name = object.empty() ? r.outputs.front().object : object;
        return Grid{released([&] { return evaluate_object(r, name, options); }), name};
      },
      py::arg("recipe"), py::arg("object") = "", py::arg("voxel_size_mm") = py::none(),
      py::arg("max_memory_gb") = py::none(), py::arg("threads") = py::none(),
      "The level set (a Grid) of one object of a recipe (a path, JSON text or a dict; default: its first output's "
      "object), with only what it needs built, at the recipe's voxel size or voxel_size_mm (mm).");
}

}  // namespace python
}  // namespace lacuna
