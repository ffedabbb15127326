#include "curves/sweep.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "errors.h"

namespace lacuna {
namespace curves {

SurfaceMap plane_map() {
  SurfaceMap m;
  m.name = "plane";
  m.point = [](double X, double Y) { return Vec3d{X, Y, 0}; };
  m.normal = [](double, double) { return Vec3d{0, 0, 1}; };
  return m;
}

std::vector<int> parse_orders(const std::string& text) {
  std::vector<int> orders;
  try {
    const size_t dots = text.find("..");
    if (dots != std::string::npos) {
      size_t used_a = 0, used_b = 0;
      const int a = std::stoi(text.substr(0, dots), &used_a), b = std::stoi(text.substr(dots + 2), &used_b);
      if (used_a != dots || used_b != text.size() - dots - 2 || b < a) throw std::invalid_argument(text);
      for (int k = a; k <= b; ++k) orders.push_back(k);
    } else {
      size_t start = 0;
      while (start <= text.size()) {
        const size_t comma = std::min(text.find(',', start), text.size());
        const std::string item = text.substr(start, comma - start);
        size_t used = 0;
        orders.push_back(std::stoi(item, &used));
        if (used != item.size()) throw std::invalid_argument(item);
        start = comma + 1;
      }
    }
  } catch (const std::logic_error&) {
    throw InvalidInput("expected FROM..TO (e.g. 1..6) or a list such as 3,4,6, got \"" + text + "\"");
  }
  return orders;
}

namespace {

void add_tube(Sweep& out, const Polyline3& line, double radius, const Vec3d& center) {
  Tube t;
  t.points_mm.reserve(line.points.size() + 1);
  for (const Vec3d& p : line.points) t.points_mm.push_back(p + center);
  if (line.closed && !line.points.empty()) t.points_mm.push_back(line.points.front() + center);
  t.radii_mm = {radius};
  out.segments += t.points_mm.size() - 1;
  out.tubes.tubes.push_back(std::move(t));
}

}  // namespace

TriMesh tessellate_map(const SurfaceMap& map, double scale, const Vec3d& center, double tolerance_mm) {
  if (!(tolerance_mm > 0)) throw InvalidInput("the tessellation tolerance must be positive (mm)");
  auto at = [&](double X, double Y) { return map.point(X, Y) * scale + center; };
  int n = 16;
  for (; n < 1024; n *= 2) {
    double worst = 0;
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) {
        const double x0 = -1 + 2.0 * i / n, x1 = -1 + 2.0 * (i + 1) / n, y0 = -1 + 2.0 * j / n, y1 = -1 + 2.0 * (j + 1) / n;
        const Vec3d mean = (at(x0, y0) + at(x1, y0) + at(x0, y1) + at(x1, y1)) * 0.25;
        worst = std::max(worst, norm(at(0.5 * (x0 + x1), 0.5 * (y0 + y1)) - mean));
      }
    if (worst <= tolerance_mm) break;
  }
  TriMesh mesh;
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) mesh.positions_mm.push_back(at(-1 + 2.0 * i / n, -1 + 2.0 * j / n));
  auto id = [n](int i, int j) { return uint32_t(j * (n + 1) + i); };
  auto add = [&](uint32_t a, uint32_t b, uint32_t c) {
    const Vec3d& pa = mesh.positions_mm[a];
    if (norm(cross(mesh.positions_mm[b] - pa, mesh.positions_mm[c] - pa)) > 1e-12 * scale * scale)
      mesh.triangles.push_back({a, b, c});
  };
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      add(id(i, j), id(i + 1, j), id(i + 1, j + 1));
      add(id(i, j), id(i + 1, j + 1), id(i, j + 1));
    }
  return mesh;
}

Sweep sweep_curves(const SweepOptions& o, const SurfaceMap& map, bool on_cube) {
  if (o.orders.empty()) throw InvalidInput("no curve orders given");
  if (o.radii_mm.size() != 1 && o.radii_mm.size() != o.orders.size())
    throw InvalidInput("expected one tube radius, or one per order (" + std::to_string(o.orders.size()) + ")");
  for (double r : o.radii_mm)
    if (!(r > 0) || !std::isfinite(r)) throw InvalidInput("tube radii must be positive (mm)");
  if (!(o.base_thickness_mm >= 0)) throw InvalidInput("the base thickness must be at least 0 (mm)");
  auto radius = [&](size_t i) { return o.radii_mm.size() == 1 ? o.radii_mm[0] : o.radii_mm[i]; };
  Sweep out;
  if (o.kind == SweepOptions::Kind::kHilbert3d) {
    std::vector<Curve3> set = superposition3d(o.orders);
    for (size_t i = 0; i < set.size(); ++i) {
      Polyline3 line = set[i].polyline;
      for (Vec3d& p : line.points) p = p * o.map.scale;
      add_tube(out, line, radius(i), o.center_mm);
    }
    return out;
  }
  const CurveKind kind = o.kind == SweepOptions::Kind::kHilbert ? CurveKind::kHilbert : CurveKind::kSierpinski;
  if (on_cube) {
    for (size_t i = 0; i < o.orders.size(); ++i)
      for (const Polyline3& line : cube_curve(kind, o.orders[i], o.map)) add_tube(out, line, radius(i), o.center_mm);
    if (o.base_thickness_mm > 0)
      for (int face = 0; face < 6; ++face)
        out.base.push_back(ThickSurface{tessellate_map(cube_face_map(face), o.map.scale, o.center_mm, o.map.tolerance_mm),
                                        o.base_thickness_mm});
    return out;
  }
  std::vector<Curve2> set = superposition(kind, o.orders);
  for (size_t i = 0; i < set.size(); ++i) add_tube(out, map_polyline(set[i].polyline, map, o.map), radius(i), o.center_mm);
  if (o.base_thickness_mm > 0)
    out.base.push_back(ThickSurface{tessellate_map(map, o.map.scale, o.center_mm, o.map.tolerance_mm), o.base_thickness_mm});
  return out;
}

}  // namespace curves
}  // namespace lacuna
