#include "fill/recipe_input.h"

#include <cmath>
#include <map>
#include <memory>
#include <string>

#include "errors.h"
#include "fill/polyhedra.h"
#include "fill/wallpaper.h"
#include "recipe/recipe.h"

namespace lacuna {
namespace fill {
namespace {

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
      o.fail("motif", "expected \"circle\", \"triangle\", \"square\", \"hexagon\", {\"regular_polygon\": n} or {\"polygon\": [[x, y], ...]}, got \"" + name + "\"");
    }
    JsonObject m = o.object("motif");
    m.allow_only({"regular_polygon", "polygon"});
    if (m.has("regular_polygon")) {
      const uint64_t n = m.unsigned_integer_or("regular_polygon", 0);
      if (n < 3 || n > 1000) m.fail("regular_polygon", "expected 3 to 1000 sides");
      return regular_polygon_motif(int(n));
    }
    if (m.has("polygon")) return polygon_motif(vec2_list(m, "polygon"));
    o.fail("motif", "expected {\"regular_polygon\": n} or {\"polygon\": [[x, y], ...]}");
  } catch (const InvalidInput& e) {
    if (std::string(e.what()).find(o.file()) == 0) throw;
    o.fail("motif", e.what());
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

GeometrySet motif_solids(const Motif2& motif, const std::vector<Placement2>& placements, const MotifSolidOptions& o) {
  if (!(o.height_mm > 0)) throw InvalidInput("the motifs' height must be positive (mm)");
  const bool wrapped = o.wrap_radius_mm > 0;
  GeometrySet set;
  // Where a motif centred at (x, y) of the pattern goes, and its frame (u along the pattern's x).
  auto frame = [&](const Vec2d& c, Vec3d& origin, Vec3d& u, Vec3d& v, Vec3d& normal) {
    if (!wrapped) {
      origin = Vec3d{c.x, c.y, o.base_z_mm};
      u = Vec3d{1, 0, 0};
      v = Vec3d{0, 1, 0};
      normal = Vec3d{0, 0, 1};
      return;
    }
    const double angle = c.x / o.wrap_radius_mm;
    normal = Vec3d{std::cos(angle), std::sin(angle), 0};
    u = Vec3d{-std::sin(angle), std::cos(angle), 0};
    v = Vec3d{0, 0, 1};
    origin = normal * (o.wrap_radius_mm - 0.5 * o.height_mm) + Vec3d{0, 0, c.y};
  };
  if (motif.kind == Motif2::Kind::kCircle) {
    for (const Placement2& p : placements) {
      Vec3d origin, u, v, n;
      frame(p.center_mm, origin, u, v, n);
      Shape s;
      s.kind = Shape::Kind::kCylinder;
      s.axis = n;
      s.radius_mm = p.scale / std::sqrt(kPi);
      s.height_mm = o.height_mm;
      s.center_mm = origin + n * (wrapped ? 0.5 * o.height_mm : 0.5 * o.height_mm);
      set.shapes.push_back(s);
    }
    return set;
  }
  // Polygons: flat ones share regions (one per layer of disjoint motifs); wrapped ones are one
  // region each, in the tangent plane at their centre.
  struct Layer {
    std::map<std::pair<int64_t, int64_t>, std::vector<size_t>> grid;
    Region2 region;
  };
  std::vector<Layer> layers;
  double reach = 0;
  for (const Placement2& p : placements) reach = std::max(reach, 2 * p.scale * motif.bounding_radius);
  const double cell = std::max(reach, 1e-9);
  for (size_t i = 0; i < placements.size(); ++i) {
    const Placement2& p = placements[i];
    std::vector<Vec2d> outline = placed_outline(motif, p);
    if (wrapped) {
      Vec3d origin, u, v, n;
      frame(p.center_mm, origin, u, v, n);
      Region2 r;
      for (Vec2d& q : outline) q = q - p.center_mm;
      r.loops_mm.push_back(outline);
      r.origin_mm = origin;
      r.axis_u = u;
      r.axis_v = v;
      r.height_mm = o.height_mm;
      set.regions.push_back(std::move(r));
      continue;
    }
    const double radius = p.scale * motif.bounding_radius;
    const int64_t cx = int64_t(std::floor(p.center_mm.x / cell)), cy = int64_t(std::floor(p.center_mm.y / cell));
    size_t chosen = layers.size();
    for (size_t l = 0; l < layers.size() && chosen == layers.size(); ++l) {
      bool free = true;
      for (int64_t dx = -1; dx <= 1 && free; ++dx)
        for (int64_t dy = -1; dy <= 1 && free; ++dy) {
          auto it = layers[l].grid.find({cx + dx, cy + dy});
          if (it == layers[l].grid.end()) continue;
          for (size_t j : it->second) {
            const Placement2& q = placements[j];
            const Vec2d d = q.center_mm - p.center_mm;
            if (std::hypot(d.x, d.y) <= radius + q.scale * motif.bounding_radius) {
              free = false;
              break;
            }
          }
        }
      if (free) chosen = l;
    }
    if (chosen == layers.size()) {
      layers.emplace_back();
      layers.back().region.origin_mm = Vec3d{0, 0, o.base_z_mm};
      layers.back().region.height_mm = o.height_mm;
    }
    layers[chosen].grid[{cx, cy}].push_back(i);
    layers[chosen].region.loops_mm.push_back(std::move(outline));
  }
  for (Layer& l : layers) set.regions.push_back(std::move(l.region));
  return set;
}

void register_recipe_inputs() {
  register_input_type(
      {"fill_motifs",
       {"motif", "region", "wallpaper", "c", "N", "count", "min_area_mm2", "max_trials", "gap_mm", "boundary_gap_mm", "seed",
        "random_rotation", "height_mm", "base_z_mm", "wrap"},
       [](const JsonObject& o, RecipeInput& in) {
         const Motif2 motif = parse_motif(o);
         FillOptions f;
         parse_law(o, f);
         f.min_area_mm2 = o.has("min_area_mm2") ? o.positive_length("min_area_mm2") : 0.0;
         f.random_rotation = o.boolean_or("random_rotation", false);
         MotifSolidOptions solid;
         solid.height_mm = o.positive_length("height_mm");
         solid.base_z_mm = o.number_or("base_z_mm", 0);
         if (o.has("region") == o.has("wallpaper")) o.fail("", "give either \"region\" or \"wallpaper\"");
         std::vector<Placement2> placements;
         try {
           if (o.has("region")) {
             if (o.has("wrap")) o.fail("wrap", "only a periodic (wallpaper) pattern wraps around a cylinder");
             FillResult2 r = fill_region(parse_region(o), motif, f);
             in.report = {{"motifs", r.motifs.size()}, {"fill_fraction", r.fill_fraction}, {"stop_reason", r.stop_reason}};
             placements = std::move(r.motifs);
           } else {
             JsonObject w = o.object("wallpaper");
             w.allow_only({"group", "a_mm", "b_mm", "cells", "policy"});
             Group group{};
             try {
               group = group_from_name(w.string("group"));
             } catch (const InvalidInput& e) {
               w.fail("group", e.what());
             }
             Lattice lattice;
             lattice.a = vec2(w.required("a_mm"), w, "a_mm");
             lattice.b = vec2(w.required("b_mm"), w, "b_mm");
             const nlohmann::json& cells = w.required("cells");
             if (!cells.is_array() || cells.size() != 2 || !cells[0].is_number_unsigned() || !cells[1].is_number_unsigned() ||
                 cells[0].get<uint64_t>() < 1 || cells[1].get<uint64_t>() < 1 || cells[0].get<uint64_t>() > 1000 ||
                 cells[1].get<uint64_t>() > 1000)
               w.fail("cells", "expected [u, v]: how many unit cells along a and b (1 to 1000 each)");
             const int cu = int(cells[0].get<uint64_t>()), cv = int(cells[1].get<uint64_t>());
             WallpaperFill pattern;
             try {
               pattern = fill_wallpaper(group, lattice, motif, f, parse_policy(w));
             } catch (const InvalidInput& e) {
               if (std::string(e.what()).find(o.file()) == 0) throw;
               w.fail("", e.what());
             }
             placements = replicate(pattern, cu, cv);
             in.report = {{"fundamental_region_motifs", pattern.fundamental.motifs.size()},
                          {"motifs", placements.size()},
                          {"fill_fraction", pattern.fundamental.fill_fraction},
                          {"stop_reason", pattern.fundamental.stop_reason}};
             if (o.has("wrap")) {
               // The pattern's period along x, times the cells, is the circumference.
               const Lattice& l = pattern.lattice;
               if (std::abs(l.a.y) > 1e-9 * std::abs(l.a.x))
                 w.fail("a_mm", "to wrap around a cylinder the lattice vector a must lie along x ([a, 0])");
               JsonObject wrap = o.object("wrap");
               wrap.allow_only({"depth_mm"});
               solid.wrap_radius_mm = cu * std::abs(l.a.x) / (2 * kPi);
               solid.height_mm = wrap.positive_length("depth_mm");
             }
           }
         } catch (const InvalidInput& e) {
           if (std::string(e.what()).find(o.file()) == 0) throw;
           o.fail("", e.what());
         }
         if (placements.empty()) o.fail("", "no motif could be placed");
         in.geometry = motif_solids(motif, placements, solid);
       }});

  register_input_type(
      {"fill_spheres",
       {"fit_to", "box", "sphere", "motif", "random_rotation", "c", "N", "count", "min_radius_mm", "max_trials", "gap_mm",
        "boundary_gap_mm", "seed"},
       [](const JsonObject& o, RecipeInput& in) {
         auto f = std::make_shared<FillOptions3>();
         parse_law(o, *f);
         // Spheres, or convex polyhedra (unit volume, scaled by the rule).
         const std::string motif_name = o.string_or("motif", "sphere");
         std::shared_ptr<Motif3> polyhedron;
         if (motif_name == "cube") polyhedron = std::make_shared<Motif3>(cube_motif());
         else if (motif_name == "tetrahedron") polyhedron = std::make_shared<Motif3>(tetrahedron_motif());
         else if (motif_name == "octahedron") polyhedron = std::make_shared<Motif3>(octahedron_motif());
         else if (motif_name != "sphere")
           o.fail("motif", "expected \"sphere\", \"cube\", \"tetrahedron\" or \"octahedron\", got \"" + motif_name + "\"");
         const bool rotate = o.boolean_or("random_rotation", false);
         if (rotate && !polyhedron) o.fail("random_rotation", "a sphere has no orientation to randomize");
         if (o.has("min_radius_mm")) {
           const double r = o.positive_length("min_radius_mm");
           f->min_volume_mm3 = 4.0 / 3.0 * kPi * r * r * r;
         }
         const int given = int(o.has("fit_to")) + int(o.has("box")) + int(o.has("sphere"));
         if (given != 1) o.fail("", "give one region: \"fit_to\" (a closed input), \"box\" or \"sphere\"");
         const std::string where = o.file() + ": " + o.path();
         auto place = [f, where, polyhedron, rotate](RecipeInput& self, const SignedDistance3& sd, const Box3& box, double volume) {
           if (polyhedron) {
             try {
               FillResult3P r = fill_polyhedra(sd, box, volume, *polyhedron, *f, rotate);
               self.report = {{"polyhedra", r.motifs.size()}, {"fill_fraction", r.fill_fraction}, {"stop_reason", r.stop_reason}};
               ConvexCells cells;
               cells.corners_per_cell = int(polyhedron->vertices.size());
               cells.faces = polyhedron->faces;
               for (const Placement3& p : r.motifs)
                 for (const Vec3d& v : placed_vertices(*polyhedron, p)) cells.corners_mm.push_back(v);
               if (cells.corners_mm.empty()) throw InvalidInput("no polyhedron could be placed");
               self.geometry.cells.push_back(std::move(cells));
             } catch (const InvalidInput& e) {
               throw InvalidInput(where + ": " + e.what());
             }
             return;
           }
           try {
             FillResult3 r = fill_spheres(sd, box, volume, *f);
             self.report = {{"spheres", r.centers_mm.size()}, {"fill_fraction", r.fill_fraction}, {"stop_reason", r.stop_reason}};
             self.geometry.spheres.centers_mm = std::move(r.centers_mm);
             self.geometry.spheres.radii_mm = std::move(r.radii_mm);
           } catch (const InvalidInput& e) {
             throw InvalidInput(where + ": " + e.what());
           }
           if (self.geometry.spheres.centers_mm.empty()) throw InvalidInput(where + ": no sphere could be placed");
         };
         if (o.has("box")) {
           JsonObject b = o.object("box");
           b.allow_only({"min_mm", "max_mm"});
           Box3 box;
           box.expand(b.vec3("min_mm"));
           box.expand(b.vec3("max_mm"));
           const Vec3d s = box.size();
           if (!(s.x > 0 && s.y > 0 && s.z > 0)) b.fail("max_mm", "expected max_mm > min_mm on every axis");
           place(in, box_region_distance(box), box, s.x * s.y * s.z);
           return;
         }
         if (o.has("sphere")) {
           JsonObject s = o.object("sphere");
           s.allow_only({"center_mm", "radius_mm"});
           const Vec3d c = s.vec3_or("center_mm", Vec3d{});
           const double r = s.positive_length("radius_mm");
           Box3 box;
           box.expand(c - Vec3d{r, r, r});
           box.expand(c + Vec3d{r, r, r});
           place(in, sphere_region_distance(c, r), box, 4.0 / 3.0 * kPi * r * r * r);
           return;
         }
         const std::string hull = o.string("fit_to");
         in.depends_on.push_back(hull);
         in.resolve = [f, hull, place, polyhedron](RecipeInput& self, const RecipeContext& context) {
           const Box3 box = context.box_of(hull);
           const double volume = context.volume_of(hull);
           // The field must be exact as deep as the largest sphere's radius plus its wall.
           const double v0 = volume / (hurwitz_zeta(f->c, f->N) * std::pow(f->N, f->c));
           // The largest motif's reach from its centre: a sphere's radius, a polyhedron's bounding radius.
           const double r0 = polyhedron ? std::cbrt(v0) * polyhedron->bounding_radius : std::cbrt(3 * v0 / (4 * kPi));
           place(self, context.signed_distance_in(hull, r0 + f->boundary_gap_mm + f->gap_mm + 1e-3, 1e-3 + 0.01 * r0), box,
                 volume);
         };
       }});
}

}  // namespace fill
}  // namespace lacuna
