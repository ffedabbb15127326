#include "recipe/recipe.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <variant>

#include "errors.h"
#include "recipe/input_parsers.h"
#include "recipe/json_fields.h"
#include "util/suggest.h"
#include "util/system.h"

namespace lacuna {
namespace {

namespace fs = std::filesystem;

// How each input type is read: the keys its object may have besides "type", and its parser.
struct InputType {
  const char* type;
  std::vector<std::string> keys;
  InputSpec (*parse)(const JsonObject& object);
};

template <class Options, Options (*Parse)(const JsonObject&)>
InputSpec parse_as(const JsonObject& object) {
  return Parse(object);
}

std::vector<std::string> voronoi_keys(std::initializer_list<const char*> more) {
  std::vector<std::string> keys = {"dimension", "d", "points", "random", "seed", "level", "period_mm", "origin_mm"};
  keys.insert(keys.end(), more.begin(), more.end());
  return keys;
}

const std::map<std::string, InputType>& types() {
  static const std::map<std::string, InputType> table = [] {
    std::map<std::string, InputType> t;
    for (InputType type : std::vector<InputType>{
             {"sphere", {"center_mm", "radius_mm"}, parse_as<SphereInput, parse_sphere_input>},
             {"spheres", {"centers_mm", "radius_mm", "radii_mm"}, parse_as<SpheresInput, parse_spheres_input>},
             {"capsule", {"a_mm", "b_mm", "radius_mm", "radius_b_mm"}, parse_as<CapsuleInput, parse_capsule_input>},
             {"tubes", {"polylines"}, parse_as<TubesInput, parse_tubes_input>},
             {"box", {"center_mm", "size_mm", "min_mm", "max_mm"}, parse_as<BoxInput, parse_box_input>},
             {"cylinder", {"center_mm", "axis", "radius_mm", "height_mm"}, parse_as<CylinderInput, parse_cylinder_input>},
             {"torus", {"center_mm", "axis", "major_radius_mm", "minor_radius_mm"}, parse_as<TorusInput, parse_torus_input>},
             {"mesh", {"file", "positions_mm", "triangles", "scale", "translate_mm", "repair"},
              parse_as<MeshInput, parse_mesh_input>},
             {"surface", {"file", "positions_mm", "triangles", "scale", "translate_mm", "thickness_mm"},
              parse_as<SurfaceInput, parse_surface_input>},
             {"region", {"loops_mm", "height_mm", "origin_mm", "axis_u", "axis_v"}, parse_as<RegionInput, parse_region_input>},
             {"lattice",
              {"cell", "period_mm", "strut_radius_mm", "min_mm", "max_mm", "fit_to", "grade", "layout", "inset_mm"},
              parse_as<LatticeInput, parse_lattice_input>},
             {"cifs", {"system", "level", "as", "radius_mm", "thickness_mm", "fit_to", "support"}, parse_as<CifsInput, parse_cifs_input>},
             {"cifs_support", {"system", "level", "thickness_mm", "fit_to", "base_mm", "base_size_mm", "fork", "shrink"},
              parse_as<CifsInput, parse_cifs_support_input>},
             {"curve",
              {"kind", "orders", "radius_mm", "surface", "patch", "mesh", "scale_mm", "center_mm", "offset_mm", "tolerance_mm",
               "base_mm"},
              parse_as<CurveInput, parse_curve_input>},
             {"fill_motifs",
              {"motif", "region", "wallpaper", "c", "N", "count", "min_area_mm2", "max_trials", "gap_mm", "boundary_gap_mm",
               "seed", "random_rotation", "height_mm", "base_z_mm", "wrap", "color_class"},
              parse_as<FillMotifsInput, parse_fill_motifs_input>},
             {"fill_spheres",
              {"fit_to", "box", "sphere", "motif", "random_rotation", "c", "N", "count", "min_radius_mm", "max_trials",
               "gap_mm", "boundary_gap_mm", "seed"},
              parse_as<FillSpheresInput, parse_fill_spheres_input>},
             {"voronoi_spheres", voronoi_keys({"radius_mm", "colours", "tiles"}),
              parse_as<VoronoiSpheresInput, parse_voronoi_spheres_input>},
             {"voronoi_tiles", voronoi_keys({"colours", "clearance_mm", "thickness_mm", "refine"}),
              parse_as<VoronoiTilesInput, parse_voronoi_tiles_input>},
             {"voronoi_foam", voronoi_keys({"wall_mm", "tiles", "cover", "thickness_mm", "refine"}),
              parse_as<VoronoiFoamInput, parse_voronoi_foam_input>},
             {"bcifs_plate",
              {"face", "faces", "shared", "level", "thickness_mm", "radius_mm", "gap_fraction", "lacuna_scale", "notch_depth",
               "realization", "origin_mm"},
              parse_as<BcifsPlateInput, parse_bcifs_plate_input>},
             {"bcifs_cell",
              {"cell", "edge_mm", "center_mm", "edge", "params", "algorithm", "level", "thickness_mm", "gap_fraction",
               "lacuna_scale", "notch_depth", "realization"},
              parse_as<BcifsCellInput, parse_bcifs_cell_input>},
             {"bcifs_volume",
              {"cell", "edge_mm", "center_mm", "corners_mm", "faces", "delay", "cells", "walls", "edge", "params",
               "algorithm", "interior", "radial", "interior_params", "interior_algorithm", "level", "lacuna_scale",
               "face_lacuna_scale", "gap_fraction", "notch_depth", "realization"},
              parse_as<BcifsVolumeInput, parse_bcifs_volume_input>},
             {"bcifs_infill",
              {"hull", "skin_mm", "cell_mm", "equal_lacunas", "walls", "edge", "params", "algorithm", "interior",
               "radial", "interior_params", "interior_algorithm", "level", "lacuna_scale", "face_lacuna_scale",
               "gap_fraction", "notch_depth", "realization", "grade", "cell_grade"},
              parse_as<BcifsInfillInput, parse_bcifs_infill_input>},
         })
      t.emplace(type.type, type);
    return t;
  }();
  return table;
}

bool valid_name(const std::string& name) {
  if (name.empty() || name.size() > 64) return false;
  if (!(std::isalpha(static_cast<unsigned char>(name[0])) || name[0] == '_')) return false;
  return std::all_of(name.begin(), name.end(), [](char c) {
    return std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-';
  });
}

bool has_control_character(const std::string& text) {
  return std::any_of(text.begin(), text.end(), [](char c) { return static_cast<unsigned char>(c) < 0x20 || c == 0x7f; });
}

// A name that becomes one path component: no folder separators, not "." or "..", not hidden (the
// output transaction's temporaries are hidden), no control characters.
bool plain_file_name(const std::string& name) {
  return !name.empty() && name.find('/') == std::string::npos && name.find('\\') == std::string::npos &&
         name != "." && name != ".." && name[0] != '.' && !has_control_character(name) && name.size() <= 200;
}

std::string lower(std::string s) {
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

// A simplification deviation: a finite length of at least 0 mm (0: off).
double deviation(const JsonObject& o, const char* key) {
  const double d = o.number(key);
  if (!(d >= 0) || !std::isfinite(d)) o.fail(key, "expected a deviation of at least 0 mm (0: no simplification)");
  return d;
}

}  // namespace

std::vector<std::string> input_type_names() {
  std::vector<std::string> names;
  for (const auto& entry : types()) names.push_back(entry.first);
  return names;
}

Recipe load_recipe(const std::string& path) {
  return parse_recipe(read_text_file(path, "a recipe file (.json)", kMaxJsonFileBytes), path);
}

Recipe parse_recipe(const std::string& text, const std::string& path) {
  if (text.size() > kMaxJsonFileBytes)
    throw InvalidInput(path + ": recipe is larger than 256 MB; put large geometry in mesh files");
  nlohmann::json root = parse_json_text(text, path);
  JsonObject top(root, path, "");
  top.allow_only({"lacuna_recipe", "name", "description", "voxel_size_mm", "band_voxels", "simplify_mm", "seed",
                  "inputs", "operations", "outputs", "printability"});
  Recipe recipe;
  recipe.file = path;
  if (top.has("lacuna_recipe") && top.unsigned_integer_or("lacuna_recipe", 1) != 1)
    top.fail("lacuna_recipe", "this version of Lacuna reads recipe format 1");
  recipe.name = top.string_or("name", fs::path(path).stem().string());
  // The default output folder is "<name>-out" in the working folder: the name must stay one plain
  // folder name there.
  if (top.has("name") && !plain_file_name(recipe.name))
    top.fail("name", "expected a plain name such as \"bracket\" (it names the output folder <name>-out): no '/', '\\', "
                     "control characters or leading '.', at most 200 characters");
  recipe.description = top.string_or("description", "");
  recipe.voxel_size_mm = top.positive_length_or("voxel_size_mm", 0.1);
  if (!(recipe.voxel_size_mm >= kMinVoxelSizeMm && recipe.voxel_size_mm <= kMaxVoxelSizeMm))
    top.fail("voxel_size_mm", "expected a voxel size from 0.0001 to 1000 mm");
  recipe.band_voxels = top.number_or("band_voxels", 3.0);
  if (recipe.band_voxels < 2 || recipe.band_voxels > 16) top.fail("band_voxels", "expected a number from 2 to 16");
  if (top.has("simplify_mm")) recipe.simplify_mm = deviation(top, "simplify_mm");
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
    const std::string type_name = o.string("type");
    auto type = types().find(type_name);
    if (type == types().end()) {
      std::string message = "unknown input type \"" + type_name + "\"" + did_you_mean(type_name, input_type_names());
      message += " (known types:";
      for (const std::string& t : input_type_names()) message += " " + t;
      o.fail("type", message + ")");
    }
    std::vector<std::string> keys = type->second.keys;
    keys.push_back("type");
    o.allow_only(keys);
    input.spec = type->second.parse(o);
    names.insert(name);
    recipe.inputs.push_back(std::move(input));
  }

