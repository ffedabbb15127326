#include "solids/printability.h"

#include <cmath>

#include "errors.h"
#include "solids/components.h"
#include "solids/extract.h"
#include "solids/rasterize.h"

namespace lacuna {
namespace {

constexpr double kPi = 3.14159265358979323846;

// Regions of `residue` that are real features rather than the slivers an opening or closing of
// radius r trims off edges: volume over surface at least r / 4 (a slab of thickness t has t / 2; a
// 90-degree edge sliver 0.06 r), and at least a voxel of volume.
std::vector<PrintFeature> features(const Volume& residue, double r, TriMesh* kept = nullptr) {
  std::vector<PrintFeature> out;
  if (residue.empty()) return out;
  const double h = residue.voxel_size_mm();
  TriMesh surface = extract_surface(residue);
  for (const MeshComponent& c : mesh_components(surface)) {
    if (c.signed_volume_mm3 <= h * h * h) continue;
    if (c.signed_volume_mm3 / c.area_mm2 < 0.25 * r) continue;
    out.push_back(PrintFeature{c.signed_volume_mm3, c.centroid_mm, c.box});
    if (!kept) continue;
    std::vector<int64_t> index(surface.positions_mm.size(), -1);
    for (uint32_t f : c.triangles) {
      std::array<uint32_t, 3> t{};
      for (int k = 0; k < 3; ++k) {
        uint32_t v = surface.triangles[f][size_t(k)];
        if (index[v] < 0) {
          index[v] = int64_t(kept->positions_mm.size());
          kept->positions_mm.push_back(surface.positions_mm[v]);
        }
        t[size_t(k)] = uint32_t(index[v]);
      }
      kept->triangles.push_back(t);
    }
  }
  return out;
}

void check_options(const PrintabilityOptions& o) {
  if (o.min_wall_mm < 0 || o.min_hole_mm < 0 || !std::isfinite(o.min_wall_mm) || !std::isfinite(o.min_hole_mm))
    throw InvalidInput("minimum wall and hole sizes must be lengths in mm (0 to skip)");
  if (!(norm(o.build_direction) > 0)) throw InvalidInput("the build direction must be a non-zero vector");
  if (!(o.critical_angle_deg >= 0 && o.critical_angle_deg <= 90)) throw InvalidInput("the critical angle must be 0 to 90 degrees");
}

}  // namespace

PrintabilityReport analyze_printability(const Volume& part, const PrintabilityOptions& options) {
  check_options(options);
  PrintabilityReport report;
  if (part.empty()) return report;
  const double h = part.voxel_size_mm();
  if (options.min_wall_mm > 0) {
    const double r = 0.5 * options.min_wall_mm;
    // Eroding by half the smallest side of the part's box or more leaves nothing: the whole part is
    // thinner than the wall asked for (and offsetting by such a distance would only cost memory).
    const Vec3d size = part.bounding_box().size();
    const double half_side = 0.5 * std::min({size.x, size.y, size.z});
    const bool all_thin = r >= half_side;
    Volume opened = all_thin ? Volume() : offset(offset(part, -r), r);
    report.thin_walls = features(subtract(part, opened), std::min(r, half_side), &report.thin_wall_surface);
  }
  if (options.min_hole_mm > 0) {
    const double r = 0.5 * options.min_hole_mm;
    Volume closed = offset(offset(part, r), -r);
    report.small_holes = features(subtract(closed, part), r);
  }
  TriMesh surface = extract_surface(part);
  for (const MeshComponent& c : mesh_components(surface))
    if (c.signed_volume_mm3 < 0) report.trapped_voids.push_back(PrintFeature{-c.signed_volume_mm3, c.centroid_mm, c.box});
  // Overhang: down-facing triangles flatter than the critical angle, except those resting on the
  // build plate (within a voxel of the lowest point).
  const Vec3d up = options.build_direction / norm(options.build_direction);
  double lowest = HUGE_VAL;
  for (const Vec3d& p : surface.positions_mm) lowest = std::min(lowest, dot(p, up));
  const double critical = std::cos(options.critical_angle_deg * kPi / 180.0);
  for (const auto& t : surface.triangles) {
    const Vec3d &a = surface.positions_mm[t[0]], &b = surface.positions_mm[t[1]], &c = surface.positions_mm[t[2]];
    Vec3d n = cross(b - a, c - a);
    double twice = norm(n);
    if (!(twice > 0)) continue;
    double down = -dot(n, up) / twice;  // cosine of the angle between the normal and straight down
    if (down <= 0) continue;
    report.down_facing_area_mm2 += 0.5 * twice;
    bool on_plate = std::max({dot(a, up), dot(b, up), dot(c, up)}) <= lowest + h;
    if (down > critical && !on_plate) report.overhang_area_mm2 += 0.5 * twice;
  }
  return report;
}

Volume thicken_thin_walls(const Volume& part, const PrintabilityReport& report, double min_wall_mm) {
  if (report.thin_wall_surface.triangles.empty()) return part;
  Volume regions = mesh_to_volume(report.thin_wall_surface, part.options());
  return unite(part, offset(regions, 0.5 * min_wall_mm));
}

Volume drill_drain_holes(const Volume& part, const std::vector<PrintFeature>& voids, double diameter_mm,
                         const PrintabilityOptions& options, bool downwards) {
  if (!(diameter_mm > 0) || !std::isfinite(diameter_mm)) throw InvalidInput("the drain hole diameter must be positive (mm)");
  if (voids.empty()) return part;
  const double h = part.voxel_size_mm(), radius = 0.5 * diameter_mm;
  TriMesh surface = extract_surface(part);
  std::vector<Vec3d> outer;  // vertices of the outward shells
  for (const MeshComponent& c : mesh_components(surface))
    if (c.signed_volume_mm3 > 0)
      for (uint32_t f : c.triangles)
        for (uint32_t v : surface.triangles[f]) outer.push_back(surface.positions_mm[v]);
  const Box3 box = part.bounding_box();
  const Vec3d up = options.build_direction / norm(options.build_direction);
  GeometrySet channels;
  for (const PrintFeature& v : voids) {
    Vec3d start = v.location_mm, end;
    if (downwards) {
      // Far enough down to leave the part's box whatever its shape.
      end = start - up * (norm(box.size()) + radius + 2 * h);
    } else {
      double best = HUGE_VAL;
      Vec3d nearest = start;
      for (const Vec3d& p : outer) {
        double d = norm(p - start);
        if (d < best) {
          best = d;
          nearest = p;
        }
      }
      Vec3d direction = nearest - start;
      end = nearest + direction / std::max(norm(direction), 1e-12) * (radius + 2 * h);
    }
    channels.tubes.tubes.push_back(Tube{{start, end}, {radius}});
  }
  return subtract(part, rasterize_primitives(channels, part.options()));
}

}  // namespace lacuna
