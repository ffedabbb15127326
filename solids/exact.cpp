#include "solids/exact.h"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>

namespace lacuna::exact {
namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Point = Kernel::Point_3;

inline Point pt(const Vec3d& v) { return Point(v.x, v.y, v.z); }

// Whether the closed segment pq meets the closed triangle abc, given the sides op = orient3d(a,
// b, c, p) and oq = orient3d(a, b, c, q): when pq is not in the plane, it meets the triangle
// exactly when its line passes through it (Plücker signs of the line against the three edges all
// agree, zeros allowed); a segment in the plane goes to CGAL's coplanar test.
bool segment_meets_plane_triangle(const Vec3d& p, const Vec3d& q, int op, int oq, const Vec3d& a, const Vec3d& b,
                            const Vec3d& c) {
  if (op != 0 && op == oq) return false;
  if (op == 0 && oq == 0) return segment_meets_triangle(p, q, a, b, c);
  const int s0 = orient3d(p, q, a, b), s1 = orient3d(p, q, b, c), s2 = orient3d(p, q, c, a);
  return !((s0 > 0 || s1 > 0 || s2 > 0) && (s0 < 0 || s1 < 0 || s2 < 0));
}

// Triangles t = (s, t1, t2) and u = (s, u1, u2) sharing only s meet elsewhere exactly when one's
// opposite edge meets the other: their intersection is convex and contains s, so any further
// point lies on a segment from s that leaves one of them through its opposite edge (coplanar
// overlaps included, since a common ray from s crosses both opposite edges).
bool share_vertex_and_meet(const Vec3d& s, const Vec3d& t1, const Vec3d& t2, const Vec3d& u1, const Vec3d& u2) {
  // Fast exits: the other triangle's free corners strictly on one side of this one's plane.
  const int a = orient3d(s, t1, t2, u1), b = orient3d(s, t1, t2, u2);
  if (a != 0 && a == b) return false;
  const int c = orient3d(s, u1, u2, t1), d = orient3d(s, u1, u2, t2);
  if (c != 0 && c == d) return false;
  return segment_meets_plane_triangle(t1, t2, c, d, s, u1, u2) || segment_meets_plane_triangle(u1, u2, a, b, s, t1, t2);
}

// Triangles (p, q, r) and (q, p, s) or (p, q, s) sharing the edge pq overlap beyond it exactly
// when they are coplanar with r and s on the same side of the edge.
bool share_edge_and_meet(const Vec3d& p, const Vec3d& q, const Vec3d& r, const Vec3d& s) {
  if (orient3d(p, q, r, s) != 0) return false;
  return CGAL::coplanar_orientation(pt(p), pt(q), pt(r), pt(s)) == CGAL::POSITIVE;
}

}  // namespace

int orient3d_exact(const Vec3d& a, const Vec3d& b, const Vec3d& c, const Vec3d& d) {
  switch (CGAL::orientation(pt(a), pt(b), pt(c), pt(d))) {
    case CGAL::POSITIVE: return 1;
    case CGAL::NEGATIVE: return -1;
    default: return 0;
  }
}

int orient2d_exact(double ax, double ay, double bx, double by, double cx, double cy) {
  switch (CGAL::orientation(Kernel::Point_2(ax, ay), Kernel::Point_2(bx, by), Kernel::Point_2(cx, cy))) {
    case CGAL::LEFT_TURN: return 1;
    case CGAL::RIGHT_TURN: return -1;
    default: return 0;
  }
}


bool segment_meets_triangle(const Vec3d& p, const Vec3d& q, const Vec3d& a, const Vec3d& b, const Vec3d& c) {
  return CGAL::do_intersect(Kernel::Segment_3(pt(p), pt(q)), Kernel::Triangle_3(pt(a), pt(b), pt(c)));
}

bool triangles_meet(const Vec3d& a, const Vec3d& b, const Vec3d& c, const Vec3d& d, const Vec3d& e, const Vec3d& f) {
  return CGAL::do_intersect(Kernel::Triangle_3(pt(a), pt(b), pt(c)), Kernel::Triangle_3(pt(d), pt(e), pt(f)));
}

bool faces_intersect(const std::array<Vec3d, 3>& tp, const std::array<uint32_t, 3>& t,
                     const std::array<Vec3d, 3>& up, const std::array<uint32_t, 3>& u) {
  int shared = 0, ti[3] = {0, 0, 0}, ui[3] = {0, 0, 0};
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      if (t[size_t(i)] == u[size_t(j)]) {
        ti[shared] = i;
        ui[shared] = j;
        ++shared;
      }
  if (shared == 0) {
    // Fast exits: one triangle strictly on one side of the other's plane.
    const int a = orient3d(tp[0], tp[1], tp[2], up[0]);
    if (a != 0 && a == orient3d(tp[0], tp[1], tp[2], up[1]) && a == orient3d(tp[0], tp[1], tp[2], up[2])) return false;
    const int b = orient3d(up[0], up[1], up[2], tp[0]);
    if (b != 0 && b == orient3d(up[0], up[1], up[2], tp[1]) && b == orient3d(up[0], up[1], up[2], tp[2])) return false;
    return triangles_meet(tp[0], tp[1], tp[2], up[0], up[1], up[2]);
  }
  if (shared >= 3) return true;
  if (shared == 1) {
    const int i = ti[0], j = ui[0];
    return share_vertex_and_meet(tp[size_t(i)], tp[size_t((i + 1) % 3)], tp[size_t((i + 2) % 3)],
                                 up[size_t((j + 1) % 3)], up[size_t((j + 2) % 3)]);
  }
  const int r = 3 - ti[0] - ti[1], s = 3 - ui[0] - ui[1];
  return share_edge_and_meet(tp[size_t(ti[0])], tp[size_t(ti[1])], tp[size_t(r)], up[size_t(s)]);
}

bool faces_intersect(const Vec3d* positions, const std::array<uint32_t, 3>& t, const std::array<uint32_t, 3>& u) {
  return faces_intersect({positions[t[0]], positions[t[1]], positions[t[2]]}, t,
                         {positions[u[0]], positions[u[1]], positions[u[2]]}, u);
}

}  // namespace lacuna::exact
