#include "solids/rasterize.h"

#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_sort.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <openvdb/tools/Prune.h>
#include <sstream>

#include "errors.h"
#include "solids/vdb_internal.h"
#include "util/progress.h"

namespace lacuna {
namespace {


enum class PrimKind : uint8_t { kSphere, kCapsule, kRoundCone, kBox, kCylinder, kTorus, kTriangle, kCell };

// A face plane of a convex cell: signed distance n . p - offset, n unit, outward.
struct Plane {
  Vec3d normal;
  double offset;
};

// One primitive with what its distance function needs precomputed.
struct Prim {
  PrimKind kind;
  bool degenerate = false;  // triangle with (almost) no area: measured as three segments
  Vec3d a, b, c;            // sphere centre / segment ends / box centre+half size / triangle
  Vec3d ba;                 // b - a for segments
  double r0 = 0, r1 = 0;    // radii (sphere, capsule ends), cylinder radius + half height, ...
  double l2 = 0, inv_l2 = 0, rr = 0, a2 = 0;  // round-cone terms (see round_cone_distance)
  uint32_t first_plane = 0, plane_count = 0;  // a cell's face planes in the batch's plane list
  Box3 box;
};

// The primitives of one batch and the face planes of its cells.
struct Flat {
  std::vector<Prim> prims;
  std::vector<Plane> planes;
};

double segment_distance(const Vec3d& p, const Vec3d& a, const Vec3d& ba, double inv_l2) {
  Vec3d pa = p - a;
  double t = inv_l2 > 0 ? std::clamp(dot(pa, ba) * inv_l2, 0.0, 1.0) : 0.0;
  return norm(pa - ba * t);
}

// Exact distance to the convex hull of two balls (a, r0) and (b, r1) with |r0 - r1| < |b - a|
// (after I. Quilez's round-cone formula, in double precision).
double round_cone_distance(const Prim& q, const Vec3d& p) {
  Vec3d pa = p - q.a;
  double y = dot(pa, q.ba);
  double z = y - q.l2;
  Vec3d w = pa * q.l2 - q.ba * y;
  double x2 = dot(w, w);
  double y2 = y * y * q.l2;
  double z2 = z * z * q.l2;
  double k = (q.rr > 0 ? 1.0 : -1.0) * q.rr * q.rr * x2;
  if ((z > 0 ? 1.0 : -1.0) * q.a2 * z2 > k) return std::sqrt(x2 + z2) * q.inv_l2 - q.r1;
  if ((y > 0 ? 1.0 : -1.0) * q.a2 * y2 < k) return std::sqrt(x2 + y2) * q.inv_l2 - q.r0;
  return (std::sqrt(x2 * q.a2 * q.inv_l2) + y * q.rr) * q.inv_l2 - q.r0;
}

// Closest point on triangle abc to p (C. Ericson, Real-Time Collision Detection, 5.1.5).
Vec3d closest_on_triangle(const Vec3d& p, const Vec3d& a, const Vec3d& b, const Vec3d& c) {
  Vec3d ab = b - a, ac = c - a, ap = p - a;
  double d1 = dot(ab, ap), d2 = dot(ac, ap);
  if (d1 <= 0 && d2 <= 0) return a;
  Vec3d bp = p - b;
  double d3 = dot(ab, bp), d4 = dot(ac, bp);
  if (d3 >= 0 && d4 <= d3) return b;
  double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return a + ab * (d1 / (d1 - d3));
  Vec3d cp = p - c;
  double d5 = dot(ab, cp), d6 = dot(ac, cp);
  if (d6 >= 0 && d5 <= d6) return c;
  double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return a + ac * (d2 / (d2 - d6));
  double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0)
    return b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)));
  double denom = 1.0 / (va + vb + vc);
  return a + ab * (vb * denom) + ac * (vc * denom);
}

