#include "recipe/recipe.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <mutex>
#include <set>
#include <sstream>

#include "bcifs/recipe_input.h"
#include "cifs/solid_input.h"
#include "curves/recipe_input.h"
#include "fill/recipe_input.h"
#include "voronoi/recipe_input.h"
#include "infill/recipe_input.h"
#include "errors.h"
#include "util/suggest.h"

namespace lacuna {
namespace {

namespace fs = std::filesystem;

std::map<std::string, InputType>& registry() {
  static std::map<std::string, InputType> types;
  return types;
}

TriMesh inline_mesh(const JsonObject& o) {
  TriMesh mesh;
  mesh.positions_mm = o.vec3_list("positions_mm");
  const nlohmann::json& tris = o.required("triangles");
  if (!tris.is_array()) o.fail("triangles", "expected a list of [i, j, k] vertex indices");
  for (size_t t = 0; t < tris.size(); ++t) {
    const nlohmann::json& tri = tris[t];
    std::string where = "triangles[" + std::to_string(t) + "]";
    if (!tri.is_array() || tri.size() != 3) o.fail(where, "expected [i, j, k]");
    std::array<uint32_t, 3> idx{};
    for (int k = 0; k < 3; ++k) {
      if (!tri[k].is_number_integer() || tri[k].get<int64_t>() < 0 ||
          tri[k].get<uint64_t>() >= mesh.positions_mm.size())
        o.fail(where, "expected vertex indices from 0 to " + std::to_string(mesh.positions_mm.size()) + " - 1");
      idx[k] = tri[k].get<uint32_t>();
    }
    mesh.triangles.push_back(idx);
  }
  if (mesh.triangles.empty()) o.fail("triangles", "expected at least one triangle");
  return mesh;
}

// A mesh input: a file to import, or vertices and triangles inline.
void parse_mesh_source(const JsonObject& o, RecipeInput& in, bool surface) {
  if (o.has("repair")) {
    JsonObject r = o.object("repair");
    r.allow_only({"weld_mm", "reorient", "close_gaps_mm", "allow_overlaps"});
    in.repair.weld_mm = r.positive_length_or("weld_mm", 0.0);
    in.repair.reorient = r.boolean_or("reorient", false);
    in.repair.close_gaps_mm = r.positive_length_or("close_gaps_mm", 0.0);
    in.repair.allow_overlaps = r.boolean_or("allow_overlaps", false);
  }
  bool has_file = o.has("file"), has_inline = o.has("positions_mm") || o.has("triangles");
  if (has_file == has_inline) o.fail("", "give either \"file\" or \"positions_mm\" and \"triangles\"");
  in.mesh_scale = o.has("scale") ? o.positive_length("scale") : 1.0;
  in.mesh_translate_mm = o.vec3_or("translate_mm", Vec3d{});
  if (surface) in.surface_thickness_mm = o.positive_length("thickness_mm");
  in.mesh_role = surface ? RecipeInput::MeshRole::kSurface : RecipeInput::MeshRole::kSolid;
  if (has_file) {
    in.mesh_file = o.string("file");
    if (in.mesh_file.empty()) o.fail("file", "expected a file name");
    return;
  }
  TriMesh mesh = inline_mesh(o);
  for (Vec3d& p : mesh.positions_mm) p = p * in.mesh_scale + in.mesh_translate_mm;
  if (surface) in.geometry.surfaces.push_back(ThickSurface{std::move(mesh), in.surface_thickness_mm});
  else in.geometry.solids.push_back(std::move(mesh));
  in.mesh_role = RecipeInput::MeshRole::kNone;  // nothing left to import
}

void register_builtin_types() {
  cifs::register_recipe_inputs();
  register_infill_inputs();
  curves::register_recipe_inputs();
  fill::register_recipe_inputs();
  voronoi::register_recipe_inputs();
  bcifs::register_recipe_inputs();
  register_input_type({"sphere", {"center_mm", "radius_mm"}, [](const JsonObject& o, RecipeInput& in) {
                         in.geometry.spheres.centers_mm.push_back(o.vec3_or("center_mm", Vec3d{}));
                         in.geometry.spheres.radii_mm.push_back(o.positive_length("radius_mm"));
                       }});
  register_input_type({"spheres", {"centers_mm", "radius_mm", "radii_mm"}, [](const JsonObject& o, RecipeInput& in) {
                         SphereSet& s = in.geometry.spheres;
                         s.centers_mm = o.vec3_list("centers_mm");
                         if (s.centers_mm.empty()) o.fail("centers_mm", "expected at least one centre");
                         if (o.has("radius_mm") == o.has("radii_mm")) o.fail("", "give either \"radius_mm\" or \"radii_mm\"");
                         if (o.has("radius_mm")) s.radii_mm = {o.positive_length("radius_mm")};
                         else s.radii_mm = o.positive_length_list("radii_mm");
                         if (s.radii_mm.size() != 1 && s.radii_mm.size() != s.centers_mm.size())
                           o.fail("radii_mm", "expected one radius per centre (" + std::to_string(s.centers_mm.size()) + ")");
                       }});
  register_input_type({"capsule", {"a_mm", "b_mm", "radius_mm", "radius_b_mm"}, [](const JsonObject& o, RecipeInput& in) {
                         double ra = o.positive_length("radius_mm");
                         double rb = o.positive_length_or("radius_b_mm", ra);
                         in.geometry.tubes.tubes.push_back(Tube{{o.vec3("a_mm"), o.vec3("b_mm")}, {ra, rb}});
                       }});
  register_input_type({"tubes", {"polylines"}, [](const JsonObject& o, RecipeInput& in) {
                         const nlohmann::json& list = o.required("polylines");
                         if (!list.is_array() || list.empty()) o.fail("polylines", "expected a non-empty list of polylines");
                         for (size_t i = 0; i < list.size(); ++i) {
                           JsonObject p(list[i], o.file(), o.path_of("polylines[" + std::to_string(i) + "]"));
                           p.allow_only({"points_mm", "radius_mm", "radii_mm"});
                           Tube tube;
                           tube.points_mm = p.vec3_list("points_mm");
                           if (tube.points_mm.empty()) p.fail("points_mm", "expected at least one point");
                           if (p.has("radius_mm") == p.has("radii_mm")) p.fail("", "give either \"radius_mm\" or \"radii_mm\"");
                           if (p.has("radius_mm")) tube.radii_mm = {p.positive_length("radius_mm")};
                           else tube.radii_mm = p.positive_length_list("radii_mm");
                           if (tube.radii_mm.size() != 1 && tube.radii_mm.size() != tube.points_mm.size())
                             p.fail("radii_mm", "expected one radius per point (" + std::to_string(tube.points_mm.size()) + ")");
                           in.geometry.tubes.tubes.push_back(std::move(tube));
                         }
                       }});
  register_input_type({"box", {"center_mm", "size_mm", "min_mm", "max_mm"}, [](const JsonObject& o, RecipeInput& in) {
                         Shape s;
                         s.kind = Shape::Kind::kBox;
                         if (o.has("size_mm")) {
                           if (o.has("min_mm") || o.has("max_mm")) o.fail("", "give either \"center_mm\" and \"size_mm\" or \"min_mm\" and \"max_mm\"");
                           Vec3d size = o.vec3("size_mm");
                           if (!(size.x > 0 && size.y > 0 && size.z > 0)) o.fail("size_mm", "expected three positive lengths in mm");
                           s.center_mm = o.vec3_or("center_mm", Vec3d{});
                           s.half_size_mm = size * 0.5;
                         } else {
                           if (o.has("center_mm")) o.fail("center_mm", "give \"size_mm\" with \"center_mm\"");
                           Vec3d lo = o.vec3("min_mm"), hi = o.vec3("max_mm");
                           if (!(hi.x > lo.x && hi.y > lo.y && hi.z > lo.z)) o.fail("max_mm", "expected max_mm > min_mm on every axis");
                           s.center_mm = (lo + hi) * 0.5;
                           s.half_size_mm = (hi - lo) * 0.5;
                         }
                         in.geometry.shapes.push_back(s);
                       }});
  register_input_type({"cylinder", {"center_mm", "axis", "radius_mm", "height_mm"}, [](const JsonObject& o, RecipeInput& in) {
                         Shape s;
                         s.kind = Shape::Kind::kCylinder;
                         s.center_mm = o.vec3_or("center_mm", Vec3d{});
                         s.axis = o.direction_or("axis", Vec3d{0, 0, 1});
                         s.radius_mm = o.positive_length("radius_mm");
                         s.height_mm = o.positive_length("height_mm");
                         in.geometry.shapes.push_back(s);
                       }});
  register_input_type({"torus", {"center_mm", "axis", "major_radius_mm", "minor_radius_mm"}, [](const JsonObject& o, RecipeInput& in) {
                         Shape s;
                         s.kind = Shape::Kind::kTorus;
                         s.center_mm = o.vec3_or("center_mm", Vec3d{});
                         s.axis = o.direction_or("axis", Vec3d{0, 0, 1});
                         s.radius_mm = o.positive_length("major_radius_mm");
                         s.minor_radius_mm = o.positive_length("minor_radius_mm");
                         if (s.minor_radius_mm >= s.radius_mm) o.fail("minor_radius_mm", "expected less than major_radius_mm");
                         in.geometry.shapes.push_back(s);
                       }});
  register_input_type({"mesh", {"file", "positions_mm", "triangles", "scale", "translate_mm", "repair"},
                       [](const JsonObject& o, RecipeInput& in) { parse_mesh_source(o, in, false); }});
  register_input_type({"surface", {"file", "positions_mm", "triangles", "scale", "translate_mm", "thickness_mm"},
                       [](const JsonObject& o, RecipeInput& in) { parse_mesh_source(o, in, true); }});
  register_input_type({"region", {"loops_mm", "height_mm", "origin_mm", "axis_u", "axis_v"}, [](const JsonObject& o, RecipeInput& in) {
                         Region2 r;
                         const nlohmann::json& loops = o.required("loops_mm");
                         if (!loops.is_array() || loops.empty()) o.fail("loops_mm", "expected a list of loops of [x, y] points");
                         for (size_t i = 0; i < loops.size(); ++i) {
                           std::string key = "loops_mm[" + std::to_string(i) + "]";
                           r.loops_mm.push_back(o.vec2_list(loops[i], key));
                           if (r.loops_mm.back().size() < 3) o.fail(key, "a loop needs at least 3 points");
                         }
                         r.height_mm = o.positive_length("height_mm");
                         r.origin_mm = o.vec3_or("origin_mm", Vec3d{});
                         r.axis_u = o.direction_or("axis_u", Vec3d{1, 0, 0});
                         r.axis_v = o.direction_or("axis_v", Vec3d{0, 1, 0});
                         if (std::fabs(dot(r.axis_u, r.axis_v)) > 1e-9) o.fail("axis_v", "expected a direction orthogonal to axis_u");
                         in.geometry.regions.push_back(std::move(r));
                       }});
}

std::map<std::string, InputType>& types() {
  static std::once_flag once;
  std::call_once(once, register_builtin_types);
  return registry();
}

bool valid_name(const std::string& name) {
  if (name.empty() || name.size() > 64) return false;
  if (!(std::isalpha(static_cast<unsigned char>(name[0])) || name[0] == '_')) return false;
  return std::all_of(name.begin(), name.end(), [](char c) {
    return std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-';
  });
}

std::string lower(std::string s) {
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

}  // namespace

void register_input_type(InputType type) { registry()[type.type] = std::move(type); }

std::vector<std::string> input_type_names() {
  std::vector<std::string> names;
  for (const auto& entry : types()) names.push_back(entry.first);
  return names;
}

Recipe load_recipe(const std::string& path) {
  std::error_code ec;
  if (fs::is_directory(path, ec)) throw IoError(path + ": is a folder, expected a recipe file (.json)");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw IoError(path + ": cannot open the recipe file");
  std::ostringstream text;
  text << in.rdbuf();
  if (in.bad()) throw IoError(path + ": cannot read the recipe file");
  return parse_recipe(text.str(), path);
}

Recipe parse_recipe(const std::string& text, const std::string& path) {
  if (text.size() > (uint64_t{256} << 20))
    throw InvalidInput(path + ": recipe is larger than 256 MB; put large geometry in mesh files");
  nlohmann::json root = parse_json_text(text, path);
  JsonObject top(root, path, "");
  top.allow_only({"lacuna_recipe", "name", "description", "voxel_size_mm", "band_voxels", "seed", "inputs",
                  "operations", "outputs", "printability"});
  Recipe recipe;
  recipe.file = path;
  if (top.has("lacuna_recipe") && top.unsigned_integer_or("lacuna_recipe", 1) != 1)
    top.fail("lacuna_recipe", "this version of Lacuna reads recipe format 1");
  recipe.name = top.string_or("name", fs::path(path).stem().string());
  recipe.description = top.string_or("description", "");
  recipe.voxel_size_mm = top.positive_length_or("voxel_size_mm", 0.1);
  recipe.band_voxels = top.number_or("band_voxels", 3.0);
  if (recipe.band_voxels < 2 || recipe.band_voxels > 16) top.fail("band_voxels", "expected a number from 2 to 16");
  recipe.seed = top.unsigned_integer_or("seed", 0);

  std::set<std::string> names;
  JsonObject inputs = top.object("inputs");
  if (inputs.json().empty()) inputs.fail("", "expected at least one input");
  for (auto it = inputs.json().begin(); it != inputs.json().end(); ++it) {
    const std::string& name = it.key();
    JsonObject o(it.value(), path, inputs.path_of(name));
    if (!valid_name(name))
      inputs.fail(name, "names use letters, digits, '_' and '-', start with a letter or '_', at most 64 characters");
    RecipeInput input;
    input.name = name;
    input.json_path = o.path();
    input.type = o.string("type");
    auto type = types().find(input.type);
    if (type == types().end()) {
      std::string message = "unknown input type \"" + input.type + "\"" + did_you_mean(input.type, input_type_names());
      message += " (known types:";
      for (const std::string& t : input_type_names()) message += " " + t;
      o.fail("type", message + ")");
    }
    std::vector<std::string> keys = type->second.keys;
    keys.push_back("type");
    o.allow_only(keys);
    type->second.parse(o, input);
    names.insert(name);
    recipe.inputs.push_back(std::move(input));
  }

  for (const RecipeInput& in : recipe.inputs)
    for (const std::string& dep : in.depends_on) {
      bool found = false;
      for (const RecipeInput& other : recipe.inputs) found = found || (other.name == dep && &other != &in);
      if (!found) {
        std::vector<std::string> input_names;
        for (const RecipeInput& other : recipe.inputs) input_names.push_back(other.name);
        throw InvalidInput(path + ": " + in.json_path + ": \"" + dep + "\" is not another input" +
                           did_you_mean(dep, input_names));
      }
    }

  if (top.has("operations")) {
    const nlohmann::json& ops = top.required("operations");
    if (!ops.is_array()) top.fail("operations", "expected a list of operations");
    const std::map<std::string, RecipeOperation::Kind> kinds = {
        {"union", RecipeOperation::Kind::kUnion},       {"difference", RecipeOperation::Kind::kDifference},
        {"intersection", RecipeOperation::Kind::kIntersection}, {"offset", RecipeOperation::Kind::kOffset},
        {"shell", RecipeOperation::Kind::kShell},       {"infill", RecipeOperation::Kind::kInfill}};
    for (size_t i = 0; i < ops.size(); ++i) {
      JsonObject o(ops[i], path, "operations[" + std::to_string(i) + "]");
      RecipeOperation op;
      op.json_path = o.path();
      op.name = o.string("name");
      if (!valid_name(op.name))
        o.fail("name", "names use letters, digits, '_' and '-', start with a letter or '_', at most 64 characters");
      if (names.count(op.name)) o.fail("name", "\"" + op.name + "\" is already the name of an input or operation");
      std::string kind = o.string("op");
      auto k = kinds.find(kind);
      if (k == kinds.end()) {
        std::vector<std::string> known;
        for (const auto& e : kinds) known.push_back(e.first);
        const std::string hint = did_you_mean(kind, known);
        o.fail("op", "unknown operation \"" + kind + "\"" +
                         (hint.empty() ? std::string("; expected union, difference, intersection, offset or shell") : hint));
      }
      op.kind = k->second;
      bool unary = op.kind == RecipeOperation::Kind::kOffset || op.kind == RecipeOperation::Kind::kShell;
      if (op.kind == RecipeOperation::Kind::kOffset) o.allow_only({"name", "op", "of", "distance_mm"});
      else if (op.kind == RecipeOperation::Kind::kShell) o.allow_only({"name", "op", "of", "thickness_mm"});
      else if (op.kind == RecipeOperation::Kind::kInfill) o.allow_only({"name", "op", "hull", "structure", "skin_mm", "fuse_mm"});
      else o.allow_only({"name", "op", "of"});
      if (op.kind == RecipeOperation::Kind::kInfill) {
        op.operands = {o.string("hull"), o.string("structure")};
        op.thickness_mm = o.positive_length("skin_mm");
        op.distance_mm = -1;
        if (o.has("fuse_mm")) {
          op.distance_mm = o.number("fuse_mm");
          if (op.distance_mm < 0 || op.distance_mm >= op.thickness_mm)
            o.fail("fuse_mm", "expected at least 0 and less than skin_mm");
        }
      }
      if (op.kind != RecipeOperation::Kind::kInfill) {
        const nlohmann::json& of = o.required("of");
        if (unary) {
          if (!of.is_string()) o.fail("of", "expected the name of one input or earlier operation");
          op.operands.push_back(of.get<std::string>());
        } else {
          if (!of.is_array() || of.size() < 2) o.fail("of", "expected a list of at least two names");
          for (const auto& n : of) {
            if (!n.is_string()) o.fail("of", "expected names (strings)");
            op.operands.push_back(n.get<std::string>());
          }
        }
      }
      for (const std::string& ref : op.operands) {
        if (names.count(ref)) continue;
        o.fail(op.kind == RecipeOperation::Kind::kInfill ? "hull" : "of", "\"" + ref + "\" is not an input or an earlier operation" +
                         did_you_mean(ref, std::vector<std::string>(names.begin(), names.end())));
      }
      if (op.kind == RecipeOperation::Kind::kOffset) {
        op.distance_mm = o.number("distance_mm");
        if (op.distance_mm == 0) o.fail("distance_mm", "expected a non-zero distance in mm (> 0 grows, < 0 shrinks)");
      }
      if (op.kind == RecipeOperation::Kind::kShell) op.thickness_mm = o.positive_length("thickness_mm");
      names.insert(op.name);
      recipe.operations.push_back(std::move(op));
    }
  }

  const nlohmann::json& outs = top.required("outputs");
  if (!outs.is_array() || outs.empty()) top.fail("outputs", "expected a non-empty list of outputs");
  std::set<std::string> files;
  for (size_t i = 0; i < outs.size(); ++i) {
    JsonObject o(outs[i], path, "outputs[" + std::to_string(i) + "]");
    o.allow_only({"of", "file", "name", "decimate_mm", "fea"});
    RecipeOutput out;
    out.json_path = o.path();
    auto known = [&](const std::string& name) {
      if (names.count(name)) return;
      o.fail("of", "\"" + name + "\" is not an input or operation" +
                       did_you_mean(name, std::vector<std::string>(names.begin(), names.end())));
    };
    if (o.required("of").is_array()) {
      // Several objects in one 3MF package.
      const nlohmann::json& of = o.required("of");
      if (of.size() < 2) o.fail("of", "expected one name, or a list of two or more names for a 3MF with several objects");
      for (const auto& n : of) {
        if (!n.is_string()) o.fail("of", "expected names (strings) of inputs or operations");
        known(n.get<std::string>());
        if (std::find(out.group.begin(), out.group.end(), n.get<std::string>()) != out.group.end())
          o.fail("of", "\"" + n.get<std::string>() + "\" is listed twice");
        out.group.push_back(n.get<std::string>());
      }
      out.object = out.group.front();
    } else {
      out.object = o.string("of");
      known(out.object);
    }
    out.file = o.string("file");
    if (out.file.empty() || out.file.find('/') != std::string::npos || out.file.find('\\') != std::string::npos ||
        out.file == "." || out.file == ".." || out.file[0] == '.')
      o.fail("file", "expected a plain file name such as \"part.stl\" (outputs go to the output folder)");
    std::string ext = lower(fs::path(out.file).extension().string());
    const std::map<std::string, std::string> formats = {{".stl", "stl"}, {".3mf", "3mf"}, {".msh", "msh"},
                                                        {".inp", "inp"}, {".vtu", "vtu"}, {".mesh", "mesh"}};
    auto format = formats.find(ext);
    if (format == formats.end())
      o.fail("file", "expected a file name ending in .stl or .3mf (or .msh, .inp, .vtu, .mesh for tetrahedra), got \"" +
                         out.file + "\"");
    out.format = format->second;
    if (!out.group.empty() && out.format != "3mf")
      o.fail("of", "a list of objects needs a .3mf file (one object each), got \"" + out.file + "\"");
    if (!out.group.empty() && o.has("name")) o.fail("name", "the objects of a list are named after their inputs");
    if (lower(out.file) == "report.json" || !files.insert(lower(out.file)).second)
      o.fail("file", "\"" + out.file + "\" is written twice or clashes with report.json");
    out.decimate_mm = o.positive_length_or("decimate_mm", 0.0);
    const bool tetrahedral = out.format != "stl" && out.format != "3mf";
    if (o.has("fea")) {
      if (!tetrahedral) o.fail("fea", "tetrahedral settings need a .msh, .inp, .vtu or .mesh file");
      JsonObject f = o.object("fea");
      f.allow_only({"max_tet_volume_mm3", "quality", "min_dihedral_deg", "preserve_surface", "msh_version", "element",
                    "regions", "time_limit_s"});
      out.fea.max_tet_volume_mm3 = f.positive_length_or("max_tet_volume_mm3", 0.0);
      out.fea.quality = f.number_or("quality", 0.0);
      if (out.fea.quality != 0 && !(out.fea.quality > 1.0)) f.fail("quality", "expected a radius-edge ratio above 1 (e.g. 1.4)");
      out.fea.min_dihedral_deg = f.number_or("min_dihedral_deg", 0.0);
      if (out.fea.min_dihedral_deg < 0 || out.fea.min_dihedral_deg >= 70) f.fail("min_dihedral_deg", "expected 0 to 70 degrees");
      out.fea.preserve_surface = f.boolean_or("preserve_surface", true);
      std::string version = f.string_or("msh_version", "4.1");
      if (version != "4.1" && version != "2.2") f.fail("msh_version", "expected \"4.1\" or \"2.2\"");
      out.fea.msh_version_2 = version == "2.2";
      std::string element = f.string_or("element", "C3D4");
      if (element != "C3D4" && element != "C3D10") f.fail("element", "expected \"C3D4\" or \"C3D10\"");
      out.fea.quadratic = element == "C3D10";
      out.fea.time_limit_s = f.positive_length_or("time_limit_s", 600);
      if (f.has("regions")) {
        const nlohmann::json& regions = f.required("regions");
        if (!regions.is_array()) f.fail("regions", "expected a list of input or operation names");
        for (const auto& r : regions) {
          if (!r.is_string() || !names.count(r.get<std::string>()))
            f.fail("regions", "expected names of inputs or operations, got " + r.dump());
          out.fea.regions.push_back(r.get<std::string>());
        }
      }
    }
    out.part_name = o.string_or("name", out.object);
    recipe.outputs.push_back(std::move(out));
  }

  if (top.has("printability")) {
    JsonObject pr = top.object("printability");
    pr.allow_only({"min_wall_mm", "min_hole_mm", "build_direction", "critical_angle_deg", "on_failure", "drain_hole_mm",
                   "drain"});
    PrintabilitySettings& p = recipe.printability;
    p.enabled = true;
    p.min_wall_mm = pr.positive_length_or("min_wall_mm", 0.0);
    p.min_hole_mm = pr.positive_length_or("min_hole_mm", 0.0);
    p.build_direction = pr.direction_or("build_direction", Vec3d{0, 0, 1});
    p.critical_angle_deg = pr.number_or("critical_angle_deg", 45);
    if (p.critical_angle_deg < 0 || p.critical_angle_deg > 90) pr.fail("critical_angle_deg", "expected 0 to 90 degrees");
    std::string on_failure = pr.string_or("on_failure", "error");
    if (on_failure == "error") p.on_failure = PrintabilitySettings::OnFailure::kError;
    else if (on_failure == "fix") p.on_failure = PrintabilitySettings::OnFailure::kFix;
    else if (on_failure == "report") p.on_failure = PrintabilitySettings::OnFailure::kReport;
    else pr.fail("on_failure", "expected \"error\", \"fix\" or \"report\", got \"" + on_failure + "\"");
    p.drain_hole_mm = pr.positive_length_or("drain_hole_mm", 2.0);
    std::string drain = pr.string_or("drain", "nearest");
    if (drain != "nearest" && drain != "down") pr.fail("drain", "expected \"nearest\" or \"down\"");
    p.drain_down = drain == "down";
  }
  return recipe;
}

}  // namespace lacuna
