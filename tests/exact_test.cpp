// Exact predicates: the fast paths agree with CGAL's exact answers on near-degenerate inputs,
// and the face-pair test knows what two triangles share.
#include <gtest/gtest.h>

#include "solids/exact.h"
#include "util/random.h"

namespace lacuna {
namespace {

TEST(Exact, FastOrientationsAgreeWithExactOnNearlyDegenerateInputs) {
  Random random(7);
  for (int i = 0; i < 20000; ++i) {
    // Points on a plane through the origin, nudged by a few ulps (or not at all): the double
    // determinant is noise there, so only the filter's bound keeps the fast answer right.
    auto on_plane = [&] {
      const double u = 10 * random.uniform() - 5, v = 10 * random.uniform() - 5;
      Vec3d p{u, v, 0.3 * u - 0.7 * v};
      if (random.next() % 2) p.z = std::nextafter(p.z, random.next() % 2 ? 1e9 : -1e9);
      return p;
    };
    const Vec3d a = on_plane(), b = on_plane(), c = on_plane(), d = on_plane();
    const int fast = exact::orient3d(a, b, c, d), slow = exact::orient3d_exact(a, b, c, d);
    ASSERT_EQ(fast, slow) << i;
    const int fast2 = exact::orient2d(a.x, a.z, b.x, b.z, c.x, c.z), slow2 = exact::orient2d_exact(a.x, a.z, b.x, b.z, c.x, c.z);
    ASSERT_EQ(fast2, slow2) << i;
  }
  // Exact zeros and both signs on plain inputs.
  EXPECT_EQ(exact::orient3d({0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {5, 7, 0}), 0);
  EXPECT_EQ(exact::orient3d({0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}), 1);  // (b - a) x (c - a) = +z
  EXPECT_EQ(exact::orient3d({0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, -1}), -1);
  EXPECT_EQ(exact::orient2d(0, 0, 1, 0, 0, 1), 1);
  EXPECT_TRUE(exact::collinear({0, 0, 0}, {1, 1, 1}, {3, 3, 3}));
  EXPECT_FALSE(exact::collinear({0, 0, 0}, {1, 1, 1}, {3, 3, std::nextafter(3.0, 4.0)}));
}

TEST(Exact, FacesIntersectKnowsWhatIsShared) {
  const std::vector<Vec3d> p = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0}, {0, 0, 1}, {0.2, 0.2, -1}, {0.2, 0.2, 1},
                                {0.3, 0.3, 0}, {-1, 0, 0}, {5, 5, 5}, {6, 5, 5}, {5, 6, 5}};
  using T = std::array<uint32_t, 3>;
  // Two triangles sharing the edge 1-2, folded open (flat, opposite sides): only the edge is shared.
  EXPECT_FALSE(exact::faces_intersect(p.data(), T{0, 1, 2}, T{1, 3, 2}));
  // The same edge with both triangles on one side in one plane: they overlap.
  EXPECT_TRUE(exact::faces_intersect(p.data(), T{0, 1, 2}, T{1, 7, 2}));
  // Sharing vertex 0 only, the second standing up out of the plane: the vertex only.
  EXPECT_FALSE(exact::faces_intersect(p.data(), T{0, 1, 2}, T{0, 4, 8}));
  // Sharing vertex 0, the second piercing the first: a crossing.
  EXPECT_TRUE(exact::faces_intersect(p.data(), T{0, 1, 2}, T{0, 5, 6}));
  // Nothing shared by index but a common point: a crossing (touching counts).
  EXPECT_TRUE(exact::faces_intersect(p.data(), T{0, 1, 2}, T{7, 4, 6}));
  // Nothing shared, apart.
  EXPECT_FALSE(exact::faces_intersect(p.data(), T{0, 1, 2}, T{9, 10, 11}));
  // The same three vertices twice.
  EXPECT_TRUE(exact::faces_intersect(p.data(), T{0, 1, 2}, T{0, 2, 1}));
}

}  // namespace
}  // namespace lacuna
