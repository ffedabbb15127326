#include "solids/extract.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <openvdb/tools/Morphology.h>
#include <openvdb/tree/LeafManager.h>
#include <stdexcept>
#include <unordered_map>

#include "errors.h"
#include "solids/vdb_internal.h"
#include "util/progress.h"

namespace lacuna {
namespace {

// Marching tetrahedra on the Freudenthal (Kuhn) split of every grid cube into six tetrahedra
// around the main diagonal. The split is the same in every cube, so neighbouring cubes cut their
// shared faces along the same diagonals and the tetrahedra form one consistent mesh of space.
// The surface is the zero set of the linear interpolant on that mesh: each piece is planar
// inside its tetrahedron, pieces meet only on shared faces along identical segments, and every
// crossing point is shared by index. With crossings kept off the grid points no triangle is
// degenerate and no two triangles meet except along their shared edges or vertices.
//
// Corner c of a cube is the offset (c & 1, (c >> 1) & 1, (c >> 2) & 1). Each tetrahedron is a
// monotone path 0 -> e_a -> e_a + e_b -> 7; listed here in positive orientation (odd axis
// permutations have their last two corners swapped).
constexpr int kTets[6][4] = {{0, 1, 3, 7}, {0, 1, 7, 5}, {0, 2, 7, 3},
                             {0, 2, 6, 7}, {0, 4, 5, 7}, {0, 4, 7, 6}};

// Even permutations of (0, 1, 2, 3) that start with a given corner, and with a given pair.
constexpr int kEvenFrom[4][4] = {{0, 1, 2, 3}, {1, 0, 3, 2}, {2, 3, 0, 1}, {3, 2, 1, 0}};
int even_from_pair(int a, int b, int out[4]) {
  static constexpr int kPairs[6][4] = {{0, 1, 2, 3}, {0, 2, 3, 1}, {0, 3, 1, 2},
                                       {1, 2, 0, 3}, {1, 3, 2, 0}, {2, 3, 0, 1}};
  for (const auto& p : kPairs)
    if (p[0] == a && p[1] == b) {
      std::copy(p, p + 4, out);
      return 1;
    }
  return 0;
}

// Writes the triangles of the six tetrahedra of one cube (corner values f, inside-corner bits
// `inside`) to out and returns the new end; vertex(ci, cj) names the crossing on the edge between
// cube corners ci and cj. A triangle faces away from its tetrahedron's inside corners; a quad is
// split along its shorter diagonal, measured on the cube-local crossing positions.
template <class VertexOf>
std::array<uint32_t, 3>* cube_triangles(const float f[8], int inside, double eps, VertexOf&& vertex,
                                        std::array<uint32_t, 3>* out) {
  for (const auto& tet : kTets) {
    int in_count = 0;
    for (int k = 0; k < 4; ++k) in_count += (inside >> tet[k]) & 1;
    if (in_count == 0 || in_count == 4) continue;
    if (in_count == 1 || in_count == 3) {
      bool want_inside = in_count == 1;
      int lone = 0;
      for (int k = 0; k < 4; ++k)
        if ((((inside >> tet[k]) & 1) != 0) == want_inside) lone = k;
      const int* p = kEvenFrom[lone];
      uint32_t a = vertex(tet[p[0]], tet[p[1]]), bb = vertex(tet[p[0]], tet[p[2]]), c = vertex(tet[p[0]], tet[p[3]]);
      // The triangle (a, bb, c) faces away from the lone corner; outward means away from an
      // inside corner and towards an outside one.
      if (want_inside) *out++ = {a, bb, c};
      else *out++ = {a, c, bb};
      continue;
    }
    int ins[2], k2 = 0;
    for (int k = 0; k < 4; ++k)
      if ((inside >> tet[k]) & 1) ins[k2++] = k;
    int p[4];
    even_from_pair(ins[0], ins[1], p);
    // Quad (ac, ad, bd, bc) is oriented from {a, b} (inside) towards {c, d}.
    uint32_t q[4] = {vertex(tet[p[0]], tet[p[2]]), vertex(tet[p[0]], tet[p[3]]), vertex(tet[p[1]], tet[p[3]]),
                     vertex(tet[p[1]], tet[p[2]])};
    auto local = [&](int ci, int cj) {
      int lo = ci & cj, dir = ci ^ cj;
      float f0 = f[lo], f1 = f[lo | dir];
      double t = std::clamp(double(f0) / (double(f0) - double(f1)), eps, 1.0 - eps);
      return Vec3d{(lo & 1) + t * (dir & 1), ((lo >> 1) & 1) + t * ((dir >> 1) & 1), ((lo >> 2) & 1) + t * ((dir >> 2) & 1)};
    };
    Vec3d l0 = local(tet[p[0]], tet[p[2]]), l1 = local(tet[p[0]], tet[p[3]]), l2 = local(tet[p[1]], tet[p[3]]),
          l3 = local(tet[p[1]], tet[p[2]]);
    Vec3d d02 = l2 - l0, d13 = l3 - l1;
    if (dot(d02, d02) <= dot(d13, d13)) {
      *out++ = {q[0], q[1], q[2]};
      *out++ = {q[0], q[2], q[3]};
    } else {
      *out++ = {q[0], q[1], q[3]};
      *out++ = {q[1], q[2], q[3]};
    }
  }
  return out;
}

using LeafT = openvdb::FloatTree::LeafNodeType;
using MaskLeafT = openvdb::MaskTree::LeafNodeType;

uint64_t pack_origin(const openvdb::Coord& c) {
  constexpr int64_t kBias = int64_t{1} << 20;
  return (uint64_t((c.x() >> 3) + kBias) << 42) | (uint64_t((c.y() >> 3) + kBias) << 21) |
         uint64_t((c.z() >> 3) + kBias);
}

struct Block {
  openvdb::Coord origin;
  uint32_t neighbours[8];            // block index of origin + 8 * bits(k); UINT32_MAX if none
  std::vector<uint16_t> edge_keys;   // local voxel offset * 8 + direction, ascending
  std::vector<float> fractions;      // where each edge is crossed, from its first end (0..1)
  uint64_t first_vertex = 0;
  uint64_t triangle_count = 0;
  uint64_t first_triangle = 0;
};

// Triangles the six tetrahedra of a cube produce, from the cube's inside-corner bits.
int triangles_in_cube(int inside) {
  int n = 0;
  for (const auto& tet : kTets) {
    int in_count = 0;
    for (int k = 0; k < 4; ++k) in_count += (inside >> tet[k]) & 1;
    n += in_count == 2 ? 2 : (in_count == 1 || in_count == 3 ? 1 : 0);
  }
  return n;
}

constexpr uint32_t kNone = UINT32_MAX;

// The values at origin + [0, 8]^3, x-major as in a leaf: index (x * 81 + y * 9 + z).
void load_values(const openvdb::FloatTree& tree, openvdb::tree::ValueAccessor<const openvdb::FloatTree>& acc,
                 const openvdb::Coord& origin, float* values) {
  const LeafT* leaf = tree.probeConstLeaf(origin);
  for (int x = 0; x <= 8; ++x) {
    for (int y = 0; y <= 8; ++y) {
      for (int z = 0; z <= 8; ++z) {
        float v;
        if (leaf && x < 8 && y < 8 && z < 8) v = leaf->getValue(openvdb::Index((x << 6) | (y << 3) | z));
        else v = acc.getValue(origin.offsetBy(x, y, z));
        values[x * 81 + y * 9 + z] = v;
      }
    }
  }
}

}  // namespace

TriMesh extract_surface(const Volume& volume, const ExtractOptions& options) {
  TriMesh mesh;
  if (volume.empty()) return mesh;
  const openvdb::FloatGrid& grid = *volume.impl().grid;
  const openvdb::FloatTree& tree = grid.tree();
  const double h = volume.voxel_size_mm();
  const double eps = std::clamp(options.min_edge_fraction, 1e-6, 0.25);

  // Cubes to visit: those with an active corner, i.e. min corners within one voxel of the band.
  openvdb::MaskTree mask(tree, false, openvdb::TopologyCopy());
  mask.voxelizeActiveTiles();
  openvdb::tools::dilateActiveValues(mask, 1, openvdb::tools::NN_FACE_EDGE_VERTEX,
                                     openvdb::tools::IGNORE_TILES);
  std::vector<const MaskLeafT*> mask_leaves;
  mask_leaves.reserve(mask.leafCount());
  for (auto it = mask.cbeginLeaf(); it; ++it) mask_leaves.push_back(it.getLeaf());

  std::vector<Block> blocks(mask_leaves.size());
  std::unordered_map<uint64_t, uint32_t> block_of;
  block_of.reserve(blocks.size() * 2);
  for (uint32_t i = 0; i < blocks.size(); ++i) {
    blocks[i].origin = mask_leaves[i]->origin();
    block_of.emplace(pack_origin(blocks[i].origin), i);
  }
  for (Block& b : blocks) {
    for (int k = 0; k < 8; ++k) {
      auto it = block_of.find(pack_origin(b.origin.offsetBy(8 * (k & 1), 8 * ((k >> 1) & 1), 8 * ((k >> 2) & 1))));
      b.neighbours[k] = it == block_of.end() ? kNone : it->second;
    }
  }

  Progress progress("mesh", blocks.size() * 2);

  // Pass 1: which of the seven edges leaving every visited voxel cross the surface, and where;
  // how many triangles every block will emit. Nothing is stored twice: pass 2 writes the
  // vertices and triangles straight into the mesh.
  tbb::parallel_for(tbb::blocked_range<size_t>(0, blocks.size(), 8), [&](const tbb::blocked_range<size_t>& r) {
    openvdb::tree::ValueAccessor<const openvdb::FloatTree> acc(tree);
    float values[729];
    for (size_t bi = r.begin(); bi != r.end(); ++bi) {
      Block& b = blocks[bi];
      const MaskLeafT& m = *mask_leaves[bi];
      load_values(tree, acc, b.origin, values);
      for (auto it = m.cbeginValueOn(); it; ++it) {
        const openvdb::Index n = it.pos();
        const int x = int(n >> 6), y = int((n >> 3) & 7), z = int(n & 7);
        const float f0 = values[x * 81 + y * 9 + z];
        const bool in0 = f0 < 0;
        int inside = 0;
        for (int d = 0; d < 8; ++d) {
          const int dx = d & 1, dy = (d >> 1) & 1, dz = (d >> 2) & 1;
          const float f1 = values[(x + dx) * 81 + (y + dy) * 9 + (z + dz)];
          inside |= (f1 < 0) << d;
          if (d == 0 || (f1 < 0) == in0) continue;
          b.edge_keys.push_back(uint16_t(n * 8 + d));
          b.fractions.push_back(float(std::clamp(double(f0) / (double(f0) - double(f1)), eps, 1.0 - eps)));
        }
        if (inside != 0 && inside != 0xff) b.triangle_count += triangles_in_cube(inside);
      }
      progress.advance();
    }
  });

  uint64_t vertex_count = 0, triangle_count = 0;
  for (Block& b : blocks) {
    b.first_vertex = vertex_count;
    vertex_count += b.edge_keys.size();
    b.first_triangle = triangle_count;
    triangle_count += b.triangle_count;
  }
  if (vertex_count >= UINT32_MAX) throw std::length_error("surface has more than 4 billion vertices");
  mesh.positions_mm.resize(vertex_count);
  mesh.triangles.resize(triangle_count);

  // Pass 2: the crossing points, then the triangles of the six tetrahedra of every cube with a
  // sign change, each block into its own slice of the mesh.
  tbb::parallel_for(tbb::blocked_range<size_t>(0, blocks.size(), 8), [&](const tbb::blocked_range<size_t>& r) {
    openvdb::tree::ValueAccessor<const openvdb::FloatTree> acc(tree);
    float values[729];
    for (size_t bi = r.begin(); bi != r.end(); ++bi) {
      Block& b = blocks[bi];
      const MaskLeafT& m = *mask_leaves[bi];
      for (size_t k = 0; k < b.edge_keys.size(); ++k) {
        const int n = b.edge_keys[k] >> 3, d = b.edge_keys[k] & 7;
        const double t = b.fractions[k];
        const openvdb::Coord base = b.origin.offsetBy(n >> 6, (n >> 3) & 7, n & 7);
        mesh.positions_mm[b.first_vertex + k] = Vec3d{(base.x() + t * (d & 1)) * h, (base.y() + t * ((d >> 1) & 1)) * h,
                                                      (base.z() + t * ((d >> 2) & 1)) * h};
      }
      std::vector<float>().swap(b.fractions);
      std::array<uint32_t, 3>* out = mesh.triangles.data() + b.first_triangle;
      load_values(tree, acc, b.origin, values);
      for (auto it = m.cbeginValueOn(); it; ++it) {
        const openvdb::Index n = it.pos();
        const int x = int(n >> 6), y = int((n >> 3) & 7), z = int(n & 7);
        float f[8];
        int inside = 0;
        for (int c = 0; c < 8; ++c) {
          f[c] = values[(x + (c & 1)) * 81 + (y + ((c >> 1) & 1)) * 9 + (z + ((c >> 2) & 1))];
          inside |= (f[c] < 0) << c;
        }
        if (inside == 0 || inside == 0xff) continue;

        // Vertex index of the crossing on the edge between cube corners ci and cj.
        auto vertex = [&](int ci, int cj) -> uint32_t {
          int lo = ci & cj, dir = ci ^ cj;  // corners of a tetrahedron are nested bit sets
          int vx = x + (lo & 1), vy = y + ((lo >> 1) & 1), vz = z + ((lo >> 2) & 1);
          int nb = (vx >> 3) | ((vy >> 3) << 1) | ((vz >> 3) << 2);
          uint32_t owner = b.neighbours[nb];
          if (owner == kNone) throw std::logic_error("surface crossing outside the narrow band");
          const Block& ob = blocks[owner];
          uint16_t key = uint16_t((((vx & 7) << 6) | ((vy & 7) << 3) | (vz & 7)) * 8 + dir);
          auto pos = std::lower_bound(ob.edge_keys.begin(), ob.edge_keys.end(), key);
          if (pos == ob.edge_keys.end() || *pos != key)
            throw std::logic_error("surface crossing outside the narrow band");
          return uint32_t(ob.first_vertex + uint64_t(pos - ob.edge_keys.begin()));
        };
        out = cube_triangles(f, inside, eps, vertex, out);
      }
      progress.advance();
    }
  });

  return mesh;
}

}  // namespace lacuna

