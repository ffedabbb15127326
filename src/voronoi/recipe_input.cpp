#include "voronoi/recipe_input.h"

#include <string>

#include "errors.h"
#include "recipe/recipe.h"
#include "voronoi/rules.h"

namespace lacuna {
namespace voronoi {

void register_recipe_inputs() {
  register_input_type(
      {"voronoi_spheres",
       {"dimension", "d", "points", "random", "seed", "level", "period_mm", "origin_mm", "radius_mm", "colours", "tiles"},
       [](const JsonObject& o, RecipeInput& in) {
         const uint64_t n = o.unsigned_integer_or("dimension", 3);
         if (n != 2 && n != 3) o.fail("dimension", "expected 2 or 3");
         const uint64_t d = o.unsigned_integer_or("d", 2);
         if (d < 2 || d > 64) o.fail("d", "expected a lacunarity from 2 to 64");
         if (o.has("points") == o.has("random")) o.fail("", "give either \"points\" (starting points in [0,1)^n) or \"random\" (how many)");
         std::vector<std::vector<double>> points;
         if (o.has("points")) {
           const nlohmann::json& v = o.required("points");
           if (!v.is_array() || v.empty()) o.fail("points", "expected a list of points in [0,1)^" + std::to_string(n));
           for (size_t i = 0; i < v.size(); ++i) {
             if (!v[i].is_array() || v[i].size() != n)
               o.fail("points", "point " + std::to_string(i) + ": expected " + std::to_string(n) + " coordinates");
             std::vector<double> p;
             for (const auto& x : v[i]) {
               if (!x.is_number()) o.fail("points", "point " + std::to_string(i) + ": expected numbers");
               p.push_back(x.get<double>());
             }
             points.push_back(p);
           }
         } else {
           const uint64_t m = o.unsigned_integer_or("random", 0);
           if (m < 1 || m > 1000) o.fail("random", "expected 1 to 1000 starting points");
           points = random_points(int(n), int(m), o.unsigned_integer_or("seed", 1));
         }
         const uint64_t level = o.unsigned_integer_or("level", 2);
         if (level > 12) o.fail("level", "expected a level from 0 to 12");
         const double period = o.positive_length("period_mm");
         const double radius = o.positive_length("radius_mm");
         const Vec3d origin = o.vec3_or("origin_mm", Vec3d{});
         std::vector<int> tiles(n, 1);
         if (o.has("tiles")) {
           const nlohmann::json& t = o.required("tiles");
           if (!t.is_array() || t.size() != n) o.fail("tiles", "expected " + std::to_string(n) + " counts of periods");
           for (size_t k = 0; k < n; ++k) {
             if (!t[k].is_number_unsigned() || t[k].get<uint64_t>() < 1 || t[k].get<uint64_t>() > 100)
               o.fail("tiles", "expected counts from 1 to 100");
             tiles[k] = int(t[k].get<uint64_t>());
           }
         }
         Level points_k;
         try {
           RulesOptions options;
           options.children = RulesOptions::Children::kScaled;
           points_k = generate_level(make_rules(int(n), int(d), points, options), int(level));
         } catch (const InvalidInput& e) {
           o.fail("", e.what());
         } catch (const ResourceLimit& e) {
           throw ResourceLimit(o.file() + ": " + o.path() + ": " + e.what());
         }
         std::vector<char> keep(points.size(), 1);
         if (o.has("colours")) {
           std::fill(keep.begin(), keep.end(), 0);
           const nlohmann::json& c = o.required("colours");
           if (!c.is_array() || c.empty()) o.fail("colours", "expected a list of colours (1-based starting point indices)");
           for (const auto& k : c) {
             if (!k.is_number_unsigned() || k.get<uint64_t>() < 1 || k.get<uint64_t>() > points.size())
               o.fail("colours", "expected colours from 1 to " + std::to_string(points.size()));
             keep[k.get<uint64_t>() - 1] = 1;
           }
         }
         const size_t total = points_k.points.size() * size_t(tiles[0]) * size_t(tiles[1]) * size_t(n == 3 ? tiles[2] : 1);
         if (total > 20'000'000) throw ResourceLimit(o.file() + ": " + o.path() + ": more than 20 000 000 spheres");
         SphereSet& s = in.geometry.spheres;
         s.radii_mm = {radius};
         for (int tz = 0; tz < (n == 3 ? tiles[2] : 1); ++tz)
           for (int ty = 0; ty < tiles[1]; ++ty)
             for (int tx = 0; tx < tiles[0]; ++tx)
               for (size_t i = 0; i < points_k.points.size(); ++i) {
                 if (!keep[size_t(points_k.colours[i])]) continue;
                 const auto& p = points_k.points[i];
                 s.centers_mm.push_back(origin + Vec3d{(tx + p[0]) * period, (ty + p[1]) * period, n == 3 ? (tz + p[2]) * period : 0.0});
               }
         in.report = {{"points", points_k.points.size()}, {"spheres", s.centers_mm.size()}};
       }});
}

}  // namespace voronoi
}  // namespace lacuna
