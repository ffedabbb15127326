// Merging each cube's marching-tetrahedra pieces: single cubes against counts from the
// definition, every sign pattern against the boundary its pieces have, and whole surfaces
// (smooth, sharp, random, nearly touching) checked as solids of the same topology within the
// deviation of the unmerged surface.
#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <iostream>
#include <map>
#include <set>

#include "cifs/library.h"
#include "cifs/solid_input.h"
#include "recipe/cifs_system.h"
#include "solids/check.h"
#include "solids/cube_surface.h"
#include "solids/exact.h"
#include "solids/extract.h"
#include "solids/mesh_distance.h"
#include "solids/voxelize.h"
#include "util/random.h"

namespace lacuna {
namespace {

using cube_surface::slot_of;
using Tri8 = std::array<uint8_t, 3>;

// A unit cube at the origin: corner values, the crossing of every sign-changing edge.
struct UnitCube {
  float f[8];
  int inside = 0;
  Vec3d positions[cube_surface::kSlots];
  cube_surface::MergeInput input(uint8_t kept_faces, double deviation) const {
    cube_surface::MergeInput in;
    in.inside = inside;
    in.values = f;
    in.eps = 0.01;
    in.positions = positions;
    in.box_lo = {0, 0, 0};
    in.box_hi = {1, 1, 1};
    in.kept_faces = kept_faces;
    in.max_deviation_mm = deviation;
    return in;
  }
};

UnitCube unit_cube(const float values[8]) {
  UnitCube c;
  for (int k = 0; k < 8; ++k) {
    c.f[k] = values[k];
    c.inside |= (values[k] < 0) << k;
  }
  for (int lo = 0; lo < 8; ++lo)
    for (int dir = 1; dir < 8; ++dir) {
      if ((lo & dir) || (values[lo] < 0) == (values[lo | dir] < 0)) continue;
      const double t = std::clamp(double(values[lo]) / (double(values[lo]) - double(values[lo | dir])), 0.01, 0.99);
      c.positions[slot_of(lo, lo | dir)] =
          round_to_output(Vec3d{(lo & 1) + t * (dir & 1), ((lo >> 1) & 1) + t * ((dir >> 1) & 1),
                                ((lo >> 2) & 1) + t * ((dir >> 2) & 1)});
    }
  return c;
}

std::vector<Tri8> pieces_of(const UnitCube& c) {
  Tri8 tris[12];
  const Tri8* end = cube_surface::cube_triangles(c.f, c.inside, 0.01, [](int ci, int cj) { return uint8_t(slot_of(ci, cj)); }, tris);
  return std::vector<Tri8>(static_cast<const Tri8*>(tris), end);
}

// Directed edges used by exactly one triangle whose reverse is not used: the boundary inside
// the cube.
std::set<std::pair<int, int>> boundary_of(const std::vector<Tri8>& tris) {
  std::map<std::pair<int, int>, int> directed;
  for (const Tri8& t : tris)
    for (int k = 0; k < 3; ++k) ++directed[{t[size_t(k)], t[size_t((k + 1) % 3)]}];
  std::set<std::pair<int, int>> out;
  for (const auto& [e, n] : directed)
    if (n == 1 && !directed.count({e.second, e.first})) out.insert(e);
  return out;
}

TEST(CubeSurface, OneCornerInsideMergesToTheCornerTriangle) {
  for (int corner = 0; corner < 8; ++corner) {
    float values[8];
    for (int k = 0; k < 8; ++k) values[k] = k == corner ? -0.5f : 0.5f;
    const UnitCube c = unit_cube(values);
    // The Freudenthal edges at a corner: three along the axes, and the diagonals towards the
    // corners that contain it or that it contains as bit sets.
    int diagonals = 0;
    for (int other = 0; other < 8; ++other)
      if (other != corner && ((other & corner) == other || (other & corner) == corner) &&
          __builtin_popcount(unsigned(other ^ corner)) > 1)
        ++diagonals;
    const std::vector<Tri8> pieces = pieces_of(c);
    std::vector<Tri8> merged;
    ASSERT_TRUE(cube_surface::merged_triangles(c.input(0, 1.0), merged)) << corner;
    ASSERT_EQ(merged.size(), 1u) << corner;
    const Vec3d p{double(corner & 1), double((corner >> 1) & 1), double((corner >> 2) & 1)};
    const Tri8& t = merged[0];
    for (uint8_t s : t) EXPECT_EQ(__builtin_popcount(unsigned(s & 7)), 1) << "an axis crossing";
    const Vec3d n = cross(c.positions[t[1]] - c.positions[t[0]], c.positions[t[2]] - c.positions[t[0]]);
    EXPECT_GT(dot(n, c.positions[t[0]] - p), 0) << "faces away from the inside corner " << corner;
    // Every diagonal kept: the boundary is the three axis crossings and the kept diagonals, and
    // a patch with an interior crossing (the body diagonal) loses it.
    merged.clear();
    ASSERT_TRUE(cube_surface::merged_triangles(c.input(0x3f, 1.0), merged));
    const size_t boundary = size_t(3 + diagonals - (corner == 0 || corner == 7 ? 1 : 0));
    EXPECT_EQ(merged.size(), boundary - 2) << corner;
    EXPECT_EQ(pieces.size(), corner == 0 || corner == 7 ? 6u : 2u);
  }
  // Corners 0 and 7 inside: the pieces are a tube around the body diagonal, which stays.
  EXPECT_TRUE(cube_surface::keeps_pieces(0x81));
  EXPECT_TRUE(cube_surface::keeps_pieces(0x7e));
  EXPECT_FALSE(cube_surface::keeps_pieces(0x01));
}

TEST(CubeSurface, EverySignPatternKeepsThePiecesBoundary) {
  Random random(11);
  int merged_cubes = 0, tried = 0;
  for (int inside = 1; inside < 255; ++inside)
    for (int trial = 0; trial < 24; ++trial) {
      float values[8];
      for (int k = 0; k < 8; ++k) {
        const float magnitude = float(0.02 + random.uniform());
        values[k] = ((inside >> k) & 1) ? -magnitude : magnitude;
      }
      const UnitCube c = unit_cube(values);
      const uint8_t kept = trial < 8 ? 0 : (trial < 16 ? 0x3f : uint8_t(random.next() & 0x3f));
      std::vector<Tri8> merged;
      ++tried;
      if (!cube_surface::merged_triangles(c.input(kept, 2.0), merged)) continue;
      ++merged_cubes;
      // The pieces' boundary with each left-out diagonal crossing d spliced out (a -> d -> b
      // becomes a -> b).
      std::set<std::pair<int, int>> expected = boundary_of(pieces_of(c));
      for (int face = 0; face < 6; ++face) {
        if ((kept >> face) & 1) continue;
        for (const auto& in_edge : std::set<std::pair<int, int>>(expected)) {
          const int d = in_edge.second;
          if (!cube_surface::is_face_diagonal(d) || cube_surface::face_of_diagonal(d) != face) continue;
          auto out_edge = std::find_if(expected.begin(), expected.end(), [&](const auto& e) { return e.first == d; });
          ASSERT_NE(out_edge, expected.end());
          const std::pair<int, int> joined{in_edge.first, out_edge->second};
          expected.erase(out_edge);
          expected.erase(in_edge);
          expected.insert(joined);
        }
      }
      EXPECT_EQ(boundary_of(merged), expected) << "inside " << inside << " kept " << int(kept);
      // Triangles sharing no corner do not meet.
      for (size_t t = 0; t < merged.size(); ++t)
        for (size_t u = t + 1; u < merged.size(); ++u) {
          const Tri8 &a = merged[t], &b = merged[u];
          int shared = 0;
          for (uint8_t x : a) shared += x == b[0] || x == b[1] || x == b[2];
          if (shared > 0) continue;
          EXPECT_FALSE(exact::triangles_meet(c.positions[a[0]], c.positions[a[1]], c.positions[a[2]], c.positions[b[0]],
                                             c.positions[b[1]], c.positions[b[2]]))
              << "inside " << inside << " kept " << int(kept);
        }
      // Each piece of the merged surface is a disk: V - E + F = 1 per connected patch, summed.
      std::set<int> vertices;
      std::set<std::pair<int, int>> edges;
      for (const Tri8& t : merged)
        for (int k = 0; k < 3; ++k) {
          vertices.insert(t[size_t(k)]);
          edges.insert({std::min(t[size_t(k)], t[size_t((k + 1) % 3)]), std::max(t[size_t(k)], t[size_t((k + 1) % 3)])});
        }
      std::map<int, int> loops;  // boundary loops = patches (one loop each)
      std::map<int, int> next;
      for (const auto& e : boundary_of(merged)) next[e.first] = e.second;
      int loop_count = 0;
      std::set<int> seen;
      for (const auto& [start, ignored] : next) {
        (void)ignored;
        if (seen.count(start)) continue;
        ++loop_count;
        for (int v = start; !seen.count(v); v = next[v]) seen.insert(v);
      }
      EXPECT_EQ(int(vertices.size()) - int(edges.size()) + int(merged.size()), loop_count)
          << "inside " << inside << " kept " << int(kept);
    }
  // Most sign patterns merge: only the tubes keep their pieces.
  EXPECT_GT(merged_cubes, tried * 3 / 4);
}

struct Surfaces {
  TriMesh plain, merged;
  MeshCheckReport plain_report, merged_report;
  double lost_mm3 = 0;  // the merge's own account of the volume it lost
};

// The unmerged surface (in blocks, so its vertices are the merged surface's to the bit) and the
// merged one.
Surfaces merge(const Volume& volume, double deviation, int block_voxels = 32) {
  Surfaces s;
  s.plain = extract_block_surface(volume, ExtractOptions(), block_voxels);
  EXPECT_EQ(s.plain.triangles.size(), extract_surface(volume).triangles.size());
  ExtractOptions options;
  options.merge_deviation_mm = deviation;
  std::vector<double> debt6;
  s.merged = extract_block_surface(volume, options, block_voxels, &debt6);
  for (double d : debt6) s.lost_mm3 += d / 6;
  s.plain_report = check_mesh(s.plain);
  s.merged_report = check_mesh(s.merged);
  return s;
}

void expect_same_solid(const Surfaces& s, double deviation, double volume_fraction) {
  EXPECT_TRUE(s.plain_report.valid()) << ::testing::PrintToString(s.plain_report.problems());
  EXPECT_TRUE(s.merged_report.valid()) << ::testing::PrintToString(s.merged_report.problems());
  EXPECT_EQ(s.merged_report.components, s.plain_report.components);
  EXPECT_EQ(s.merged_report.genus, s.plain_report.genus);
  EXPECT_LE(sampled_hausdorff_mm(s.merged, s.plain), deviation);
  EXPECT_LE(sampled_hausdorff_mm(s.plain, s.merged), deviation);
  EXPECT_NEAR(s.merged_report.volume_mm3, s.plain_report.volume_mm3, volume_fraction * s.plain_report.volume_mm3);
  // Every cube's share of the loss, summed, is the whole surface's loss.
  EXPECT_NEAR(s.lost_mm3, s.plain_report.volume_mm3 - s.merged_report.volume_mm3, 1e-9 * s.plain_report.volume_mm3);
  EXPECT_LT(s.merged.triangles.size(), s.plain.triangles.size());
}

// On a flat patch the merge takes a candidate by an exact argument instead of running the sampled
// deviation tests (solids/cube_surface.cpp): it must give what the sampled tests give, triangles and
// volume shares, on planes and bent planes through single cubes, for any kept faces and deviations
// from tight to loose; and on these the argument must take the triangulations of more patches than
// half the merged cubes.
TEST(CubeSurface, FlatPatchesMergeAsTheSampledTestsDo) {
  Random random(29);
  uint64_t proven = 0, merged = 0, compared = 0;
  for (int trial = 0; trial < 6000; ++trial) {
    // f(x) = n . (x - p) + c |x - p|^2: a plane through p, bent by c (none for a third of them).
    Vec3d n{2 * random.uniform() - 1, 2 * random.uniform() - 1, 2 * random.uniform() - 1};
    if (!(norm(n) > 0.1)) continue;
    n = n / norm(n);
    const Vec3d p{0.2 + 0.6 * random.uniform(), 0.2 + 0.6 * random.uniform(), 0.2 + 0.6 * random.uniform()};
    const double c = trial % 3 == 0 ? 0.0 : (random.uniform() - 0.5) * (trial % 3 == 1 ? 0.2 : 2.0);
    float values[8];
    for (int k = 0; k < 8; ++k) {
      const Vec3d corner{double(k & 1), double((k >> 1) & 1), double((k >> 2) & 1)};
      values[k] = float(dot(n, corner - p) + c * dot(corner - p, corner - p));
      if (values[k] == 0) values[k] = 1e-3f;
    }
    const UnitCube cube = unit_cube(values);
    if (cube.inside == 0 || cube.inside == 255) continue;
    for (double deviation : {0.002, 0.01, 0.05, 0.3}) {
      const uint8_t kept = trial % 4 == 0 ? 0 : uint8_t(random.next() & 0x3f);
      cube_surface::MergeInput in = cube.input(kept, deviation);
      uint64_t here = 0;
      in.proven_candidates = &here;
      cube_surface::MergeInput sampled_in = cube.input(kept, deviation);
      sampled_in.sampled_tests_only = true;
      std::vector<Tri8> fast, sampled;
      cube_surface::VolumeShares fast_lost, sampled_lost;
      const bool fast_merged = cube_surface::merged_triangles(in, fast, &fast_lost);
      const bool sampled_merged = cube_surface::merged_triangles(sampled_in, sampled, &sampled_lost);
      ++compared;
      ASSERT_EQ(fast_merged, sampled_merged) << "trial " << trial << ", deviation " << deviation;
      ASSERT_EQ(fast, sampled) << "trial " << trial << ", deviation " << deviation;
      if (!fast_merged) continue;
      ++merged;
      proven += here;
      ASSERT_EQ(fast_lost.count, sampled_lost.count);
      for (int i = 0; i < fast_lost.count; ++i) {
        EXPECT_EQ(fast_lost.slots[i], sampled_lost.slots[i]);
        EXPECT_EQ(fast_lost.volume6[i], sampled_lost.volume6[i]);
      }
    }
  }
  std::cout << compared << " compared, " << merged << " merged, " << proven << " proven\n";
  EXPECT_GT(merged, compared / 2);
  EXPECT_GT(proven, merged / 2);
}

TEST(CubeSurface, SphereMergesToAThirdOfItsPieces) {
  GeometrySet set;
  set.spheres.centers_mm = {{0.013, -0.021, 0.007}};
  set.spheres.radii_mm = {3};
  const double h = 0.1;
  const Surfaces s = merge(voxelize(set, VolumeOptions{h, 3.0}), 0.05 * h);
  expect_same_solid(s, 0.05 * h, 0.002);
  EXPECT_EQ(s.merged_report.genus, 0);
  // Marching cubes has about a third of the pieces' crossings (three grid edges of seven).
  EXPECT_LT(s.merged.triangles.size(), s.plain.triangles.size() * 45 / 100);
}

TEST(CubeSurface, SmallBlocksAndSharpEdges) {
  // Level 2 of a Menger sponge, faces a quarter voxel off the grid, in blocks of 8 voxels: many
  // block faces, flat faces and right-angled edges.
  const double side = 3, h = 1.0 / 9.0;
  nlohmann::json spec = {{"library", "menger_sponge"}, {"scale", side}, {"translate_mm", {h / 4, h / 4, h / 4}}};
  const cifs::Cifs menger = cifs::parse_system(spec, "test", "system");
  const Surfaces s = merge(voxelize(cifs::attractor_geometry(menger, 2, {}), VolumeOptions{h, 3.0}), 0.05 * h, 8);
  expect_same_solid(s, 0.05 * h, 0.002);
  EXPECT_EQ(s.merged_report.genus, 81);
}

TEST(CubeSurface, RandomFoamOfSmallSpheres) {
  // Spheres of 0.3 to 1.5 voxels, many touching: sign patterns of every kind, tubes included.
  Random random(5);
  GeometrySet set;
  const double h = 0.1;
  for (int i = 0; i < 400; ++i) {
    set.spheres.centers_mm.push_back({3 * random.uniform(), 3 * random.uniform(), 3 * random.uniform()});
    set.spheres.radii_mm.push_back(h * (0.3 + 1.2 * random.uniform()));
  }
  const Surfaces s = merge(voxelize(set, VolumeOptions{h, 3.0}), 0.05 * h, 8);
  expect_same_solid(s, 0.05 * h, 0.01);
  EXPECT_GT(s.merged_report.components, 20u);
}

TEST(CubeSurface, NearlyTouchingSpheresStayApart) {
  // A tenth of a voxel apart, merged within two voxels: the face rules keep the gap.
  const double h = 0.1, r = 1;
  GeometrySet set;
  set.spheres.centers_mm = {{-r - h / 20, 0.01, 0.02}, {r + h / 20, 0.01, 0.02}};
  set.spheres.radii_mm = {r, r};
  const Surfaces s = merge(voxelize(set, VolumeOptions{h, 3.0}), 2 * h, 8);
  EXPECT_TRUE(s.merged_report.valid()) << ::testing::PrintToString(s.merged_report.problems());
  EXPECT_EQ(s.merged_report.components, s.plain_report.components);
  EXPECT_EQ(s.merged_report.genus, s.plain_report.genus);
}

TEST(CubeSurface, SameTrianglesForAnyThreadCount) {
  GeometrySet set;
  set.tubes.tubes.push_back(Tube{{{-2, 0.1, 0.3}, {2, -0.4, 0.7}, {1, 2, -1}}, {0.45}});
  const Volume volume = voxelize(set, VolumeOptions{0.05, 3.0});
  ExtractOptions options;
  options.merge_deviation_mm = 0.0025;
  TriMesh one, two;
  {
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 1);
    one = extract_block_surface(volume, options, 16);
  }
  two = extract_block_surface(volume, options, 16);
  EXPECT_EQ(one.triangles, two.triangles);
  ASSERT_EQ(one.positions_mm.size(), two.positions_mm.size());
  for (size_t v = 0; v < one.positions_mm.size(); ++v) EXPECT_EQ(one.positions_mm[v], two.positions_mm[v]);
}

}  // namespace
}  // namespace lacuna
