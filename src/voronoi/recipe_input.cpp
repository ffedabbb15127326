#include "voronoi/recipe_input.h"

#include <array>
#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "errors.h"
#include "recipe/recipe.h"
#include "voronoi/rules.h"
#include "voronoi/walls.h"

namespace lacuna {
namespace voronoi {

namespace {

const std::vector<std::string> kPartitionKeys = {"dimension", "d", "points", "random", "seed", "level", "period_mm",
                                                 "origin_mm"};

std::vector<std::string> keys_with(std::initializer_list<const char*> more) {
  std::vector<std::string> keys = kPartitionKeys;
  keys.insert(keys.end(), more.begin(), more.end());
  return keys;
}

// The partition every Voronoi input starts from: rules with scaled children and one generated level.
struct Partition {
  int n = 3;
  Rules rules;
  Level level;
  double period_mm = 1;
  Vec3d origin_mm;

  Vec3d to_mm(double x, double y, double z) const {
    return origin_mm + Vec3d{x * period_mm, y * period_mm, n == 3 ? z * period_mm : 0.0};
  }
};

Partition parse_partition(const JsonObject& o, bool keep_unwrapped) {
  Partition part;
  const uint64_t n = o.unsigned_integer_or("dimension", 3);
  if (n != 2 && n != 3) o.fail("dimension", "expected 2 or 3");
  part.n = int(n);
  const uint64_t d = o.unsigned_integer_or("d", 2);
  if (d < 2 || d > 64) o.fail("d", "expected a lacunarity from 2 to 64");
  if (o.has("points") == o.has("random"))
    o.fail("", "give either \"points\" (starting points in [0,1)^n) or \"random\" (how many)");
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
  part.period_mm = o.positive_length("period_mm");
  part.origin_mm = o.vec3_or("origin_mm", Vec3d{});
  try {
    RulesOptions options;
    options.children = RulesOptions::Children::kScaled;
    part.rules = make_rules(int(n), int(d), points, options);
    part.level = generate_level(part.rules, int(level), keep_unwrapped);
  } catch (const InvalidInput& e) {
    o.fail("", e.what());
  } catch (const ResourceLimit& e) {
    throw ResourceLimit(o.file() + ": " + o.path() + ": " + e.what());
  }
  return part;
}

// 1-based colours from "colours" (all when absent), as a keep-flag per colour.
std::vector<char> parse_colours(const JsonObject& o, size_t m) {
  std::vector<char> keep(m, 1);
  if (!o.has("colours")) return keep;
  std::fill(keep.begin(), keep.end(), 0);
  const nlohmann::json& c = o.required("colours");
  if (!c.is_array() || c.empty()) o.fail("colours", "expected a list of colours (1-based starting point indices)");
  for (const auto& k : c) {
    if (!k.is_number_unsigned() || k.get<uint64_t>() < 1 || k.get<uint64_t>() > m)
      o.fail("colours", "expected colours from 1 to " + std::to_string(m));
    keep[k.get<uint64_t>() - 1] = 1;
  }
  return keep;
}

std::vector<int> parse_tiles(const JsonObject& o, int n) {
  std::vector<int> tiles(3, 1);
  if (!o.has("tiles")) return tiles;
  const nlohmann::json& t = o.required("tiles");
  if (!t.is_array() || t.size() != size_t(n)) o.fail("tiles", "expected " + std::to_string(n) + " counts of periods");
  for (size_t k = 0; k < size_t(n); ++k) {
    if (!t[k].is_number_unsigned() || t[k].get<uint64_t>() < 1 || t[k].get<uint64_t>() > 100)
      o.fail("tiles", "expected counts from 1 to 100");
    tiles[k] = int(t[k].get<uint64_t>());
  }
  return tiles;
}

// A 2D polygon (torus units) as a prism [0, height] in mm; a 3D piece as is.
void add_piece(const Partition& part, const std::vector<std::vector<Point3>>& faces, double height_mm,
               GeometrySet& geometry) {
  ConvexCells cell;
  if (part.n == 2) {
    const auto& loop = faces[0];
    const size_t k = loop.size();
    cell.corners_per_cell = int(2 * k);
    for (const Point3& p : loop) cell.corners_mm.push_back(part.to_mm(p[0], p[1], 0));
    for (const Point3& p : loop) cell.corners_mm.push_back(part.to_mm(p[0], p[1], 0) + Vec3d{0, 0, height_mm});
    std::vector<int> bottom, top;
    for (size_t i = 0; i < k; ++i) {
      bottom.push_back(int(i));
      top.push_back(int(k + i));
      cell.faces.push_back({int(i), int((i + 1) % k), int(k + (i + 1) % k), int(k + i)});
    }
    cell.faces.push_back(bottom);
    cell.faces.push_back(top);
  } else {
    int corners = 0;
    for (const auto& face : faces) {
      std::vector<int> loop;
      for (const Point3& p : face) {
        cell.corners_mm.push_back(part.to_mm(p[0], p[1], p[2]));
        loop.push_back(corners++);
      }
      cell.faces.push_back(std::move(loop));
    }
    cell.corners_per_cell = corners;
  }
  geometry.cells.push_back(std::move(cell));
}

nlohmann::json walls_report(const Partition& part, const Walls& walls) {
  const double unit = part.n == 2 ? part.period_mm : part.period_mm * part.period_mm;
  return {{"points", walls.points},
          {"boundary_generators", walls.boundary_generators},
          {"wall_facets", walls.facets.size()},
          {part.n == 2 ? "wall_length_mm" : "wall_area_mm2", walls.measure * unit}};
}

// The foam: every wall of the periodic network, thickened, in the periods [lo, hi) of each axis (torus units).
void add_foam(const Partition& part, const Walls& walls, const std::array<int, 3>& lo, const std::array<int, 3>& hi,
              double wall_mm, double height_mm, GeometrySet& geometry) {
  if (part.n == 3) {
    ThickSurface surface;
    surface.thickness_mm = wall_mm;
    surface.surface = wall_triangles(walls, part.period_mm, part.origin_mm, lo, hi);
    if (!surface.surface.triangles.empty()) geometry.surfaces.push_back(std::move(surface));
    return;
  }
  // A 2D wall segment as a convex prism of the wall's width reaching half a width past each end, so that
  // it covers the disk of the wall's width around both ends (where walls meet).
  const double half = wall_mm / 2 / part.period_mm;  // torus units
  for (int ty = lo[1]; ty < hi[1]; ++ty)
    for (int tx = lo[0]; tx < hi[0]; ++tx)
      for (const auto& facet : walls.facets) {
        const Point3 &a = facet[0], &b = facet[1];
        const double dx = b[0] - a[0], dy = b[1] - a[1], length = std::hypot(dx, dy);
        const double ux = dx / length * half, uy = dy / length * half;  // along the wall, half a width
        const double x0 = a[0] + tx - ux, y0 = a[1] + ty - uy, x1 = b[0] + tx + ux, y1 = b[1] + ty + uy;
        add_piece(part, {{{x0 + uy, y0 - ux, 0}, {x1 + uy, y1 - ux, 0}, {x1 - uy, y1 + ux, 0}, {x0 - uy, y0 + ux, 0}}},
                  height_mm, geometry);
      }
}

}  // namespace

void register_recipe_inputs() {
  register_input_type(
      {"voronoi_spheres", keys_with({"radius_mm", "colours", "tiles"}),
       [](const JsonObject& o, RecipeInput& in) {
         const Partition part = parse_partition(o, false);
         const int n = part.n;
         const double radius = o.positive_length("radius_mm");
         const std::vector<int> tiles = parse_tiles(o, n);
         const std::vector<char> keep = parse_colours(o, part.rules.points.size());
         const Level& points_k = part.level;
         const size_t total = points_k.points.size() * size_t(tiles[0]) * size_t(tiles[1]) * size_t(tiles[2]);
         if (total > 20'000'000) throw ResourceLimit(o.file() + ": " + o.path() + ": more than 20 000 000 spheres");
         SphereSet& s = in.geometry.spheres;
         s.radii_mm = {radius};
         for (int tz = 0; tz < tiles[2]; ++tz)
           for (int ty = 0; ty < tiles[1]; ++ty)
             for (int tx = 0; tx < tiles[0]; ++tx)
               for (size_t i = 0; i < points_k.points.size(); ++i) {
                 if (!keep[size_t(points_k.colours[i])]) continue;
                 const auto& p = points_k.points[i];
                 s.centers_mm.push_back(part.to_mm(tx + p[0], ty + p[1], n == 3 ? tz + p[2] : 0.0));
               }
         in.report = {{"points", points_k.points.size()}, {"spheres", s.centers_mm.size()}};
       }});

  // Compact tiles: each kept colour's fractal cell around its starting point, with a clearance to the others.
  register_input_type(
      {"voronoi_tiles", keys_with({"colours", "clearance_mm", "thickness_mm"}),
       [](const JsonObject& o, RecipeInput& in) {
         const Partition part = parse_partition(o, true);
         const std::vector<char> keep = parse_colours(o, part.rules.points.size());
         const double clearance = o.has("clearance_mm") ? o.number("clearance_mm") : 0.0;
         if (!(clearance >= 0 && clearance < part.period_mm / 4))
           o.fail("clearance_mm", "expected a gap from 0 to a quarter of period_mm");
         double height = 0;
         if (part.n == 2) height = o.positive_length("thickness_mm");
         else if (o.has("thickness_mm")) o.fail("thickness_mm", "only 2D partitions are extruded into plates");
         size_t pieces = 0;
         for (int colour = 0; colour < int(keep.size()); ++colour) {
           if (!keep[size_t(colour)]) continue;
           for (const ConvexPiece& piece : tile_pieces(part.rules, part.level, colour, clearance / 2 / part.period_mm)) {
             add_piece(part, piece.faces, height, in.geometry);
             ++pieces;
           }
         }
         in.report = walls_report(part, extract_walls(part.rules, part.level));
         in.report["pieces"] = pieces;
         in.report["clearance_mm"] = clearance;
       }});

  // Foam: the walls between colours thickened, repeated over whole periods (clip it with an intersection).
  register_input_type(
      {"voronoi_foam", keys_with({"wall_mm", "tiles", "cover", "thickness_mm"}),
       [](const JsonObject& o, RecipeInput& in) {
         const Partition part = parse_partition(o, false);
         const double wall = o.positive_length("wall_mm");
         if (wall >= part.period_mm / 4) o.fail("wall_mm", "expected a wall thinner than a quarter of period_mm");
         double height = 0;
         if (part.n == 2) height = o.positive_length("thickness_mm");
         else if (o.has("thickness_mm")) o.fail("thickness_mm", "only 2D foams are extruded into plates");
         if (o.has("tiles") && o.has("cover")) o.fail("cover", "give \"tiles\" or \"cover\", not both");
         auto walls = std::make_shared<Walls>(extract_walls(part.rules, part.level));
         in.report = walls_report(part, *walls);
         auto partition = std::make_shared<Partition>(part);
         partition->level = Level();  // the walls are all that is needed from here on
         if (!o.has("cover")) {
           const std::vector<int> tiles = parse_tiles(o, part.n);
           add_foam(*partition, *walls, {0, 0, 0}, {tiles[0], tiles[1], tiles[2]}, wall, height, in.geometry);
           return;
         }
         // Every period that meets the covered input's box (walls reach a little past their own period).
         const std::string cover = o.string("cover");
         const std::string where = o.file() + ": " + o.path_of("cover");
         in.depends_on.push_back(cover);
         in.resolve = [partition, walls, cover, wall, height, where](RecipeInput& self, const RecipeContext& context) {
           const Box3 box = context.box_of(cover);
           const Vec3d lo = (box.min - partition->origin_mm) / partition->period_mm;
           const Vec3d hi = (box.max - partition->origin_mm) / partition->period_mm;
           std::array<int, 3> a{int(std::floor(lo.x)) - 1, int(std::floor(lo.y)) - 1, int(std::floor(lo.z)) - 1};
           std::array<int, 3> b{int(std::ceil(hi.x)) + 1, int(std::ceil(hi.y)) + 1, int(std::ceil(hi.z)) + 1};
           if (partition->n == 2) {
             a[2] = 0;
             b[2] = 1;
           }
           const double periods = double(b[0] - a[0]) * (b[1] - a[1]) * (b[2] - a[2]);
           if (periods * double(walls->facets.size()) > 5e7)
             throw ResourceLimit(where + ": covering it takes " + std::to_string(int64_t(periods)) + " periods of " +
                                 std::to_string(walls->facets.size()) + " walls; use a larger period_mm");
           add_foam(*partition, *walls, a, b, wall, height, self.geometry);
         };
       }});
}

}  // namespace voronoi
}  // namespace lacuna
