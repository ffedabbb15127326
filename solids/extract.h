// Surface extraction from a volume: marching tetrahedra over the narrow band. The result is
// closed, edge- and vertex-manifold, outward-oriented and free of self-intersections by
// construction (see README, "Why marching tetrahedra").
#pragma once

#include <memory>

#include "geometry.h"
#include "solids/volume.h"

namespace lacuna {

struct ExtractOptions {
  // Crossing points are kept at least this fraction of an edge away from grid points, so no
  // triangle degenerates and neighbouring cells keep a margin after float32 rounding.
  double min_edge_fraction = 0.01;
};

// Triangulates the zero level set of the volume. Vertices are in mm, triangles counter-clockwise
// seen from outside. Deterministic for any number of threads.
TriMesh extract_surface(const Volume& volume, const ExtractOptions& options = {});

// The same surface cut into cubic blocks of whole voxels, one block at a time, so a consumer
// (the simplifier) can work on each while the whole mesh never exists. A block holds the pieces
// of the cubes inside it; a crossing on the block's boundary faces is computed identically by both
// blocks that share it and carries a key naming its grid edge.
struct SurfaceBlock {
  int64_t origin_voxels[3] = {0, 0, 0};  // grid index of the block's lowest corner
  int size_voxels = 0;
  Box3 box_mm;                            // the block's closed box, corners rounded to float like the vertices
  std::vector<Vec3d> positions_mm;        // float32 values
  std::vector<uint64_t> keys;             // kInteriorVertex, or the grid edge of a vertex on the boundary
  std::vector<std::array<uint32_t, 3>> triangles;
};
constexpr uint64_t kInteriorVertex = UINT64_MAX;

class BlockExtractor {
 public:
  // Blocks of `block_voxels` (a multiple of 8) voxels per side. Throws InvalidInput for other sizes.
  BlockExtractor(const Volume& volume, int block_voxels, const ExtractOptions& options = {});
  ~BlockExtractor();
  BlockExtractor(const BlockExtractor&) = delete;
  BlockExtractor& operator=(const BlockExtractor&) = delete;

  // The blocks the narrow band reaches, in increasing order of their origin.
  size_t block_count() const;
  // Extracts block i into `out` (its vectors are reused). Safe to call from several threads.
  void extract(size_t i, SurfaceBlock& out) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace lacuna
