#include "fill/wallpaper.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <sstream>
#include <string>
#include <utility>

#include "errors.h"
#include "fill/shape2.h"

namespace lacuna {
namespace fill {
namespace {

constexpr double kPi = 3.14159265358979323846;

using detail::dot2;
using detail::length2;

constexpr const char* kNames[] = {"p1",  "p2",  "pm",  "pg", "cm",   "pmm",  "pmg", "pgg", "cmm",
                                  "p4",  "p4m", "p4g", "p3", "p3m1", "p31m", "p6",  "p6m"};

// (x, y) -> (a x + b y + tx, c x + d y + ty), in cell coordinates.
struct Op {
  int a, b, c, d;
  double tx, ty;
};

constexpr Op kI{1, 0, 0, 1, 0, 0}, kMinusI{-1, 0, 0, -1, 0, 0};
constexpr Op kRot90{0, -1, 1, 0, 0, 0}, kRot270{0, 1, -1, 0, 0, 0};
constexpr Op kRot120{0, -1, 1, -1, 0, 0}, kRot240{-1, 1, -1, 0, 0, 0};  // hexagonal cell at 120 degrees
constexpr Op kRot60{1, -1, 1, 0, 0, 0}, kRot300{0, 1, -1, 1, 0, 0};
constexpr Op kSwap{0, 1, 1, 0, 0, 0}, kMinusSwap{0, -1, -1, 0, 0, 0};
constexpr Op kFlipU{-1, 0, 0, 1, 0, 0}, kFlipV{1, 0, 0, -1, 0, 0};
constexpr double h = 0.5;

// The International Tables' coordinate triplets (cm and cmm in the rhombic primitive cell).
std::vector<Op> ops_of(Group g) {
  switch (g) {
    case Group::p1: return {kI};
    case Group::p2: return {kI, kMinusI};
    case Group::pm: return {kI, kFlipU};
    case Group::pg: return {kI, {-1, 0, 0, 1, 0, h}};
    case Group::cm: return {kI, kSwap};
    case Group::pmm: return {kI, kMinusI, kFlipU, kFlipV};
    case Group::pmg: return {kI, kMinusI, {-1, 0, 0, 1, h, 0}, {1, 0, 0, -1, h, 0}};
    case Group::pgg: return {kI, kMinusI, {-1, 0, 0, 1, h, h}, {1, 0, 0, -1, h, h}};
    case Group::cmm: return {kI, kSwap, kMinusI, kMinusSwap};
    case Group::p4: return {kI, kMinusI, kRot90, kRot270};
    case Group::p4m: return {kI, kMinusI, kRot90, kRot270, kFlipU, kFlipV, kSwap, kMinusSwap};
    case Group::p4g:
      return {kI, kMinusI, kRot90, kRot270, {-1, 0, 0, 1, h, h}, {1, 0, 0, -1, h, h}, {0, 1, 1, 0, h, h},
              {0, -1, -1, 0, h, h}};
    case Group::p3: return {kI, kRot120, kRot240};
    case Group::p3m1: return {kI, kRot120, kRot240, kMinusSwap, {-1, 1, 0, 1, 0, 0}, {1, 0, 1, -1, 0, 0}};
    case Group::p31m: return {kI, kRot120, kRot240, kSwap, {1, -1, 0, -1, 0, 0}, {-1, 0, -1, 1, 0, 0}};
    case Group::p6: return {kI, kRot120, kRot240, kMinusI, kRot300, kRot60};
    case Group::p6m:
      return {kI,         kRot120, kRot240, kMinusI, kRot300, kRot60, kMinusSwap, {-1, 1, 0, 1, 0, 0},
              {1, 0, 1, -1, 0, 0}, kSwap,   {1, -1, 0, -1, 0, 0}, {-1, 0, -1, 1, 0, 0}};
  }
  return {kI};
}

enum class Shape { kOblique, kRectangular, kRhombic, kSquare, kHexagonal };

Shape lattice_shape(Group g) {
  switch (g) {
    case Group::p1: case Group::p2: return Shape::kOblique;
    case Group::pm: case Group::pg: case Group::pmm: case Group::pmg: case Group::pgg: return Shape::kRectangular;
    case Group::cm: case Group::cmm: return Shape::kRhombic;
    case Group::p4: case Group::p4m: case Group::p4g: return Shape::kSquare;
    default: return Shape::kHexagonal;
  }
}

struct Frame {  // B = [a b] and its inverse
  Vec2d a, b;
  double inv[2][2];
  Vec2d to_world(const Vec2d& f) const { return a * f.x + b * f.y; }
  Vec2d to_cell(const Vec2d& p) const { return {inv[0][0] * p.x + inv[0][1] * p.y, inv[1][0] * p.x + inv[1][1] * p.y}; }
};

Frame frame_of(const Lattice& l) {
  Frame f{l.a, l.b, {}};
  const double det = cross2(l.a, l.b);
  f.inv[0][0] = l.b.y / det, f.inv[0][1] = -l.b.x / det;
  f.inv[1][0] = -l.a.y / det, f.inv[1][1] = l.a.x / det;
  return f;
}

Affine2 compose(const Affine2& p, const Affine2& q) {  // p after q
  Affine2 r;
  for (int i = 0; i < 2; ++i)
    for (int j = 0; j < 2; ++j) r.linear[i][j] = p.linear[i][0] * q.linear[0][j] + p.linear[i][1] * q.linear[1][j];
  r.translation = apply(p, q.translation);
  return r;
}

Affine2 shifted(const Affine2& m, const Vec2d& t) {
  Affine2 r = m;
  r.translation = r.translation + t;
  return r;
}

double det(const Affine2& m) { return m.linear[0][0] * m.linear[1][1] - m.linear[0][1] * m.linear[1][0]; }

// An element g(x) = L x + t of the group acting on the plane (one operation plus a lattice translation).
struct Element {
  int op;
  int i, j;  // the lattice translation added, i a + j b
  Affine2 map;
};

// The group and its lattice in millimetres, with the enumeration of elements near a point.
struct Pattern {
  Group group;
  Frame frame;
  std::vector<Affine2> ops;
  double row_u, row_v;  // norms of the rows of B^-1: how many cells one millimetre can span
  double tol;           // 1e-9 of the cell size

