// Validity checks of a triangle mesh as a printable solid: closed, manifold, consistently and
// outward oriented, free of self-intersections and degenerate faces, finite, positive volume.
// Validity is data: the report says what holds and what does not; nothing here throws for an
// invalid mesh.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "geometry.h"

namespace lacuna {

struct CheckOptions {
  bool self_intersections = true;  // test every pair of nearby faces for intersections (the slowest check)
};

struct MeshCheckReport {
  uint64_t vertices = 0;
  uint64_t triangles = 0;
  uint64_t edges = 0;
  uint64_t non_finite_vertices = 0;
  uint64_t bad_indices = 0;            // triangle corners that name no vertex
  uint64_t degenerate_faces = 0;       // repeated corner or collinear corners (exact test)
  uint64_t boundary_edges = 0;         // edges with one face: the mesh is open
  uint64_t non_manifold_edges = 0;     // edges with more than two faces
  uint64_t misoriented_edges = 0;      // edges whose two faces run them the same way
  uint64_t non_manifold_vertices = 0;  // vertices whose faces form more than one fan
  bool vertex_manifold_checked = false;
  bool self_intersections_checked = false;
  bool self_intersecting = false;
  bool orientation_checked = false;
  uint64_t inward_components = 0;      // components oriented against the volume they bound
  uint64_t components = 0;             // connected components (through shared vertices)
  int64_t genus = 0;                   // sum over components of (2 - Euler characteristic) / 2
  double volume_mm3 = 0;               // signed; positive for an outward-oriented solid
  double area_mm2 = 0;
  Box3 bounding_box;

  bool closed() const { return boundary_edges == 0; }
  bool manifold() const { return non_manifold_edges == 0 && vertex_manifold_checked && non_manifold_vertices == 0; }
  bool outward() const { return orientation_checked && misoriented_edges == 0 && inward_components == 0; }
  bool valid() const;
  // One line per failed check, in words a user can act on; empty when valid.
  std::vector<std::string> problems() const;
};

// Runs every check on the mesh. Deterministic; parallel where it pays.
MeshCheckReport check_mesh(const TriMesh& mesh, const CheckOptions& options = {});

// How many other components enclose each component of the mesh, in the order of
// mesh_components() (solids/components.h): the parity of exact ray crossings. The components must
// not intersect each other.
std::vector<uint32_t> component_depths(const TriMesh& mesh);

// check_mesh's checks of a mesh too large to hold, read in chunks of whole triangles as written
// (corners as float triples, shared corners equal), two chunks at a time: so every triangle of a
// chunk must lie above (in z) every triangle of the chunks before the last, which is tested (when it
// does not hold, self-intersections count as not checked and the figures are not the mesh's). The
// figures are the whole mesh's (the volume up to rounding; problem edges of an invalid mesh may be
// counted in two windows).
class ChunkedCheck {
 public:
  explicit ChunkedCheck(const CheckOptions& options = {});
  ~ChunkedCheck();
  ChunkedCheck(const ChunkedCheck&) = delete;
  ChunkedCheck& operator=(const ChunkedCheck&) = delete;
  // The next chunk, in order; `last` for the last one.
  void add(std::vector<std::array<Vec3d, 3>> chunk, bool last);
  MeshCheckReport finish();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace lacuna
