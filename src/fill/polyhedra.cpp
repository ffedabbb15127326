#include "fill/polyhedra.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <utility>

#include "errors.h"
#include "fill/shape2.h"

namespace lacuna {
namespace fill {
namespace {

constexpr double kPi = 3.14159265358979323846;
using Matrix3 = std::array<std::array<double, 3>, 3>;

std::string number(double v) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.17g", v);
  return buffer;
}

Vec3d rotate(const Matrix3& m, const Vec3d& v) {
  return {m[0][0] * v.x + m[0][1] * v.y + m[0][2] * v.z, m[1][0] * v.x + m[1][1] * v.y + m[1][2] * v.z,
          m[2][0] * v.x + m[2][1] * v.y + m[2][2] * v.z};
}

// Newell's normal of a face, unit length (zero for a degenerate face).
Vec3d face_normal(const std::vector<Vec3d>& v, const std::vector<int>& face) {
  Vec3d n;
  for (size_t i = 0, k = face.size(); i < k; ++i) {
    const Vec3d& p = v[size_t(face[i])];
    const Vec3d& q = v[size_t(face[(i + 1) % k])];
    n += Vec3d{(p.y - q.y) * (p.z + q.z), (p.z - q.z) * (p.x + q.x), (p.x - q.x) * (p.y + q.y)};
  }
  const double l = norm(n);
  return l > 0 ? n / l : Vec3d{};
}

Vec3d face_center(const std::vector<Vec3d>& v, const std::vector<int>& face) {
  Vec3d c;
  for (int i : face) c += v[size_t(i)];
  return c / double(face.size());
}

// Faces turned counter-clockwise seen from outside (the origin is inside), and the bounding radius.
Motif3 make_motif(std::vector<Vec3d> vertices, std::vector<std::vector<int>> faces) {
  Motif3 m;
  m.vertices = std::move(vertices);
  for (std::vector<int>& f : faces)
    if (dot(face_normal(m.vertices, f), face_center(m.vertices, f)) < 0) std::reverse(f.begin(), f.end());
  m.faces = std::move(faces);
  for (const Vec3d& p : m.vertices) m.bounding_radius = std::max(m.bounding_radius, norm(p));
  return m;
}

// The motif's separating-axis candidates in its own frame, each direction once up to sign, and the probe
// points whose signed distance decides containment.
struct MotifFrame {
  std::vector<Vec3d> normals;  // unit face normals
  std::vector<Vec3d> edges;    // unit edge directions
  std::vector<Vec3d> probes;   // centroid, vertices, edge midpoints, face centroids
  double inradius = 0;         // least distance from the centroid to a face plane
};

void add_direction(std::vector<Vec3d>& list, const Vec3d& d) {
  for (const Vec3d& e : list)
    if (std::fabs(dot(e, d)) > 1 - 1e-12) return;
  list.push_back(d);
}

MotifFrame frame_of(const Motif3& m) {
  MotifFrame f;
  f.inradius = HUGE_VAL;
  f.probes.push_back({0, 0, 0});
  f.probes.insert(f.probes.end(), m.vertices.begin(), m.vertices.end());
  std::vector<std::pair<int, int>> seen;
  for (const std::vector<int>& face : m.faces) {
    const Vec3d n = face_normal(m.vertices, face);
    add_direction(f.normals, n);
    f.inradius = std::min(f.inradius, dot(n, m.vertices[size_t(face[0])]));
    f.probes.push_back(face_center(m.vertices, face));
    for (size_t i = 0, k = face.size(); i < k; ++i) {
      const int a = face[i], b = face[(i + 1) % k];
      const std::pair<int, int> key{std::min(a, b), std::max(a, b)};
      if (std::find(seen.begin(), seen.end(), key) != seen.end()) continue;
      seen.push_back(key);
      const Vec3d e = m.vertices[size_t(b)] - m.vertices[size_t(a)];
      add_direction(f.edges, e / norm(e));
      f.probes.push_back((m.vertices[size_t(a)] + m.vertices[size_t(b)]) * 0.5);
    }
  }
  return f;
}

// Throws InvalidInput unless the motif is a closed convex polyhedron of volume 1 with its centroid at the
// origin and outward, planar faces (all to 1e-9).
void check_motif(const Motif3& m) {
  if (m.vertices.size() < 4 || m.faces.size() < 4) throw InvalidInput("a polyhedron motif needs at least 4 vertices and 4 faces");
  for (const Vec3d& p : m.vertices)
    if (!is_finite(p)) throw InvalidInput("a polyhedron motif has a non-finite vertex");
  for (size_t i = 0; i < m.faces.size(); ++i) {
    if (m.faces[i].size() < 3) throw InvalidInput("polyhedron motif face " + std::to_string(i) + " has fewer than 3 vertices");
    for (int v : m.faces[i])
      if (v < 0 || size_t(v) >= m.vertices.size())
        throw InvalidInput("polyhedron motif face " + std::to_string(i) + " has a vertex index out of range");
  }
  double volume = 0;
  Vec3d centroid;
  for (const std::vector<int>& face : m.faces)
    for (size_t i = 1; i + 1 < face.size(); ++i) {
      const Vec3d &a = m.vertices[size_t(face[0])], &b = m.vertices[size_t(face[i])], &c = m.vertices[size_t(face[i + 1])];
      const double v = dot(a, cross(b, c)) / 6;
      volume += v;
      centroid += (a + b + c) * (v / 4);
    }
  if (!(std::fabs(volume - 1) <= 1e-9))
    throw InvalidInput("a polyhedron motif must have volume 1 (faces counter-clockwise from outside), got " + number(volume));
  if (!(norm(centroid) <= 1e-9)) throw InvalidInput("a polyhedron motif must have its centroid at the origin");
  double radius = 0;
  for (const Vec3d& p : m.vertices) radius = std::max(radius, norm(p));
  if (!(std::fabs(radius - m.bounding_radius) <= 1e-9 * radius))
    throw InvalidInput("a polyhedron motif's bounding_radius must be its largest vertex distance, " + number(radius));
  for (size_t i = 0; i < m.faces.size(); ++i) {
    const Vec3d n = face_normal(m.vertices, m.faces[i]);
    const Vec3d& p0 = m.vertices[size_t(m.faces[i][0])];
    for (const Vec3d& p : m.vertices)
      if (dot(n, p - p0) > 1e-9 * radius)
        throw InvalidInput("a polyhedron motif must be convex with planar, outward faces; face " + std::to_string(i) + " is not");
    for (int v : m.faces[i])
      if (std::fabs(dot(n, m.vertices[size_t(v)] - p0)) > 1e-9 * radius)
        throw InvalidInput("polyhedron motif face " + std::to_string(i) + " is not planar");
  }
}

// A motif placed in space, with its axes turned into world space.
struct Shape3 {
  Vec3d center;
  double radius = 0;
  std::vector<Vec3d> vertices;
  std::vector<Vec3d> normals;
  std::vector<Vec3d> edges;
};

Shape3 place(const Motif3& m, const MotifFrame& f, const Placement3& pl) {
  Shape3 s;
  s.center = pl.center_mm;
  s.radius = pl.scale * m.bounding_radius;
  s.vertices = placed_vertices(m, pl);
  for (const Vec3d& n : f.normals) s.normals.push_back(rotate(pl.rotation, n));
  for (const Vec3d& e : f.edges) s.edges.push_back(rotate(pl.rotation, e));
  return s;
}

// Whether the projections of the two vertex sets on the unit axis are at least gap apart.
bool separated_along(const Vec3d& axis, const Shape3& a, const Shape3& b, double gap) {
  double amin = HUGE_VAL, amax = -HUGE_VAL, bmin = HUGE_VAL, bmax = -HUGE_VAL;
  for (const Vec3d& p : a.vertices) {
    const double t = dot(p, axis);
    amin = std::min(amin, t), amax = std::max(amax, t);
  }
  for (const Vec3d& p : b.vertices) {
    const double t = dot(p, axis);
    bmin = std::min(bmin, t), bmax = std::max(bmax, t);
  }
  return bmin - amax >= gap || amin - bmax >= gap;
}

bool overlap(const Shape3& a, const Shape3& b, double gap) {
  if (norm(a.center - b.center) >= a.radius + b.radius + gap) return false;
  for (const Vec3d& n : a.normals)
    if (separated_along(n, a, b, gap)) return false;
  for (const Vec3d& n : b.normals)
    if (separated_along(n, a, b, gap)) return false;
  for (const Vec3d& ea : a.edges)
    for (const Vec3d& eb : b.edges) {
      const Vec3d n = cross(ea, eb);
      const double l = norm(n);
      // Parallel edges add no axis that the face normals miss; any unit axis is a valid lower bound.
      if (l > 1e-12 && separated_along(n / l, a, b, gap)) return false;
    }
  return true;
}

// A uniformly distributed rotation, from a uniform unit quaternion (Shoemake's method).
Matrix3 random_rotation_matrix(Random& random) {
  const double u1 = random.uniform(), u2 = random.uniform(), u3 = random.uniform();
  const double a = std::sqrt(1 - u1), b = std::sqrt(u1);
  const double x = a * std::sin(2 * kPi * u2), y = a * std::cos(2 * kPi * u2);
  const double z = b * std::sin(2 * kPi * u3), w = b * std::cos(2 * kPi * u3);
  return {{{1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)},
           {2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)},
           {2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)}}};
}

}  // namespace