  // Inputs coloured into classes without "keep": one part per class and their union under the input's name.
  std::map<std::string, std::vector<std::string>> split;
  {
    std::vector<RecipeInput> expanded;
    for (RecipeInput& in : recipe.inputs) {
      const auto* f = std::get_if<FillMotifsInput>(&in.spec);
      if (!f || !f->color_class || f->color_class->keep >= 0) {
        expanded.push_back(std::move(in));
        continue;
      }
      std::vector<std::string>& parts = split[in.name];
      for (int k = 0; k < f->color_class->classes; ++k) {
        RecipeInput part = in;
        part.name = in.name + "-" + std::to_string(k);
        part.json_path = in.json_path;
        if (names.count(part.name) || !valid_name(part.name))
          throw InvalidInput(path + ": " + in.json_path + ".color_class: colour class " + std::to_string(k) +
                             " becomes the object \"" + part.name + "\", " +
                             (names.count(part.name) ? "which is already the name of an input"
                                                     : "a name longer than 64 characters") +
                             "; rename one of them");
        std::get<FillMotifsInput>(part.spec).color_class->keep = k;
        recipe.display_colors[part.name] = f->color_class->palette[size_t(k)];
        names.insert(part.name);
        parts.push_back(part.name);
        expanded.push_back(std::move(part));
      }
      RecipeOperation whole;
      whole.name = in.name;
      whole.json_path = in.json_path;
      whole.spec = CsgOperation{CsgOperation::Kind::kUnion, parts};
      recipe.operations.push_back(std::move(whole));
    }
    recipe.inputs = std::move(expanded);
  }

