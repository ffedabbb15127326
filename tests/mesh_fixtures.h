// Triangle meshes of simple solids that several test files build their cases from.
#pragma once

#include <algorithm>
#include <array>
#include <map>
#include <utility>
#include <vector>

#include "geometry.h"

namespace lacuna {
namespace test {

// The triangles of a (cells + 1) x (cells + 1) vertex grid, vertex (i, j) at j * (cells + 1) + i: each cell
// split in two with diagonals alternating, counter-clockwise when i runs along +x and j along +y.
inline void append_grid_triangles(TriMesh& mesh, int cells) {
  auto at = [&](int i, int j) { return uint32_t(j * (cells + 1) + i); };
  for (int j = 0; j < cells; ++j)
    for (int i = 0; i < cells; ++i) {
      const uint32_t a = at(i, j), b = at(i + 1, j), c = at(i + 1, j + 1), d = at(i, j + 1);
      if ((i + j) % 2 == 0) {
        mesh.triangles.push_back({a, b, c});
        mesh.triangles.push_back({a, c, d});
      } else {
        mesh.triangles.push_back({a, b, d});
        mesh.triangles.push_back({b, c, d});
      }
    }
}

// An octahedron subdivided `levels` times and pushed onto the sphere of radius r about c: closed,
// outward, 8 * 4^levels triangles.
inline TriMesh geodesic_sphere(const Vec3d& c, double r, int levels) {
  TriMesh m;
  m.positions_mm = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
  m.triangles = {{0, 2, 4}, {2, 1, 4}, {1, 3, 4}, {3, 0, 4}, {2, 0, 5}, {1, 2, 5}, {3, 1, 5}, {0, 3, 5}};
  for (int l = 0; l < levels; ++l) {
    std::map<std::pair<uint32_t, uint32_t>, uint32_t> middle;
    auto mid = [&](uint32_t a, uint32_t b) {
      auto key = std::minmax(a, b);
      auto it = middle.find(key);
      if (it != middle.end()) return it->second;
      m.positions_mm.push_back((m.positions_mm[a] + m.positions_mm[b]) * 0.5);
      return middle[key] = uint32_t(m.positions_mm.size() - 1);
    };
    std::vector<std::array<uint32_t, 3>> next;
    for (auto [a, b, d] : m.triangles) {
      const uint32_t ab = mid(a, b), bd = mid(b, d), da = mid(d, a);
      next.insert(next.end(), {{a, ab, da}, {ab, b, bd}, {da, bd, d}, {ab, bd, da}});
    }
    m.triangles = std::move(next);
  }
  for (Vec3d& p : m.positions_mm) p = c + p * (r / norm(p));
  return m;
}

// Appends the axis-aligned box [lo, hi] as 8 corners and 12 outward triangles.
inline void append_box(TriMesh& m, const Vec3d& lo, const Vec3d& hi) {
  const auto base = uint32_t(m.positions_mm.size());
  for (int i = 0; i < 8; ++i)
    m.positions_mm.push_back({(i & 1) ? hi.x : lo.x, (i & 2) ? hi.y : lo.y, (i & 4) ? hi.z : lo.z});
  const uint32_t quads[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  for (const auto& q : quads) {
    m.triangles.push_back({base + q[0], base + q[1], base + q[2]});
    m.triangles.push_back({base + q[0], base + q[2], base + q[3]});
  }
}

}  // namespace test
}  // namespace lacuna