Motif3 cube_motif() {
  std::vector<Vec3d> v;
  for (int i = 0; i < 8; ++i) v.push_back({i & 1 ? 0.5 : -0.5, i & 2 ? 0.5 : -0.5, i & 4 ? 0.5 : -0.5});
  return make_motif(v, {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}});
}

Motif3 tetrahedron_motif() {
  // The tetrahedron on alternate corners of the cube [-1, 1]^3 has volume 8 - 4 * 4/3 = 8/3.
  const double s = std::cbrt(3.0 / 8);
  return make_motif({{s, s, s}, {s, -s, -s}, {-s, s, -s}, {-s, -s, s}}, {{0, 1, 2}, {0, 3, 1}, {0, 2, 3}, {1, 3, 2}});
}

Motif3 octahedron_motif() {
  // Vertices at distance a on the axes: volume 4 a^3 / 3.
  const double a = std::cbrt(3.0 / 4);
  return make_motif({{a, 0, 0}, {-a, 0, 0}, {0, a, 0}, {0, -a, 0}, {0, 0, a}, {0, 0, -a}},
                    {{0, 2, 4}, {2, 1, 4}, {1, 3, 4}, {3, 0, 4}, {2, 0, 5}, {1, 2, 5}, {3, 1, 5}, {0, 3, 5}});
}

