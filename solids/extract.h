// Surface extraction from a volume: marching tetrahedra over the narrow band. The result is
// closed, edge- and vertex-manifold, outward-oriented and free of self-intersections by
// construction (see README, "Why marching tetrahedra").
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <vector>

#include "geometry.h"
#include "solids/volume.h"

namespace lacuna {

struct ExtractOptions {
  // Crossing points are kept at least this fraction of an edge away from grid points, so no
  // triangle degenerates and neighbouring cells keep a margin after float32 rounding.
  double min_edge_fraction = 0.01;
  // BlockExtractor only: when positive, each cube's pieces are merged into fewer triangles on the
  // same boundary, leaving out the crossings on its body diagonal and on the face diagonals both
  // cubes of a face agree to leave out, wherever every test passes within this deviation (mm) of
  // the pieces (see solids/cube_surface.h); 0 keeps the marching-tetrahedra pieces.
  double merge_deviation_mm = 0;
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
  uint64_t piece_triangles = 0;           // the marching-tetrahedra triangles of the block (before merging)
  // Per vertex: six times the volume the merge lost near it (its share of its patches' losses;
  // all zero unmerged). The shares of all blocks sum to six times the whole surface's loss.
  std::vector<double> volume_debt6;
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
  // Block i's lowest voxel.
  std::array<int64_t, 3> block_origin(size_t i) const;
  // Extracts block i into `out` (its vectors are reused). Safe to call from several threads.
  void extract(size_t i, SurfaceBlock& out) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// Global vertex numbers for blocks extracted one by one (keys[b] the keys of block b's vertices):
// the blocks' interior vertices in block order, then the vertices on block faces once per grid
// edge, in key order. Fills global[b][v] and returns the number of vertices. Throws
// std::length_error past 4 billion vertices.
uint64_t number_block_vertices(const std::vector<const std::vector<uint64_t>*>& keys,
                               std::vector<std::vector<uint32_t>>& global);

// The surface cut into blocks of `block_voxels`, each extracted with `options` (so merged when
// options.merge_deviation_mm > 0), and welded into one mesh. The same guarantees as
// extract_surface. `volume_debt6`, when given, receives the blocks' SurfaceBlock::volume_debt6
// per vertex of the mesh (summed where blocks share a vertex).
TriMesh extract_block_surface(const Volume& volume, const ExtractOptions& options, int block_voxels = 32,
                              std::vector<double>* volume_debt6 = nullptr);

}  // namespace lacuna
