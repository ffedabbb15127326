#include "solids/voxelize.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "errors.h"
#include "solids/rasterize.h"
#include "solids/region.h"

namespace lacuna {
namespace {
constexpr double kPi = 3.14159265358979323846;
}  // namespace

double surface_area_bound_mm2(const GeometrySet& set) {
  double area = 0;
  for (const Tube& tube : set.tubes.tubes) {
    auto radius = [&](size_t i) { return tube.radii_mm.size() == 1 ? tube.radii_mm[0] : tube.radii_mm[i]; };
    size_t n = tube.points_mm.size();
    if (n == 0) continue;
    area += 2 * kPi * (radius(0) * radius(0) + radius(n - 1) * radius(n - 1));
    for (size_t i = 0; i + 1 < n; ++i) {
      double l = norm(tube.points_mm[i + 1] - tube.points_mm[i]);
      double dr = radius(i) - radius(i + 1);
      area += kPi * (radius(i) + radius(i + 1)) * std::sqrt(l * l + dr * dr);
    }
  }
  for (size_t i = 0; i < set.spheres.centers_mm.size(); ++i) {
    double r = set.spheres.radii_mm.size() == 1 ? set.spheres.radii_mm[0] : set.spheres.radii_mm[i];
    area += 4 * kPi * r * r;
  }
  for (const Shape& s : set.shapes) {
    switch (s.kind) {
      case Shape::Kind::kBox: {
        Vec3d e = s.half_size_mm * 2.0;
        area += 2 * (e.x * e.y + e.y * e.z + e.z * e.x);
        break;
      }
      case Shape::Kind::kCylinder:
        area += 2 * kPi * s.radius_mm * (s.radius_mm + s.height_mm);
        break;
      case Shape::Kind::kTorus:
        area += 4 * kPi * kPi * s.radius_mm * s.minor_radius_mm;
        break;
    }
  }
  for (const ThickSurface& s : set.surfaces) area += 2 * surface_area(s.surface);
  for (const TriMesh& m : set.solids) area += surface_area(m);
  for (const ConvexCells& cells : set.cells) {
    const size_t m = size_t(cells.corners_per_cell);
    for (size_t c = 0; c < cells.size(); ++c) {
      const Vec3d* v = cells.corners_mm.data() + c * m;
      for (const auto& face : cells.faces) {
        Vec3d n{0, 0, 0};
        for (size_t i = 0; i < face.size(); ++i) n += cross(v[face[i]], v[face[(i + 1) % face.size()]]);
        area += 0.5 * norm(n);
      }
    }
  }
  for (const GeometryStream& stream : set.streams)
    stream.emit([&](const GeometrySet& batch) { area += surface_area_bound_mm2(batch); });
  for (const Region2& r : set.regions) {
    double perimeter = 0;
    for (const auto& loop : r.loops_mm)
      for (size_t i = 0; i < loop.size(); ++i) {
        Vec2d d = loop[(i + 1) % loop.size()] - loop[i];
        perimeter += std::hypot(d.x, d.y);
      }
    area += 2 * region_area_mm2(r) + perimeter * r.height_mm;
  }
  return area;
}

Box3 bounding_box(const GeometrySet& set) {
  Box3 box;
  auto ball = [&box](const Vec3d& c, double r) {
    box.expand(c - Vec3d{r, r, r});
    box.expand(c + Vec3d{r, r, r});
  };
  for (const Tube& tube : set.tubes.tubes)
    for (size_t i = 0; i < tube.points_mm.size(); ++i)
      ball(tube.points_mm[i], tube.radii_mm.size() == 1 ? tube.radii_mm[0] : tube.radii_mm[i]);
  for (size_t i = 0; i < set.spheres.centers_mm.size(); ++i)
    ball(set.spheres.centers_mm[i], set.spheres.radii_mm.size() == 1 ? set.spheres.radii_mm[0] : set.spheres.radii_mm[i]);
  for (const Shape& s : set.shapes) {
    switch (s.kind) {
      case Shape::Kind::kBox:
        box.expand(s.center_mm - s.half_size_mm);
        box.expand(s.center_mm + s.half_size_mm);
        break;
      case Shape::Kind::kCylinder:
        ball(s.center_mm, std::hypot(s.radius_mm, 0.5 * s.height_mm));
        break;
      case Shape::Kind::kTorus:
        ball(s.center_mm, s.radius_mm + s.minor_radius_mm);
        break;
    }
  }
  for (const ThickSurface& ts : set.surfaces)
    for (const Vec3d& p : ts.surface.positions_mm) ball(p, 0.5 * ts.thickness_mm);
  for (const TriMesh& m : set.solids) box.expand(lacuna::bounding_box(m));
  for (const ConvexCells& cells : set.cells)
    for (const Vec3d& p : cells.corners_mm) box.expand(p);
  for (const GeometryStream& stream : set.streams)
    stream.emit([&](const GeometrySet& batch) { box.expand(bounding_box(batch)); });
  for (const Region2& r : set.regions) {
    Vec3d n = cross(r.axis_u, r.axis_v);
    for (const auto& loop : r.loops_mm)
      for (const Vec2d& p : loop) {
        Vec3d q = r.origin_mm + r.axis_u * p.x + r.axis_v * p.y;
        box.expand(q);
        box.expand(q + n * r.height_mm);
      }
  }
  return box;
}

void validate(const GeometrySet& set) {
  auto fail = [](const std::string& what) { throw InvalidInput(what); };
  auto positive = [](double v) { return std::isfinite(v) && v > 0; };
  for (size_t t = 0; t < set.tubes.tubes.size(); ++t) {
    const Tube& tube = set.tubes.tubes[t];
    std::string where = "tube " + std::to_string(t);
    if (tube.points_mm.empty()) fail(where + ": has no points");
    if (tube.radii_mm.size() != 1 && tube.radii_mm.size() != tube.points_mm.size())
      fail(where + ": expected 1 radius or one per point (" + std::to_string(tube.points_mm.size()) +
           "), got " + std::to_string(tube.radii_mm.size()));
    for (size_t i = 0; i < tube.points_mm.size(); ++i)
      if (!is_finite(tube.points_mm[i])) fail(where + ", point " + std::to_string(i) + ": not a finite coordinate");
    for (size_t i = 0; i < tube.radii_mm.size(); ++i)
      if (!positive(tube.radii_mm[i])) fail(where + ", radius " + std::to_string(i) + ": expected a positive length in mm");
  }
  const SphereSet& s = set.spheres;
  if (!s.centers_mm.empty() && s.radii_mm.size() != 1 && s.radii_mm.size() != s.centers_mm.size())
    fail("spheres: expected 1 radius or one per centre");
  for (size_t i = 0; i < s.centers_mm.size(); ++i)
    if (!is_finite(s.centers_mm[i])) fail("sphere " + std::to_string(i) + ": centre is not finite");
  for (double r : s.radii_mm)
    if (!positive(r)) fail("spheres: expected positive radii in mm");
  for (size_t i = 0; i < set.shapes.size(); ++i) {
    const Shape& sh = set.shapes[i];
    std::string where = "shape " + std::to_string(i);
    if (!is_finite(sh.center_mm)) fail(where + ": centre is not finite");
    switch (sh.kind) {
      case Shape::Kind::kBox:
        if (!positive(sh.half_size_mm.x) || !positive(sh.half_size_mm.y) || !positive(sh.half_size_mm.z))
          fail(where + ": box sizes must be positive");
        break;
      case Shape::Kind::kCylinder:
        if (!positive(sh.radius_mm) || !positive(sh.height_mm)) fail(where + ": cylinder radius and height must be positive");
        if (!is_finite(sh.axis) || norm(sh.axis) == 0) fail(where + ": axis must be a non-zero vector");
        break;
      case Shape::Kind::kTorus:
        if (!positive(sh.radius_mm) || !positive(sh.minor_radius_mm)) fail(where + ": torus radii must be positive");
        if (sh.minor_radius_mm >= sh.radius_mm) fail(where + ": torus minor radius must be smaller than the major radius");
        if (!is_finite(sh.axis) || norm(sh.axis) == 0) fail(where + ": axis must be a non-zero vector");
        break;
    }
  }
  for (size_t i = 0; i < set.surfaces.size(); ++i) {
    const ThickSurface& ts = set.surfaces[i];
    if (!positive(ts.thickness_mm)) fail("surface " + std::to_string(i) + ": thickness must be positive");
    for (const Vec3d& p : ts.surface.positions_mm)
      if (!is_finite(p)) fail("surface " + std::to_string(i) + ": has a non-finite vertex");
    for (const auto& t : ts.surface.triangles)
      for (uint32_t v : t)
        if (v >= ts.surface.positions_mm.size()) fail("surface " + std::to_string(i) + ": triangle index out of range");
  }
  for (size_t i = 0; i < set.solids.size(); ++i) {
    const TriMesh& m = set.solids[i];
    if (m.triangles.empty()) fail("solid mesh " + std::to_string(i) + ": has no triangles");
    for (const Vec3d& p : m.positions_mm)
      if (!is_finite(p)) fail("solid mesh " + std::to_string(i) + ": has a non-finite vertex");
    for (const auto& t : m.triangles)
      for (uint32_t v : t)
        if (v >= m.positions_mm.size()) fail("solid mesh " + std::to_string(i) + ": triangle index out of range");
  }
  for (size_t i = 0; i < set.cells.size(); ++i) {
    const ConvexCells& cells = set.cells[i];
    const std::string where = "cells " + std::to_string(i);
    if (cells.corners_per_cell < 4) fail(where + ": a cell needs at least 4 corners");
    if (cells.corners_mm.size() % size_t(cells.corners_per_cell) != 0)
      fail(where + ": the corner list is not a whole number of cells");
    if (cells.faces.size() < 4) fail(where + ": a cell needs at least 4 faces");
    for (const auto& face : cells.faces) {
      if (face.size() < 3) fail(where + ": a face needs at least 3 corners");
      for (int c : face)
        if (c < 0 || c >= cells.corners_per_cell) fail(where + ": a face names corner " + std::to_string(c));
    }
    for (const Vec3d& p : cells.corners_mm)
      if (!is_finite(p)) fail(where + ": has a non-finite corner");
  }
  for (size_t i = 0; i < set.regions.size(); ++i) {
    const Region2& r = set.regions[i];
    std::string where = "region " + std::to_string(i);
    if (!positive(r.height_mm)) fail(where + ": height must be a positive length in mm");
    if (r.loops_mm.empty()) fail(where + ": has no loops");
    if (!is_finite(r.origin_mm)) fail(where + ": origin is not finite");
    if (!is_finite(r.axis_u) || !is_finite(r.axis_v) || std::fabs(norm(r.axis_u) - 1) > 1e-9 ||
        std::fabs(norm(r.axis_v) - 1) > 1e-9 || std::fabs(dot(r.axis_u, r.axis_v)) > 1e-9)
      fail(where + ": axis_u and axis_v must be orthogonal unit vectors");
    for (const auto& loop : r.loops_mm) {
      if (loop.size() < 3) fail(where + ": a loop needs at least 3 points");
      for (const Vec2d& p : loop)
        if (!std::isfinite(p.x) || !std::isfinite(p.y)) fail(where + ": has a non-finite point");
    }
  }
}

Volume clip_to_slab(const Volume& volume, const ZSlab& slab) {
  if (volume.empty()) return volume;
  // The slab as a box reaching a band beyond the volume's sides, rasterized under the same clip so
  // that its faces carry the same values as a clipped rasterization.
  const Box3 box = volume.bounding_box();
  const double reach = 2 * volume.band_mm() + volume.voxel_size_mm();
  Shape s;
  s.kind = Shape::Kind::kBox;
  s.center_mm = {0.5 * (box.min.x + box.max.x), 0.5 * (box.min.y + box.max.y), 0.5 * (slab.lo_mm + slab.hi_mm)};
  s.half_size_mm = {0.5 * (box.max.x - box.min.x) + reach, 0.5 * (box.max.y - box.min.y) + reach,
                    0.5 * (slab.hi_mm - slab.lo_mm) + reach};
  GeometrySet set;
  set.shapes.push_back(s);
  PrimitiveRasterizer rasterizer(volume.options());
  rasterizer.clip_z(slab.lo_mm, slab.hi_mm);
  rasterizer.add(set);
  return intersect(volume, rasterizer.finish());
}

Volume voxelize_meshes(const GeometrySet& set, const VolumeOptions& options) {
  Volume result;
  for (const TriMesh& m : set.solids) result = unite(result, mesh_to_volume(m, options));
  for (const Region2& r : set.regions) result = unite(result, mesh_to_volume(extrude_region(r), options));
  return result;
}

Volume voxelize(const GeometrySet& set, const VolumeOptions& options, const ZSlab* slab, const Volume* meshes) {
  validate(set);
  PrimitiveRasterizer rasterizer(options);
  if (slab) rasterizer.clip_z(slab->lo_mm, slab->hi_mm);
  rasterizer.add(set);
  for (const GeometryStream& stream : set.streams)
    stream.emit([&](const GeometrySet& batch) {
      validate(batch);
      rasterizer.add(batch);
    });
  Volume result = rasterizer.finish();
  if (set.solids.empty() && set.regions.empty()) return result;
  const Volume converted = meshes ? *meshes : voxelize_meshes(set, options);
  return unite(result, slab ? clip_to_slab(converted, *slab) : converted);
}

}  // namespace lacuna