namespace lacuna {

struct BlockExtractor::Impl {
  Volume volume;  // keeps the grid alive
  const openvdb::FloatTree* tree = nullptr;
  double h = 0, eps = 0;
  int size = 0;
  std::vector<openvdb::Coord> origins;
};

BlockExtractor::BlockExtractor(const Volume& volume, int block_voxels, const ExtractOptions& options)
    : impl_(std::make_unique<Impl>()) {
  if (block_voxels < 8 || block_voxels % 8 != 0 || block_voxels > 256)
    throw InvalidInput("surface blocks must be a multiple of 8 voxels from 8 to 256");
  Impl& m = *impl_;
  m.volume = volume;
  m.size = block_voxels;
  m.eps = std::clamp(options.min_edge_fraction, 1e-6, 0.25);
  if (volume.empty()) return;
  m.tree = &volume.impl().grid->tree();
  m.h = volume.voxel_size_mm();
  // Cubes with a corner in the band have their lowest corner within one voxel below a leaf; a
  // block is listed for every leaf and for the blocks just below it.
  std::vector<openvdb::Coord> found;
  auto floor_div = [&](int v) { return v >= 0 ? v / block_voxels : -((-v + block_voxels - 1) / block_voxels); };
  for (auto it = m.tree->cbeginLeaf(); it; ++it) {
    const openvdb::Coord o = it->origin();
    for (int dx = -1; dx <= 0; ++dx)
      for (int dy = -1; dy <= 0; ++dy)
        for (int dz = -1; dz <= 0; ++dz)
          found.push_back(openvdb::Coord(floor_div(o.x() + dx), floor_div(o.y() + dy), floor_div(o.z() + dz)));
  }
  std::sort(found.begin(), found.end(), [](const openvdb::Coord& a, const openvdb::Coord& b) {
    return a.x() != b.x() ? a.x() < b.x() : (a.y() != b.y() ? a.y() < b.y() : a.z() < b.z());
  });
  found.erase(std::unique(found.begin(), found.end()), found.end());
  m.origins.reserve(found.size());
  for (const openvdb::Coord& c : found) m.origins.push_back(openvdb::Coord(c.x() * block_voxels, c.y() * block_voxels, c.z() * block_voxels));
}

BlockExtractor::~BlockExtractor() = default;

size_t BlockExtractor::block_count() const { return impl_->origins.size(); }

void BlockExtractor::extract(size_t i, SurfaceBlock& out) const {
  const Impl& m = *impl_;
  const int n = m.size, n1 = n + 1;
  const openvdb::Coord o = m.origins.at(i);
  out.origin_voxels[0] = o.x();
  out.origin_voxels[1] = o.y();
  out.origin_voxels[2] = o.z();
  out.size_voxels = n;
  for (int k = 0; k < 3; ++k) {
    out.box_mm.min[k] = round_to_output(double(o[k]) * m.h);
    out.box_mm.max[k] = round_to_output(double(o[k] + n) * m.h);
  }
  out.positions_mm.clear();
  out.keys.clear();
  out.triangles.clear();

  // The values at o + [0, n]^3, x-major; leaves copied whole, tiles and background by one lookup.
  thread_local std::vector<float> values;
  thread_local std::vector<uint32_t> vertex_of;  // per grid point and direction: vertex + 1, or 0
  thread_local std::vector<size_t> used_slots;   // the slots set, cleared again at the end
  values.assign(size_t(n1) * n1 * n1, 0.0f);
  openvdb::tree::ValueAccessor<const openvdb::FloatTree> acc(*m.tree);
  for (int lx = 0; lx <= n; lx += 8)
    for (int ly = 0; ly <= n; ly += 8)
      for (int lz = 0; lz <= n; lz += 8) {
        const openvdb::Coord lo = o.offsetBy(lx, ly, lz);
        const LeafT* leaf = m.tree->probeConstLeaf(lo);
        const float tile = leaf ? 0.0f : acc.getValue(lo);
        for (int x = lx; x < std::min(lx + 8, n1); ++x)
          for (int y = ly; y < std::min(ly + 8, n1); ++y)
            for (int z = lz; z < std::min(lz + 8, n1); ++z)
              values[(size_t(x) * n1 + y) * n1 + z] =
                  leaf ? leaf->getValue(openvdb::Index(((x - lx) << 6) | ((y - ly) << 3) | (z - lz))) : tile;
      }
  auto value = [&](int x, int y, int z) { return values[(size_t(x) * n1 + y) * n1 + z]; };
  if (vertex_of.size() != size_t(n1) * n1 * n1 * 8) vertex_of.assign(size_t(n1) * n1 * n1 * 8, 0);
  used_slots.clear();
  auto vertex = [&](int px, int py, int pz, int dir) -> uint32_t {
    uint32_t& slot = vertex_of[((size_t(px) * n1 + py) * n1 + pz) * 8 + size_t(dir)];
    if (slot) return slot - 1;
    const int dx = dir & 1, dy = (dir >> 1) & 1, dz = (dir >> 2) & 1;
    const float f0 = value(px, py, pz), f1 = value(px + dx, py + dy, pz + dz);
    const double t = std::clamp(double(f0) / (double(f0) - double(f1)), m.eps, 1.0 - m.eps);
    // The same expression as extract_surface, on global grid coordinates.
    const double gx = o.x() + px, gy = o.y() + py, gz = o.z() + pz;
    out.positions_mm.push_back(round_to_output(Vec3d{(gx + t * dx) * m.h, (gy + t * dy) * m.h, (gz + t * dz) * m.h}));
    const bool on_boundary = (dx == 0 && (px == 0 || px == n)) || (dy == 0 && (py == 0 || py == n)) ||
                             (dz == 0 && (pz == 0 || pz == n));
    constexpr int64_t kBias = int64_t{1} << 19;
    out.keys.push_back(on_boundary ? (uint64_t(gx + kBias) << 43) | (uint64_t(gy + kBias) << 23) |
                                         (uint64_t(gz + kBias) << 3) | uint64_t(dir)
                                   : kInteriorVertex);
    slot = uint32_t(out.positions_mm.size());
    used_slots.push_back(size_t(&slot - vertex_of.data()));
    return slot - 1;
  };
  // Inside bits first (one byte per grid point), so cubes away from the surface cost eight loads.
  thread_local std::vector<uint8_t> negative;
  negative.resize(values.size());
  for (size_t p = 0; p < values.size(); ++p) negative[p] = values[p] < 0;
  size_t corner_offset[8];
  for (int c = 0; c < 8; ++c) corner_offset[c] = (size_t(c & 1) * n1 + ((c >> 1) & 1)) * n1 + ((c >> 2) & 1);
  std::array<uint32_t, 3> tris[12];
  for (int x = 0; x < n; ++x)
    for (int y = 0; y < n; ++y) {
      const size_t row = (size_t(x) * n1 + y) * n1;
      for (int z = 0; z < n; ++z) {
        const size_t base = row + size_t(z);
        int inside = 0;
        for (int c = 0; c < 8; ++c) inside |= negative[base + corner_offset[c]] << c;
        if (inside == 0 || inside == 0xff) continue;
        float f[8];
        for (int c = 0; c < 8; ++c) f[c] = values[base + corner_offset[c]];
        auto crossing = [&](int ci, int cj) {
          const int lo = ci & cj, dir = ci ^ cj;
          return vertex(x + (lo & 1), y + ((lo >> 1) & 1), z + ((lo >> 2) & 1), dir);
        };
        std::array<uint32_t, 3>* end = cube_triangles(f, inside, m.eps, crossing, tris);
        out.triangles.insert(out.triangles.end(), &tris[0], end);
      }
    }
  for (size_t slot : used_slots) vertex_of[slot] = 0;
}

}  // namespace lacuna
