#include "solids/region.h"

#include <CGAL/Constrained_Delaunay_triangulation_2.h>
#include <CGAL/Constrained_triangulation_plus_2.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Triangulation_face_base_with_info_2.h>
#include <CGAL/Triangulation_vertex_base_with_info_2.h>

#include <algorithm>
#include <cmath>
#include <list>
#include <string>

#include "errors.h"

namespace lacuna {
namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
struct FaceInfo {
  int nesting_level = -1;
  bool in_domain() const { return nesting_level % 2 == 1; }
};
using VertexBase = CGAL::Triangulation_vertex_base_with_info_2<uint32_t, Kernel>;
using FaceBaseInfo = CGAL::Triangulation_face_base_with_info_2<FaceInfo, Kernel>;
using FaceBase = CGAL::Constrained_triangulation_face_base_2<Kernel, FaceBaseInfo>;
using Tds = CGAL::Triangulation_data_structure_2<VertexBase, FaceBase>;
// Crossing loops would need new intersection points; refuse them instead of guessing.
using CdtBase = CGAL::Constrained_Delaunay_triangulation_2<Kernel, Tds,
                                                           CGAL::No_constraint_intersection_requiring_constructions_tag>;
// The "plus" hierarchy counts how many loops run along each constrained edge, for the even-odd rule.
using Cdt = CGAL::Constrained_triangulation_plus_2<CdtBase>;

// Whether the constrained edge separates material from void: an edge that an even number of loop
// edges run along (two identical loops, a loop doubling back) is no border under the even-odd rule.
bool is_border(const Cdt& cdt, const Cdt::Edge& e) {
  if (!cdt.is_constrained(e)) return false;
  const auto va = e.first->vertex(Cdt::cw(e.second)), vb = e.first->vertex(Cdt::ccw(e.second));
  return cdt.number_of_enclosing_constraints(va, vb) % 2 == 1;
}

// Nesting level of every face: 0 outside, odd inside the material (even-odd rule), as in CGAL's
// polygon-with-holes example.
void mark_domains(Cdt& cdt) {
  for (auto f : cdt.all_face_handles()) f->info().nesting_level = -1;
  std::list<Cdt::Edge> border;
  auto flood = [&](Cdt::Face_handle start, int level) {
    if (start->info().nesting_level != -1) return;
    std::list<Cdt::Face_handle> queue{start};
    while (!queue.empty()) {
      Cdt::Face_handle fh = queue.front();
      queue.pop_front();
      if (fh->info().nesting_level != -1) continue;
      fh->info().nesting_level = level;
      for (int i = 0; i < 3; ++i) {
        Cdt::Edge e(fh, i);
        Cdt::Face_handle n = fh->neighbor(i);
        if (n->info().nesting_level == -1) {
          if (is_border(cdt, e)) border.push_back(e);
          else queue.push_back(n);
        }
      }
    }
  };
  flood(cdt.infinite_face(), 0);
  while (!border.empty()) {
    Cdt::Edge e = border.front();
    border.pop_front();
    Cdt::Face_handle n = e.first->neighbor(e.second);
    if (n->info().nesting_level == -1) flood(n, e.first->info().nesting_level + 1);
  }
}

Cdt triangulate(const Region2& region) {
  Cdt cdt;
  try {
    for (size_t l = 0; l < region.loops_mm.size(); ++l) {
      const auto& loop = region.loops_mm[l];
      if (loop.size() < 3)
        throw InvalidInput("region loop " + std::to_string(l) + ": needs at least 3 points");
      std::vector<Kernel::Point_2> points;
      for (const Vec2d& p : loop) {
        if (!std::isfinite(p.x) || !std::isfinite(p.y))
          throw InvalidInput("region loop " + std::to_string(l) + ": has a non-finite point");
        points.emplace_back(p.x, p.y);
      }
      // A loop on one line (or of one repeated point) encloses nothing, and leaves the triangulation
      // without faces when it is the only one.
      const auto second = std::find_if(points.begin(), points.end(), [&](const Kernel::Point_2& p) { return p != points.front(); });
      const bool flat = second == points.end() || std::none_of(points.begin(), points.end(), [&](const Kernel::Point_2& q) {
                          return CGAL::orientation(points.front(), *second, q) != CGAL::COLLINEAR;
                        });
      if (flat)
        throw InvalidInput("region loop " + std::to_string(l) + ": its points lie on one line (or repeat one point); a loop must enclose an area");
      cdt.insert_constraint(points.begin(), points.end(), /*close=*/true);
    }
  } catch (const Cdt::Intersection_of_constraints_exception&) {
    throw InvalidInput("region: loops cross each other or themselves");
  }
  if (cdt.dimension() < 2) throw InvalidInput("region: the loops enclose no area");
  mark_domains(cdt);
  return cdt;
}

}  // namespace

TriMesh extrude_region(const Region2& region) {
  Cdt cdt = triangulate(region);
  TriMesh mesh;
  const Vec3d normal = cross(region.axis_u, region.axis_v);
  const Vec3d lift = normal * region.height_mm;
  uint32_t n = 0;
  for (auto v : cdt.finite_vertex_handles()) v->info() = n++;
  mesh.positions_mm.resize(2 * size_t(n));
  for (auto v : cdt.finite_vertex_handles()) {
    Vec3d p = region.origin_mm + region.axis_u * v->point().x() + region.axis_v * v->point().y();
    mesh.positions_mm[v->info()] = p;
    mesh.positions_mm[n + v->info()] = p + lift;
  }
  for (auto f : cdt.finite_face_handles()) {
    if (!f->info().in_domain()) continue;
    uint32_t a = f->vertex(0)->info(), b = f->vertex(1)->info(), c = f->vertex(2)->info();
    mesh.triangles.push_back({n + a, n + b, n + c});  // top, counter-clockwise seen from +normal
    mesh.triangles.push_back({a, c, b});              // bottom, facing -normal
    for (int i = 0; i < 3; ++i) {
      Cdt::Face_handle other = f->neighbor(i);
      if (other->info().in_domain()) continue;
      // Edge opposite vertex i, running counter-clockwise around f: the wall faces away from f.
      uint32_t p = f->vertex(cdt.ccw(i))->info(), q = f->vertex(cdt.cw(i))->info();
      mesh.triangles.push_back({p, q, n + q});
      mesh.triangles.push_back({p, n + q, n + p});
    }
  }
  if (mesh.triangles.empty()) throw InvalidInput("region: the loops enclose no area");
  return mesh;
}

double region_area_mm2(const Region2& region) {
  Cdt cdt = triangulate(region);
  double area = 0;
  for (auto f : cdt.finite_face_handles())
    if (f->info().in_domain()) area += std::fabs(cdt.triangle(f).area());
  return area;
}

}  // namespace lacuna