  for (const RecipeInput& in : recipe.inputs)
    for (const std::string& dep : dependencies(in.spec)) {
      bool found = false;
      for (const RecipeInput& other : recipe.inputs) found = found || (other.name == dep && &other != &in);
      if (!found) {
        std::vector<std::string> input_names;
        for (const RecipeInput& other : recipe.inputs) input_names.push_back(other.name);
        if (dep == in.name) throw InvalidInput(path + ": " + in.json_path + ": refers to itself; name another input");
        throw InvalidInput(path + ": " + in.json_path + ": \"" + dep + "\" is not another input" +
                           did_you_mean(dep, input_names));
      }
    }

  if (top.has("operations")) {
    const nlohmann::json& ops = top.required("operations");
    if (!ops.is_array()) top.fail("operations", "expected a list of operations");
    enum class Kind { kUnion, kDifference, kIntersection, kOffset, kShell, kInfill };
    const std::map<std::string, Kind> kinds = {{"union", Kind::kUnion},   {"difference", Kind::kDifference},
                                               {"intersection", Kind::kIntersection}, {"offset", Kind::kOffset},
                                               {"shell", Kind::kShell},   {"infill", Kind::kInfill}};
    for (size_t i = 0; i < ops.size(); ++i) {
      JsonObject o(ops[i], path, "operations[" + std::to_string(i) + "]");
      RecipeOperation op;
      op.json_path = o.path();
      op.name = o.string("name");
      if (!valid_name(op.name))
        o.fail("name", "names use letters, digits, '_' and '-', start with a letter or '_', at most 64 characters");
      if (names.count(op.name)) o.fail("name", "\"" + op.name + "\" is already the name of an input or operation");
      std::string kind_name = o.string("op");
      auto k = kinds.find(kind_name);
      if (k == kinds.end()) {
        std::vector<std::string> known;
        for (const auto& e : kinds) known.push_back(e.first);
        const std::string hint = did_you_mean(kind_name, known);
        o.fail("op", "unknown operation \"" + kind_name + "\"" +
                         (hint.empty() ? std::string("; expected union, difference, intersection, offset or shell") : hint));
      }
      const Kind kind = k->second;
      bool unary = kind == Kind::kOffset || kind == Kind::kShell;
      if (kind == Kind::kOffset) o.allow_only({"name", "op", "of", "distance_mm"});
      else if (kind == Kind::kShell) o.allow_only({"name", "op", "of", "thickness_mm"});
      else if (kind == Kind::kInfill) o.allow_only({"name", "op", "hull", "structure", "skin_mm", "fuse_mm"});
      else o.allow_only({"name", "op", "of"});
      std::vector<std::string> of;
      InfillOperation infill;
      if (kind == Kind::kInfill) {
        infill.hull = o.string("hull");
        infill.structure = o.string("structure");
        of = {infill.hull, infill.structure};
        infill.skin_mm = o.positive_length("skin_mm");
        infill.fuse_mm = -1;
        if (o.has("fuse_mm")) {
          infill.fuse_mm = o.number("fuse_mm");
          if (infill.fuse_mm < 0 || infill.fuse_mm >= infill.skin_mm)
            o.fail("fuse_mm", "expected at least 0 and less than skin_mm");
        }
      } else {
        const nlohmann::json& of_json = o.required("of");
        if (unary) {
          if (!of_json.is_string()) o.fail("of", "expected the name of one input or earlier operation");
          of.push_back(of_json.get<std::string>());
        } else {
          if (!of_json.is_array() || of_json.size() < 2) o.fail("of", "expected a list of at least two names");
          for (const auto& n : of_json) {
            if (!n.is_string()) o.fail("of", "expected names (strings)");
            of.push_back(n.get<std::string>());
          }
        }
      }
      for (const std::string& ref : of) {
        if (names.count(ref)) continue;
        o.fail(kind == Kind::kInfill ? "hull" : "of", "\"" + ref + "\" is not an input or an earlier operation" +
                         did_you_mean(ref, std::vector<std::string>(names.begin(), names.end())));
      }
      switch (kind) {
        case Kind::kUnion:
          op.spec = CsgOperation{CsgOperation::Kind::kUnion, of};
          break;
        case Kind::kDifference:
          op.spec = CsgOperation{CsgOperation::Kind::kDifference, of};
          break;
        case Kind::kIntersection:
          op.spec = CsgOperation{CsgOperation::Kind::kIntersection, of};
          break;
        case Kind::kOffset: {
          OffsetOperation offset{of[0], o.number("distance_mm")};
          if (offset.distance_mm == 0) o.fail("distance_mm", "expected a non-zero distance in mm (> 0 grows, < 0 shrinks)");
          op.spec = offset;
          break;
        }
        case Kind::kShell:
          op.spec = ShellOperation{of[0], o.positive_length("thickness_mm")};
          break;
        case Kind::kInfill:
          op.spec = infill;
          break;
      }
      names.insert(op.name);
      recipe.operations.push_back(std::move(op));
    }
  }

