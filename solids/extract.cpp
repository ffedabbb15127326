#include "solids/extract.h"

#include <tbb/parallel_for.h>
#include <tbb/parallel_sort.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <openvdb/tools/Morphology.h>
#include <openvdb/tree/LeafManager.h>
#include <stdexcept>
#include <unordered_map>

#include "errors.h"
#include "solids/cube_surface.h"
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
// degenerate and no two triangles meet except along their shared edges or vertices. The pieces
// of one cube come from cube_surface::cube_triangles.
using cube_surface::cube_triangles;
using cube_surface::triangles_in_cube;

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
  double h = 0, eps = 0, merge_deviation_mm = 0;
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
  m.merge_deviation_mm = options.merge_deviation_mm;
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

std::array<int64_t, 3> BlockExtractor::block_origin(size_t i) const {
  const openvdb::Coord o = impl_->origins.at(i);
  return {int64_t(o.x()), int64_t(o.y()), int64_t(o.z())};
}

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
  out.volume_debt6.clear();

  // The values at o + [0, n]^3, x-major; leaves copied whole, tiles and background by one lookup.
  thread_local std::vector<float> values;
  thread_local std::vector<uint32_t> vertex_of;  // per grid point and direction: vertex + 1, or 0
  thread_local std::vector<size_t> used_slots;   // the slots set, cleared again at the end
  values.assign(size_t(n1) * n1 * n1, 0.0f);
  // Per 8^3 part of the values: 1 all outside, 2 all inside, 3 both (so a cube whose corners lie
  // in parts that are all outside or all inside is skipped without looking at it).
  const int parts = n / 8 + 1;
  thread_local std::vector<uint8_t> part_sign;
  part_sign.assign(size_t(parts) * parts * parts, 0);
  openvdb::tree::ValueAccessor<const openvdb::FloatTree> acc(*m.tree);
  for (int lx = 0; lx <= n; lx += 8)
    for (int ly = 0; ly <= n; ly += 8)
      for (int lz = 0; lz <= n; lz += 8) {
        const openvdb::Coord lo = o.offsetBy(lx, ly, lz);
        const LeafT* leaf = m.tree->probeConstLeaf(lo);
        const float tile = leaf ? 0.0f : acc.getValue(lo);
        uint8_t sign = 0;
        for (int x = lx; x < std::min(lx + 8, n1); ++x)
          for (int y = ly; y < std::min(ly + 8, n1); ++y)
            for (int z = lz; z < std::min(lz + 8, n1); ++z) {
              const float v = leaf ? leaf->getValue(openvdb::Index(((x - lx) << 6) | ((y - ly) << 3) | (z - lz))) : tile;
              values[(size_t(x) * n1 + y) * n1 + z] = v;
              sign |= v < 0 ? 2 : 1;
            }
        part_sign[size_t(((lx / 8) * parts + ly / 8) * parts + lz / 8)] = sign;
      }
  auto value = [&](int x, int y, int z) { return values[(size_t(x) * n1 + y) * n1 + z]; };
  if (vertex_of.size() != size_t(n1) * n1 * n1 * 8) vertex_of.assign(size_t(n1) * n1 * n1 * 8, 0);
  used_slots.clear();
  // The crossing on the grid edge from (px, py, pz) along dir: the same expression as
  // extract_surface, on global grid coordinates.
  auto position = [&](int px, int py, int pz, int dir) {
    const int dx = dir & 1, dy = (dir >> 1) & 1, dz = (dir >> 2) & 1;
    const float f0 = value(px, py, pz), f1 = value(px + dx, py + dy, pz + dz);
    const double t = std::clamp(double(f0) / (double(f0) - double(f1)), m.eps, 1.0 - m.eps);
    const double gx = o.x() + px, gy = o.y() + py, gz = o.z() + pz;
    return round_to_output(Vec3d{(gx + t * dx) * m.h, (gy + t * dy) * m.h, (gz + t * dz) * m.h});
  };
  auto vertex = [&](int px, int py, int pz, int dir) -> uint32_t {
    uint32_t& slot = vertex_of[((size_t(px) * n1 + py) * n1 + pz) * 8 + size_t(dir)];
    if (slot) return slot - 1;
    const int dx = dir & 1, dy = (dir >> 1) & 1, dz = (dir >> 2) & 1;
    out.positions_mm.push_back(position(px, py, pz, dir));
    const bool on_boundary = (dx == 0 && (px == 0 || px == n)) || (dy == 0 && (py == 0 || py == n)) ||
                             (dz == 0 && (pz == 0 || pz == n));
    constexpr int64_t kBias = int64_t{1} << 19;
    const int64_t gx = o.x() + px, gy = o.y() + py, gz = o.z() + pz;
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
  auto cube_values = [&](int x, int y, int z, float f[8]) {
    const size_t base = (size_t(x) * n1 + y) * n1 + size_t(z);
    for (int c = 0; c < 8; ++c) f[c] = values[base + corner_offset[c]];
  };
  auto emit_pieces = [&](int x, int y, int z, int inside) {
    float f[8];
    cube_values(x, y, z, f);
    auto crossing = [&](int ci, int cj) {
      const int lo = ci & cj, dir = ci ^ cj;
      return vertex(x + (lo & 1), y + ((lo >> 1) & 1), z + ((lo >> 2) & 1), dir);
    };
    std::array<uint32_t, 3> tris[12];
    std::array<uint32_t, 3>* end = cube_triangles(f, inside, m.eps, crossing, tris);
    out.triangles.insert(out.triangles.end(), &tris[0], end);
  };

  // The cubes the surface crosses, in order, with their inside bits.
  thread_local std::vector<uint32_t> cubes;
  thread_local std::vector<uint8_t> cube_inside;
  cubes.clear();
  cube_inside.clear();
  out.piece_triangles = 0;
  // Parts whose cubes all have corners of one side: those of the part and of the parts above it.
  thread_local std::vector<uint8_t> part_skipped;
  part_skipped.assign(size_t(parts) * parts * parts, 0);
  for (int px = 0; px + 1 < parts; ++px)
    for (int py = 0; py + 1 < parts; ++py)
      for (int pz = 0; pz + 1 < parts; ++pz) {
        uint8_t sign = 0;
        for (int d = 0; d < 8; ++d)
          sign |= part_sign[size_t(((px + (d & 1)) * parts + py + ((d >> 1) & 1)) * parts + pz + ((d >> 2) & 1))];
        part_skipped[size_t((px * parts + py) * parts + pz)] = sign != 3;
      }
  for (int x = 0; x < n; ++x)
    for (int y = 0; y < n; ++y) {
      const size_t row = (size_t(x) * n1 + y) * n1;
      const size_t part_row = size_t(((x / 8) * parts + y / 8) * parts);
      for (int z = 0; z < n; ++z) {
        if (part_skipped[part_row + size_t(z / 8)]) {
          z += 7;  // the rest of this part's row
          continue;
        }
        const size_t base = row + size_t(z);
        int inside = 0;
        for (int c = 0; c < 8; ++c) inside |= negative[base + corner_offset[c]] << c;
        if (inside == 0 || inside == 0xff) continue;
        cubes.push_back(uint32_t((x * n + y) * n + z));
        cube_inside.push_back(uint8_t(inside));
        out.piece_triangles += uint64_t(triangles_in_cube(inside));
      }
    }
  auto coords = [&](uint32_t cube, int& x, int& y, int& z) {
    z = int(cube % uint32_t(n));
    y = int((cube / uint32_t(n)) % uint32_t(n));
    x = int(cube / uint32_t(n * n));
  };

  if (!(m.merge_deviation_mm > 0)) {
    for (size_t ci = 0; ci < cubes.size(); ++ci) {
      int x, y, z;
      coords(cubes[ci], x, y, z);
      emit_pieces(x, y, z, cube_inside[ci]);
    }
  } else {
    // A face keeps its diagonal crossing when it is on the block's boundary (the cube beyond
    // is another block's), when a cube on it keeps its pieces, or when no merged triangulation
    // of a cube on it passed the tests (that cube then keeps its pieces). A face that starts to
    // keep its crossing sends the merged cube across it back to the queue, so both cubes of
    // every face agree on it. Cubes only ever go from merged to pieces, so this ends.
    thread_local std::vector<uint8_t> kept;        // per face key: 1 keeps its diagonal crossing
    thread_local std::vector<uint32_t> kept_keys;  // the keys set, cleared again at the end
    thread_local std::vector<int32_t> cube_index;  // per cube of the block: its index in cubes, or -1
    thread_local std::vector<uint8_t> state;       // per listed cube
    thread_local std::vector<uint32_t> queue, first, count;
    thread_local std::vector<std::array<uint8_t, 3>> merged;
    thread_local std::vector<std::pair<uint8_t, double>> shares;  // (slot, volume6) of merged cubes
    thread_local std::vector<uint32_t> first_share, share_count;
    constexpr uint8_t kWaiting = 0, kMerged = 1, kPieces = 2, kQueued = 4;
    if (kept.size() != size_t(n1) * n1 * n1 * 3) kept.assign(size_t(n1) * n1 * n1 * 3, 0);
    if (cube_index.size() != size_t(n) * n * n) cube_index.assign(size_t(n) * n * n, -1);
    const size_t nc = cubes.size();
    for (size_t ci = 0; ci < nc; ++ci) cube_index[cubes[ci]] = int32_t(ci);
    state.assign(nc, kWaiting);
    first.assign(nc, 0);
    count.assign(nc, 0);
    first_share.assign(nc, 0);
    share_count.assign(nc, 0);
    merged.clear();
    shares.clear();
    kept_keys.clear();
    auto face_key = [&](int x, int y, int z, int face, bool& on_block_boundary) {
      int c[3] = {x, y, z};
      const int k = face / 2;
      c[k] += face % 2;
      on_block_boundary = c[k] == 0 || c[k] == n;
      return uint32_t(((c[0] * n1 + c[1]) * n1 + c[2]) * 3 + k);
    };
    auto neighbour = [&](int x, int y, int z, int face) -> int32_t {
      int c[3] = {x, y, z};
      c[face / 2] += face % 2 ? 1 : -1;
      for (int k = 0; k < 3; ++k)
        if (c[k] < 0 || c[k] >= n) return -1;
      return cube_index[uint32_t((c[0] * n + c[1]) * n + c[2])];
    };
    queue.clear();
    auto keep_pieces = [&](size_t ci) {
      int x, y, z;
      coords(cubes[ci], x, y, z);
      state[ci] = uint8_t((state[ci] & kQueued) | kPieces);
      for (int face = 0; face < 6; ++face) {
        bool boundary;
        const uint32_t key = face_key(x, y, z, face, boundary);
        if (boundary || kept[key] || !cube_surface::diagonal_crossed(cube_inside[ci], face)) continue;
        kept[key] = 1;
        kept_keys.push_back(key);
        const int32_t j = neighbour(x, y, z, face);
        if (j >= 0 && (state[size_t(j)] & 3) == kMerged && !(state[size_t(j)] & kQueued)) {
          state[size_t(j)] |= kQueued;
          queue.push_back(uint32_t(j));
        }
      }
    };
    for (size_t ci = 0; ci < nc; ++ci)
      if (cube_surface::keeps_pieces(cube_inside[ci])) keep_pieces(ci);
    for (size_t ci = 0; ci < nc; ++ci)
      if (state[ci] == kWaiting) {
        state[ci] = kQueued;
        queue.push_back(uint32_t(ci));
      }
    Vec3d pos[cube_surface::kSlots];
    for (size_t head = 0; head < queue.size(); ++head) {
      const size_t ci = queue[head];
      state[ci] = uint8_t(state[ci] & ~kQueued);
      if ((state[ci] & 3) == kPieces) continue;
      int x, y, z;
      coords(cubes[ci], x, y, z);
      const int inside = cube_inside[ci];
      cube_surface::MergeInput in;
      float f[8];
      cube_values(x, y, z, f);
      in.inside = inside;
      in.values = f;
      in.eps = m.eps;
      for (int lo = 0; lo < 8; ++lo)
        for (int dir = 1; dir < 8; ++dir)
          if (!(lo & dir) && ((inside >> lo) & 1) != ((inside >> (lo | dir)) & 1))
            pos[cube_surface::slot_of(lo, lo | dir)] = position(x + (lo & 1), y + ((lo >> 1) & 1), z + ((lo >> 2) & 1), dir);
      in.positions = pos;
      for (int k = 0; k < 3; ++k) {
        const int c = k == 0 ? x : (k == 1 ? y : z);
        in.box_lo[k] = round_to_output(double(o[k] + c) * m.h);
        in.box_hi[k] = round_to_output(double(o[k] + c + 1) * m.h);
      }
      for (int face = 0; face < 6; ++face) {
        bool boundary;
        const uint32_t key = face_key(x, y, z, face, boundary);
        if (boundary || kept[key]) in.kept_faces |= uint8_t(1u << face);
      }
      in.max_deviation_mm = m.merge_deviation_mm;
      first[ci] = uint32_t(merged.size());
      cube_surface::VolumeShares lost;
      if (cube_surface::merged_triangles(in, merged, &lost)) {
        count[ci] = uint32_t(merged.size() - first[ci]);
        first_share[ci] = uint32_t(shares.size());
        share_count[ci] = uint32_t(lost.count);
        for (int k = 0; k < lost.count; ++k) shares.push_back({lost.slots[k], lost.volume6[k]});
        state[ci] = kMerged;
      } else {
        keep_pieces(ci);
      }
    }
    for (size_t ci = 0; ci < nc; ++ci) {
      int x, y, z;
      coords(cubes[ci], x, y, z);
      if ((state[ci] & 3) == kPieces) {
        emit_pieces(x, y, z, cube_inside[ci]);
        continue;
      }
      for (uint32_t t = first[ci]; t < first[ci] + count[ci]; ++t) {
        std::array<uint32_t, 3> tri;
        for (int k = 0; k < 3; ++k) {
          const int slot = merged[t][size_t(k)], lo = slot >> 3, dir = slot & 7;
          tri[size_t(k)] = vertex(x + (lo & 1), y + ((lo >> 1) & 1), z + ((lo >> 2) & 1), dir);
        }
        out.triangles.push_back(tri);
      }
      for (uint32_t k = first_share[ci]; k < first_share[ci] + share_count[ci]; ++k) {
        const int slot = shares[k].first, lo = slot >> 3, dir = slot & 7;
        const uint32_t v = vertex(x + (lo & 1), y + ((lo >> 1) & 1), z + ((lo >> 2) & 1), dir);
        if (out.volume_debt6.size() <= v) out.volume_debt6.resize(out.positions_mm.size(), 0.0);
        out.volume_debt6[v] += shares[k].second;
      }
    }

    for (uint32_t key : kept_keys) kept[key] = 0;
    for (uint32_t c : cubes) cube_index[c] = -1;
  }
  out.volume_debt6.resize(out.positions_mm.size(), 0.0);
  for (size_t slot : used_slots) vertex_of[slot] = 0;
}

