#include "bcifs/plate.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <string>
#include <utility>

#include "errors.h"

namespace lacuna {
namespace bcifs {
double plate_leaves(const Plate& plate) {
  double leaves = 0;
  for (int root : plate.rules.roots) leaves += lacunarity(plate.rules, root, plate.options.level).subfaces.back();
  return leaves;
}

std::vector<std::vector<Vec2d>> plate_loops(const Plate& plate, int level) {
  const PlateOptions& o = plate.options;
  std::vector<std::vector<Vec2d>> polygons;
  for (const auto& face : realize_assembly(plate.rules, o.assembly, o.controls, level, o.options, o.bends))
    for (auto& outline : polygons_of(face)) polygons.push_back(std::move(outline));
  return union_loops(polygons);
}

std::vector<std::vector<Vec2d>> union_loops(const std::vector<std::vector<Vec2d>>& polygons) {
  // Chained by following, from each end point, an unused edge that starts there (in-degree equals out-degree
  // at every vertex, so every chain closes).
  const auto segments = boundary_segments(polygons);
  auto key = [](const Vec2d& p) { return std::make_pair(p.x, p.y); };
  std::multimap<std::pair<double, double>, size_t> starts;
  for (size_t i = 0; i < segments.size(); ++i) starts.emplace(key(segments[i].first), i);
  std::vector<char> used(segments.size(), 0);
  std::vector<std::vector<Vec2d>> loops;
  for (size_t first = 0; first < segments.size(); ++first) {
    if (used[first]) continue;
    std::vector<Vec2d> loop;
    size_t s = first;
    for (;;) {
      used[s] = 1;
      loop.push_back(segments[s].first);
      const Vec2d end = segments[s].second;
      if (end == segments[first].first) break;
      size_t next = segments.size();
      auto range = starts.equal_range(key(end));
      for (auto it = range.first; it != range.second; ++it)
        if (!used[it->second]) {
          next = it->second;
          break;
        }
      if (next == segments.size()) throw std::logic_error("bcifs: the boundary of the leaves does not close");
      s = next;
    }
    loops.push_back(std::move(loop));
  }
  return loops;
}

CellKind cell_kind_from_name(const std::string& name) {
  if (name == "hexahedron") return CellKind::kHexahedron;
  if (name == "truncated_tetrahedron") return CellKind::kTruncatedTetrahedron;
  if (name == "tetrahedron") return CellKind::kTetrahedron;
  if (name == "prism") return CellKind::kPrism;
  throw InvalidInput("expected \"hexahedron\", \"truncated_tetrahedron\", \"tetrahedron\" or \"prism\", got \"" +
                     name + "\"");
}

std::vector<std::vector<Vec3d>> cell_faces(CellKind cell, double edge_mm) {
  std::vector<std::vector<Vec3d>> faces;
  if (cell == CellKind::kHexahedron) {
    const double h = edge_mm / 2;
    auto corner = [&](int i) { return Vec3d{i & 1 ? h : -h, i & 2 ? h : -h, i & 4 ? h : -h}; };
    for (const auto& f : std::vector<std::array<int, 4>>{
             {0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}})
      faces.push_back({corner(f[0]), corner(f[1]), corner(f[2]), corner(f[3])});
    return faces;
  }
  // Orient a face counter-clockwise seen from outside (the centre is the origin).
  auto outward = [](std::vector<Vec3d> f) {
    Vec3d n{0, 0, 0}, c{0, 0, 0};
    for (size_t k = 0; k < f.size(); ++k) {
      n += cross(f[k], f[(k + 1) % f.size()]);
      c += f[k];
    }
    if (dot(n, c) < 0) std::reverse(f.begin(), f.end());
    return f;
  };
  if (cell == CellKind::kTetrahedron) {
    const double h = edge_mm / (2 * std::sqrt(2.0));
    const std::array<Vec3d, 4> t = {Vec3d{h, h, h}, Vec3d{h, -h, -h}, Vec3d{-h, h, -h}, Vec3d{-h, -h, h}};
    for (const auto& f : std::vector<std::array<int, 3>>{{1, 2, 3}, {0, 3, 2}, {0, 1, 3}, {0, 2, 1}})
      faces.push_back(outward({t[size_t(f[0])], t[size_t(f[1])], t[size_t(f[2])]}));
    return faces;
  }
  if (cell == CellKind::kPrism) {
    const double r = edge_mm / std::sqrt(3.0), h = edge_mm / 2;
    std::array<Vec3d, 3> bottom, top;
    for (int k = 0; k < 3; ++k) {
      const double pi = std::acos(-1.0), a = pi / 2 + 2 * pi * k / 3;
      bottom[size_t(k)] = {r * std::cos(a), r * std::sin(a), -h};
      top[size_t(k)] = {r * std::cos(a), r * std::sin(a), h};
    }
    faces.push_back(outward({bottom[0], bottom[1], bottom[2]}));
    faces.push_back(outward({top[0], top[1], top[2]}));
    for (size_t k = 0; k < 3; ++k)
      faces.push_back(outward({bottom[k], bottom[(k + 1) % 3], top[(k + 1) % 3], top[k]}));
    return faces;
  }
  // The regular tetrahedron (1,1,1), (1,-1,-1), (-1,1,-1), (-1,-1,1) (edge 2 sqrt 2) with each corner cut a
  // third of the way along its edges: 12 vertices, edges 2 sqrt(2) / 3.
  const std::array<Vec3d, 4> t = {Vec3d{1, 1, 1}, Vec3d{1, -1, -1}, Vec3d{-1, 1, -1}, Vec3d{-1, -1, 1}};
  const double scale = edge_mm / (2 * std::sqrt(2.0) / 3);
  auto cut = [&](int i, int j) { return (t[size_t(i)] * (2.0 / 3) + t[size_t(j)] * (1.0 / 3)) * scale; };
  for (int i = 0; i < 4; ++i) {
    // The triangle cut off corner i, and the hexagon opposite it (the face of the other three corners).
    std::vector<int> others;
    for (int j = 0; j < 4; ++j)
      if (j != i) others.push_back(j);
    std::vector<Vec3d> triangle, hexagon;
    for (int j : others) triangle.push_back(cut(i, j));
    for (size_t k = 0; k < 3; ++k) {
      const int a = others[k], b = others[(k + 1) % 3];
      hexagon.push_back(cut(a, b));
      hexagon.push_back(cut(b, a));
    }
    for (auto* f : {&triangle, &hexagon}) {
      // Orient counter-clockwise seen from outside (the centre is the origin).
      Vec3d n{0, 0, 0}, c{0, 0, 0};
      for (size_t k = 0; k < f->size(); ++k) {
        n += cross((*f)[k], (*f)[(k + 1) % f->size()]);
        c += (*f)[k];
      }
      if (dot(n, c) < 0) std::reverse(f->begin(), f->end());
      faces.push_back(*f);
    }
  }
  return faces;
}

}  // namespace bcifs
}  // namespace lacuna
