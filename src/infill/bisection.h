// Tetrahedra of a cube grid refined where a size field asks for smaller ones, and conforming: every face
// of one is a whole face of its neighbour. Each cube is split into Kuhn's six tetrahedra around its main
// diagonal, corners listed along their path from the cube's lowest corner to its highest; Maubach's
// bisection (SIAM J. Sci. Comput. 16, 1995) then halves a tetrahedron (x0, x1, x2, x3) with tag k at the
// midpoint z of x0-xk into (x0 .. x(k-1), z, x(k+1) .. x3) and (x1 .. xk, z, x(k+1) .. x3), both with tag
// k - 1 (3 after 1). Three bisections make tetrahedra like the first at half the size; on Kuhn's grid the
// refinement edges of neighbours agree, so halving every tetrahedron that has a split edge until none has
// one ends, with a conforming grid.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <vector>

#include "geometry.h"

namespace lacuna {

struct GridTet {
  std::array<uint32_t, 4> v{};  // corners, in Maubach's order
  int tag = 3;                  // the refinement edge runs from v[0] to v[tag]
  int depth = 0;                // bisections since the grid's tetrahedron (3 per halving of the size)
};

// Kuhn's six tetrahedra of the cube whose corner bit b (x = 1, y = 2, z = 4) is vertex corner(b).
std::array<GridTet, 6> kuhn_tetrahedra(const std::function<uint32_t(int)>& corner);

// Bisects the tetrahedra until each that could reach the region of interest (some corner's `distances`
// entry, negative inside, below the tetrahedron's longest edge) has at least `wanted(its centroid)`
// bisections, and every tetrahedron with a split edge is split there too. New vertices (edge midpoints,
// one per edge) are appended to `points`, their `distance` to `distances` (one entry per point, in and
// out). `check(count)` is called as the list of tetrahedra grows, to refuse before it grows further.
void refine_grid_tets(std::vector<Vec3d>& points, std::vector<double>& distances, std::vector<GridTet>& tets,
                      const std::function<int(const Vec3d&)>& wanted, const std::function<double(const Vec3d&)>& distance,
                      const std::function<void(size_t)>& check);

}  // namespace lacuna
