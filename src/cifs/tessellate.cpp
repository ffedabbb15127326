#include "cifs/tessellate.h"

#include <cmath>
#include <string>
#include <unordered_map>

#include "errors.h"

namespace lacuna {
namespace cifs {
namespace {

// Placed vertices of a primitive: the control points times the barycentric vertices, rational
// control points divided by their weight.
void place(const Eigen::MatrixXd& product, const Eigen::MatrixXd& vertices, bool rational, Eigen::Matrix3Xd& out) {
  Eigen::MatrixXd p = product * vertices;
  out.resize(3, p.cols());
  if (rational) {
    for (Eigen::Index c = 0; c < p.cols(); ++c) out.col(c) = p.col(c).head<3>() / p(3, c);
  } else {
    out = p.topRows<3>();
  }
}

// Welds points closer than `tolerance`, in the order they come (deterministic).
class Welder {
 public:
  explicit Welder(double tolerance) : tolerance_(tolerance), cell_(tolerance * 1024) {}

  uint32_t index(const Vec3d& p, std::vector<Vec3d>& points) {
    const int64_t cx = int64_t(std::floor(p.x / cell_)), cy = int64_t(std::floor(p.y / cell_)),
                  cz = int64_t(std::floor(p.z / cell_));
    for (int64_t dx = -1; dx <= 1; ++dx)
      for (int64_t dy = -1; dy <= 1; ++dy)
        for (int64_t dz = -1; dz <= 1; ++dz) {
          auto it = cells_.find(key(cx + dx, cy + dy, cz + dz));
          if (it == cells_.end()) continue;
          for (uint32_t i : it->second)
            if (norm(points[i] - p) <= tolerance_) return i;
        }
    points.push_back(p);
    cells_[key(cx, cy, cz)].push_back(uint32_t(points.size() - 1));
    return uint32_t(points.size() - 1);
  }

