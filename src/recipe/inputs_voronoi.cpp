// The fractal Voronoi inputs: `voronoi_spheres` (spheres on the generators of a level: clusters,
// granular structures), `voronoi_tiles` (each colour's compact tile, with a clearance) and `voronoi_foam`
// (the walls between colours, thickened).
#include <string>
#include <vector>

#include "recipe/input_parsers.h"

namespace lacuna {
namespace {

VoronoiPartition parse_partition(const JsonObject& o) {
  VoronoiPartition part;
  const uint64_t n = o.unsigned_integer_or("dimension", 3);
  if (n != 2 && n != 3) o.fail("dimension", "expected 2 or 3");
  part.dimension = int(n);
  const uint64_t d = o.unsigned_integer_or("d", 2);
  if (d < 2 || d > 64) o.fail("d", "expected a lacunarity from 2 to 64");
  part.d = int(d);
  if (o.has("points") == o.has("random"))
    o.fail("", "give either \"points\" (starting points in [0,1)^n) or \"random\" (how many)");
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
      part.points.push_back(p);
    }
  } else {
    const uint64_t m = o.unsigned_integer_or("random", 0);
    if (m < 1 || m > 1000) o.fail("random", "expected 1 to 1000 starting points");
    part.random_points = int(m);
    part.seed = o.unsigned_integer_or("seed", 1);
  }
  const uint64_t level = o.unsigned_integer_or("level", 2);
  if (level > 12) o.fail("level", "expected a level from 0 to 12");
  part.level = int(level);
  part.period_mm = o.positive_length("period_mm");
  part.origin_mm = o.vec3_or("origin_mm", Vec3d{});
  return part;
}

// 1-based colours from "colours" (empty when absent: all of them), each at most m.
std::vector<int> parse_colours(const JsonObject& o, size_t m) {
  std::vector<int> colours;
  if (!o.has("colours")) return colours;
  const nlohmann::json& c = o.required("colours");
  if (!c.is_array() || c.empty()) o.fail("colours", "expected a list of colours (1-based starting point indices)");
  for (const auto& k : c) {
    if (!k.is_number_unsigned() || k.get<uint64_t>() < 1 || k.get<uint64_t>() > m)
      o.fail("colours", "expected colours from 1 to " + std::to_string(m));
    colours.push_back(int(k.get<uint64_t>()));
  }
  return colours;
}

// "refine": {field keys, "levels"} (voronoi_tiles, voronoi_foam).
void parse_refine(const JsonObject& o, GradeField& field, int& levels) {
  if (!o.has("refine")) return;
  const JsonObject r = o.object("refine");
  r.allow_only({"field", "axis", "from_mm", "to_mm", "points_mm", "falloff_mm", "depth_mm", "levels"});
  if (r.string("field") == "depth") r.fail("field", "a partition has no hull to measure depth in: use \"ramp\" or \"points\"");
  field = parse_grade_field(r, "");
  const uint64_t n = r.unsigned_integer_or("levels", 1);
  if (n < 1 || n > 6) r.fail("levels", "expected 1 to 6 refinement levels");
  levels = int(n);
}

std::array<int, 3> parse_tiles(const JsonObject& o, int n) {
  std::array<int, 3> tiles{1, 1, 1};
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

}  // namespace

VoronoiSpheresInput parse_voronoi_spheres_input(const JsonObject& o) {
  VoronoiSpheresInput in;
  in.partition = parse_partition(o);
  in.radius_mm = o.positive_length("radius_mm");
  in.tiles = parse_tiles(o, in.partition.dimension);
  in.colours = parse_colours(o, in.partition.colour_count());
  return in;
}

VoronoiTilesInput parse_voronoi_tiles_input(const JsonObject& o) {
  VoronoiTilesInput in;
  in.partition = parse_partition(o);
  in.colours = parse_colours(o, in.partition.colour_count());
  in.clearance_mm = o.has("clearance_mm") ? o.number("clearance_mm") : 0.0;
  if (!(in.clearance_mm >= 0 && in.clearance_mm < in.partition.period_mm / 4))
    o.fail("clearance_mm", "expected a gap from 0 to a quarter of period_mm");
  if (in.partition.dimension == 2) in.thickness_mm = o.positive_length("thickness_mm");
  else if (o.has("thickness_mm")) o.fail("thickness_mm", "only 2D partitions are extruded into plates");
  parse_refine(o, in.refine, in.refine_levels);
  return in;
}

VoronoiFoamInput parse_voronoi_foam_input(const JsonObject& o) {
  VoronoiFoamInput in;
  in.partition = parse_partition(o);
  in.wall_mm = o.positive_length("wall_mm");
  if (in.wall_mm >= in.partition.period_mm / 4) o.fail("wall_mm", "expected a wall thinner than a quarter of period_mm");
  if (in.partition.dimension == 2) in.thickness_mm = o.positive_length("thickness_mm");
  else if (o.has("thickness_mm")) o.fail("thickness_mm", "only 2D foams are extruded into plates");
  if (o.has("tiles") && o.has("cover")) o.fail("cover", "give \"tiles\" or \"cover\", not both");
  if (o.has("cover")) in.cover = o.string("cover");
  else in.tiles = parse_tiles(o, in.partition.dimension);
  parse_refine(o, in.refine, in.refine_levels);
  return in;
}

}  // namespace lacuna
