#include "infill/bisection.h"

#include <algorithm>
#include <cmath>
#include <unordered_map>
#include <utility>

namespace lacuna {
namespace {

uint64_t edge_key(uint32_t a, uint32_t b) {
  if (a > b) std::swap(a, b);
  return (uint64_t(a) << 32) | b;
}

constexpr int kEdges[6][2] = {{0, 1}, {0, 2}, {0, 3}, {1, 2}, {1, 3}, {2, 3}};

}  // namespace

std::array<GridTet, 6> kuhn_tetrahedra(const std::function<uint32_t(int)>& corner) {
  static const int kKuhn[6][4] = {{0, 1, 3, 7}, {0, 1, 5, 7}, {0, 2, 3, 7}, {0, 2, 6, 7}, {0, 4, 5, 7}, {0, 4, 6, 7}};
  std::array<GridTet, 6> out;
  for (size_t t = 0; t < 6; ++t)
    for (size_t q = 0; q < 4; ++q) out[t].v[q] = corner(kKuhn[t][q]);
  return out;
}

void refine_grid_tets(std::vector<Vec3d>& points, std::vector<double>& dist, std::vector<GridTet>& tets,
                      const std::function<int(const Vec3d&)>& wanted, const std::function<double(const Vec3d&)>& distance,
                      const std::function<void(size_t)>& check) {
  std::unordered_map<uint64_t, uint32_t> midpoint;  // every split edge, with its midpoint
  auto bisect = [&](size_t t) {
    const GridTet parent = tets[t];
    const int k = parent.tag;
    const uint32_t a = parent.v[0], b = parent.v[size_t(k)];
    const auto [it, made] = midpoint.try_emplace(edge_key(a, b), uint32_t(points.size()));
    if (made) {
      points.push_back((points[a] + points[b]) * 0.5);
      dist.push_back(distance(points.back()));
    }
    const uint32_t z = it->second;
    GridTet first, second;
    size_t n = 0, m = 0;
    for (int i = 0; i < k; ++i) first.v[n++] = parent.v[size_t(i)];
    first.v[n++] = z;
    for (int i = 1; i <= k; ++i) second.v[m++] = parent.v[size_t(i)];
    second.v[m++] = z;
    for (int i = k + 1; i < 4; ++i) first.v[n++] = second.v[m++] = parent.v[size_t(i)];
    first.tag = second.tag = k > 1 ? k - 1 : 3;
    first.depth = second.depth = parent.depth + 1;
    tets[t] = first;
    tets.push_back(second);
    check(tets.size());
  };
  auto split_edge = [&](const GridTet& t) {
    for (const auto& e : kEdges)
      if (midpoint.count(edge_key(t.v[size_t(e[0])], t.v[size_t(e[1])]))) return true;
    return false;
  };
  auto coarse = [&](const GridTet& t) {
    Vec3d centre{0, 0, 0};
    double nearest = HUGE_VAL, longest = 0;
    for (uint32_t v : t.v) {
      centre += points[v] * 0.25;
      nearest = std::min(nearest, dist[v]);
    }
    for (const auto& e : kEdges) longest = std::max(longest, norm(points[t.v[size_t(e[0])]] - points[t.v[size_t(e[1])]]));
    return nearest < longest && t.depth < wanted(centre);
  };
  for (bool changed = true; changed;) {
    changed = false;
    // Each pass first halves what the field wants smaller, then what a split neighbour leaves hanging; a
    // halved tetrahedron is looked at again in the same pass (its first half in place, its second appended).
    for (size_t t = 0; t < tets.size(); ++t)
      while (coarse(tets[t]) || split_edge(tets[t])) {
        bisect(t);
        changed = true;
      }
  }
}

}  // namespace lacuna