  const nlohmann::json& outs = top.required("outputs");
  if (!outs.is_array() || outs.empty()) top.fail("outputs", "expected a non-empty list of outputs");
  std::set<std::string> files;
  for (size_t i = 0; i < outs.size(); ++i) {
    JsonObject o(outs[i], path, "outputs[" + std::to_string(i) + "]");
    o.allow_only({"of", "file", "name", "simplify_mm", "decimate_mm", "fea", "quantize_mm", "render", "layers"});
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
      auto parts = split.find(out.object);
      if (parts != split.end() && lower(fs::path(o.string("file")).extension().string()) == ".3mf") {
        out.group = parts->second;  // one object per colour class
        out.object = out.group.front();
      }
    }
    out.file = o.string("file");
    if (!plain_file_name(out.file))
      o.fail("file", "expected a plain file name such as \"part.stl\" (outputs go to the output folder): no '/', '\\', "
                     "control characters or leading '.', at most 200 characters");
    std::string ext = lower(fs::path(out.file).extension().string());
    const std::map<std::string, std::string> formats = {{".stl", "stl"}, {".3mf", "3mf"}, {".drc", "drc"}, {".msh", "msh"},
                                                        {".inp", "inp"}, {".vtu", "vtu"}, {".mesh", "mesh"},
                                                        {".cli", "cli"}, {".zip", "png_layers"}, {".sl1", "sl1"}};
    auto format = formats.find(ext);
    if (format == formats.end())
      o.fail("file", "expected a file name ending in .stl, .3mf or .drc (or .msh, .inp, .vtu, .mesh for tetrahedra, .cli, "
                     ".sl1 or .zip for layers), got \"" + out.file + "\"");
    out.format = format->second;
    if (!out.group.empty() && out.format != "3mf")
      o.fail("of", "a list of objects needs a .3mf file (one object each), got \"" + out.file + "\"");
    if (!out.group.empty() && o.has("name")) o.fail("name", "the objects of a list are named after their inputs");
    if (lower(out.file) == "report.json" || !files.insert(lower(out.file)).second)
      o.fail("file", "\"" + out.file + "\" is written twice or clashes with report.json");
    if (o.has("simplify_mm") && o.has("decimate_mm"))
      o.fail("decimate_mm", "give \"simplify_mm\" only (\"decimate_mm\" is its older name)");
    const bool layered = out.format == "cli" || out.format == "png_layers" || out.format == "sl1";
    if (layered) {
      if (!out.group.empty()) o.fail("of", "layers are cut from one object: give one name");
      for (const char* key : {"simplify_mm", "decimate_mm", "quantize_mm", "fea", "render"})
        if (o.has(key)) o.fail(key, "layers (.cli, .sl1, .zip) are cut from the level set: no mesh, so no \"" + std::string(key) + "\"");
      RecipeOutput::Layers layers;
      if (o.has("layers")) {
        JsonObject l = o.object("layers");
        l.allow_only({"layer_mm", "pixel_mm", "tolerance_mm", "binary"});
        layers.layer_mm = l.positive_length_or("layer_mm", 0.0);
        layers.pixel_mm = l.positive_length_or("pixel_mm", 0.0);
        if (l.has("tolerance_mm")) {
          layers.tolerance_mm = l.number_or("tolerance_mm", 0.0);
          if (!(layers.tolerance_mm >= 0) || !std::isfinite(layers.tolerance_mm))
            l.fail("tolerance_mm", "expected a length >= 0 (0: contours not simplified)");
        }
        layers.binary = l.boolean_or("binary", false);
        if (out.format == "sl1" && l.has("pixel_mm")) l.fail("pixel_mm", "an SL1 archive has the printer's pixels");
        if (layers.binary && out.format != "cli") l.fail("binary", "only a .cli file is binary or ASCII");
        for (const auto& [key, v] : {std::pair{"layer_mm", layers.layer_mm}, std::pair{"pixel_mm", layers.pixel_mm}})
          if (v != 0 && (v < kMinVoxelSizeMm || v > kMaxVoxelSizeMm))
            l.fail(key, "expected a length between " + std::to_string(kMinVoxelSizeMm) + " and " +
                            std::to_string(kMaxVoxelSizeMm) + " mm");
      }
      out.layers = layers;
    } else if (o.has("layers")) {
      o.fail("layers", "layer settings need a .cli, .sl1 or .zip file");
    }
    if (o.has("simplify_mm")) out.simplify_mm = deviation(o, "simplify_mm");
    if (o.has("decimate_mm")) out.simplify_mm = deviation(o, "decimate_mm");
    const bool tetrahedral = out.format == "msh" || out.format == "inp" || out.format == "vtu" || out.format == "mesh";
    if (o.has("quantize_mm")) {
      if (out.format != "drc") o.fail("quantize_mm", "only a .drc output is quantized");
      out.quantize_mm = o.positive_length_or("quantize_mm", 0.0);
    }
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
    if (o.has("render")) {
      if (tetrahedral) o.fail("render", "pictures are made of surface outputs (.stl, .3mf, .drc)");
      if (!out.group.empty()) o.fail("render", "pictures are made of one object: give \"render\" on an output of one");
      RecipeOutput::Render render;
      const nlohmann::json& r = o.required("render");
      if (r.is_string()) {
        render.file = r.get<std::string>();
      } else {
        JsonObject ro = o.object("render");
        ro.allow_only({"file", "views", "size", "section"});
        if (ro.has("section")) {
          render.section = ro.number_or("section", 0.0);
          if (!(*render.section >= 0 && *render.section <= 1)) ro.fail("section", "expected a fraction of the height, 0 to 1");
        }
        render.file = ro.string("file");
        if (ro.has("views")) {
          const nlohmann::json& views = ro.required("views");
          if (!views.is_array() || views.empty()) ro.fail("views", "expected a list of \"iso\", \"front\", \"top\", \"side\"");
          render.views.clear();
          for (const auto& v : views) {
            static const std::set<std::string> view_names = {"iso", "front", "top", "side"};
            if (!v.is_string() || !view_names.count(v.get<std::string>()))
              ro.fail("views", "expected \"iso\", \"front\", \"top\" or \"side\", got " + v.dump());
            render.views.push_back(v.get<std::string>());
          }
        }
        if (ro.has("size")) {
          const nlohmann::json& size = ro.required("size");
          if (!size.is_array() || size.size() != 2 || !size[0].is_number_integer() || !size[1].is_number_integer() ||
              size[0].get<int64_t>() < 64 || size[0].get<int64_t>() > 8192 || size[1].get<int64_t>() < 64 ||
              size[1].get<int64_t>() > 8192)
            ro.fail("size", "expected [width, height] in pixels, each 64 to 8192");
          render.width = int(size[0].get<int64_t>());
          render.height = int(size[1].get<int64_t>());
        }
      }
      if (!plain_file_name(render.file) || lower(fs::path(render.file).extension().string()) != ".png")
        o.fail("render", "expected a plain file name ending in .png, such as \"part.png\"");
      if (lower(render.file) == "report.json" || !files.insert(lower(render.file)).second)
        o.fail("render", "\"" + render.file + "\" is written twice");
      out.render = render;
    }
    out.part_name = o.string_or("name", out.object);
    if (has_control_character(out.part_name)) o.fail("name", "an object name may not hold control characters");
    recipe.outputs.push_back(std::move(out));
  }