std::vector<Vec3d> placed_vertices(const Motif3& motif, const Placement3& placement) {
  std::vector<Vec3d> out;
  out.reserve(motif.vertices.size());
  for (const Vec3d& p : motif.vertices) out.push_back(placement.center_mm + rotate(placement.rotation, p) * placement.scale);
  return out;
}

bool polyhedra_overlap(const Motif3& a, const Placement3& pa, const Motif3& b, const Placement3& pb, double gap_mm) {
  return overlap(place(a, frame_of(a), pa), place(b, frame_of(b), pb), gap_mm);
}

FillResult3P fill_polyhedra(const SignedDistance3& signed_distance_mm, const Box3& box, double volume_mm3,
                            const Motif3& motif, const FillOptions3& options, bool random_rotation) {
  detail::check_law(options.c, options.N, options.gap_mm, options.boundary_gap_mm, options.max_trials, options.max_count);
  if (!signed_distance_mm) throw InvalidInput("fill_polyhedra needs a signed distance function");
  if (box.empty() || !is_finite(box.min) || !is_finite(box.max))
    throw InvalidInput("fill_polyhedra needs a finite, non-empty box");
  if (!(std::isfinite(volume_mm3) && volume_mm3 > 0))
    throw InvalidInput("fill_polyhedra needs a region volume > 0, got " + number(volume_mm3));
  check_motif(motif);
  const MotifFrame frame = frame_of(motif);
  const double g = options.boundary_gap_mm;
  Random random(options.seed);
  detail::GridIndex<3> index;
  std::vector<Shape3> shapes;
  FillResult3P result;
  result.fill_fraction = detail::place_by_rule(
      volume_mm3, options.c, options.N, options.max_count, options.min_volume_mm3, "min_volume", options.max_trials,
      "motif", result.stop_reason, [&](size_t, double volume_i) {
        Placement3 pl;
        pl.volume_mm3 = volume_i;
        pl.scale = std::cbrt(volume_i);
        // The motif reaches at least its inradius from its centroid in every direction, so a motif inside the
        // region has its centre in the box shrunk by that plus the boundary gap; centres are drawn there.
        const double m = pl.scale * frame.inradius + g;
        const Vec3d lo = box.min + Vec3d{m, m, m}, hi = box.max - Vec3d{m, m, m};
        pl.center_mm = {lo.x + (hi.x - lo.x) * random.uniform(), lo.y + (hi.y - lo.y) * random.uniform(),
                        lo.z + (hi.z - lo.z) * random.uniform()};
        if (random_rotation) pl.rotation = random_rotation_matrix(random);
        if (lo.x > hi.x || lo.y > hi.y || lo.z > hi.z) return false;
        for (size_t k = 0; k < frame.probes.size(); ++k)
          if (!(signed_distance_mm(pl.center_mm + rotate(pl.rotation, frame.probes[k]) * pl.scale) <= -g)) return false;
        Shape3 s = place(motif, frame, pl);
        const double gap = options.gap_mm;
        if (index.any({s.center.x, s.center.y, s.center.z}, s.radius + gap,
                      [&](int id) { return overlap(s, shapes[size_t(id)], gap); }))
          return false;
        index.insert(int(shapes.size()), {s.center.x, s.center.y, s.center.z}, s.radius);
        shapes.push_back(std::move(s));
        result.motifs.push_back(pl);
        return true;
      });
  return result;
}

}  // namespace fill
}  // namespace lacuna
