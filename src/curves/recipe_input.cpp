#include "curves/recipe_input.h"

#include <filesystem>
#include <memory>
#include <string>

#include "curves/sweep.h"
#include "errors.h"
#include "recipe/recipe.h"

namespace lacuna {
namespace curves {
namespace {

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

BSplinePatch parse_patch(const JsonObject& p) {
  p.allow_only({"degree_u", "degree_v", "count_u", "count_v", "control_points_mm"});
  BSplinePatch patch;
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

}  // namespace

void register_recipe_inputs() {
  register_input_type(
      {"curve",
       {"kind", "orders", "radius_mm", "surface", "patch", "mesh", "scale_mm", "center_mm", "offset_mm", "tolerance_mm",
        "base_mm"},
       [](const JsonObject& o, RecipeInput& in) {
         SweepOptions options;
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
         const std::string where = o.file() + ": " + o.path();
         auto build = [options, where](RecipeInput& self, const SurfaceMap& map, bool on_cube) {
           try {
             Sweep sweep = sweep_curves(options, map, on_cube);
             self.report = {{"tubes", sweep.tubes.tubes.size()}, {"segments", sweep.segments}};
             self.geometry.tubes = std::move(sweep.tubes);
             self.geometry.surfaces = std::move(sweep.base);
           } catch (const InvalidInput& e) {
             throw InvalidInput(where + ": " + e.what());
           } catch (const ResourceLimit& e) {
             throw ResourceLimit(where + ": " + e.what());
           }
         };
         SurfaceMap map;
         bool on_cube = false;
         if (surface == "plane") map = plane_map();
         else if (surface == "sphere") map = sphere_map();
         else if (surface == "cylinder") map = cylinder_map();
         else if (surface == "torus") map = torus_map();
         else if (surface == "cone") map = cone_map();
         else if (surface == "cube") on_cube = true;
         else if (surface == "bspline") map = bspline_map(parse_patch(o.object("patch")));
         else if (!mesh) o.fail("surface", "expected \"plane\", \"sphere\", \"cylinder\", \"torus\", \"cone\", \"cube\", \"bspline\" or \"mesh\", got \"" + surface + "\"");
         if (!mesh) {
           build(in, map, on_cube);
           return;
         }
         // A disk-like patch of a mesh, flattened onto the square when the recipe is resolved.
         std::string file = o.string("mesh");
         if (file.empty()) o.fail("mesh", "expected a file name");
         const std::string path = (std::filesystem::path(o.file()).parent_path() / file).string();
         in.resolve = [build, path, where](RecipeInput& self, const RecipeContext& context) {
           build(self, context.surface_of_mesh(path, where), false);
         };
       }});
}

}  // namespace curves
}  // namespace lacuna
