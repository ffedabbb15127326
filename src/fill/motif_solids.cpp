#include "fill/motif_solids.h"

#include <cmath>
#include <map>
#include <string>

#include "errors.h"

namespace lacuna {
namespace fill {
namespace {

constexpr double kPi = 3.14159265358979323846;

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

}  // namespace fill
}  // namespace lacuna