double distance(const Prim& q, const Plane* planes, const Vec3d& p) {
  switch (q.kind) {
    case PrimKind::kCell: {
      // Exact inside a convex cell; outside a lower bound (exact off edges and corners): the zero
      // set is the cell exactly and the function stays 1-Lipschitz, which is all the band needs.
      double d = -HUGE_VAL;
      for (uint32_t i = 0; i < q.plane_count; ++i) {
        const Plane& f = planes[q.first_plane + i];
        d = std::max(d, dot(f.normal, p) - f.offset);
      }
      return d;
    }
    case PrimKind::kSphere:
      return norm(p - q.a) - q.r0;
    case PrimKind::kCapsule:
      return segment_distance(p, q.a, q.ba, q.inv_l2) - q.r0;
    case PrimKind::kRoundCone:
      return round_cone_distance(q, p);
    case PrimKind::kBox: {
      Vec3d d{std::fabs(p.x - q.a.x) - q.b.x, std::fabs(p.y - q.a.y) - q.b.y,
              std::fabs(p.z - q.a.z) - q.b.z};
      Vec3d outside{std::max(d.x, 0.0), std::max(d.y, 0.0), std::max(d.z, 0.0)};
      return norm(outside) + std::min(std::max(d.x, std::max(d.y, d.z)), 0.0);
    }
    case PrimKind::kCylinder: {
      Vec3d rel = p - q.a;
      double along = dot(rel, q.b);
      double radial = norm(rel - q.b * along);
      double dx = radial - q.r0, dy = std::fabs(along) - q.r1;
      double ox = std::max(dx, 0.0), oy = std::max(dy, 0.0);
      return std::sqrt(ox * ox + oy * oy) + std::min(std::max(dx, dy), 0.0);
    }
    case PrimKind::kTorus: {
      Vec3d rel = p - q.a;
      double along = dot(rel, q.b);
      double radial = norm(rel - q.b * along);
      double dr = radial - q.r0;
      return std::sqrt(dr * dr + along * along) - q.r1;
    }
    case PrimKind::kTriangle: {
      if (q.degenerate) {
        double d = std::min(segment_distance(p, q.a, q.b - q.a, 1.0 / std::max(dot(q.b - q.a, q.b - q.a), 1e-300)),
                            segment_distance(p, q.b, q.c - q.b, 1.0 / std::max(dot(q.c - q.b, q.c - q.b), 1e-300)));
        d = std::min(d, segment_distance(p, q.c, q.a - q.c, 1.0 / std::max(dot(q.a - q.c, q.a - q.c), 1e-300)));
        return d - q.r0;
      }
      return norm(p - closest_on_triangle(p, q.a, q.b, q.c)) - q.r0;
    }
  }
  return std::numeric_limits<double>::infinity();
}

Box3 ball_box(const Vec3d& c, double r) {
  Box3 box;
  box.expand(c - Vec3d{r, r, r});
  box.expand(c + Vec3d{r, r, r});
  return box;
}

Prim make_segment(const Vec3d& a, double ra, const Vec3d& b, double rb) {
  Prim q;
  q.a = a;
  q.b = b;
  q.ba = b - a;
  q.r0 = ra;
  q.r1 = rb;
  q.l2 = dot(q.ba, q.ba);
  q.box = ball_box(a, ra);
  q.box.expand(ball_box(b, rb));
  double rr = ra - rb;
  if (q.l2 == 0 || std::fabs(rr) >= std::sqrt(q.l2)) {
    // One ball contains the other: the hull is the larger ball.
    q.kind = PrimKind::kSphere;
    if (rb > ra) { q.a = b; q.r0 = rb; }
    q.box = ball_box(q.a, q.r0);
    return q;
  }
  q.inv_l2 = 1.0 / q.l2;
  if (ra == rb) {
    q.kind = PrimKind::kCapsule;
  } else {
    q.kind = PrimKind::kRoundCone;
    q.rr = rr;
    q.a2 = q.l2 - rr * rr;
  }
  return q;
}

Vec3d unit(const Vec3d& v) { return v / norm(v); }