 private:
  static uint64_t key(int64_t x, int64_t y, int64_t z) {
    return (uint64_t(x) * 73856093u) ^ (uint64_t(y) * 19349663u) ^ (uint64_t(z) * 83492791u);
  }
  double tolerance_, cell_;
  std::unordered_map<uint64_t, std::vector<uint32_t>> cells_;
};

double drawing_size(const Cifs& c) {
  Box3 box;
  for (Eigen::Index i = 0; i < c.control_points.cols(); ++i) {
    Eigen::Vector3d p = c.rational ? Eigen::Vector3d(c.control_points.col(i).head<3>() / c.control_points(3, i))
                                   : Eigen::Vector3d(c.control_points.col(i).head<3>());
    box.expand(Vec3d{p.x(), p.y(), p.z()});
  }
  return std::max(norm(box.size()), 1e-300);
}

Vec3d as_vec(const Eigen::Vector3d& v) { return Vec3d{v.x(), v.y(), v.z()}; }

void check_level(int level) {
  if (level < 0 || level > 64) throw InvalidInput("level must be from 0 to 64, got " + std::to_string(level));
}

}  // namespace

uint64_t count_pieces(const Automaton& a, int level) {
  check_level(level);
  // words[q] = accepted words of the remaining length starting in q.
  std::vector<double> words(a.states.size(), 1.0);
  for (int l = 0; l < level; ++l) {
    std::vector<double> next(a.states.size(), 0.0);
    for (size_t q = 0; q < a.states.size(); ++q)
      for (const Transition& t : a.transitions[q]) next[q] += words[size_t(t.target)];
    words = next;
  }
  double n = words[size_t(a.initial)];
  return n >= 1.8e19 ? UINT64_MAX : uint64_t(n);
}

void for_each_piece(const Cifs& c, int level, const std::function<void(const Piece&)>& visit) {
  check_level(level);
  const Automaton& a = c.automaton;
  for (const State& s : a.states)
    if (s.vertices.size() == 0) throw InvalidInput("state \"" + s.name + "\" has no primitive vertices");
  std::vector<Eigen::MatrixXd> products(size_t(level) + 1);
  std::vector<int> word(static_cast<size_t>(level)), states(static_cast<size_t>(level) + 1);
  std::vector<size_t> next(size_t(level) + 1, 0);
  products[0] = c.control_points;
  states[0] = a.initial;
  Eigen::Matrix3Xd placed;
  int depth = 0;
  next[0] = 0;
  for (;;) {
    if (depth == level) {
      const State& s = a.states[size_t(states[size_t(depth)])];
      place(products[size_t(depth)], s.vertices, c.rational, placed);
      visit(Piece{&word, states[size_t(depth)], &placed});
      if (depth == 0) return;
      --depth;
      continue;
    }
    const auto& out = a.transitions[size_t(states[size_t(depth)])];
    if (next[size_t(depth)] >= out.size()) {
      if (depth == 0) return;
      --depth;
      continue;
    }
    const Transition& t = out[next[size_t(depth)]++];
    word[size_t(depth)] = t.symbol;
    products[size_t(depth) + 1].noalias() = products[size_t(depth)] * t.matrix;
    states[size_t(depth) + 1] = t.target;
    ++depth;
    next[size_t(depth)] = 0;
  }
}

std::vector<std::vector<Vec3d>> tessellate_curves(const Cifs& c, int level) {
  const double tolerance = 1e-9 * drawing_size(c);
  std::vector<std::vector<Vec3d>> lines;
  for_each_piece(c, level, [&](const Piece& piece) {
    const Eigen::Matrix3Xd& v = *piece.vertices;
    if (v.cols() < 2) throw InvalidInput("curve pieces need segment primitives (two end points)");
    Vec3d start = as_vec(v.col(0)), end = as_vec(v.col(v.cols() - 1));
    if (lines.empty() || norm(lines.back().back() - start) > tolerance) lines.push_back({start});
    lines.back().push_back(end);
  });
  return lines;
}

TriMesh tessellate_surface(const Cifs& c, int level) {
  TriMesh mesh;
  Welder welder(1e-9 * drawing_size(c));
  for_each_piece(c, level, [&](const Piece& piece) {
    const Eigen::Matrix3Xd& v = *piece.vertices;
    const Primitive kind = c.automaton.states[size_t(piece.state)].primitive;
    if (primitive_dimension(kind) != 2) throw InvalidInput("surface pieces need triangle, quad or polygon primitives");
    std::vector<uint32_t> ids;
    for (Eigen::Index i = 0; i < v.cols(); ++i) ids.push_back(welder.index(as_vec(v.col(i)), mesh.positions_mm));
    for (size_t i = 1; i + 1 < ids.size(); ++i) {
      if (ids[0] == ids[i] || ids[i] == ids[i + 1] || ids[0] == ids[i + 1]) continue;  // collapsed corner
      mesh.triangles.push_back({ids[0], ids[i], ids[i + 1]});
    }
  });
  return mesh;
}

std::vector<std::vector<int>> primitive_faces(const State& s) {
  switch (s.primitive) {
    case Primitive::kTetrahedron:
      return {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}};
    case Primitive::kHexahedron:
      // Corners 0-3 the bottom quad counter-clockwise, 4-7 above them.
      return {{0, 3, 2, 1}, {4, 5, 6, 7}, {0, 1, 5, 4}, {1, 2, 6, 5}, {2, 3, 7, 6}, {3, 0, 4, 7}};
    case Primitive::kPolyhedron:
      return s.faces;
    default:
      throw InvalidInput(std::string("a ") + primitive_name(s.primitive) + " is not a volume primitive");
  }
}

void tessellate_cells(const Cifs& c, int level, size_t batch_cells,
                      const std::function<void(const ConvexCells&)>& sink) {
  const Automaton& a = c.automaton;
  const State& first = a.states[size_t(a.initial)];
  ConvexCells batch;
  batch.faces = primitive_faces(first);
  batch.corners_per_cell = int(first.vertices.cols());
  for (const State& s : a.states)
    if (s.primitive != first.primitive || s.vertices.cols() != first.vertices.cols())
      throw InvalidInput("every state of a volume system must have the same primitive");
  batch_cells = std::max<size_t>(batch_cells, 1);
  batch.corners_mm.reserve(batch_cells * size_t(batch.corners_per_cell));
  for_each_piece(c, level, [&](const Piece& piece) {
    const Eigen::Matrix3Xd& v = *piece.vertices;
    for (Eigen::Index i = 0; i < v.cols(); ++i) batch.corners_mm.push_back(as_vec(v.col(i)));
    if (batch.size() >= batch_cells) {
      sink(batch);
      batch.corners_mm.clear();
    }
  });
  if (!batch.corners_mm.empty()) sink(batch);
}

}  // namespace cifs
}  // namespace lacuna