  if (top.has("printability")) {
    JsonObject pr = top.object("printability");
    pr.allow_only({"min_wall_mm", "min_hole_mm", "build_direction", "critical_angle_deg", "on_failure", "drain_hole_mm",
                   "drain", "min_piece_mm3"});
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
    p.min_piece_mm3 = pr.number_or("min_piece_mm3", 0.0);
    if (!(p.min_piece_mm3 >= 0) || !std::isfinite(p.min_piece_mm3))
      pr.fail("min_piece_mm3", "expected a volume >= 0 (mm^3; 0: loose pieces are not checked)");
  }
  return recipe;
}

std::vector<std::string> dependencies(const InputSpec& spec) {
  if (const auto* lattice = std::get_if<LatticeInput>(&spec))
    return lattice->fit_to ? std::vector<std::string>{*lattice->fit_to} : std::vector<std::string>{};
  if (const auto* cifs = std::get_if<CifsInput>(&spec))
    return cifs->fit_to ? std::vector<std::string>{*cifs->fit_to} : std::vector<std::string>{};
  if (const auto* fill = std::get_if<FillSpheresInput>(&spec))
    return fill->region == FillSpheresInput::Region::kFitTo ? std::vector<std::string>{fill->fit_to}
                                                            : std::vector<std::string>{};
  if (const auto* foam = std::get_if<VoronoiFoamInput>(&spec))
    return foam->cover ? std::vector<std::string>{*foam->cover} : std::vector<std::string>{};
  if (const auto* infill = std::get_if<BcifsInfillInput>(&spec)) return {infill->hull};
  return {};
}

bool built_after_others(const InputSpec& spec) {
  if (const auto* curve = std::get_if<CurveInput>(&spec))
    if (curve->surface == CurveInput::Surface::kMesh) return true;
  return !dependencies(spec).empty();
}

std::vector<std::string> operands(const OperationSpec& op) {
  if (const auto* csg = std::get_if<CsgOperation>(&op)) return csg->of;
  if (const auto* offset = std::get_if<OffsetOperation>(&op)) return {offset->of};
  if (const auto* shell = std::get_if<ShellOperation>(&op)) return {shell->of};
  const auto& infill = std::get<InfillOperation>(op);
  return {infill.hull, infill.structure};
}

double simplify_deviation_mm(const Recipe& recipe, const RecipeOutput& output) {
  if (output.simplify_mm) return *output.simplify_mm;
  if (recipe.simplify_mm) return *recipe.simplify_mm;
  return kDefaultSimplifyVoxels * recipe.voxel_size_mm;
}

}  // namespace lacuna
