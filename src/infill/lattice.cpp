#include "infill/lattice.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <string>
#include <tuple>
#include <unordered_map>
#include <unordered_set>

#include "errors.h"

namespace lacuna {

double GradeField::at(const Vec3d& p, const std::function<double(const Vec3d&)>& depth_of) const {
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

Vec3d project_to_level(const std::function<double(const Vec3d&)>& sd, const Vec3d& p, double inset_mm, double step_mm) {
  Vec3d x = p;
  for (int iteration = 0; iteration < 12; ++iteration) {
    const double d = sd(x) + inset_mm;
    if (std::abs(d) < 1e-9 * step_mm) break;
    Vec3d g;
    for (int k = 0; k < 3; ++k) {
      Vec3d e{0, 0, 0};
      e[k] = step_mm;
      g[k] = (sd(x + e) - sd(x - e)) / (2 * step_mm);
    }
    const double g2 = dot(g, g);
    if (!(g2 > 1e-12)) break;
    x = x - g * (d / g2);
  }
  return x;
}

namespace {

// A node of the finest grid, in half units of the finest cell (so bcc centres are nodes too).
struct Node {
  int64_t i, j, k;
  bool operator==(const Node& o) const { return i == o.i && j == o.j && k == o.k; }
};
struct Edge {
  Node a, b;
  bool operator==(const Edge& o) const { return a == o.a && b == o.b; }
};
struct EdgeHash {
  size_t operator()(const Edge& e) const {
    uint64_t h = 1469598103934665603ull;
    for (int64_t v : {e.a.i, e.a.j, e.a.k, e.b.i, e.b.j, e.b.k}) h = (h ^ uint64_t(v)) * 1099511628211ull;
    return size_t(h);
  }
};
struct NodeHash {
  size_t operator()(const Node& n) const { return EdgeHash{}(Edge{n, n}); }
};
bool less(const Node& a, const Node& b) { return std::tie(a.i, a.j, a.k) < std::tie(b.i, b.j, b.k); }

}  // namespace

TubeSet lattice_tubes(const Box3& box, const LatticeOptions& o, const HullFields& hull) {
  if (box.empty()) throw InvalidInput("the lattice's box is empty");
  if (!(o.period_mm > 0) || !std::isfinite(o.period_mm)) throw InvalidInput("the lattice period must be positive (mm)");
  const bool radius_graded = o.grade.kind != GradeField::Kind::kNone && o.graded == LatticeOptions::Graded::kRadius;
  const bool level_graded = o.grade.kind != GradeField::Kind::kNone && o.graded == LatticeOptions::Graded::kLevel;
  if (radius_graded ? !(o.radius_min_mm > 0 && o.radius_max_mm > 0) : !(o.radius_mm > 0))
    throw InvalidInput("strut radii must be positive (mm)");
  if (o.grade.kind == GradeField::Kind::kRamp && !(o.grade.to_mm != o.grade.from_mm))
    throw InvalidInput("a ramp needs from_mm and to_mm apart");
  if (level_graded && (o.levels < 1 || o.levels > 6)) throw InvalidInput("levels must be 1 to 6");
  const bool conforming = o.layout == LatticeOptions::Layout::kConforming;
  if (conforming && !hull.signed_distance_mm) throw InvalidInput("a conforming lattice needs the hull it conforms to");
  if (conforming && !(o.conform_inset_mm >= 0)) throw InvalidInput("the conforming inset must be at least 0 (mm)");

  // The coarse grid: cells of `cell` mm from `origin`, indices lo..hi-1 on each axis.
  Vec3d origin{0, 0, 0}, cell{o.period_mm, o.period_mm, o.period_mm};
  int64_t lo[3], hi[3];
  double cells = 1;
  for (int k = 0; k < 3; ++k) {
    if (o.layout == LatticeOptions::Layout::kScaled) {
      const double n = std::max(1.0, std::round(box.size()[k] / o.period_mm));
      cell[k] = box.size()[k] / n;
      origin[k] = box.min[k];
      lo[k] = 0;
      hi[k] = int64_t(n);
    } else {
      // A conforming lattice keeps a cell outside the box: its nodes move onto the skin.
      const int64_t margin = conforming ? 1 : 0;
      // Counted in double first: a tiny period would overflow the integer cell indices.
      const double first = std::floor(box.min[k] / o.period_mm), last = std::ceil(box.max[k] / o.period_mm);
      if (!(last - first < 1e7)) throw InvalidInput("the lattice would have more than 10 000 000 struts; use a larger period");
      lo[k] = int64_t(first) - margin;
      hi[k] = int64_t(last) + margin;
    }
    cells *= double(hi[k] - lo[k]);
  }
  const int levels = level_graded ? o.levels : 0;
  const int64_t fine = int64_t(2) << levels;  // half units of the finest cell per coarse cell
  const double per_cell = o.cell == LatticeOptions::Cell::kCubic ? 3 : 7;
  if (cells * per_cell > 1e7) throw InvalidInput("the lattice would have more than 10 000 000 struts; use a larger period");

  auto position = [&](const Node& n) {
    return Vec3d{origin.x + double(n.i) / double(fine) * cell.x, origin.y + double(n.j) / double(fine) * cell.y,
                 origin.z + double(n.k) / double(fine) * cell.z};
  };
  auto radius = [&](const Vec3d& x) {
    if (!radius_graded) return o.radius_mm;
    return o.radius_min_mm + (o.radius_max_mm - o.radius_min_mm) * o.grade.at(x, hull.depth_mm);
  };

  // Conforming: where each node goes (kept, moved onto the inset surface, or dropped).
  struct Placed {
    Vec3d x;
    bool kept, moved;
  };
  std::unordered_map<Node, Placed, NodeHash> placed;
  const double reach = std::max({cell.x, cell.y, cell.z});
  auto place = [&](const Node& n) -> const Placed& {
    auto it = placed.find(n);
    if (it != placed.end()) return it->second;
    Placed p{position(n), true, false};
    if (conforming) {
      const double d = hull.signed_distance_mm(p.x);
      if (d > reach) {
        p.kept = false;
      } else if (d > -o.conform_inset_mm) {
        p.x = project_to_level(hull.signed_distance_mm, p.x, o.conform_inset_mm, 0.05 * reach);
        p.moved = true;
      }
    }
    return placed.emplace(n, p).first->second;
  };

  TubeSet out;
  std::unordered_set<Edge, EdgeHash> seen;
  auto strut = [&](Node a, Node b) {
    if (less(b, a)) std::swap(a, b);
    if (!seen.insert(Edge{a, b}).second) return;
    const Placed& pa = place(a);
    const Placed& pb = place(b);
    // Struts running along the skin, or reaching out of the hull, are left to the skin.
    if (!pa.kept || !pb.kept || (pa.moved && pb.moved)) return;
    const double length = norm(pb.x - pa.x);
    if (!(length > 1e-9 * reach)) return;
    if (out.tubes.size() >= size_t(1e7)) throw InvalidInput("the lattice would have more than 10 000 000 struts; use a larger period");
    const int pieces = radius_graded ? std::max(1, int(std::ceil(length / (0.25 * o.period_mm)))) : 1;
    Tube t;
    for (int i = 0; i <= pieces; ++i) {
      Vec3d x = pa.x + (pb.x - pa.x) * (double(i) / pieces);
      t.points_mm.push_back(x);
      t.radii_mm.push_back(radius(x));
    }
    out.tubes.push_back(std::move(t));
  };
  // A cell of `size` half units at corner c: split while the grade asks for it, else its struts.
  std::function<void(const Node&, int64_t, int)> visit = [&](const Node& c, int64_t size, int level) {
    const int64_t h = size / 2;
    if (level < levels) {
      const double f = o.grade.at(position(Node{c.i + h, c.j + h, c.k + h}), hull.depth_mm);
      if (f > double(level + 1) / double(levels + 1)) {
        for (int q = 0; q < 8; ++q) visit(Node{c.i + (q & 1) * h, c.j + ((q >> 1) & 1) * h, c.k + ((q >> 2) & 1) * h}, h, level + 1);
        return;
      }
    }
    auto corner = [&](int q) { return Node{c.i + (q & 1) * size, c.j + ((q >> 1) & 1) * size, c.k + ((q >> 2) & 1) * size}; };
    for (int q = 0; q < 8; ++q)
      for (int axis = 0; axis < 3; ++axis)
        if (!(q >> axis & 1)) strut(corner(q), corner(q | 1 << axis));
    if (o.cell == LatticeOptions::Cell::kBodyCentred)
      for (int q = 0; q < 8; ++q) strut(Node{c.i + h, c.j + h, c.k + h}, corner(q));
  };
  for (int64_t i = lo[0]; i < hi[0]; ++i)
    for (int64_t j = lo[1]; j < hi[1]; ++j)
      for (int64_t k = lo[2]; k < hi[2]; ++k) visit(Node{i * fine, j * fine, k * fine}, fine, 0);
  // An empty lattice would vanish from an infill without a word.
  if (out.tubes.empty()) {
    if (conforming)
      throw InvalidInput("no strut is left: every node lies less than inset_mm (" + message_number(o.conform_inset_mm) +
                         " mm) deep in the hull or outside it; use a smaller inset_mm or period_mm");
    throw InvalidInput("the lattice has no strut in its box");
  }
  return out;
}

}  // namespace lacuna