// Every distance-bearing piece of the set, flattened.
Flat flatten(const GeometrySet& set) {
  Flat flat;
  std::vector<Prim>& prims = flat.prims;
  prims.reserve(primitive_count(set));
  for (const Tube& tube : set.tubes.tubes) {
    auto radius = [&](size_t i) { return tube.radii_mm.size() == 1 ? tube.radii_mm[0] : tube.radii_mm[i]; };
    if (tube.points_mm.size() == 1) {
      prims.push_back(make_segment(tube.points_mm[0], radius(0), tube.points_mm[0], radius(0)));
      continue;
    }
    for (size_t i = 0; i + 1 < tube.points_mm.size(); ++i)
      prims.push_back(make_segment(tube.points_mm[i], radius(i), tube.points_mm[i + 1], radius(i + 1)));
  }
  const SphereSet& spheres = set.spheres;
  for (size_t i = 0; i < spheres.centers_mm.size(); ++i) {
    Prim q;
    q.kind = PrimKind::kSphere;
    q.a = spheres.centers_mm[i];
    q.r0 = spheres.radii_mm.size() == 1 ? spheres.radii_mm[0] : spheres.radii_mm[i];
    q.box = ball_box(q.a, q.r0);
    prims.push_back(q);
  }
  for (const Shape& s : set.shapes) {
    Prim q;
    q.a = s.center_mm;
    switch (s.kind) {
      case Shape::Kind::kBox:
        q.kind = PrimKind::kBox;
        q.b = s.half_size_mm;
        q.box.expand(s.center_mm - s.half_size_mm);
        q.box.expand(s.center_mm + s.half_size_mm);
        break;
      case Shape::Kind::kCylinder: {
        q.kind = PrimKind::kCylinder;
        q.b = unit(s.axis);
        q.r0 = s.radius_mm;
        q.r1 = 0.5 * s.height_mm;
        // Conservative: the ball around the cylinder.
        q.box = ball_box(q.a, std::sqrt(q.r0 * q.r0 + q.r1 * q.r1));
        break;
      }
      case Shape::Kind::kTorus:
        q.kind = PrimKind::kTorus;
        q.b = unit(s.axis);
        q.r0 = s.radius_mm;
        q.r1 = s.minor_radius_mm;
        q.box = ball_box(q.a, q.r0 + q.r1);
        break;
    }
    prims.push_back(q);
  }
  for (const ThickSurface& surface : set.surfaces) {
    for (const auto& t : surface.surface.triangles) {
      Prim q;
      q.kind = PrimKind::kTriangle;
      q.a = surface.surface.positions_mm[t[0]];
      q.b = surface.surface.positions_mm[t[1]];
      q.c = surface.surface.positions_mm[t[2]];
      q.r0 = 0.5 * surface.thickness_mm;
      Vec3d n = cross(q.b - q.a, q.c - q.a);
      double scale = std::max({dot(q.b - q.a, q.b - q.a), dot(q.c - q.a, q.c - q.a),
                               dot(q.c - q.b, q.c - q.b)});
      q.degenerate = dot(n, n) <= 1e-24 * scale * scale;
      q.box = ball_box(q.a, q.r0);
      q.box.expand(ball_box(q.b, q.r0));
      q.box.expand(ball_box(q.c, q.r0));
      prims.push_back(q);
    }
  }

  for (const ConvexCells& cells : set.cells) {
    const size_t m = size_t(cells.corners_per_cell);
    for (size_t c = 0; c < cells.size(); ++c) {
      const Vec3d* v = cells.corners_mm.data() + c * m;
      Vec3d centroid{0, 0, 0};
      Prim q;
      q.kind = PrimKind::kCell;
      for (size_t i = 0; i < m; ++i) {
        centroid += v[i];
        q.box.expand(v[i]);
      }
      centroid = centroid / double(m);
      q.first_plane = uint32_t(flat.planes.size());
      bool degenerate = false;
      for (const auto& face : cells.faces) {
        // Newell's normal is robust for any polygon; the centroid decides which side is out.
        Vec3d n{0, 0, 0}, mean{0, 0, 0};
        for (size_t i = 0; i < face.size(); ++i) {
          const Vec3d &a = v[face[i]], &b = v[face[(i + 1) % face.size()]];
          n += Vec3d{(a.y - b.y) * (a.z + b.z), (a.z - b.z) * (a.x + b.x), (a.x - b.x) * (a.y + b.y)};
          mean += a;
        }
        mean = mean / double(face.size());
        double length = norm(n);
        if (!(length > 0)) continue;  // a face collapsed to a line or point adds no constraint
        n = n / length;
        double offset = dot(n, mean);
        if (dot(n, centroid) - offset > 0) {
          n = -n;
          offset = -offset;
        }
        if (dot(n, centroid) - offset > -1e-12 * (1 + norm(q.box.size()))) degenerate = true;
        flat.planes.push_back(Plane{n, offset});
      }
      q.plane_count = uint32_t(flat.planes.size() - q.first_plane);
      if (degenerate || q.plane_count < 4) {
        flat.planes.resize(q.first_plane);  // a flat cell has no interior: nothing to add
        continue;
      }
      prims.push_back(q);
    }
  }
  return flat;
}