uint64_t number_block_vertices(const std::vector<const std::vector<uint64_t>*>& keys,
                               std::vector<std::vector<uint32_t>>& global) {
  const size_t blocks = keys.size();
  std::vector<uint64_t> first_interior(blocks + 1, 0);
  size_t boundary_count = 0;
  for (size_t b = 0; b < blocks; ++b) {
    const size_t interior = size_t(std::count(keys[b]->begin(), keys[b]->end(), kInteriorVertex));
    first_interior[b + 1] = first_interior[b] + interior;
    boundary_count += keys[b]->size() - interior;
  }
  std::vector<uint64_t> boundary_keys;
  boundary_keys.reserve(boundary_count);
  for (const std::vector<uint64_t>* k : keys)
    for (uint64_t key : *k)
      if (key != kInteriorVertex) boundary_keys.push_back(key);
  tbb::parallel_sort(boundary_keys.begin(), boundary_keys.end());
  boundary_keys.erase(std::unique(boundary_keys.begin(), boundary_keys.end()), boundary_keys.end());
  const uint64_t total = first_interior[blocks] + boundary_keys.size();
  if (total >= kNone) throw std::length_error("surface has more than 4 billion vertices");
  global.assign(blocks, {});
  tbb::parallel_for(size_t(0), blocks, [&](size_t b) {
    const std::vector<uint64_t>& k = *keys[b];
    std::vector<uint32_t>& g = global[b];
    g.resize(k.size());
    uint64_t next = first_interior[b];
    for (size_t v = 0; v < k.size(); ++v)
      g[v] = uint32_t(k[v] == kInteriorVertex
                          ? next++
                          : first_interior[blocks] + uint64_t(std::lower_bound(boundary_keys.begin(), boundary_keys.end(),
                                                                               k[v]) - boundary_keys.begin()));
  });
  return total;
}

