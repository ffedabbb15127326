// The self-intersection test of solids/check.cpp against CGAL's does_self_intersect, an
// independent implementation, on closed manifold meshes with and without crossings.
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polygon_mesh_processing/self_intersections.h>
#include <CGAL/Surface_mesh.h>
#include <gtest/gtest.h>

#include "solids/check.h"
#include "solids/extract.h"
#include "solids/voxelize.h"
#include "util/random.h"

namespace lacuna {
namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using SurfaceMesh = CGAL::Surface_mesh<Kernel::Point_3>;

bool cgal_self_intersects(const TriMesh& mesh) {
  SurfaceMesh sm;
  for (const Vec3d& p : mesh.positions_mm) sm.add_vertex(Kernel::Point_3(p.x, p.y, p.z));
  for (const auto& t : mesh.triangles) {
    auto f = sm.add_face(SurfaceMesh::Vertex_index(t[0]), SurfaceMesh::Vertex_index(t[1]), SurfaceMesh::Vertex_index(t[2]));
    EXPECT_NE(f, SurfaceMesh::null_face());
  }
  return CGAL::Polygon_mesh_processing::does_self_intersect(sm);
}

TEST(CheckAgainstCgal, SameVerdictOnPerturbedSpheres) {
  GeometrySet set;
  set.spheres.centers_mm = {{0.03, -0.02, 0.01}};
  set.spheres.radii_mm = {1.0};
  const TriMesh sphere = extract_surface(voxelize(set, VolumeOptions{0.2, 3.0}));
  int crossing = 0, clean = 0;
  for (uint64_t seed = 1; seed <= 40; ++seed) {
    // Move a few vertices far enough to fold faces through their neighbours in some seeds, by
    // little in others; the topology stays closed and manifold, so every check runs.
    Random random(seed);
    TriMesh mesh = sphere;
    const int moves = int(1 + random.next() % 4);
    const double reach = seed % 2 ? 0.5 : 0.02;
    auto offset = [&] { return reach * (2 * random.uniform() - 1); };
    for (int m = 0; m < moves; ++m) {
      Vec3d& p = mesh.positions_mm[random.next() % mesh.positions_mm.size()];
      p += Vec3d{offset(), offset(), offset()};
    }
    const MeshCheckReport r = check_mesh(mesh);
    ASSERT_TRUE(r.self_intersections_checked) << seed;
    const bool expected = cgal_self_intersects(mesh);
    EXPECT_EQ(r.self_intersecting, expected) << "seed " << seed;
    (expected ? crossing : clean) += 1;
  }
  // Both verdicts occur, so the comparison means something either way.
  EXPECT_GT(crossing, 3);
  EXPECT_GT(clean, 3);
}

TEST(CheckAgainstCgal, SameVerdictOnTouchingCopies) {
  // Two copies of a closed mesh, the second shifted by less and more than its size: the copies
  // cross, touch or stay apart, which the check must see exactly as CGAL does.
  GeometrySet set;
  set.spheres.centers_mm = {{0, 0, 0}};
  set.spheres.radii_mm = {1.0};
  const TriMesh one = extract_surface(voxelize(set, VolumeOptions{0.25, 3.0}));
  for (double shift : {0.5, 1.9, 2.6, 4.0}) {
    TriMesh two = one;
    const uint32_t offset = uint32_t(one.positions_mm.size());
    for (const Vec3d& p : one.positions_mm) two.positions_mm.push_back(p + Vec3d{shift, 0, 0});
    for (const auto& t : one.triangles) two.triangles.push_back({t[0] + offset, t[1] + offset, t[2] + offset});
    const MeshCheckReport r = check_mesh(two);
    EXPECT_EQ(r.self_intersecting, cgal_self_intersects(two)) << "shift " << shift;
  }
}

}  // namespace
}  // namespace lacuna