// Leaf coordinates are packed 21 bits per axis.
constexpr int kLeafCoordBits = 21;
constexpr int64_t kLeafCoordBias = int64_t{1} << (kLeafCoordBits - 1);

uint64_t pack_leaf(int64_t x, int64_t y, int64_t z) {
  return (uint64_t(x + kLeafCoordBias) << (2 * kLeafCoordBits)) |
         (uint64_t(y + kLeafCoordBias) << kLeafCoordBits) | uint64_t(z + kLeafCoordBias);
}

openvdb::Coord unpack_leaf_origin(uint64_t key) {
  const uint64_t mask = (uint64_t{1} << kLeafCoordBits) - 1;
  int64_t x = int64_t((key >> (2 * kLeafCoordBits)) & mask) - kLeafCoordBias;
  int64_t y = int64_t((key >> kLeafCoordBits) & mask) - kLeafCoordBias;
  int64_t z = int64_t(key & mask) - kLeafCoordBias;
  return openvdb::Coord(int(x * 8), int(y * 8), int(z * 8));
}

struct Pair {
  uint64_t leaf;
  uint32_t prim;
  uint32_t interior;  // 1 when the primitive contains the whole leaf and its band
  bool operator<(const Pair& o) const {
    if (leaf != o.leaf) return leaf < o.leaf;
    if (prim != o.prim) return prim < o.prim;
    return interior < o.interior;
  }
};

struct Grid {
  double h;     // voxel size
  double band;  // half band in mm
};

// Adds (leaf, primitive) pairs for the leaves [lo, hi) the primitive's band can reach, refining
// a block of leaves only where the distance at its centre does not settle it.
void collect_pairs(const Prim& q, const Plane* planes, uint32_t index, const int64_t lo[3], const int64_t hi[3],
                   const Grid& g, std::vector<Pair>& out) {
  Vec3d center, half;
  for (int k = 0; k < 3; ++k) {
    double first = double(lo[k] * 8), last = double(hi[k] * 8 - 1);
    center[k] = 0.5 * (first + last) * g.h;
    half[k] = 0.5 * (last - first) * g.h;
  }
  double reach = g.band + norm(half);
  double d = distance(q, planes, center);
  if (d >= reach) return;
  bool inside = d <= -reach;
  int64_t extent[3] = {hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]};
  if (inside || (extent[0] == 1 && extent[1] == 1 && extent[2] == 1)) {
    for (int64_t x = lo[0]; x < hi[0]; ++x)
      for (int64_t y = lo[1]; y < hi[1]; ++y)
        for (int64_t z = lo[2]; z < hi[2]; ++z)
          out.push_back(Pair{pack_leaf(x, y, z), index, inside ? 1u : 0u});
    return;
  }
  int axis = 0;
  if (extent[1] > extent[axis]) axis = 1;
  if (extent[2] > extent[axis]) axis = 2;
  int64_t mid = lo[axis] + extent[axis] / 2;
  int64_t lo2[3] = {lo[0], lo[1], lo[2]}, hi1[3] = {hi[0], hi[1], hi[2]};
  hi1[axis] = mid;
  lo2[axis] = mid;
  collect_pairs(q, planes, index, lo, hi1, g, out);
  collect_pairs(q, planes, index, lo2, hi, g, out);
}

int64_t floor_div8(int64_t v) { return v >= 0 ? v / 8 : -((-v + 7) / 8); }

}  // namespace

size_t primitive_count(const GeometrySet& set) {
  size_t n = set.spheres.centers_mm.size() + set.shapes.size();
  for (const Tube& t : set.tubes.tubes) n += t.points_mm.size() <= 1 ? 1 : t.points_mm.size() - 1;
  for (const ThickSurface& s : set.surfaces) n += s.surface.triangles.size();
  for (const ConvexCells& c : set.cells) n += c.size();
  return n;
}

struct PrimitiveRasterizer::Impl {
  VolumeOptions options;
  openvdb::FloatGrid::Ptr grid;
  bool clipped = false;
  double clip_lo = 0, clip_hi = 0;  // mm
};

PrimitiveRasterizer::PrimitiveRasterizer(const VolumeOptions& options) : impl_(std::make_unique<Impl>()) {
  impl_->options = options;
  impl_->grid = make_level_set_grid(options);
}

PrimitiveRasterizer::~PrimitiveRasterizer() = default;

