// Lacunar volumes: rules and counts against closed forms (the plain hexahedron's 6^i, the tetrahedron's
// prisms and hexahedra), volumes against (1 - s^3)^k and against the faces' own 2D areas, the cells a level
// realizes against the rules' counts, shared faces of an assembly of mixed cells with delays, and bad specs.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "bcifs/realize.h"
#include "bcifs/topology.h"
#include "bcifs/volume.h"
#include "errors.h"
#include "solids/check.h"
#include "solids/extract.h"
#include "solids/voxelize.h"

namespace lacuna {
namespace {

using namespace bcifs;

FaceType quad_face(const std::string& edge, const std::string& params, int delay = 1) {
  return FaceType{std::vector<EdgeType>(4, parse_edge(edge)), parse_edge_set(params), Algorithm::kA1, delay};
}

// A cell whose faces all have one edge type (or are all plain).
CellSpec uniform_cell(const Polyhedron& shape, bool plain, const std::string& edge = "B2",
                      const std::string& params = "B2 B2 B2", int delay = 1) {
  CellSpec c;
  c.shape = shape;
  c.delay = delay;
  for (const auto& f : shape.faces) {
    c.face_types.push_back(FaceType{std::vector<EdgeType>(f.size(), parse_edge(edge)), parse_edge_set(params),
                                    Algorithm::kA1, 1});
    c.plain.push_back(plain ? 1 : 0);
  }
  return c;
}

VolumeSpec plain_spec(CellKind kind, double edge) {
  VolumeSpec spec;
  spec.cells.push_back(uniform_cell(regular_cell(kind, edge), true));
  spec.interior.plain = true;
  return spec;
}

// convex_pieces grows every piece by a relative 1e-9: its volume by (1 + 1e-9)^3.
const double kGrown = std::pow(1 + 1e-9, 3);

// Faces of a level lying in the plane x = `x`, and how many of them two cells have.
std::pair<int, int> faces_on_plane(const VolumeLevel& level, double x) {
  int on_plane = 0, twice = 0;
  for (size_t f = 0; f < level.faces.size(); ++f) {
    bool in = true;
    for (const Vec3d& p : level.faces[f].polygon) in = in && std::fabs(p.x - x) < 1e-9;
    on_plane += in;
    twice += in && level.owners[f] == 2;
  }
  return {on_plane, twice};
}

double total_volume(const VolumeLevel& level, const VolumeSpec& spec) {
  double v = 0;
  for (const VolumeCell& c : level.cells) v += cell_volume(c, spec);
  return v;
}

// The volume of convex pieces, each from its faces oriented away from its corners' average.
double pieces_volume(const std::vector<ConvexCells>& pieces) {
  double v = 0;
  for (const ConvexCells& cells : pieces)
    for (size_t k = 0; k < cells.size(); ++k) {
      const Vec3d* p = cells.corners_mm.data() + k * size_t(cells.corners_per_cell);
      Vec3d c{0, 0, 0};
      for (int i = 0; i < cells.corners_per_cell; ++i) c += p[i];
      c = c / double(cells.corners_per_cell);
      for (const auto& face : cells.faces) {
        double part = 0;
        for (size_t j = 1; j + 1 < face.size(); ++j)
          part += dot(p[face[0]] - c, cross(p[face[j]] - c, p[face[j + 1]] - c));
        v += std::fabs(part) / 6;
      }
    }
  return v;
}

TEST(BcifsVolume, PlainHexahedronIsSixHexahedraAroundALacuna) {
  const VolumeSpec spec = plain_spec(CellKind::kHexahedron, 10);
  const VolumeRules rules = build_volume_rules(spec);
  ASSERT_EQ(rules.cells.size(), 1u);  // the frustum over a plain square is a plain hexahedron again
  ASSERT_EQ(rules.cells[0].children.size(), 6u);
  const Lacunarity l = volume_lacunarity(rules, rules.roots[0], 6);
  for (int i = 0; i <= 6; ++i) {
    EXPECT_EQ(l.subfaces[size_t(i)], std::pow(6.0, i));
    EXPECT_EQ(l.lacunas[size_t(i)], (std::pow(6.0, i) - 1) / 5);
  }
  EXPECT_NEAR(l.limit, 1.0 / 6, 1e-12);  // N^L_1 / (N^L_1 + N^C_1 - 1)

  const double s = 0.5;
  VolumeGeometryOptions options;
  options.lacuna_scale = s;
  for (int k = 0; k <= 3; ++k) {
    const VolumeLevel level = realize_volume(rules, spec, k, options);
    ASSERT_EQ(level.cells.size(), size_t(std::pow(6, k)));
    for (const VolumeCell& c : level.cells) EXPECT_EQ(c.faces.size(), 6u);
    // Every sub-cell is a frustum towards its parent's centre: (1 - s^3) of the parent per level.
    EXPECT_NEAR(total_volume(level, spec), 1000 * std::pow(1 - s * s * s, k), 1e-9);
    EXPECT_NEAR(pieces_volume(convex_pieces(level, spec)), 1000 * std::pow(1 - s * s * s, k) * kGrown, 1e-9);
  }
  VolumeLevel last;
  const VolumeMeasures m = volume_measures(rules, spec, 3, options, &last);
  EXPECT_EQ(last.cells.size(), 216u);  // the level it measured last, handed back
  EXPECT_NEAR(total_volume(last, spec), m.volume[3], 1e-9);
  EXPECT_NEAR(m.volume_factor, 1 - s * s * s, 1e-12);
  EXPECT_NEAR(m.surface[0], 600, 1e-9);
  // Level 1: the cube's faces and the lacuna's (the six hexahedra share their slanted sides).
  EXPECT_NEAR(m.surface[1], 600 * (1 + s * s), 1e-9);
}

TEST(BcifsVolume, PlainTetrahedronMakesPrismsThenHexahedra) {
  // A tetrahedron's four frusta are triangular prisms; a prism's five are two prisms and three hexahedra.
  const VolumeSpec spec = plain_spec(CellKind::kTetrahedron, 10);
  const VolumeRules rules = build_volume_rules(spec);
  EXPECT_EQ(rules.cells.size(), 3u);
  const Lacunarity l = volume_lacunarity(rules, rules.roots[0], 4);
  // t -> 4p, p -> 2p + 3h, h -> 6h: N_1 = 4, N_2 = 4 * 5, N_3 = 4 (2 * 5 + 3 * 6), N_4 = 4 (2 * 28 + 3 * 36).
  EXPECT_EQ(l.subfaces[1], 4);
  EXPECT_EQ(l.subfaces[2], 20);
  EXPECT_EQ(l.subfaces[3], 112);
  EXPECT_EQ(l.subfaces[4], 4 * (2 * 28 + 3 * 36));
  const double v0 = std::pow(10.0, 3) / (6 * std::sqrt(2.0));
  for (CellKind kind : {CellKind::kTetrahedron, CellKind::kPrism, CellKind::kTruncatedTetrahedron}) {
    const VolumeSpec sp = plain_spec(kind, 10);
    const VolumeRules r = build_volume_rules(sp);
    const VolumeLevel zero = realize_volume(r, sp, 0);
    const double base = total_volume(zero, sp);
    const double closed_form = kind == CellKind::kTetrahedron ? v0
                               : kind == CellKind::kPrism     ? std::sqrt(3.0) / 4 * 1000
                                                              : 23 * std::sqrt(2.0) / 12 * 1000;
    EXPECT_NEAR(base, closed_form, 1e-9);
    const VolumeLevel two = realize_volume(r, sp, 2);
    EXPECT_EQ(double(two.cells.size()), volume_lacunarity(r, r.roots[0], 2).subfaces[2]);
    EXPECT_NEAR(total_volume(two, sp), base * std::pow(1 - 0.125, 2), 1e-9);
  }
}

TEST(BcifsVolume, LacunarFacesOpenTheWallsAndTheCountsAgree) {
  VolumeSpec spec;
  spec.cells.push_back(uniform_cell(regular_cell(CellKind::kHexahedron, 10), false, "B2", "B2 B2 B2"));
  const VolumeRules rules = build_volume_rules(spec);
  const Lacunarity l = volume_lacunarity(rules, rules.roots[0], 3);
  // <B2 B2 B2 B2> under A1: four corner pentagons per face.
  EXPECT_EQ(l.subfaces[1], 24);
  VolumeGeometryOptions options;
  options.lacuna_scale = 0.5;
  for (int k = 1; k <= 3; ++k) {
    const VolumeLevel level = realize_volume(rules, spec, k, options);
    EXPECT_EQ(double(level.cells.size()), l.subfaces[size_t(k)]) << "level " << k;
    for (int owners : level.owners) EXPECT_TRUE(owners == 1 || owners == 2);
  }

  // Level 1 from the faces' own 2D realization: each face's sub-faces (its area less its lacuna) times the
  // frustum factor (1 - s^3) h / 3, h = 5 the distance from the centre.
  const RuleSet faces2d = build_rules(quad_face("B2", "B2 B2 B2"));
  const std::vector<Vec2d> square{{0, 0}, {10, 0}, {10, 10}, {0, 10}};
  const GeometricMeasures g = geometric_measures(faces2d, 0, square, 1, RealizeOptions{});
  const double s = 0.5;
  const double expected = 6 * g.area[1] * 5 / 3 * (1 - s * s * s);
  const VolumeLevel one = realize_volume(rules, spec, 1, options);
  EXPECT_NEAR(total_volume(one, spec), expected, 1e-9);
  EXPECT_LT(g.area[1], 100 - 1);  // the walls really are opened
  // The convex pieces (pentagons are convex here) hold the same volume.
  EXPECT_NEAR(pieces_volume(convex_pieces(one, spec)), expected * kGrown, 1e-9);
}

// The solid of a hexahedron with Bezier walls at level 2: one component whose genus is the tunnels less the
// lacunas counted on the cells (6 + 24 * 5 - 25 = 101), and whose volume is the cells' exact volume.
TEST(BcifsVolume, SolidGenusAndVolumeMatchTheCells) {
  VolumeSpec spec;
  spec.cells.push_back(uniform_cell(regular_cell(CellKind::kHexahedron, 20), false, "B2", "B2 B2 B2"));
  const VolumeRules rules = build_volume_rules(spec);
  VolumeGeometryOptions options;
  options.lacuna_scale = 0.5;
  const VolumeMeasures m = volume_measures(rules, spec, 2, options);
  ASSERT_EQ(m.genus.size(), 3u);
  EXPECT_EQ(m.genus[1], 5);  // six faces opened into one lacuna: a hollow cube with six windows
  EXPECT_EQ(m.tunnels[2], 6 * 4 * 2 + 24 * 3);  // 48 pentagons (outer and inner) and 72 distinct side quads
  EXPECT_EQ(m.genus[2], 101);
  GeometrySet geometry;
  geometry.cells = convex_pieces(realize_volume(rules, spec, 2, options), spec);
  const MeshCheckReport r = check_mesh(extract_surface(voxelize(geometry, VolumeOptions{0.125, 3.0})));
  EXPECT_TRUE(r.valid()) << ::testing::PrintToString(r.problems());
  EXPECT_EQ(r.components, 1u);
  EXPECT_EQ(double(r.genus), m.genus[2]);
  EXPECT_NEAR(r.volume_mm3, m.volume[2], 0.01 * m.volume[2]);
}

TEST(BcifsVolume, NotchedSubFacesAreSplitIntoConvexPieces) {
  // Faces delayed by 2: each has one sub-face, its boundary notched at the Cantor gaps (a non-convex octagon
  // with four notches), so the first level's six frusta are not convex.
  VolumeSpec spec;
  spec.cells.push_back(uniform_cell(regular_cell(CellKind::kHexahedron, 10), false, "C2", "C2 B2 B2"));
  for (FaceType& f : spec.cells[0].face_types) f.delay = 2;
  const VolumeRules rules = build_volume_rules(spec);
  EXPECT_EQ(volume_cells(rules, 1), 6);
  for (int k = 1; k <= 2; ++k) {
    const VolumeLevel level = realize_volume(rules, spec, k);
    const std::vector<ConvexCells> pieces = convex_pieces(level, spec);
    size_t count = 0;
    for (const ConvexCells& p : pieces) count += p.size();
    EXPECT_GT(count, level.cells.size());  // notched (non-convex) bases were split
    EXPECT_NEAR(pieces_volume(pieces), total_volume(level, spec) * kGrown, 1e-9);
  }
}

// A cube and a prism on its +x face, the prism delayed by 2: the face they share is subdivided identically
// from both sides at every level, so every sub-face on it belongs to two cells.
TEST(BcifsVolume, AssemblyOfMixedCellsAndDelaysSharesItsFaceAtEveryLevel) {
  VolumeSpec spec;
  spec.interior.plain = true;
  const Polyhedron cube = regular_cell(CellKind::kHexahedron, 10);
  spec.cells.push_back(uniform_cell(cube, false, "B2", "B2 B2 B2"));
  Polyhedron prism;
  const double r = 5 + 5 * std::sqrt(3.0);
  prism.corners_mm = {{5, -5, -5}, {5, 5, -5}, {r, 0, -5}, {5, -5, 5}, {5, 5, 5}, {r, 0, 5}};
  prism.faces = {{0, 1, 2}, {3, 5, 4}, {0, 3, 4, 1}, {1, 4, 5, 2}, {2, 5, 3, 0}};
  spec.cells.push_back(uniform_cell(prism, false, "B2", "B2 B2 B2", 2));
  const VolumeRules rules = build_volume_rules(spec);
  ASSERT_EQ(rules.shared.size(), 1u);
  EXPECT_EQ(rules.shared[0].cell_a, 0);
  EXPECT_EQ(rules.shared[0].cell_b, 1);
  // The shared face carries the prism's delay from both sides.
  const int shared_type = find_type(rules.faces, quad_face("B2", "B2 B2 B2", 2));
  ASSERT_GE(shared_type, 0);
  const Lacunarity face = lacunarity(rules.faces, shared_type, 4);
  EXPECT_EQ(face.subfaces[1], 1);
  for (int k = 1; k <= 4; ++k) {
    const VolumeLevel level = realize_volume(rules, spec, k);
    const auto [on_plane, twice] = faces_on_plane(level, 5);
    EXPECT_EQ(on_plane, twice) << "level " << k;
    EXPECT_EQ(double(twice), face.subfaces[size_t(k)]) << "level " << k;
    EXPECT_EQ(double(level.cells.size()), volume_cells(rules, k)) << "level " << k;
  }
}

// Cells of edges 1 to 4 mm: without delays the last subdivision's lacunas keep that 4x spread; with the delays
// by size 1 and 2 mm round to one delay and keep their factor 2, so the spread halves (delays are whole levels and
// a level shrinks these cells about 3.5 times: two cells end within that of each other, 1.5 is out of reach for
// sizes between two delays); cells whose sizes differ by whole levels' shrinks get lacunas within 1.5.
TEST(BcifsVolume, DelaysBySizeEqualizeTheLacunas) {
  VolumeSpec one;
  one.cells.push_back(uniform_cell(regular_cell(CellKind::kHexahedron, 1), false, "B2", "B2 B2 B2"));
  const double shrink = level_shrink(one, 0);
  EXPECT_GT(shrink, 3);
  EXPECT_LT(shrink, 4);
  auto spread = [&](const std::vector<double>& edges, bool delayed) {
    VolumeSpec spec;
    const std::vector<int> delays = delays_for_sizes(edges, 3, shrink);
    for (size_t c = 0; c < edges.size(); ++c) {
      spec.cells.push_back(uniform_cell(regular_cell(CellKind::kHexahedron, edges[c], {10.0 * double(c), 0, 0}),
                                        false, "B2", "B2 B2 B2"));
      if (delayed) spec.cells.back().delay = delays[c];
    }
    const std::vector<double> sizes = last_lacuna_sizes(build_volume_rules(spec), spec, 3).mean_mm;
    for (double s : sizes) EXPECT_GT(s, 0);
    return *std::max_element(sizes.begin(), sizes.end()) / *std::min_element(sizes.begin(), sizes.end());
  };
  EXPECT_NEAR(spread({1, 2, 4}, false), 4, 1e-9);  // the same subdivision at three scales
  EXPECT_NEAR(spread({1, 2, 4}, true), 2, 0.05);
  EXPECT_EQ(delays_for_sizes({1, shrink, shrink * shrink}, 3, shrink), (std::vector<int>{3, 2, 1}));
  EXPECT_LT(spread({1, shrink, shrink * shrink}, true), 1.5);
}

// The lacunas the last subdivision makes, one per parent cell that subdivides then, from the realized geometry:
// the parent's volume (level - 1) and the scale its sub-cells show (an inner corner's distance to the parent's
// centre over its outer corner's), size = scale * cbrt(volume). With plain walls the parent's volume less its
// sub-cells' is the lacuna's volume, which `from_volumes` checks against scale^3 * volume.
struct MeasuredLacuna {
  int origin = -1;
  double size = 0;
};
std::vector<MeasuredLacuna> measured_lacunas(const VolumeRules& rules, const VolumeSpec& spec, int level,
                                             const VolumeGeometryOptions& options, bool from_volumes) {
  VolumeGeometryOptions common = options;  // the last scales belong to the last subdivision only
  common.last_lacuna_mm.clear();
  const VolumeLevel before = realize_volume(rules, spec, level - 1, common);
  const VolumeLevel after = realize_volume(rules, spec, level, options);
  std::map<std::array<double, 3>, std::pair<double, double>> children;  // by apex: sub-cells' volume, scale
  for (const VolumeCell& cell : after.cells) {
    if (cell.root >= 0 || cell.delay != 1 || cell.base.empty()) continue;
    auto& [volume, scale] = children[{cell.base_apex.x, cell.base_apex.y, cell.base_apex.z}];
    volume += cell_volume(cell, spec);
    const Vec3d inner = cell.base_apex * (1 - cell.base_scale) + cell.base[0] * cell.base_scale;  // as realized
    scale = norm(inner - cell.base_apex) / norm(cell.base[0] - cell.base_apex);
  }
  std::vector<MeasuredLacuna> out;
  for (const VolumeCell& cell : before.cells) {
    if (cell.delay != 1) continue;
    const auto& [filled, scale] = children.at({cell.apex.x, cell.apex.y, cell.apex.z});
    const double volume = cell_volume(cell, spec);
    if (from_volumes) {
      EXPECT_NEAR(volume - filled, scale * scale * scale * volume, 1e-9 * volume);
    }
    out.push_back({cell.origin, scale * std::cbrt(volume)});
  }
  return out;
}

// Largest over smallest of the lacunas, and of their geometric means per cell of the spec.
std::pair<double, double> spreads(const std::vector<MeasuredLacuna>& lacunas, size_t cells) {
  std::vector<double> log_sum(cells, 0.0), count(cells, 0.0);
  double lo = HUGE_VAL, hi = 0;
  for (const MeasuredLacuna& l : lacunas) {
    log_sum[size_t(l.origin)] += std::log(l.size);
    count[size_t(l.origin)] += 1;
    lo = std::min(lo, l.size);
    hi = std::max(hi, l.size);
  }
  double mlo = HUGE_VAL, mhi = 0;
  for (size_t c = 0; c < cells; ++c) {
    const double m = std::exp(log_sum[c] / count[c]);
    mlo = std::min(mlo, m);
    mhi = std::max(mhi, m);
  }
  return {hi / lo, mhi / mlo};
}

// Cells of edges varying 4x (1, 1.6, 2.5, 4), delayed by size, their last lacunas measured from the geometry:
// delays alone leave them more than 1.5 apart (also their geometric means per cell); with one last lacuna size
// for all (the smallest, each cell scaling its own lacuna down) every lacuna is within 1.5 of every other, with
// plain walls and with Bezier (B2) walls.
TEST(BcifsVolume, LastLacunaSizeBringsLacunasOfCellsVarying4xWithin1_5) {
  const std::vector<double> edges{1, 1.6, 2.5, 4};
  const int level = 3;
  for (bool plain : {true, false}) {
    VolumeSpec spec;
    for (size_t c = 0; c < edges.size(); ++c)
      spec.cells.push_back(
          uniform_cell(regular_cell(CellKind::kHexahedron, edges[c], {10.0 * double(c), 0, 0}), plain));
    spec.interior.plain = plain;
    const double shrink = level_shrink(spec, 3);
    EXPECT_GT(shrink, 1.5);
    const std::vector<int> delays = delays_for_sizes(edges, level, shrink);
    for (size_t c = 0; c < edges.size(); ++c) spec.cells[c].delay = delays[c];
    const VolumeRules rules = build_volume_rules(spec);
    VolumeGeometryOptions options;
    const auto [each_delayed, cells_delayed] = spreads(measured_lacunas(rules, spec, level, options, plain), 4);
    EXPECT_GT(each_delayed, 1.5) << plain;
    EXPECT_GT(cells_delayed, 1.5) << plain;
    const LastLacunas before = last_lacuna_sizes(rules, spec, level, options);
    const double smallest = *std::min_element(before.smallest_mm.begin(), before.smallest_mm.end());
    options.last_lacuna_mm.assign(edges.size(), smallest);
    const LastLacunas after = last_lacuna_sizes(rules, spec, level, options);
    EXPECT_GE(after.min_scale, 0.5 / 3);
    EXPECT_LE(after.max_scale, 0.5);
    const auto [each, cells] = spreads(measured_lacunas(rules, spec, level, options, plain), 4);
    EXPECT_LT(each, 1.5) << plain;
    EXPECT_LT(cells, 1.5) << plain;
  }
}

// Two cubes of edge 5 sharing the face x = 5 with last lacuna sizes 1.5 and 2 mm (scales 0.3 and 0.4 at level 1):
// the shared face's sub-faces are still one set, owned by both cubes' cells; a plain cube of edge 2 whose level-1
// cells (volume 7/6 each) take the scale 0.3 at level 2 keeps 8 (7/8) (1 - 0.3^3).
TEST(BcifsVolume, LastLacunaSizesKeepSharedFacesShared) {
  VolumeSpec spec;
  spec.cells.push_back(uniform_cell(regular_cell(CellKind::kHexahedron, 5, {2.5, 2.5, 2.5}), false));
  spec.cells.push_back(uniform_cell(regular_cell(CellKind::kHexahedron, 5, {7.5, 2.5, 2.5}), false));
  const VolumeRules rules = build_volume_rules(spec);
  VolumeGeometryOptions same, own;
  own.last_lacuna_mm = {1.5, 2.0};
  EXPECT_NEAR(last_lacuna_sizes(rules, spec, 1, own).min_scale, 0.3, 1e-12);
  EXPECT_NEAR(last_lacuna_sizes(rules, spec, 1, own).max_scale, 0.4, 1e-12);
  for (int level = 1; level <= 2; ++level) {
    const auto [on_plane, twice] = faces_on_plane(realize_volume(rules, spec, level, own), 5.0);
    EXPECT_EQ(faces_on_plane(realize_volume(rules, spec, level, same), 5.0), std::make_pair(on_plane, twice));
    EXPECT_GT(twice, 0);
    EXPECT_EQ(on_plane, twice);
  }
  VolumeSpec plain = plain_spec(CellKind::kHexahedron, 2);
  const VolumeRules plain_rules = build_volume_rules(plain);
  VolumeGeometryOptions last;
  last.last_lacuna_mm = {0.3 * std::cbrt(7.0 / 6)};
  EXPECT_NEAR(total_volume(realize_volume(plain_rules, plain, 2, last), plain), 8 * (1 - 0.125) * (1 - 0.027), 1e-9);
  last.last_lacuna_mm = {0.3, 0.4};
  EXPECT_THROW(realize_volume(plain_rules, plain, 2, last), InvalidInput);
  last.last_lacuna_mm = {-1.0};
  EXPECT_THROW(realize_volume(plain_rules, plain, 2, last), InvalidInput);
}

// A plain cube sampled: at level 0 the voxel centres inside are those within the cube along each axis (the grid
// has a margin), at level 1 less those within its lacuna (the middle half along each axis); box counts of a grid
// the cube fills are N_eps = (1/eps)^3 (dimension 3) and for its boundary the shell b^3 - (b - 2)^3; the middle
// section is the square's pixels less the lacuna's, counted the same way.
TEST(BcifsVolume, VoxelMasksBoxCountsAndSectionsOfACube) {
  const VolumeSpec spec = plain_spec(CellKind::kHexahedron, 2);
  const VolumeRules rules = build_volume_rules(spec);
  const std::vector<ConvexCells> whole = convex_pieces(realize_volume(rules, spec, 0), spec);
  const std::vector<ConvexCells> opened = convex_pieces(realize_volume(rules, spec, 1), spec);
  // Centres origin + (i + 1/2) step, 0 <= i < n, within [lo, hi].
  auto centres = [](double origin, double step, int n, double lo, double hi) {
    int count = 0;
    for (int i = 0; i < n; ++i) count += origin + (i + 0.5) * step >= lo && origin + (i + 0.5) * step <= hi;
    return count;
  };
  auto mask_of = [](const std::vector<ConvexCells>& pieces, const VoxelGrid& grid) {
    const size_t n = size_t(grid.size);
    std::vector<uint8_t> mask(n * n * n);
    // In two calls, as callers do in parallel.
    mark_voxels(pieces, grid, 0, grid.size / 2, mask.data());
    mark_voxels(pieces, grid, grid.size / 2, grid.size, mask.data() + n * n * n / 2);
    return mask;
  };
  const VoxelGrid grid = voxel_grid(opened, 64);
  EXPECT_NEAR(grid.origin_mm.x, -1 - 2 * std::sqrt(2.0) / 128, 1e-8);
  EXPECT_NEAR(grid.voxel_mm * 64, 2 + 4 * std::sqrt(2.0) / 128, 1e-8);
  const int inside = centres(grid.origin_mm.x, grid.voxel_mm, 64, -1, 1);
  const int lacuna = centres(grid.origin_mm.x, grid.voxel_mm, 64, -0.5, 0.5);
  EXPECT_GT(inside, 60);
  EXPECT_GT(lacuna, 30);
  const std::vector<uint8_t> full = mask_of(whole, grid), hollow = mask_of(opened, grid);
  EXPECT_EQ(std::count(full.begin(), full.end(), 1), inside * inside * inside);
  EXPECT_EQ(std::count(hollow.begin(), hollow.end(), 1), inside * inside * inside - lacuna * lacuna * lacuna);
  const std::vector<uint8_t> ones(16 * 16 * 16, 1);
  const BoxCount region = box_count_3d(ones, 16, false), shell = box_count_3d(ones, 16, true);
  ASSERT_EQ(region.log_count.size(), 3u);
  for (size_t i = 0; i < 3; ++i) {
    const double b = std::exp(region.log_inverse_size[i]);
    EXPECT_NEAR(b, 4.0 * double(1 << i), 1e-9);
    EXPECT_NEAR(region.log_count[i], 3 * std::log(b), 1e-12);
    EXPECT_NEAR(shell.log_count[i], std::log(b * b * b - (b - 2) * (b - 2) * (b - 2)), 1e-12);
  }
  EXPECT_NEAR(region.dimension, 3, 1e-12);
  const double pixel = grid.voxel_mm * 64 / 1024;
  const int square = centres(grid.origin_mm.x, pixel, 1024, -1, 1), hole = centres(grid.origin_mm.x, pixel, 1024, -0.5, 0.5);
  for (int axis = 0; axis < 3; ++axis) {
    const std::vector<uint8_t> section = section_mask(opened, grid, axis, 0.0, 1024);
    EXPECT_EQ(std::count(section.begin(), section.end(), 1), square * square - hole * hole) << axis;
  }
  EXPECT_THROW(voxel_grid(opened, 48), InvalidInput);
  EXPECT_THROW(box_count_3d(hollow, 32, false), InvalidInput);
  EXPECT_THROW(section_mask(opened, grid, 3, 0.0, 64), InvalidInput);
}

// A cell whose edges along `axis` are C2 and the others B2: its faces have mixed boundaries.
CellSpec mixed_cell(const Polyhedron& shape, int axis) {
  CellSpec c;
  c.shape = shape;
  for (const auto& loop : shape.faces) {
    FaceType t{{}, parse_edge_set("B2 B2 B2"), Algorithm::kA1, 1};
    for (size_t j = 0; j < loop.size(); ++j) {
      const Vec3d d = shape.corners_mm[size_t(loop[(j + 1) % loop.size()])] - shape.corners_mm[size_t(loop[j])];
      t.boundary.push_back(parse_edge(std::fabs(d[axis]) > 0 ? "C2" : "B2"));
    }
    c.face_types.push_back(t);
    c.plain.push_back(0);
  }
  return c;
}

// Two cubes sharing the face x = 5, whose edges along y are C2 and along z B2: read backwards from the second
// cube the face has the same edges, so it is shared; a second cube with the C2 edges along z sees the face's
// edges swapped and is refused, naming both faces.
TEST(BcifsVolume, SharedFacesWithMixedEdgesAreReadBackwards) {
  VolumeSpec same;
  same.cells.push_back(mixed_cell(regular_cell(CellKind::kHexahedron, 10), 1));
  same.cells.push_back(mixed_cell(regular_cell(CellKind::kHexahedron, 10, {10, 0, 0}), 1));
  const VolumeRules rules = build_volume_rules(same);
  ASSERT_EQ(rules.shared.size(), 1u);
  for (int k = 1; k <= 2; ++k) {
    const auto [on_plane, twice] = faces_on_plane(realize_volume(rules, same, k), 5);
    EXPECT_GT(twice, 0);
    EXPECT_EQ(on_plane, twice) << "level " << k;
  }
  VolumeSpec swapped = same;
  swapped.cells[1] = mixed_cell(regular_cell(CellKind::kHexahedron, 10, {10, 0, 0}), 2);
  try {
    build_volume_rules(swapped);
    ADD_FAILURE() << "a face seen with its edges swapped was shared";
  } catch (const InvalidInput& e) {
    EXPECT_NE(std::string(e.what()).find("share a face but see different types"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("cell 0 face"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("cell 1 face"), std::string::npos) << e.what();
  }
}

TEST(BcifsVolume, BadSpecsAreNamed) {
  auto message = [](const VolumeSpec& spec) {
    try {
      build_volume_rules(spec);
    } catch (const InvalidInput& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  VolumeSpec mixed;
  mixed.cells.push_back(uniform_cell(regular_cell(CellKind::kHexahedron, 10), false));
  mixed.cells[0].face_types[2].boundary = std::vector<EdgeType>(4, parse_edge("C2"));
  EXPECT_NE(message(mixed).find("cell 0 face"), std::string::npos) << message(mixed);
  EXPECT_NE(message(mixed).find("is C2 but the same edge of face"), std::string::npos) << message(mixed);

  VolumeSpec bent;
  bent.cells.push_back(uniform_cell(regular_cell(CellKind::kHexahedron, 10), true));
  bent.cells[0].shape.corners_mm[0].x += 0.5;
  EXPECT_NE(message(bent).find("not planar"), std::string::npos) << message(bent);

  VolumeSpec open;
  open.cells.push_back(uniform_cell(regular_cell(CellKind::kHexahedron, 10), true));
  open.cells[0].shape.faces.pop_back();
  open.cells[0].face_types.pop_back();
  open.cells[0].plain.pop_back();
  EXPECT_NE(message(open).find("not closed"), std::string::npos) << message(open);

  // An arrowhead (a quadrilateral with a reflex corner) extruded: closed, planar faces, outward, not convex.
  Polyhedron arrow;
  arrow.corners_mm = {{0, 0, 0}, {4, 2, 0}, {0, 4, 0}, {1, 2, 0}, {0, 0, 2}, {4, 2, 2}, {0, 4, 2}, {1, 2, 2}};
  arrow.faces = {{0, 3, 2, 1}, {4, 5, 6, 7}, {0, 1, 5, 4}, {1, 2, 6, 5}, {2, 3, 7, 6}, {3, 0, 4, 7}};
  VolumeSpec dented;
  dented.cells.push_back(uniform_cell(arrow, true));
  EXPECT_NE(message(dented).find("not convex"), std::string::npos) << message(dented);

  VolumeSpec level;
  level.cells.push_back(uniform_cell(regular_cell(CellKind::kHexahedron, 10), false));
  const VolumeRules rules = build_volume_rules(level);
  EXPECT_THROW(realize_volume(rules, level, 8), ResourceLimit);
}

}  // namespace
}  // namespace lacuna
