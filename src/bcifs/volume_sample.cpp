// Sampling a lacunar volume's convex pieces: voxel masks for box counting in 3D, and sections.
#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "bcifs/volume.h"
#include "errors.h"

namespace lacuna {
namespace bcifs {
namespace {

bool power_of_two(int n) { return n > 0 && (n & (n - 1)) == 0; }

// One convex piece as half-spaces: n . p <= d for every face (n pointing away from the corners' average).
struct Piece {
  std::vector<Vec3d> normal;
  std::vector<double> offset;
  Vec3d lo{HUGE_VAL, HUGE_VAL, HUGE_VAL}, hi{-HUGE_VAL, -HUGE_VAL, -HUGE_VAL};

  bool contains(const Vec3d& p) const {
    for (size_t f = 0; f < normal.size(); ++f)
      if (dot(normal[f], p) > offset[f]) return false;
    return true;
  }
};

Piece piece_of(const ConvexCells& cells, size_t k) {
  const size_t m = size_t(cells.corners_per_cell);
  const Vec3d* p = cells.corners_mm.data() + k * m;
  Piece out;
  Vec3d centre{0, 0, 0};
  for (size_t i = 0; i < m; ++i) {
    centre += p[i];
    for (int a = 0; a < 3; ++a) {
      out.lo[a] = std::min(out.lo[a], p[i][a]);
      out.hi[a] = std::max(out.hi[a], p[i][a]);
    }
  }
  centre = centre / double(m);
  for (const std::vector<int>& face : cells.faces) {
    // Newell's normal of the face's corners (robust to a corner repeated by a degenerate frustum).
    Vec3d n{0, 0, 0};
    for (size_t j = 0; j < face.size(); ++j) {
      const Vec3d& a = p[face[j]];
      const Vec3d& b = p[face[(j + 1) % face.size()]];
      n += Vec3d{(a.y - b.y) * (a.z + b.z), (a.z - b.z) * (a.x + b.x), (a.x - b.x) * (a.y + b.y)};
    }
    const double length = norm(n);
    if (!(length > 0)) continue;
    n = n / length;
    Vec3d on{0, 0, 0};
    for (int i : face) on += p[i];
    on = on / double(face.size());
    double d = dot(n, on);
    if (dot(n, centre) > d) {  // pointing inwards
      n = n * -1.0;
      d = -d;
    }
    out.normal.push_back(n);
    out.offset.push_back(d);
  }
  return out;
}

// Calls f(piece) for every piece whose box meets [lo, hi] along `axis`.
template <typename F>
void for_pieces(const std::vector<ConvexCells>& pieces, int axis, double lo, double hi, F&& f) {
  for (const ConvexCells& cells : pieces) {
    const size_t m = size_t(cells.corners_per_cell);
    for (size_t k = 0; k < cells.size(); ++k) {
      const Vec3d* p = cells.corners_mm.data() + k * m;
      double a = HUGE_VAL, b = -HUGE_VAL;
      for (size_t i = 0; i < m; ++i) a = std::min(a, p[i][axis]), b = std::max(b, p[i][axis]);
      if (b < lo || a > hi) continue;
      f(piece_of(cells, k));
    }
  }
}

// The index range of cell centres origin + (i + 1/2) voxel within [lo, hi], clipped to [0, size).
std::pair<int, int> centres_within(double lo, double hi, double origin, double voxel, int size) {
  const int first = std::max(0, int(std::ceil((lo - origin) / voxel - 0.5)));
  const int last = std::min(size - 1, int(std::floor((hi - origin) / voxel - 0.5)));
  return {first, last};
}

}  // namespace

VoxelGrid voxel_grid(const std::vector<ConvexCells>& pieces, int size) {
  if (!power_of_two(size) || size < 4 || size > 1024)
    throw InvalidInput("voxel_grid: the size must be a power of two from 4 to 1024, got " + std::to_string(size));
  Vec3d lo{HUGE_VAL, HUGE_VAL, HUGE_VAL}, hi{-HUGE_VAL, -HUGE_VAL, -HUGE_VAL};
  for (const ConvexCells& cells : pieces)
    for (const Vec3d& p : cells.corners_mm)
      for (int a = 0; a < 3; ++a) lo[a] = std::min(lo[a], p[a]), hi[a] = std::max(hi[a], p[a]);
  if (!(hi.x >= lo.x)) throw InvalidInput("voxel_grid: no piece to sample");
  const double longest = std::max({hi.x - lo.x, hi.y - lo.y, hi.z - lo.z});
  if (!(longest > 0)) throw InvalidInput("voxel_grid: the pieces have no extent");
  // Cells subdivided by fixed ratios put their faces at dyadic fractions of their box (a cube's lacunas at 1/4,
  // 3/16, ... of its side). On a grid spanning the box exactly those faces lie on voxel planes or centre planes,
  // all at one offset, and the sampling errors of parallel faces add up instead of cancelling (a level-4 cube read
  // 1.4 % light). A margin of sqrt(2)/128 of the side on each end spreads the faces' offsets over the voxel.
  const double margin = longest * std::sqrt(2.0) / 128;
  return VoxelGrid{size, lo - Vec3d{margin, margin, margin}, (longest + 2 * margin) / size};
}

void mark_voxels(const std::vector<ConvexCells>& pieces, const VoxelGrid& grid, int z_first, int z_last, uint8_t* out) {
  const int n = grid.size;
  std::fill(out, out + size_t(n) * size_t(n) * size_t(std::max(0, z_last - z_first)), uint8_t(0));
  if (z_last <= z_first) return;
  const double h = grid.voxel_mm;
  const Vec3d& o = grid.origin_mm;
  const double z_lo = o.z + (z_first + 0.5) * h, z_hi = o.z + (z_last - 0.5) * h;
  for_pieces(pieces, 2, z_lo, z_hi, [&](const Piece& piece) {
    const auto [x0, x1] = centres_within(piece.lo.x, piece.hi.x, o.x, h, n);
    const auto [y0, y1] = centres_within(piece.lo.y, piece.hi.y, o.y, h, n);
    const auto [k0, k1] = centres_within(piece.lo.z, piece.hi.z, o.z, h, n);
    for (int k = std::max(k0, z_first); k <= std::min(k1, z_last - 1); ++k)
      for (int j = y0; j <= y1; ++j)
        for (int i = x0; i <= x1; ++i) {
          uint8_t& v = out[(size_t(k - z_first) * size_t(n) + size_t(j)) * size_t(n) + size_t(i)];
          if (!v && piece.contains(o + Vec3d{(i + 0.5) * h, (j + 0.5) * h, (k + 0.5) * h})) v = 1;
        }
  });
}

BoxCount box_count_3d(const std::vector<uint8_t>& mask, int size, bool boundary) {
  if (!power_of_two(size) || size < 8 || mask.size() != size_t(size) * size_t(size) * size_t(size))
    throw InvalidInput("box_count_3d: expected a size^3 mask, size a power of two >= 8 (two box sizes for a slope)");
  const size_t n = size_t(size);
  auto at = [&](size_t i, size_t j, size_t k) { return mask[(k * n + j) * n + i]; };
  // The finest level: the set, or its boundary voxels.
  std::vector<uint8_t> level(mask.size());
  for (size_t k = 0; k < n; ++k)
    for (size_t j = 0; j < n; ++j)
      for (size_t i = 0; i < n; ++i) {
        uint8_t v = at(i, j, k);
        if (v && boundary) {
          const bool border = i == 0 || j == 0 || k == 0 || i + 1 == n || j + 1 == n || k + 1 == n;
          v = border || !at(i - 1, j, k) || !at(i + 1, j, k) || !at(i, j - 1, k) || !at(i, j + 1, k) ||
              !at(i, j, k - 1) || !at(i, j, k + 1);
        }
        level[(k * n + j) * n + i] = v;
      }
  // Boxes of 1, 2, 4, ... voxels: each level ORs 2 x 2 x 2 boxes of the one below.
  std::vector<double> x, y;
  size_t boxes = n;
  while (boxes >= 4) {
    size_t count = 0;
    for (uint8_t v : level) count += v;
    x.push_back(std::log(double(boxes)));
    y.push_back(std::log(double(std::max<size_t>(count, 1))));
    const size_t half = boxes / 2;
    std::vector<uint8_t> up(half * half * half, 0);
    for (size_t k = 0; k < boxes; ++k)
      for (size_t j = 0; j < boxes; ++j)
        for (size_t i = 0; i < boxes; ++i)
          if (level[(k * boxes + j) * boxes + i]) up[((k / 2) * half + j / 2) * half + i / 2] = 1;
    level.swap(up);
    boxes = half;
  }
  BoxCount out;
  // Coarse to fine, as the 2D counts.
  out.log_inverse_size.assign(x.rbegin(), x.rend());
  out.log_count.assign(y.rbegin(), y.rend());
  const double m = double(x.size());
  double sx = 0, sy = 0, sxx = 0, sxy = 0;
  for (size_t i = 0; i < x.size(); ++i) sx += x[i], sy += y[i], sxx += x[i] * x[i], sxy += x[i] * y[i];
  out.dimension = (m * sxy - sx * sy) / (m * sxx - sx * sx);
  return out;
}

std::vector<uint8_t> section_mask(const std::vector<ConvexCells>& pieces, const VoxelGrid& grid, int axis,
                                  double value, int size) {
  if (axis < 0 || axis > 2) throw InvalidInput("section_mask: the axis must be 0, 1 or 2");
  if (size < 1 || size > 4096) throw InvalidInput("section_mask: the size must be from 1 to 4096 pixels");
  const int u = (axis + 1) % 3, v = (axis + 2) % 3;
  const double pixel = grid.voxel_mm * grid.size / size;
  const Vec3d& o = grid.origin_mm;
  std::vector<uint8_t> mask(size_t(size) * size_t(size), 0);
  for_pieces(pieces, axis, value, value, [&](const Piece& piece) {
    const auto [i0, i1] = centres_within(piece.lo[u], piece.hi[u], o[u], pixel, size);
    const auto [j0, j1] = centres_within(piece.lo[v], piece.hi[v], o[v], pixel, size);
    Vec3d p;
    p[axis] = value;
    for (int j = j0; j <= j1; ++j)
      for (int i = i0; i <= i1; ++i) {
        uint8_t& m = mask[size_t(j) * size_t(size) + size_t(i)];
        if (m) continue;
        p[u] = o[u] + (i + 0.5) * pixel;
        p[v] = o[v] + (j + 0.5) * pixel;
        if (piece.contains(p)) m = 1;
      }
  });
  return mask;
}

}  // namespace bcifs
}  // namespace lacuna