void PrimitiveRasterizer::clip_z(double lo_mm, double hi_mm) {
  const double band = impl_->options.voxel_size_mm * impl_->options.half_band_voxels;
  if (!(std::isfinite(lo_mm) && std::isfinite(hi_mm) && hi_mm - lo_mm > 2 * band))
    throw InvalidInput("a slab must be finite and more than two bands high");
  impl_->clipped = true;
  impl_->clip_lo = lo_mm;
  impl_->clip_hi = hi_mm;
}

void PrimitiveRasterizer::add(const GeometrySet& batch) {
  const Grid g{impl_->options.voxel_size_mm, impl_->options.voxel_size_mm * impl_->options.half_band_voxels};
  const float band = static_cast<float>(g.band);
  const Flat flat = flatten(batch);
  const std::vector<Prim>& prims = flat.prims;
  const Plane* planes = flat.planes.data();
  if (prims.empty()) return;
  Progress progress("rasterize", prims.size() * 2);

  // A slab: leaves beyond its band are never made; the slab's own distance, max(lo - z, z - hi),
  // bounds every value from below (an intersection), so its faces get a band of their own.
  const bool clipped = impl_->clipped;
  const double clip_lo = impl_->clip_lo, clip_hi = impl_->clip_hi;
  const int64_t clip_leaf_lo = clipped ? floor_div8(int64_t(std::ceil((clip_lo - g.band) / g.h))) : 0;
  const int64_t clip_leaf_hi = clipped ? floor_div8(int64_t(std::floor((clip_hi + g.band) / g.h))) + 1 : 0;
  auto slab_distance = [&](int z) { return static_cast<float>(std::max(clip_lo - z * g.h, z * g.h - clip_hi)); };
  auto near_slab_face = [&](const openvdb::Coord& origin) {
    return clipped && (slab_distance(origin[2]) > -band || slab_distance(origin[2] + 7) > -band);
  };

  // 1. Which leaves each primitive's band reaches, sorted so every leaf is computed once from a
  // list in a fixed order (the result does not depend on the number of threads).
  const double limit = double(kLeafCoordBias - 2) * 8;
  tbb::enumerable_thread_specific<std::vector<Pair>> local_pairs;
  tbb::parallel_for(tbb::blocked_range<size_t>(0, prims.size(), 256), [&](const tbb::blocked_range<size_t>& r) {
    std::vector<Pair>& out = local_pairs.local();
    for (size_t i = r.begin(); i != r.end(); ++i) {
      const Prim& q = prims[i];
      int64_t lo[3], hi[3];
      for (int k = 0; k < 3; ++k) {
        double vlo = std::ceil((q.box.min[k] - g.band) / g.h);
        double vhi = std::floor((q.box.max[k] + g.band) / g.h);
        if (!(std::fabs(vlo) < limit && std::fabs(vhi) < limit))
          throw ResourceLimit("the part spans more voxels than a grid can address; use a larger voxel size");
        lo[k] = floor_div8(int64_t(vlo));
        hi[k] = floor_div8(int64_t(vhi)) + 1;
      }
      if (clipped) {
        lo[2] = std::max(lo[2], clip_leaf_lo);
        hi[2] = std::min(hi[2], clip_leaf_hi);
        if (lo[2] >= hi[2]) continue;
      }
      collect_pairs(q, planes, uint32_t(i), lo, hi, g, out);
    }
    progress.advance(r.size());
  });
  std::vector<Pair> pairs;
  size_t total = 0;
  for (auto& v : local_pairs) total += v.size();
  pairs.reserve(total);
  for (auto& v : local_pairs) {
    pairs.insert(pairs.end(), v.begin(), v.end());
    std::vector<Pair>().swap(v);
  }
  tbb::parallel_sort(pairs.begin(), pairs.end());

  // 2. Each leaf's values from its primitives, in parallel; leaves inside a primitive become
  // interior tiles.
  std::vector<size_t> starts;
  for (size_t i = 0; i < pairs.size(); ++i)
    if (i == 0 || pairs[i].leaf != pairs[i - 1].leaf) starts.push_back(i);
  starts.push_back(pairs.size());
  const size_t leaf_count = starts.size() - 1;
  using LeafT = openvdb::FloatTree::LeafNodeType;
  std::vector<std::unique_ptr<LeafT>> leaves(leaf_count);
  std::vector<uint8_t> interior(leaf_count, 0);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, leaf_count, 16), [&](const tbb::blocked_range<size_t>& r) {
    float values[512];
    for (size_t li = r.begin(); li != r.end(); ++li) {
      const size_t begin = starts[li], end = starts[li + 1];
      bool inside = false;
      for (size_t k = begin; k < end && !inside; ++k) inside = pairs[k].interior != 0;
      const openvdb::Coord origin = unpack_leaf_origin(pairs[begin].leaf);
      const bool at_face = near_slab_face(origin);
      if (inside && !at_face) {
        interior[li] = 1;
        continue;
      }
      std::fill(values, values + 512, inside ? -band : band);
      for (size_t k = begin; k < end && !inside; ++k) {
        const Prim& q = prims[pairs[k].prim];
        int lo[3], hi[3];
        for (int a = 0; a < 3; ++a) {
          lo[a] = std::max(origin[a], int(std::ceil((q.box.min[a] - g.band) / g.h)));
          hi[a] = std::min(origin[a] + 7, int(std::floor((q.box.max[a] + g.band) / g.h)));
        }
        for (int x = lo[0]; x <= hi[0]; ++x) {
          for (int y = lo[1]; y <= hi[1]; ++y) {
            float* row = values + ((x - origin[0]) << 6) + ((y - origin[1]) << 3);
            for (int z = lo[2]; z <= hi[2]; ++z) {
              float f = static_cast<float>(distance(q, planes, Vec3d{x * g.h, y * g.h, z * g.h}));
              float& v = row[z - origin[2]];
              if (f < v) v = f;
            }
          }
        }
      }
      if (at_face)
        for (int n = 0; n < 512; ++n) values[n] = std::max(values[n], slab_distance(origin[2] + (n & 7)));
      bool any_active = false, all_negative = true;
      for (float v : values) {
        if (std::fabs(v) < band) any_active = true;
        if (v > -band) all_negative = false;
      }
      if (!any_active) {
        if (all_negative) interior[li] = 1;
        continue;
      }
      auto leaf = std::make_unique<LeafT>(origin, band, false);
      for (openvdb::Index n = 0; n < 512; ++n) {
        float v = values[n];
        if (std::fabs(v) < band) leaf->setValueOn(n, v);
        else leaf->setValueOff(n, v < 0 ? -band : band);
      }
      leaves[li] = std::move(leaf);
    }
    progress.advance(r.size() * prims.size() / std::max<size_t>(1, leaf_count));
  });

  // 3. Into the grid, as the minimum with what earlier batches put there. The tree is not
  // thread-safe for insertion, so new leaves and tiles go in serially; leaves that already
  // exist are merged in parallel.
  openvdb::FloatTree& tree = impl_->grid->tree();
  std::vector<std::pair<LeafT*, LeafT*>> merges;  // (existing, new)
  for (size_t li = 0; li < leaf_count; ++li) {
    const openvdb::Coord origin = unpack_leaf_origin(pairs[starts[li]].leaf);
    if (interior[li]) {
      tree.addTile(1, origin, -band, false);
      continue;
    }
    if (!leaves[li]) continue;
    if (LeafT* existing = tree.probeLeaf(origin)) {
      merges.emplace_back(existing, leaves[li].get());
    } else if (tree.getValue(origin) > 0) {
      tree.addLeaf(leaves[li].release());
    }
    // else: inside an interior tile from an earlier batch; nothing to add.
  }
  tbb::parallel_for(tbb::blocked_range<size_t>(0, merges.size(), 64), [&](const tbb::blocked_range<size_t>& r) {
    for (size_t i = r.begin(); i != r.end(); ++i) {
      LeafT& old_leaf = *merges[i].first;
      const LeafT& new_leaf = *merges[i].second;
      for (openvdb::Index n = 0; n < 512; ++n) {
        float v = std::min(old_leaf.getValue(n), new_leaf.getValue(n));
        if (std::fabs(v) < band) old_leaf.setValueOn(n, v);
        else old_leaf.setValueOff(n, v < 0 ? -band : band);
      }
    }
  });
}

Volume PrimitiveRasterizer::finish() {
  openvdb::tools::pruneLevelSet(impl_->grid->tree());
  Volume v = wrap_grid(impl_->grid, impl_->options);
  impl_->grid = make_level_set_grid(impl_->options);
  return v;
}

Volume rasterize_primitives(const GeometrySet& set, const VolumeOptions& options) {
  PrimitiveRasterizer rasterizer(options);
  rasterizer.add(set);
  return rasterizer.finish();
}

}  // namespace lacuna