TriMesh extract_block_surface(const Volume& volume, const ExtractOptions& options, int block_voxels,
                              std::vector<double>* volume_debt6) {
  TriMesh mesh;
  const BlockExtractor extractor(volume, block_voxels, options);
  const size_t blocks = extractor.block_count();
  std::vector<SurfaceBlock> parts(blocks);
  tbb::parallel_for(size_t(0), blocks, [&](size_t b) { extractor.extract(b, parts[b]); });
  std::vector<const std::vector<uint64_t>*> keys(blocks);
  for (size_t b = 0; b < blocks; ++b) keys[b] = &parts[b].keys;
  std::vector<std::vector<uint32_t>> global;
  mesh.positions_mm.resize(number_block_vertices(keys, global));
  if (volume_debt6) volume_debt6->assign(mesh.positions_mm.size(), 0.0);
  for (size_t b = 0; b < blocks; ++b) {
    for (size_t v = 0; v < parts[b].positions_mm.size(); ++v) {
      mesh.positions_mm[global[b][v]] = parts[b].positions_mm[v];
      if (volume_debt6) (*volume_debt6)[global[b][v]] += parts[b].volume_debt6[v];
    }
    for (const auto& t : parts[b].triangles) mesh.triangles.push_back({global[b][t[0]], global[b][t[1]], global[b][t[2]]});
  }
  return mesh;
}

}  // namespace lacuna
