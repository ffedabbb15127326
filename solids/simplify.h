// Guarded simplification of closed surfaces: edge collapses by quadric error, each one tested with
// exact predicates against the triangles near it before it is taken, so a valid solid stays valid
// (closed, manifold, outward, free of self-intersections and degenerate faces, same components
// and genus). Parallel in independent regions with locked borders, then across the borders;
// identical output for any number of threads.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <limits>
#include <memory>
#include <vector>

#include "geometry.h"
#include "solids/volume.h"

namespace lacuna {

struct SimplifyOptions {
  double max_deviation_mm = 0.01;     // bound on the quadric deviation of every merged vertex (mm, > 0)
  double max_normal_change_deg = 60;  // no collapse turns a face's normal further than this
  // Side of the independent regions (mm); 0 picks one from the mesh so that each holds a few tens
  // of thousands of triangles.
  double region_mm = 0;
  // extract_simplified_surface only: the share of the deviation the cubes' pieces may be merged
  // within as they are extracted (ExtractOptions::merge_deviation_mm); the collapses keep to the
  // rest. 0 extracts the marching-tetrahedra pieces unmerged.
  double merge_fraction = 0.25;
};

struct SimplifyStats {
  uint64_t input_triangles = 0;   // of the marching-tetrahedra surface
  uint64_t merged_triangles = 0;  // extract_simplified_surface: after the cubes' pieces were merged
  uint64_t output_triangles = 0;
  uint64_t collapses = 0;
  uint64_t rejected_by_intersection = 0;  // collapses the exact guard refused
  uint64_t regions = 0;                   // regions simplified (blocks and cross-block regions)
  uint64_t regions_redone = 0;            // regions whose result failed verification and were redone
  uint64_t regions_guarded = 0;           // of those, the ones the plain bound did not mend: redone guarded
  // Where the time went, in seconds summed over the threads (so on two busy cores about twice the
  // wall time): extracting and merging the blocks' cubes; the regions' first runs (loading them and
  // the collapses); their verifications; the redone regions' second and third runs (their first
  // runs and verifications are counted in the two before).
  double extract_thread_seconds = 0;
  double run_thread_seconds = 0;
  double verify_thread_seconds = 0;
  double redo_thread_seconds = 0;
  // extract_simplified_surface only, wall time: the blocks (extracted and simplified), putting their
  // results together, and the pass across the blocks' faces.
  double blocks_seconds = 0;
  double assemble_seconds = 0;
  double pass_seconds = 0;
};

// Simplifies a closed mesh to within the deviation. Every coordinate of the result is a float32
// value (the mesh is written as float32), and every check ran on those coordinates. Vertices on a
// boundary, a non-manifold edge or a non-manifold vertex never move, so an input that is not a
// clean closed surface is simplified only where it is one. Throws InvalidInput for a non-positive
// deviation.
TriMesh simplify_mesh(const TriMesh& mesh, const SimplifyOptions& options, SimplifyStats* stats = nullptr);

// The surface of the volume (extract_surface's marching tetrahedra), simplified block by block
// as it is extracted, then across the blocks' faces: the full mesh is never held. Same
// guarantees as simplify_mesh.
TriMesh extract_simplified_surface(const Volume& volume, const SimplifyOptions& options,
                                   SimplifyStats* stats = nullptr);

// Final triangles of a streamed surface, with a number per vertex: the same number wherever the
// vertex appears, distinct vertices distinct numbers (from 0, in the order they first came in).
struct EmittedTriangles {
  std::vector<std::array<Vec3d, 3>> corners;  // float32 values, counter-clockwise seen from outside
  std::vector<std::array<uint64_t, 3>> numbers;
};

// extract_simplified_surface of a volume that comes slab by slab, bottom to top: each slab's
// blocks are simplified as they come, the pass across the blocks' faces runs region by region as
// the blocks it meets are in, and the final triangles go to `emit` as they are made, so memory
// holds a slab and the regions around its cuts. The triangles, in the order emitted, are the
// whole volume's extract_simplified_surface, triangle for triangle (before its vertices are
// renumbered), when every slab's volume equals the whole one over its blocks and a voxel above.
class StreamedSurface {
 public:
  static constexpr int kSlabVoxels = 32;  // slabs start and end on whole blocks of this many voxels
  static constexpr int64_t kUnbounded = std::numeric_limits<int64_t>::max();
  StreamedSurface(const SimplifyOptions& options, double voxel_size_mm,
                  std::function<void(const EmittedTriangles&)> emit);
  ~StreamedSurface();
  StreamedSurface(const StreamedSurface&) = delete;
  StreamedSurface& operator=(const StreamedSurface&) = delete;

  // Adds the surface blocks of `volume` whose lowest voxel z index lies in [z0, z1): the first
  // slab from -kUnbounded, each next one from where the last ended, the last to kUnbounded.
  void add(const Volume& volume, int64_t z0_voxels, int64_t z1_voxels);
  // Emits what is left (after the last slab).
  void finish();
  const SimplifyStats& stats() const;
  uint64_t numbers_given() const;

  // One part of a surface streamed by several processes, each a block of the slabs: this one emits
  // only the triangles the whole stream emits after a slab ending at `cut_voxels` (a whole block),
  // up to the end of its last add (then finish, only for the last part). Call before the first add,
  // whose slabs must start at least three blocks below the cut (those below it are a lead-in: their
  // blocks are simplified again here, their regions are not run). Concatenated in order, the parts'
  // triangles are the whole stream's.
  void begin_after(int64_t cut_voxels);
  // The vertices in the window now (those a later triangle may still use), each with its number
  // and its identity in the whole surface (the same in every part that has the vertex). After the
  // lead-in, and after a part's last add: a vertex both parts emit is in both lists.
  struct WindowVertex {
    uint64_t number;
    std::array<uint64_t, 2> identity;
  };
  std::vector<WindowVertex> window_vertices() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace lacuna
