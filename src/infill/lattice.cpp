#include "infill/lattice.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "errors.h"

namespace lacuna {

double GradeField::at(const Vec3d& p) const {
  switch (kind) {
    case Kind::kNone:
      return 0;
    case Kind::kRamp:
      return std::clamp((dot(p, axis) - from_mm) / (to_mm - from_mm), 0.0, 1.0);
    case Kind::kPoints: {
      double v = 0;
      for (const Vec3d& q : points_mm) {
        double d = norm(p - q) / falloff_mm;
        v = std::max(v, std::exp(-d * d));
      }
      return v;
    }
    case Kind::kDepth:
      return depth_of ? std::clamp(depth_of(p) / depth_mm, 0.0, 1.0) : 0.0;
  }
  return 0;
}

TubeSet lattice_tubes(const Box3& box, const LatticeOptions& o) {
  if (box.empty()) throw InvalidInput("the lattice's box is empty");
  if (!(o.period_mm > 0) || !std::isfinite(o.period_mm)) throw InvalidInput("the lattice period must be positive (mm)");
  const bool graded = o.grade.kind != GradeField::Kind::kNone;
  if (graded ? !(o.radius_min_mm > 0 && o.radius_max_mm > 0) : !(o.radius_mm > 0))
    throw InvalidInput("strut radii must be positive (mm)");
  if (o.grade.kind == GradeField::Kind::kRamp && !(o.grade.to_mm != o.grade.from_mm))
    throw InvalidInput("a ramp needs from_mm and to_mm apart");
  const double p = o.period_mm;
  int64_t lo[3], hi[3];
  double cells = 1;
  for (int k = 0; k < 3; ++k) {
    lo[k] = int64_t(std::floor(box.min[k] / p));
    hi[k] = int64_t(std::ceil(box.max[k] / p));
    cells *= double(hi[k] - lo[k] + 1);
  }
  if (cells * (o.cell == LatticeOptions::Cell::kCubic ? 3 : 7) > 1e7)
    throw InvalidInput("the lattice would have more than 10 000 000 struts; use a larger period");
  auto radius = [&](const Vec3d& x) {
    if (!graded) return o.radius_mm;
    return o.radius_min_mm + (o.radius_max_mm - o.radius_min_mm) * o.grade.at(x);
  };
  TubeSet out;
  auto strut = [&](const Vec3d& a, const Vec3d& b) {
    const int pieces = graded ? std::max(1, int(std::ceil(norm(b - a) / (0.25 * p)))) : 1;
    Tube t;
    for (int i = 0; i <= pieces; ++i) {
      Vec3d x = a + (b - a) * (double(i) / pieces);
      t.points_mm.push_back(x);
      t.radii_mm.push_back(radius(x));
    }
    out.tubes.push_back(std::move(t));
  };
  for (int64_t i = lo[0]; i <= hi[0]; ++i)
    for (int64_t j = lo[1]; j <= hi[1]; ++j)
      for (int64_t k = lo[2]; k <= hi[2]; ++k) {
        const Vec3d node{i * p, j * p, k * p};
        if (i < hi[0]) strut(node, node + Vec3d{p, 0, 0});
        if (j < hi[1]) strut(node, node + Vec3d{0, p, 0});
        if (k < hi[2]) strut(node, node + Vec3d{0, 0, p});
        if (o.cell == LatticeOptions::Cell::kBodyCentred && i < hi[0] && j < hi[1] && k < hi[2]) {
          const Vec3d centre = node + Vec3d{p, p, p} * 0.5;
          for (int c = 0; c < 8; ++c) strut(centre, node + Vec3d{(c & 1) * p, ((c >> 1) & 1) * p, ((c >> 2) & 1) * p});
        }
      }
  return out;
}

}  // namespace lacuna