  // Calls f(element, image) for each element g whose image g(p) lies within reach of `around`.
  template <class F>
  void images(const Vec2d& p, const Vec2d& around, double reach, F&& f) const {
    for (size_t k = 0; k < ops.size(); ++k) {
      const Vec2d q = apply(ops[k], p);
      const Vec2d c = frame.to_cell(around - q);
      const int i0 = int(std::ceil(c.x - reach * row_u)), i1 = int(std::floor(c.x + reach * row_u));
      const int j0 = int(std::ceil(c.y - reach * row_v)), j1 = int(std::floor(c.y + reach * row_v));
      for (int i = i0; i <= i1; ++i)
        for (int j = j0; j <= j1; ++j) {
          const Vec2d t = frame.a * double(i) + frame.b * double(j);
          const Vec2d image = q + t;
          if (length2(image - around) > reach) continue;
          f(Element{int(k), i, j, shifted(ops[k], t)}, image);
        }
    }
  }
};

bool is_identity(const Element& e) { return e.op == 0 && e.i == 0 && e.j == 0; }

// A reflection's mirror direction alpha (its linear part is [[cos 2a, sin 2a], [sin 2a, -cos 2a]]).
double mirror_angle(const Affine2& m) { return std::atan2(m.linear[1][0], m.linear[0][0]) / 2; }

// For a reflection: whether it is one (no glide, to tol), and then its line n.x = offset.
bool mirror_line(const Affine2& m, double tol, Vec2d& normal, double& offset) {
  const double alpha = mirror_angle(m);
  const Vec2d d{std::cos(alpha), std::sin(alpha)};
  normal = {-d.y, d.x};
  if (std::fabs(dot2(m.translation, d)) > tol) return false;
  offset = dot2(m.translation, normal) / 2;
  return true;
}

// The centre of a rotation: the solution of (I - L) p = t.
Vec2d rotation_center(const Affine2& m) {
  const double a = 1 - m.linear[0][0], b = -m.linear[0][1], c = -m.linear[1][0], d = 1 - m.linear[1][1];
  const double det2 = a * d - b * c;
  return {(d * m.translation.x - b * m.translation.y) / det2, (a * m.translation.y - c * m.translation.x) / det2};
}

bool is_rotation(const Affine2& m) {
  return det(m) > 0 && std::fabs(m.linear[0][0] - 1) + std::fabs(m.linear[1][0]) > 1e-12;
}

// Whether the element fixes a point or a line that cuts the placed shape (the allow policy lets the shape
// overlap such images).
bool cuts(const Affine2& m, const detail::Shape2& s, double tol) {
  if (is_rotation(m)) {
    const Vec2d p = rotation_center(m);
    return s.circle ? length2(p - s.center) < s.radius : detail::point_in_polygon(s.points, p);
  }
  if (det(m) < 0) {
    Vec2d normal;
    double offset;
    if (!mirror_line(m, tol, normal, offset)) return false;
    if (s.circle) return std::fabs(dot2(normal, s.center) - offset) < s.radius;
    double lo = HUGE_VAL, hi = -HUGE_VAL;
    for (const Vec2d& p : s.points) lo = std::min(lo, dot2(normal, p) - offset), hi = std::max(hi, dot2(normal, p) - offset);
    return lo < 0 && hi > 0;
  }
  return false;
}

bool in_region(const std::vector<Vec2d>& region, const Vec2d& p, double tol) {
  return detail::point_in_polygon(region, p) || detail::outline_distance(region, p) <= tol;
}

// The snap policy: moves a motif cut by a rotation centre onto it, or one cut by a mirror line onto the line,
// aligned and enlarged by its stabilizer's order; false when the motif lacks the symmetry needed.
bool snap(const Pattern& pattern, const Motif2& motif, const std::vector<Vec2d>& region, Placement2& pl) {
  const bool circle = motif.kind == Motif2::Kind::kCircle;
  const double r = pl.scale * motif.bounding_radius;
  const Vec2d c = pl.center_mm;
  double best_point = HUGE_VAL, best_line = HUGE_VAL;
  Vec2d point, line_normal;
  double line_offset = 0, line_angle = 0;
  // An element whose fixed point or line is within r of c moves c by less than 2r.
  pattern.images(c, c, 2 * r, [&](const Element& e, const Vec2d&) {
    if (is_identity(e)) return;
    if (is_rotation(e.map)) {
      const Vec2d p = rotation_center(e.map);
      const double d = length2(p - c);
      if (d < r && d < best_point) best_point = d, point = p;
    } else if (det(e.map) < 0) {
      Vec2d normal;
      double offset;
      if (!mirror_line(e.map, pattern.tol, normal, offset)) return;
      const double d = std::fabs(dot2(normal, c) - offset);
      if (d < r && d < best_line) best_line = d, line_normal = normal, line_offset = offset, line_angle = mirror_angle(e.map);
    }
  });
  if (best_point == HUGE_VAL && best_line == HUGE_VAL) return true;
  const Vec2d target = best_point < HUGE_VAL ? point : c - line_normal * (dot2(line_normal, c) - line_offset);
  // The stabilizer of the target: its rotations must be the motif's, and a mirror among them must be one.
  int order = 0, rotations = 0;
  double alpha = line_angle;
  bool mirrors = false;
  pattern.images(target, target, pattern.tol, [&](const Element& e, const Vec2d&) {
    ++order;
    if (det(e.map) > 0) {
      ++rotations;
    } else if (!mirrors) {
      mirrors = true;
      alpha = mirror_angle(e.map);
    }
  });
  if (!circle) {
    if (motif.rotation_order % rotations != 0) return false;
    if (mirrors && motif.mirror_angles_rad.empty()) return false;
  }
  pl.center_mm = target;
  if (mirrors && !circle) pl.angle_rad = alpha - motif.mirror_angles_rad.front(), pl.mirrored = false;
  pl.area_mm2 *= order;
  pl.scale = std::sqrt(pl.area_mm2);
  pl.stabilizer_order = order;
  // A target outside the fundamental region (on a mirror that only touches it) is replaced by its image inside.
  if (!in_region(region, pl.center_mm, pattern.tol)) {
    bool moved = false;
    const Placement2 original = pl;
    pattern.images(target, target, 4 * (length2(pattern.frame.a) + length2(pattern.frame.b)), [&](const Element& e, const Vec2d& q) {
      if (!moved && in_region(region, q, pattern.tol)) pl = transform(e.map, original), moved = true;
    });
  }
  return true;
}

}  // namespace

Vec2d apply(const Affine2& m, const Vec2d& p) {
  return {m.linear[0][0] * p.x + m.linear[0][1] * p.y + m.translation.x,
          m.linear[1][0] * p.x + m.linear[1][1] * p.y + m.translation.y};
}

Group group_from_name(const std::string& name) {
  for (int g = 0; g < 17; ++g)
    if (name == kNames[g]) return Group(g);
  std::string list;
  for (const char* n : kNames) list += std::string(list.empty() ? "" : ", ") + n;
  throw InvalidInput("unknown wallpaper group \"" + name + "\"; expected one of " + list);
}

std::string group_name(Group group) { return kNames[int(group)]; }

Lattice group_lattice(Group group, const Lattice& lattice) {
  const std::string name = group_name(group);
  const Vec2d a = lattice.a, b = lattice.b;
  if (!std::isfinite(a.x) || !std::isfinite(a.y) || !std::isfinite(b.x) || !std::isfinite(b.y))
    throw InvalidInput("wallpaper group " + name + ": the lattice vectors must be finite");
  const double la = length2(a), lb = length2(b);
  if (!(la > 0 && lb > 0) || std::fabs(cross2(a, b)) <= 1e-9 * la * lb)
    throw InvalidInput("wallpaper group " + name + ": the lattice vectors a and b must be non-zero and not parallel");
  const double cosine = dot2(a, b) / (la * lb);
  const bool equal = std::fabs(la - lb) <= 1e-9 * std::max(la, lb);
  const bool perpendicular = std::fabs(cosine) <= 1e-9;
  switch (lattice_shape(group)) {
    case Shape::kOblique:
      return lattice;
    case Shape::kRectangular:
      if (!perpendicular) throw InvalidInput("wallpaper group " + name + " needs a rectangular lattice: a and b perpendicular");
      return lattice;
    case Shape::kRhombic:
      if (!equal) throw InvalidInput("wallpaper group " + name + " needs a rhombic lattice: |a| = |b|");
      return lattice;
    case Shape::kSquare:
      if (!equal || !perpendicular)
        throw InvalidInput("wallpaper group " + name + " needs a square lattice: |a| = |b| and a perpendicular to b");
      return lattice;
    case Shape::kHexagonal:
      if (!equal || std::fabs(std::fabs(cosine) - 0.5) > 1e-9)
        throw InvalidInput("wallpaper group " + name + " needs a hexagonal lattice: |a| = |b| at 60 or 120 degrees");
      if (cosine > 0) return {a, b - a};
      return lattice;
  }
  return lattice;
}

std::vector<Affine2> cell_operations(Group group) {
  std::vector<Affine2> out;
  for (const Op& o : ops_of(group)) {
    Affine2 m;
    m.linear[0][0] = o.a, m.linear[0][1] = o.b, m.linear[1][0] = o.c, m.linear[1][1] = o.d;
    m.translation = {o.tx, o.ty};
    out.push_back(m);
  }
  return out;
}

std::vector<Affine2> world_operations(Group group, const Lattice& lattice) {
  const Frame f = frame_of(group_lattice(group, lattice));
  Affine2 to_cell, to_world;
  to_world.linear[0][0] = f.a.x, to_world.linear[0][1] = f.b.x, to_world.linear[1][0] = f.a.y, to_world.linear[1][1] = f.b.y;
  for (int i = 0; i < 2; ++i)
    for (int j = 0; j < 2; ++j) to_cell.linear[i][j] = f.inv[i][j];
  std::vector<Affine2> out;
  for (const Affine2& m : cell_operations(group)) out.push_back(compose(to_world, compose(m, to_cell)));
  return out;
}

std::vector<Vec2d> fundamental_region(Group group) {
  const double t = 1.0 / 3, q = 0.25;
  switch (group) {
    case Group::p1: return {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
    case Group::p2: case Group::pm: return {{0, 0}, {h, 0}, {h, 1}, {0, 1}};
    case Group::pg: return {{0, 0}, {1, 0}, {1, h}, {0, h}};
    case Group::cm: return {{0, 0}, {1, 0}, {1, 1}};
    case Group::pmm: case Group::pgg: case Group::p4: return {{0, 0}, {h, 0}, {h, h}, {0, h}};
    case Group::pmg: return {{q, 0}, {3 * q, 0}, {3 * q, h}, {q, h}};
    case Group::cmm: return {{0, 0}, {1, 0}, {h, h}};
    case Group::p4m: return {{0, 0}, {h, 0}, {h, h}};
    case Group::p4g: return {{0, 0}, {h, 0}, {0, h}};
    case Group::p3: return {{0, 0}, {t, -t}, {2 * t, t}, {t, 2 * t}};
    case Group::p3m1: case Group::p6: return {{0, 0}, {2 * t, t}, {t, 2 * t}};
    case Group::p31m: return {{0, 0}, {1, 0}, {2 * t, t}};
    case Group::p6m: return {{0, 0}, {2 * t, t}, {h, h}};
  }
  return {};
}

std::vector<Vec2d> fundamental_region_mm(Group group, const Lattice& lattice) {
  const Frame f = frame_of(group_lattice(group, lattice));
  std::vector<Vec2d> out;
  for (const Vec2d& p : fundamental_region(group)) out.push_back(f.to_world(p));
  if (signed_area(out) < 0) std::reverse(out.begin(), out.end());
  return out;
}

Placement2 transform(const Affine2& m, const Placement2& pl) {
  Placement2 out = pl;
  out.center_mm = apply(m, pl.center_mm);
  // L = R(phi) for a rotation, R(phi) F for a reflection (F = diag(1, -1)); R(phi) F R(theta) = R(phi - theta) F.
  const double phi = std::atan2(m.linear[1][0], m.linear[0][0]);
  if (det(m) > 0) {
    out.angle_rad = phi + pl.angle_rad;
  } else {
    out.angle_rad = phi - pl.angle_rad;
    out.mirrored = !pl.mirrored;
  }
  return out;
}

WallpaperFill fill_wallpaper(Group group, const Lattice& lattice, const Motif2& motif, const FillOptions& options,
                             BoundaryPolicy policy) {
  if (!(std::isfinite(options.c) && options.c > 1)) throw InvalidInput("fill: the exponent c must be > 1");
  if (!(std::isfinite(options.N) && options.N > 1)) throw InvalidInput("fill: the offset N must be > 1");
  if (!(std::isfinite(options.gap_mm) && options.gap_mm >= 0)) throw InvalidInput("fill: gap_mm must be >= 0");
  if (options.max_trials == 0) throw InvalidInput("fill: max_trials must be at least 1");
  WallpaperFill out;
  out.group = group;
  out.lattice = group_lattice(group, lattice);
  out.motif = motif;
  out.policy = policy;
  Pattern pattern{group, frame_of(out.lattice), world_operations(group, out.lattice), 0, 0, 0};
  pattern.row_u = std::hypot(pattern.frame.inv[0][0], pattern.frame.inv[0][1]);
  pattern.row_v = std::hypot(pattern.frame.inv[1][0], pattern.frame.inv[1][1]);
  pattern.tol = 1e-9 * (length2(out.lattice.a) + length2(out.lattice.b));

  const std::vector<Vec2d> cell_region = fundamental_region(group);
  const std::vector<Vec2d> region = fundamental_region_mm(group, out.lattice);
  const double A = std::fabs(signed_area(region));
  Vec2d lo{HUGE_VAL, HUGE_VAL}, hi{-HUGE_VAL, -HUGE_VAL}, mid;
  for (const Vec2d& p : cell_region) lo = {std::min(lo.x, p.x), std::min(lo.y, p.y)}, hi = {std::max(hi.x, p.x), std::max(hi.y, p.y)};
  for (const Vec2d& p : region) mid = mid + p * (1.0 / double(region.size()));
  double region_radius = 0;
  for (const Vec2d& p : region) region_radius = std::max(region_radius, length2(p - mid));

  const double zeta = hurwitz_zeta(options.c, options.N);
  // Every motif is at most the first one, enlarged by a stabilizer of order <= 12 when snapped.
  const double largest = std::sqrt(A / (zeta * std::pow(options.N, options.c)) * (policy == BoundaryPolicy::kSnap ? 12 : 1)) *
                         motif.bounding_radius;
  const bool turn = options.random_rotation && motif.kind == Motif2::Kind::kPolygon;
  const double turn_range = 2 * kPi / std::max(1, motif.rotation_order);
  Random random(options.seed);
  detail::GridIndex<2> index;
  std::vector<detail::Shape2> shapes;  // images of the placed motifs near the fundamental region
  FillResult2& result = out.fundamental;
  result.fill_fraction = detail::place_by_rule(
      A, options.c, options.N, options.max_count, options.min_area_mm2, "min_area", options.max_trials, "motif",
      result.stop_reason, [&](size_t, double area_i) {
        // Uniform in the fundamental region: uniform in its cell-coordinate box, kept when inside.
        Vec2d f;
        do f = {lo.x + (hi.x - lo.x) * random.uniform(), lo.y + (hi.y - lo.y) * random.uniform()};
        while (!detail::point_in_polygon(cell_region, f));
        Placement2 pl;
        pl.center_mm = pattern.frame.to_world(f);
        pl.area_mm2 = area_i;
        pl.scale = std::sqrt(area_i);
        if (turn) pl.angle_rad = turn_range * random.uniform();
        if (policy == BoundaryPolicy::kSnap && !snap(pattern, motif, region, pl)) return false;
        const detail::Shape2 s = detail::place(motif, pl);
        const double gap = options.gap_mm;
        if (index.any({s.center.x, s.center.y}, s.radius + gap,
                      [&](int id) { return detail::overlap(s, shapes[size_t(id)], gap); }))
          return false;
        // Its own images: those that could come within the gap, except the ones the policy lets it overlap.
        bool clear = true;
        pattern.images(s.center, s.center, 2 * s.radius + gap, [&](const Element& e, const Vec2d& q) {
          if (!clear || is_identity(e)) return;
          if (policy == BoundaryPolicy::kSnap && length2(q - s.center) <= pattern.tol) return;  // its stabilizer
          if (policy == BoundaryPolicy::kAllow && cuts(e.map, s, pattern.tol)) return;
          if (detail::overlap(s, detail::place(motif, transform(e.map, pl)), gap)) clear = false;
        });
        if (!clear) return false;
        // Keep every image that a later motif in the fundamental region could come near.
        pattern.images(s.center, mid, region_radius + s.radius + largest + gap, [&](const Element& e, const Vec2d&) {
          detail::Shape2 image = detail::place(motif, transform(e.map, pl));
          index.insert(int(shapes.size()), {image.center.x, image.center.y}, image.radius);
          shapes.push_back(std::move(image));
        });
        result.motifs.push_back(pl);
        return true;
      });
  return out;
}

std::vector<Placement2> replicate(const WallpaperFill& fill, int cells_u, int cells_v, std::vector<uint32_t>* orbits) {
  if (cells_u < 1 || cells_v < 1)
    throw InvalidInput("replicate needs at least one cell along each lattice vector, got " + std::to_string(cells_u) +
                       " x " + std::to_string(cells_v));
  const std::vector<Affine2> ops = world_operations(fill.group, fill.lattice);
  const double count = double(cells_u) * cells_v * double(ops.size()) * double(fill.fundamental.motifs.size());
  if (count > 1e8) throw ResourceLimit("replicate would make " + std::to_string(count) + " placements, over 100 000 000");
  const Frame f = frame_of(fill.lattice);
  std::vector<Placement2> out;
  if (orbits) orbits->clear();
  for (size_t motif = 0; motif < fill.fundamental.motifs.size(); ++motif) {
    const Placement2& pl = fill.fundamental.motifs[motif];
    std::vector<Vec2d> seen;
    for (const Affine2& op : ops) {
      Placement2 image = transform(op, pl);
      // Into the cell [0, 1)^2, a coordinate within 1e-9 below a whole number counting as that number.
      const Vec2d c = f.to_cell(image.center_mm);
      const Vec2d whole{std::floor(c.x + 1e-9), std::floor(c.y + 1e-9)};
      const Vec2d home = c - whole;
      bool repeated = false;
      for (const Vec2d& s : seen) repeated = repeated || (std::fabs(s.x - home.x) < 1e-9 && std::fabs(s.y - home.y) < 1e-9);
      if (repeated) continue;
      seen.push_back(home);
      image.center_mm = image.center_mm - f.to_world(whole);
      for (int i = 0; i < cells_u; ++i)
        for (int j = 0; j < cells_v; ++j) {
          Placement2 copy = image;
          copy.center_mm = image.center_mm + f.to_world({double(i), double(j)});
          out.push_back(copy);
          if (orbits) orbits->push_back(uint32_t(motif));
        }
    }
  }
  return out;
}

Coloring coloring_from_name(const std::string& name) {
  if (name == "size") return Coloring::kSize;
  if (name == "orbit") return Coloring::kOrbit;
  if (name == "random") return Coloring::kRandom;
  throw InvalidInput("expected size, orbit or random, got \"" + name + "\"");
}

std::vector<int> motif_colors(const FillResult2& fill, Coloring by, int palette_size, uint64_t seed) {
  if (palette_size < 1) throw InvalidInput("a palette needs at least one colour");
  std::vector<int> colors;
  colors.reserve(fill.motifs.size());
  Random random(seed ^ 0x636f6c6f7572ull);  // its own stream: the placements' generator is not disturbed
  const double first = fill.motifs.empty() ? 0 : fill.motifs.front().area_mm2;
  for (size_t i = 0; i < fill.motifs.size(); ++i) {
    switch (by) {
      case Coloring::kSize: {
        // Octaves of area below the first motif's, exact on powers of two.
        int k = 0;
        for (double a = first / 2; fill.motifs[i].area_mm2 <= a && k < 1000; a /= 2) ++k;
        colors.push_back(k % palette_size);
        break;
      }
      case Coloring::kOrbit: colors.push_back(int(i % size_t(palette_size))); break;
      case Coloring::kRandom: colors.push_back(int(random.next() % uint64_t(palette_size))); break;
    }
  }
  return colors;
}

std::vector<std::string> motif_palette_colors(const FillResult2& fill, Coloring by, const std::vector<std::string>& palette,
                                              uint64_t seed) {
  std::vector<std::string> colors;
  for (int c : motif_colors(fill, by, int(palette.size()), seed)) colors.push_back(palette[size_t(c)]);
  return colors;
}

std::vector<std::string> parse_palette(const std::string& text) {
  std::vector<std::string> palette;
  size_t start = 0;
  while (start <= text.size()) {
    const size_t comma = text.find(',', start);
    std::string c = text.substr(start, comma == std::string::npos ? std::string::npos : comma - start);
    while (!c.empty() && std::isspace(static_cast<unsigned char>(c.front()))) c.erase(c.begin());
    while (!c.empty() && std::isspace(static_cast<unsigned char>(c.back()))) c.pop_back();
    bool ok = c.size() == 7 && c[0] == '#';
    for (size_t k = 1; ok && k < 7; ++k) ok = std::isxdigit(static_cast<unsigned char>(c[k])) != 0;
    if (!ok)
      throw InvalidInput("colour " + std::to_string(palette.size() + 1) + " \"" + c + "\" is not #rrggbb (e.g. #1b9e77)");
    for (char& ch : c) ch = char(std::tolower(static_cast<unsigned char>(ch)));
    palette.push_back(c);
    if (palette.size() > 64) throw InvalidInput("a palette has at most 64 colours");
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
  return palette;
}

std::vector<std::string> default_palette() {
  return {"#1b9e77", "#d95f02", "#7570b3", "#e7298a", "#66a61e", "#e6ab02", "#a6761d", "#666666"};
}

std::string wallpaper_svg(const WallpaperFill& pattern, int cells, const std::vector<std::string>& fills) {
  if (!fills.empty() && fills.size() != pattern.fundamental.motifs.size())
    throw InvalidInput("one colour per motif of the fundamental region is needed: " +
                       std::to_string(pattern.fundamental.motifs.size()) + " motifs, " + std::to_string(fills.size()) +
                       " colours");
  std::vector<uint32_t> orbits;
  const std::vector<Placement2> all = replicate(pattern, cells, cells, &orbits);
  const Lattice& l = pattern.lattice;
  Vec2d lo{HUGE_VAL, HUGE_VAL}, hi{-HUGE_VAL, -HUGE_VAL};
  for (const Vec2d& q : {Vec2d{0, 0}, l.a * double(cells), l.b * double(cells), (l.a + l.b) * double(cells)}) {
    lo = Vec2d{std::min(lo.x, q.x), std::min(lo.y, q.y)};
    hi = Vec2d{std::max(hi.x, q.x), std::max(hi.y, q.y)};
  }
  char buf[256];
  std::ostringstream s;
  std::snprintf(buf, sizeof buf,
                "<svg xmlns=\"http://www.w3.org/2000/svg\" viewBox=\"%.6g %.6g %.6g %.6g\" width=\"800\">\n", lo.x,
                -hi.y, hi.x - lo.x, hi.y - lo.y);
  s << buf << "<g transform=\"scale(1,-1)\">\n";
  for (size_t k = 0; k < all.size(); ++k) {
    const Placement2& p = all[k];
    const char* colour = fills.empty() ? "black" : fills[orbits[k]].c_str();
    if (pattern.motif.kind == Motif2::Kind::kCircle) {
      std::snprintf(buf, sizeof buf, "<circle cx=\"%.9g\" cy=\"%.9g\" r=\"%.9g\" fill=\"%s\"/>\n", p.center_mm.x,
                    p.center_mm.y, p.scale / std::sqrt(3.14159265358979323846), colour);
      s << buf;
      continue;
    }
    s << "<polygon fill=\"" << colour << "\" points=\"";
    for (const Vec2d& q : placed_outline(pattern.motif, p)) {
      std::snprintf(buf, sizeof buf, "%.9g,%.9g ", q.x, q.y);
      s << buf;
    }
    s << "\"/>\n";
  }
  s << "<polygon fill=\"none\" stroke=\"red\" stroke-width=\"" << 0.002 * (hi.x - lo.x) << "\" points=\"";
  for (const Vec2d& q : fundamental_region_mm(pattern.group, l)) {
    std::snprintf(buf, sizeof buf, "%.9g,%.9g ", q.x, q.y);
    s << buf;
  }
  s << "\"/>\n</g>\n</svg>\n";
  return s.str();
}

}  // namespace fill
}  // namespace lacuna
