// The random fractal fillings: motifs in a region or a wallpaper pattern, spheres or polyhedra in a volume.
#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include "errors.h"
#include "fill/motif_file.h"
#include "recipe/input_parsers.h"

namespace lacuna {
namespace {

using namespace fill;

constexpr double kPi = 3.14159265358979323846;

Vec2d vec2(const nlohmann::json& v, const JsonObject& o, const char* key) {
  if (!v.is_array() || v.size() != 2 || !v[0].is_number() || !v[1].is_number())
    o.fail(key, "expected [x, y] in mm, got " + describe_json_type(v));
  return Vec2d{v[0].get<double>(), v[1].get<double>()};
}

std::vector<Vec2d> vec2_list(const JsonObject& o, const char* key) {
  const nlohmann::json& v = o.required(key);
  if (!v.is_array()) o.fail(key, "expected a list of [x, y] points, got " + describe_json_type(v));
  return o.vec2_list(v, o.path_of(key));
}

Motif2 parse_motif(const JsonObject& o) {
  const nlohmann::json& v = o.required("motif");
  try {
    if (v.is_string()) {
      const std::string name = v.get<std::string>();
      if (name == "circle") return circle_motif();
      if (name == "square") return regular_polygon_motif(4);
      if (name == "triangle") return regular_polygon_motif(3);
      if (name == "hexagon") return regular_polygon_motif(6);
      o.fail("motif", "expected \"circle\", \"triangle\", \"square\", \"hexagon\", {\"regular_polygon\": n}, {\"polygon\": [[x, y], ...]} or {\"file\": \"motif.svg\"}, got \"" + name + "\"");
    }
    JsonObject m = o.object("motif");
    m.allow_only({"regular_polygon", "polygon", "file"});
    if (m.has("file")) {  // relative to the recipe's folder
      const std::string name = m.string("file");
      const std::filesystem::path file = std::filesystem::path(o.file()).parent_path() / name;
      return motif_from_file(file.string());
    }
    if (m.has("regular_polygon")) {
      const uint64_t n = m.unsigned_integer_or("regular_polygon", 0);
      if (n < 3 || n > 1000) m.fail("regular_polygon", "expected 3 to 1000 sides");
      return regular_polygon_motif(int(n));
    }
    if (m.has("polygon")) return polygon_motif(vec2_list(m, "polygon"));
    o.fail("motif", "expected {\"regular_polygon\": n}, {\"polygon\": [[x, y], ...]} or {\"file\": \"motif.svg\"} (.json or .svg)");
  } catch (const InvalidInput& e) {
    if (std::string(e.what()).find(o.file()) == 0) throw;
    o.fail("motif", e.what());
  } catch (const IoError& e) {
    throw IoError(o.file() + ": " + o.path_of("motif") + ": " + e.what());
  }
}

FillRegion2 parse_region(const JsonObject& o) {
  JsonObject r = o.object("region");
  r.allow_only({"rectangle", "disk", "polygon"});
  if (r.json().size() != 1) r.fail("", "expected one of \"rectangle\", \"disk\" or \"polygon\"");
  try {
    if (r.has("rectangle")) {
      JsonObject b = r.object("rectangle");
      b.allow_only({"min_mm", "max_mm"});
      const Vec2d lo = vec2(b.required("min_mm"), b, "min_mm"), hi = vec2(b.required("max_mm"), b, "max_mm");
      if (!(hi.x > lo.x && hi.y > lo.y)) b.fail("max_mm", "expected max_mm > min_mm on both axes");
      return rectangle_region(lo, hi);
    }
    if (r.has("disk")) {
      JsonObject d = r.object("disk");
      d.allow_only({"center_mm", "radius_mm"});
      return disk_region(d.has("center_mm") ? vec2(d.required("center_mm"), d, "center_mm") : Vec2d{0, 0}, d.positive_length("radius_mm"));
    }
    return polygon_region(vec2_list(r, "polygon"));
  } catch (const InvalidInput& e) {
    if (std::string(e.what()).find(o.file()) == 0) throw;
    r.fail("", e.what());
  }
}

BoundaryPolicy parse_policy(const JsonObject& w) {
  const std::string policy = w.string_or("policy", "reject");
  if (policy == "allow") return BoundaryPolicy::kAllow;
  if (policy == "reject") return BoundaryPolicy::kReject;
  if (policy == "snap") return BoundaryPolicy::kSnap;
  w.fail("policy", "expected \"allow\", \"reject\" or \"snap\", got \"" + policy + "\"");
}

// Keys shared by both fills: the law, the stopping rules, the gaps and the seed.
template <class Options>
void parse_law(const JsonObject& o, Options& f) {
  f.c = o.number_or("c", 1.3);
  if (!(f.c > 1)) o.fail("c", "expected an exponent c > 1 (the fractal dimension is 2/c, or 3/c for volumes)");
  f.N = o.number_or("N", 2);
  if (!(f.N > 1)) o.fail("N", "expected N > 1");
  f.max_count = size_t(o.unsigned_integer_or("count", 1000));
  if (f.max_count < 1 || f.max_count > 10'000'000) o.fail("count", "expected 1 to 10 000 000 motifs");
  f.max_trials = size_t(o.unsigned_integer_or("max_trials", 100000));
  if (f.max_trials < 1) o.fail("max_trials", "expected at least 1 trial");
  f.gap_mm = o.has("gap_mm") ? o.number("gap_mm") : 0.0;
  if (!(f.gap_mm >= 0)) o.fail("gap_mm", "expected a gap of at least 0 mm");
  f.boundary_gap_mm = o.has("boundary_gap_mm") ? o.number("boundary_gap_mm") : 0.0;
  if (!(f.boundary_gap_mm >= 0)) o.fail("boundary_gap_mm", "expected a gap of at least 0 mm");
  f.seed = o.unsigned_integer_or("seed", 1);
}

}  // namespace

FillMotifsInput parse_fill_motifs_input(const JsonObject& o) {
  FillMotifsInput in;
  in.motif = parse_motif(o);
  if (o.has("color_class")) {
    JsonObject c = o.object("color_class");
    c.allow_only({"by", "classes", "keep", "palette"});
    FillMotifsInput::ColorClass cc;
    try {
      cc.by = coloring_from_name(c.string_or("by", "size"));
    } catch (const InvalidInput& e) {
      c.fail("by", e.what());
    }
    const uint64_t classes = c.unsigned_integer_or("classes", 2);
    if (classes < 1 || classes > 64) c.fail("classes", "expected 1 to 64 colour classes");
    cc.classes = int(classes);
    if (c.has("keep")) {
      const uint64_t keep = c.unsigned_integer_or("keep", 0);
      if (keep >= classes) c.fail("keep", "expected a class from 0 to " + std::to_string(classes - 1));
      cc.keep = int(keep);
    } else if (classes < 2) {
      c.fail("classes", "expected 2 to 64 colour classes to split the input into (or \"keep\": 0)");
    }
    if (c.has("palette")) {
      const nlohmann::json& p = c.required("palette");
      std::string text;
      if (p.is_string()) {
        text = p.get<std::string>();
      } else if (p.is_array()) {
        for (const auto& e : p) {
          if (!e.is_string()) c.fail("palette", "expected colours \"#rrggbb\", got " + e.dump());
          text += (text.empty() ? "" : ",") + e.get<std::string>();
        }
      } else {
        c.fail("palette", "expected a list of colours [\"#rrggbb\", ...] or one string \"#rrggbb,#rrggbb\"");
      }
      try {
        cc.palette = fill::parse_palette(text);
      } catch (const InvalidInput& e) {
        c.fail("palette", e.what());
      }
      if (cc.palette.size() < classes)
        c.fail("palette", "expected a colour for each of the " + std::to_string(classes) + " classes, got " +
                              std::to_string(cc.palette.size()));
    } else {
      const std::vector<std::string> dark2 = fill::default_palette();
      for (uint64_t k = 0; k < classes; ++k) cc.palette.push_back(dark2[k % dark2.size()]);
    }
    in.color_class = cc;
  }
  FillOptions& f = in.fill;
  parse_law(o, f);
  f.min_area_mm2 = o.has("min_area_mm2") ? o.positive_length("min_area_mm2") : 0.0;
  f.random_rotation = o.boolean_or("random_rotation", false);
  in.solid.height_mm = o.positive_length("height_mm");
  in.solid.base_z_mm = o.number_or("base_z_mm", 0);
  if (o.has("region") == o.has("wallpaper")) o.fail("", "give either \"region\" or \"wallpaper\"");
  try {
    if (o.has("region")) {
      if (o.has("wrap")) o.fail("wrap", "only a periodic (wallpaper) pattern wraps around a cylinder");
      in.region = parse_region(o);
      return in;
    }
    in.wallpaper = true;
    JsonObject w = o.object("wallpaper");
    w.allow_only({"group", "a_mm", "b_mm", "cells", "policy"});
    try {
      in.group = group_from_name(w.string("group"));
    } catch (const InvalidInput& e) {
      w.fail("group", e.what());
    }
    in.lattice.a = vec2(w.required("a_mm"), w, "a_mm");
    in.lattice.b = vec2(w.required("b_mm"), w, "b_mm");
    const nlohmann::json& cells = w.required("cells");
    if (!cells.is_array() || cells.size() != 2 || !cells[0].is_number_unsigned() || !cells[1].is_number_unsigned() ||
        cells[0].get<uint64_t>() < 1 || cells[1].get<uint64_t>() < 1 || cells[0].get<uint64_t>() > 1000 ||
        cells[1].get<uint64_t>() > 1000)
      w.fail("cells", "expected [u, v]: how many unit cells along a and b (1 to 1000 each)");
    in.cells_u = int(cells[0].get<uint64_t>());
    in.cells_v = int(cells[1].get<uint64_t>());
    in.policy = parse_policy(w);
    if (o.has("wrap")) {
      JsonObject wrap = o.object("wrap");
      wrap.allow_only({"depth_mm"});
      in.wrap_depth_mm = wrap.positive_length("depth_mm");
    }
  } catch (const InvalidInput& e) {
    if (std::string(e.what()).find(o.file()) == 0) throw;
    o.fail("", e.what());
  }
  return in;
}

FillSpheresInput parse_fill_spheres_input(const JsonObject& o) {
  FillSpheresInput in;
  FillOptions3& f = in.fill;
  parse_law(o, f);
  // Spheres, or convex polyhedra (unit volume, scaled by the rule).
  const std::string motif_name = o.string_or("motif", "sphere");
  if (motif_name == "cube") in.motif = FillSpheresInput::Motif::kCube;
  else if (motif_name == "tetrahedron") in.motif = FillSpheresInput::Motif::kTetrahedron;
  else if (motif_name == "octahedron") in.motif = FillSpheresInput::Motif::kOctahedron;
  else if (motif_name != "sphere")
    o.fail("motif", "expected \"sphere\", \"cube\", \"tetrahedron\" or \"octahedron\", got \"" + motif_name + "\"");
  in.random_rotation = o.boolean_or("random_rotation", false);
  if (in.random_rotation && in.motif == FillSpheresInput::Motif::kSphere)
    o.fail("random_rotation", "a sphere has no orientation to randomize");
  if (o.has("min_radius_mm")) {
    const double r = o.positive_length("min_radius_mm");
    f.min_volume_mm3 = 4.0 / 3.0 * kPi * r * r * r;
  }
  const int given = int(o.has("fit_to")) + int(o.has("box")) + int(o.has("sphere"));
  if (given != 1) o.fail("", "give one region: \"fit_to\" (a closed input), \"box\" or \"sphere\"");
  if (o.has("box")) {
    JsonObject b = o.object("box");
    b.allow_only({"min_mm", "max_mm"});
    in.region = FillSpheresInput::Region::kBox;
    in.box.expand(b.vec3("min_mm"));
    in.box.expand(b.vec3("max_mm"));
    const Vec3d s = in.box.size();
    if (!(s.x > 0 && s.y > 0 && s.z > 0)) b.fail("max_mm", "expected max_mm > min_mm on every axis");
    return in;
  }
  if (o.has("sphere")) {
    JsonObject s = o.object("sphere");
    s.allow_only({"center_mm", "radius_mm"});
    in.region = FillSpheresInput::Region::kSphere;
    in.sphere_center_mm = s.vec3_or("center_mm", Vec3d{});
    in.sphere_radius_mm = s.positive_length("radius_mm");
    return in;
  }
  in.region = FillSpheresInput::Region::kFitTo;
  in.fit_to = o.string("fit_to");
  return in;
}

}  // namespace lacuna
