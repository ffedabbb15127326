// Guarded simplification: every result is a valid solid of the same components and genus, the
// sampled one-sided Hausdorff distances both ways stay within the deviation asked for, volumes
// stay at their closed forms, and the result does not depend on the number of threads.
#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <map>
#include <numeric>
#include <set>

#include "cifs/library.h"
#include "cifs/solid_input.h"
#include "recipe/cifs_system.h"
#include "errors.h"
#include "pipeline/mesh_object.h"
#include "recipe/recipe.h"
#include "solids/check.h"
#include "solids/extract.h"
#include "solids/mesh_distance.h"
#include "solids/simplify.h"
#include "solids/voxelize.h"

namespace lacuna {
namespace {

constexpr double kPi = 3.14159265358979323846;

struct Simplified {
  TriMesh plain, compact;
  MeshCheckReport plain_report, compact_report;
  SimplifyStats stats;
  double to_plain_mm = 0, to_compact_mm = 0;  // sampled one-sided Hausdorff distances
};

// The plain and the simplified surface of a volume, both checked, and the distances between them
// (the simplified side sampled inside its larger triangles as well).
Simplified simplify(const Volume& volume, double deviation_mm) {
  Simplified s;
  s.plain = extract_surface(volume);
  SimplifyOptions options;
  options.max_deviation_mm = deviation_mm;
  s.compact = extract_simplified_surface(volume, options, &s.stats);
  s.plain_report = check_mesh(s.plain);
  s.compact_report = check_mesh(s.compact);
  const double h = volume.voxel_size_mm();
  s.to_plain_mm = sampled_hausdorff_mm(s.compact, s.plain, h * h);
  s.to_compact_mm = sampled_hausdorff_mm(s.plain, s.compact);
  return s;
}

void expect_same_solid_within(const Simplified& s, double deviation_mm) {
  EXPECT_TRUE(s.plain_report.valid()) << ::testing::PrintToString(s.plain_report.problems());
  EXPECT_TRUE(s.compact_report.valid()) << ::testing::PrintToString(s.compact_report.problems());
  EXPECT_EQ(s.compact_report.components, s.plain_report.components);
  EXPECT_EQ(s.compact_report.genus, s.plain_report.genus);
  EXPECT_LE(s.to_plain_mm, deviation_mm);
  EXPECT_LE(s.to_compact_mm, deviation_mm);
  EXPECT_EQ(s.stats.output_triangles, s.compact.triangles.size());
  EXPECT_EQ(s.stats.input_triangles, s.plain.triangles.size());
}

GeometrySet sphere(const Vec3d& c, double r) {
  GeometrySet set;
  set.spheres.centers_mm.push_back(c);
  set.spheres.radii_mm.push_back(r);
  return set;
}

TEST(Simplify, SphereKeepsItsVolumeWithinTheDeviation) {
  const double r = 4, h = 0.1;
  const Simplified s = simplify(voxelize(sphere({0.013, -0.021, 0.007}, r), VolumeOptions{h, 3.0}), 0.2 * h);
  expect_same_solid_within(s, 0.2 * h);
  EXPECT_EQ(s.compact_report.genus, 0);
  const double exact = 4.0 / 3.0 * kPi * r * r * r;
  EXPECT_NEAR(s.compact_report.volume_mm3, exact, 0.005 * exact);
  EXPECT_NEAR(s.compact_report.volume_mm3, s.plain_report.volume_mm3, 0.0005 * exact);
  EXPECT_LT(s.compact.triangles.size(), s.plain.triangles.size() / 4);
}

TEST(Simplify, ClosedChainOfCapsulesStaysATorus) {
  const int n = 300;
  std::vector<Vec3d> points;
  for (int i = 0; i <= n; ++i) {
    const double phi = 2 * kPi * (i % n) / n;
    const double radius = 8 + 2 * std::sin(5 * phi);
    points.push_back({radius * std::cos(phi), radius * std::sin(phi), 0.7 * std::sin(3 * phi)});
  }
  GeometrySet set;
  set.tubes.tubes.push_back(Tube{points, {0.6}});
  const double h = 0.1;
  const Simplified s = simplify(voxelize(set, VolumeOptions{h, 3.0}), 0.2 * h);
  expect_same_solid_within(s, 0.2 * h);
  EXPECT_EQ(s.compact_report.genus, 1);
  EXPECT_NEAR(s.compact_report.volume_mm3, s.plain_report.volume_mm3, 0.001 * s.plain_report.volume_mm3);
}

TEST(Simplify, MengerSpongeKeepsGenusAndVolume) {
  // Level 2 of a 9 mm sponge, faces half a voxel off the grid: genus 81, volume 9^3 (20/27)^2.
  const double side = 9, h = 1.0 / 9.0;
  nlohmann::json spec = {{"library", "menger_sponge"}, {"scale", side}, {"translate_mm", {h / 2, h / 2, h / 2}}};
  const cifs::Cifs menger = cifs::parse_system(spec, "test", "system");
  const Simplified s = simplify(voxelize(cifs::attractor_geometry(menger, 2, {}), VolumeOptions{h, 3.0}), 0.2 * h);
  expect_same_solid_within(s, 0.2 * h);
  EXPECT_EQ(s.compact_report.genus, 81);
  const double exact = side * side * side * std::pow(20.0 / 27.0, 2);
  EXPECT_NEAR(s.compact_report.volume_mm3, exact, 0.005 * exact);
  // Flat faces need few triangles.
  EXPECT_LT(s.compact.triangles.size(), s.plain.triangles.size() / 10);
}

TEST(Simplify, CubicLatticeKeepsItsGenus) {
  // A 2 x 2 x 2 cubic lattice of struts: nodes 3^3 = 27, struts 3 * 2 * 3^2 = 54, so the genus
  // is struts - nodes + 1 = 28.
  GeometrySet set;
  const double period = 2, r = 0.3;
  for (int a = 0; a <= 2; ++a)
    for (int b = 0; b <= 2; ++b)
      for (int axis = 0; axis < 3; ++axis) {
        Vec3d p0, p1;
        p0[(axis + 1) % 3] = p1[(axis + 1) % 3] = a * period + 0.011;
        p0[(axis + 2) % 3] = p1[(axis + 2) % 3] = b * period - 0.007;
        p0[axis] = 0.003;
        p1[axis] = 2 * period + 0.003;
        set.tubes.tubes.push_back(Tube{{p0, p1}, {r}});
      }
  const double h = 0.08;
  const Simplified s = simplify(voxelize(set, VolumeOptions{h, 3.0}), 0.2 * h);
  expect_same_solid_within(s, 0.2 * h);
  EXPECT_EQ(s.compact_report.genus, 28);
  EXPECT_EQ(s.compact_report.components, 1u);
}

TEST(Simplify, NearlyTouchingSpheresStayApart) {
  // Two balls a third of a voxel apart, simplified with a deviation of two voxels: collapses that
  // would push one surface through the other must be refused by the exact guard.
  const double h = 0.1, r = 2;
  GeometrySet set = sphere({-r - h / 6, 0.01, 0.02}, r);
  set.spheres.centers_mm.push_back({r + h / 6, 0.01, 0.02});
  set.spheres.radii_mm.push_back(r);
  SimplifyOptions options;
  options.max_deviation_mm = 2 * h;
  SimplifyStats stats;
  const Volume volume = voxelize(set, VolumeOptions{h, 3.0});
  const TriMesh plain = extract_surface(volume);
  const MeshCheckReport before = check_mesh(plain);
  const MeshCheckReport after = check_mesh(extract_simplified_surface(volume, options, &stats));
  EXPECT_TRUE(after.valid()) << ::testing::PrintToString(after.problems());
  EXPECT_EQ(after.components, before.components);
  EXPECT_EQ(after.genus, before.genus);
}

TEST(Simplify, NearlyTouchingSpheresStayApartBesideABlockFace) {
  // The same, with the gap on the grid planes 1 to 7 voxels from a block face (blocks of 32
  // voxels: x = 3.2 mm), where the block and the pass across the block faces share the work.
  const double h = 0.1, r = 2;
  for (int voxels = 1; voxels <= 7; ++voxels) {
    const double gap_x = 3.2 + voxels * h;
    GeometrySet set = sphere({gap_x - r - h / 6, 0.01, 0.02}, r);
    set.spheres.centers_mm.push_back({gap_x + r + h / 6, 0.01, 0.02});
    set.spheres.radii_mm.push_back(r);
    SimplifyOptions options;
    options.max_deviation_mm = 2 * h;
    const Volume volume = voxelize(set, VolumeOptions{h, 3.0});
    const MeshCheckReport after = check_mesh(extract_simplified_surface(volume, options));
    EXPECT_TRUE(after.valid()) << voxels << " voxels: " << ::testing::PrintToString(after.problems());
    EXPECT_EQ(after.components, 2u) << voxels;
  }
}

TEST(Simplify, ThinWallsNearBlockFacesStayApart) {
  // A corner of a lacunar cube at level 3: walls of one or two voxels and tunnels everywhere, many
  // across the block faces (a pass across them that loaded only the triangles near the faces once
  // let a collapse push a wall through one it had not loaded).
  const Recipe recipe = parse_recipe(R"({"lacuna_recipe": 1, "name": "corner", "voxel_size_mm": 0.12,
    "inputs": {"cube": {"type": "bcifs_volume", "cell": "hexahedron", "edge_mm": 24, "level": 3, "edge": "B2",
                        "params": "B2 B2 B2", "lacuna_scale": 0.5, "face_lacuna_scale": 0.5},
               "clip": {"type": "box", "min_mm": [6, -13, -0.5], "max_mm": [13, -6, 6.5]}},
    "operations": [{"name": "part", "op": "intersection", "of": ["cube", "clip"]}],
    "outputs": [{"of": "part", "file": "part.stl"}]})", "corner.json");
  const Volume volume = evaluate_object(recipe, "part");
  SimplifyOptions options;
  options.max_deviation_mm = 0.2 * 0.12;
  const TriMesh plain = extract_surface(volume);
  const MeshCheckReport before = check_mesh(plain);
  SimplifyStats stats;
  const MeshCheckReport after = check_mesh(extract_simplified_surface(volume, options, &stats));
  EXPECT_TRUE(after.valid()) << ::testing::PrintToString(after.problems());
  EXPECT_EQ(after.components, before.components);
  EXPECT_EQ(after.genus, before.genus);
  // Here collapses tested only against the faces sharing their vertices push a wall into one
  // they share none with: the verification of that region finds it and the region is redone with
  // every collapse tested against the faces near it (so this test covers both ways of guarding).
  EXPECT_GT(stats.regions_redone, 0u);
  EXPECT_GT(stats.regions_guarded, 0u);
  EXPECT_LE(stats.regions_guarded, stats.regions_redone);
  EXPECT_GT(stats.rejected_by_intersection, 0u);
}

TEST(Simplify, SameResultForAnyThreadCount) {
  GeometrySet set = sphere({0.1, 0.2, 0.3}, 3);
  set.tubes.tubes.push_back(Tube{{{-4, 0, 0}, {4, 1, 0.5}, {4, 4, -1}}, {0.7}});
  const Volume volume = voxelize(set, VolumeOptions{0.08, 3.0});
  SimplifyOptions options;
  options.max_deviation_mm = 0.016;
  TriMesh one, two;
  {
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 1);
    one = extract_simplified_surface(volume, options);
  }
  {
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 2);
    two = extract_simplified_surface(volume, options);
  }
  ASSERT_EQ(one.triangles.size(), two.triangles.size());
  EXPECT_EQ(one.triangles, two.triangles);
  ASSERT_EQ(one.positions_mm.size(), two.positions_mm.size());
  for (size_t i = 0; i < one.positions_mm.size(); ++i) ASSERT_EQ(one.positions_mm[i], two.positions_mm[i]) << i;
}

// The surface streamed slab by slab (slabs of `slab_voxels`, cut from the same volume) as one
// list of triangles and the vertex numbers the stream gave them.
struct Streamed {
  std::vector<std::array<Vec3d, 3>> corners;
  std::vector<std::array<uint64_t, 3>> numbers;
  size_t batches = 0;
};
Streamed stream(const Volume& volume, const SimplifyOptions& options, int slab_voxels, const Box3& box) {
  Streamed out;
  StreamedSurface surface(options, volume.voxel_size_mm(), [&](const EmittedTriangles& batch) {
    out.corners.insert(out.corners.end(), batch.corners.begin(), batch.corners.end());
    out.numbers.insert(out.numbers.end(), batch.numbers.begin(), batch.numbers.end());
    ++out.batches;
  });
  const double h = volume.voxel_size_mm();
  int64_t z = int64_t(std::floor(box.min.z / h / 32) - 1) * 32, z0 = -StreamedSurface::kUnbounded;
  for (; double(z) * h < box.max.z; z += slab_voxels) {
    surface.add(volume, z0, z + slab_voxels);
    z0 = z + slab_voxels;
  }
  surface.add(volume, z0, StreamedSurface::kUnbounded);
  surface.finish();
  return out;
}

TEST(Simplify, StreamedSlabBySlabIsTheWholeSurface) {
  GeometrySet set = sphere({0.1, 0.2, 0.3}, 3);
  set.tubes.tubes.push_back(Tube{{{-4, 0, -6}, {4, 1, 0.5}, {4, 4, 6}}, {0.7}});
  const double h = 1.0 / 9.0;
  nlohmann::json spec = {{"library", "menger_sponge"}, {"scale", 9.0}, {"translate_mm", {h / 2, h / 2, 8.0}}};
  GeometrySet menger = cifs::attractor_geometry(cifs::parse_system(spec, "test", "system"), 2, {});
  for (const auto& [what, volume] : {std::pair<std::string, Volume>{"sphere and tube", voxelize(set, VolumeOptions{0.08, 3.0})},
                                     {"Menger sponge", voxelize(menger, VolumeOptions{h, 3.0})}}) {
    SimplifyOptions options;
    options.max_deviation_mm = 0.2 * volume.voxel_size_mm();
    const TriMesh whole = extract_simplified_surface(volume, options);
    ASSERT_TRUE(check_mesh(whole).valid()) << what;
    for (int slab : {32, 64, 96}) {
      Box3 box;
      for (const Vec3d& p : whole.positions_mm) box.expand(p);
      const Streamed s = stream(volume, options, slab, box);
      // Slabs of 32 voxels emit once per slab past the first two, 1.5 blocks behind the cut.
      EXPECT_GE(double(s.batches), (box.size().z / volume.voxel_size_mm() - 48) / slab) << what << ", slabs of " << slab;
      EXPECT_GE(s.batches, 2u) << what << ", slabs of " << slab;
      ASSERT_EQ(s.corners.size(), whole.triangles.size()) << what << ", slabs of " << slab;
      size_t differ = 0;
      std::map<std::array<double, 3>, uint64_t> number_of;
      size_t inconsistent = 0;
      for (size_t t = 0; t < whole.triangles.size(); ++t)
        for (int k = 0; k < 3; ++k) {
          const Vec3d& p = whole.positions_mm[whole.triangles[t][size_t(k)]];
          differ += !(s.corners[t][size_t(k)] == p);
          auto [it, inserted] = number_of.try_emplace({p.x, p.y, p.z}, s.numbers[t][size_t(k)]);
          inconsistent += !inserted && it->second != s.numbers[t][size_t(k)];
        }
      EXPECT_EQ(differ, 0u) << what << ", slabs of " << slab;
      EXPECT_EQ(inconsistent, 0u) << what << ", slabs of " << slab;
      std::set<uint64_t> numbers;
      for (const auto& n : s.numbers) numbers.insert(n.begin(), n.end());
      EXPECT_EQ(numbers.size(), number_of.size()) << what << ": one number per vertex";
    }
  }
}

// The surface streamed in `parts` parts as a job's processes stream it: slabs of 32 voxels, each
// part a block of them, starting after its first cut with a lead-in from three blocks below it.
struct StreamedPart {
  Streamed emitted;
  std::vector<StreamedSurface::WindowVertex> lead, tail;
};
std::vector<StreamedPart> stream_parts(const Volume& volume, const SimplifyOptions& options, const Box3& box, size_t parts) {
  const double h = volume.voxel_size_mm();
  const int64_t start = int64_t(std::floor(box.min.z / h / 32)) * 32;
  std::vector<int64_t> z0{-StreamedSurface::kUnbounded}, z1;  // slab i: [z0[i], z1[i])
  for (int64_t z = start + 32; double(z - 32) * h < box.max.z; z += 32) {
    z1.push_back(z);
    z0.push_back(z);
  }
  z1.push_back(StreamedSurface::kUnbounded);
  const size_t n = z0.size();
  std::vector<StreamedPart> out(parts);
  for (size_t p = 0; p < parts; ++p) {
    const size_t first = n * p / parts, end = n * (p + 1) / parts;
    StreamedPart& part = out[p];
    StreamedSurface surface(options, h, [&](const EmittedTriangles& batch) {
      part.emitted.corners.insert(part.emitted.corners.end(), batch.corners.begin(), batch.corners.end());
      part.emitted.numbers.insert(part.emitted.numbers.end(), batch.numbers.begin(), batch.numbers.end());
      ++part.emitted.batches;
    });
    size_t from = first;
    if (first > 0) {
      surface.begin_after(z0[first]);
      from = first - 3;  // slabs of one block: three below the cut
    }
    for (size_t i = from; i < end; ++i) {
      surface.add(volume, z0[i], z1[i]);
      if (i + 1 == first) part.lead = surface.window_vertices();
    }
    if (end == n)
      surface.finish();
    else
      part.tail = surface.window_vertices();
  }
  return out;
}

TEST(Simplify, StreamedInPartsIsTheWholeSurface) {
  GeometrySet set = sphere({0.1, 0.2, 0.3}, 3);
  set.tubes.tubes.push_back(Tube{{{-4, 0, -6}, {4, 1, 0.5}, {4, 4, 6}}, {0.7}});
  const double h = 1.0 / 27.0;  // the sponge 243 voxels high
  nlohmann::json spec = {{"library", "menger_sponge"}, {"scale", 9.0}, {"translate_mm", {h / 2, h / 2, 8.0}}};
  GeometrySet menger = cifs::attractor_geometry(cifs::parse_system(spec, "test", "system"), 2, {});
  for (const auto& [what, volume] : {std::pair<std::string, Volume>{"sphere and tube", voxelize(set, VolumeOptions{0.06, 3.0})},
                                     {"Menger sponge", voxelize(menger, VolumeOptions{h, 3.0})}}) {
    SimplifyOptions options;
    options.max_deviation_mm = 0.2 * volume.voxel_size_mm();
    const TriMesh whole = extract_simplified_surface(volume, options);
    Box3 box;
    for (const Vec3d& p : whole.positions_mm) box.expand(p);
    ASSERT_GE(box.size().z / volume.voxel_size_mm(), 6 * 32.0) << what << ": tall enough for three parts";
    for (size_t parts : {2u, 3u}) {
      const std::vector<StreamedPart> streamed = stream_parts(volume, options, box, parts);
      // Concatenated, the parts' triangles are the whole surface's, corner for corner.
      std::vector<std::array<Vec3d, 3>> corners;
      std::vector<uint64_t> base{0};  // each part's numbers after the ones before
      for (const StreamedPart& part : streamed) {
        EXPECT_GE(part.emitted.batches, 1u) << what << ": every part emits";
        corners.insert(corners.end(), part.emitted.corners.begin(), part.emitted.corners.end());
        uint64_t top = 0;
        for (const auto& n : part.emitted.numbers) top = std::max({top, n[0] + 1, n[1] + 1, n[2] + 1});
        for (const auto& v : part.lead) top = std::max(top, v.number + 1);
        for (const auto& v : part.tail) top = std::max(top, v.number + 1);
        base.push_back(base.back() + top);
      }
      ASSERT_EQ(corners.size(), whole.triangles.size()) << what << ", " << parts << " parts";
      size_t differ = 0;
      for (size_t t = 0; t < whole.triangles.size(); ++t)
        for (int k = 0; k < 3; ++k) differ += !(corners[t][size_t(k)] == whole.positions_mm[whole.triangles[t][size_t(k)]]);
      EXPECT_EQ(differ, 0u) << what << ", " << parts << " parts";
      // The numbers of neighbouring parts joined where the tail of one and the lead of the next
      // name the same vertex: then each whole vertex is one class, and each class one whole vertex.
      std::vector<uint64_t> parent(base.back());
      std::iota(parent.begin(), parent.end(), uint64_t(0));
      std::function<uint64_t(uint64_t)> find = [&](uint64_t a) { return parent[a] == a ? a : parent[a] = find(parent[a]); };
      size_t joined = 0;
      for (size_t p = 1; p < parts; ++p) {
        std::map<std::array<uint64_t, 2>, uint64_t> tail;
        for (const auto& v : streamed[p - 1].tail) tail[v.identity] = base[p - 1] + v.number;
        for (const auto& v : streamed[p].lead) {
          const auto it = tail.find(v.identity);
          if (it == tail.end()) continue;
          parent[find(it->second)] = find(base[p] + v.number);
          ++joined;
        }
      }
      EXPECT_GT(joined, 0u) << what;
      std::map<uint32_t, uint64_t> class_of;  // whole vertex -> class
      std::map<uint64_t, uint32_t> vertex_of;  // class -> whole vertex
      size_t split = 0, merged = 0, t = 0;
      for (size_t p = 0; p < parts; ++p)
        for (const auto& n : streamed[p].emitted.numbers) {
          for (int k = 0; k < 3; ++k) {
            const uint32_t v = whole.triangles[t][size_t(k)];
            const uint64_t c = find(base[p] + n[size_t(k)]);
            auto [a, new_vertex] = class_of.try_emplace(v, c);
            split += !new_vertex && a->second != c;
            auto [b, new_class] = vertex_of.try_emplace(c, v);
            merged += !new_class && b->second != v;
          }
          ++t;
        }
      EXPECT_EQ(split, 0u) << what << ", " << parts << " parts: a vertex in two classes";
      EXPECT_EQ(merged, 0u) << what << ", " << parts << " parts: two vertices in one class";
      EXPECT_EQ(class_of.size(), whole.positions_mm.size()) << what;
    }
  }
}

// The mesh's triangles in bands of `height` mm by their centroids' z, each band in mesh order.
std::vector<std::vector<std::array<Vec3d, 3>>> z_bands(const TriMesh& mesh, double height) {
  std::map<int64_t, std::vector<std::array<Vec3d, 3>>> bands;
  for (const auto& t : mesh.triangles) {
    const std::array<Vec3d, 3> c{mesh.positions_mm[t[0]], mesh.positions_mm[t[1]], mesh.positions_mm[t[2]]};
    bands[int64_t(std::floor((c[0].z + c[1].z + c[2].z) / 3 / height))].push_back(c);
  }
  std::vector<std::vector<std::array<Vec3d, 3>>> out;
  for (auto& [k, band] : bands) out.push_back(std::move(band));
  return out;
}

MeshCheckReport chunked_check(const TriMesh& mesh, double height) {
  ChunkedCheck check;
  auto bands = z_bands(mesh, height);
  for (size_t i = 0; i < bands.size(); ++i) check.add(std::move(bands[i]), i + 1 == bands.size());
  return check.finish();
}

void expect_same_report(const MeshCheckReport& a, const MeshCheckReport& b, const std::string& what) {
  EXPECT_EQ(a.valid(), b.valid()) << what << ": " << ::testing::PrintToString(a.problems());
  EXPECT_EQ(a.problems(), b.problems()) << what;
  EXPECT_EQ(a.triangles, b.triangles) << what;
  EXPECT_EQ(a.vertices, b.vertices) << what;
  EXPECT_EQ(a.edges, b.edges) << what;
  EXPECT_EQ(a.boundary_edges, b.boundary_edges) << what;
  EXPECT_EQ(a.components, b.components) << what;
  EXPECT_EQ(a.genus, b.genus) << what;
  EXPECT_EQ(a.inward_components, b.inward_components) << what;
  EXPECT_EQ(a.self_intersecting, b.self_intersecting) << what;
  if (b.closed()) {
    EXPECT_NEAR(a.volume_mm3, b.volume_mm3, 1e-9 * std::fabs(b.volume_mm3) + 1e-9) << what;
  }
  EXPECT_NEAR(a.area_mm2, b.area_mm2, 1e-9 * b.area_mm2) << what;
}

TEST(Simplify, ChunkedCheckReadsAsTheWholeCheck) {
  GeometrySet set = sphere({0.1, 0.2, 0.3}, 3);
  set.tubes.tubes.push_back(Tube{{{-4, 0, -6}, {4, 1, 0.5}, {4, 4, 6}}, {0.7}});
  SimplifyOptions options;
  options.max_deviation_mm = 0.016;
  const TriMesh part = extract_simplified_surface(voxelize(set, VolumeOptions{0.08, 3.0}), options);
  const double h = 1.0 / 9.0;
  nlohmann::json spec = {{"library", "menger_sponge"}, {"scale", 9.0}, {"translate_mm", {h / 2, h / 2, 8.0}}};
  options.max_deviation_mm = 0.2 * h;
  const TriMesh menger = extract_simplified_surface(
      voxelize(cifs::attractor_geometry(cifs::parse_system(spec, "test", "system"), 2, {}), VolumeOptions{h, 3.0}), options);
  // A hollow ball: the inner shell turned inward bounds a cavity.
  options.max_deviation_mm = 0.016;
  TriMesh hollow = extract_simplified_surface(voxelize(sphere({0, 0, 0}, 5), VolumeOptions{0.08, 3.0}), options);
  TriMesh inner = extract_simplified_surface(voxelize(sphere({0.3, 0, 0.2}, 3), VolumeOptions{0.08, 3.0}), options);
  auto append = [](TriMesh& to, const TriMesh& from, bool flip) {
    const uint32_t base = uint32_t(to.positions_mm.size());
    to.positions_mm.insert(to.positions_mm.end(), from.positions_mm.begin(), from.positions_mm.end());
    for (auto t : from.triangles) {
      if (flip) std::swap(t[1], t[2]);
      to.triangles.push_back({base + t[0], base + t[1], base + t[2]});
    }
  };
  TriMesh with_cavity = hollow, inward = hollow, open = part, overlapping = hollow;
  append(with_cavity, inner, true);
  append(inward, inner, false);
  open.triangles.erase(open.triangles.begin() + long(open.triangles.size() / 2));
  TriMesh shifted = inner;
  for (Vec3d& p : shifted.positions_mm) p.x += 4.5;  // crosses the outer shell
  append(overlapping, shifted, false);
  for (const auto& [what, mesh] : {std::pair<std::string, const TriMesh*>{"sphere and tube", &part}, {"Menger sponge", &menger},
                                   {"hollow ball", &with_cavity}, {"inner shell outward", &inward},
                                   {"a triangle missing", &open}, {"overlapping shells", &overlapping}}) {
    const MeshCheckReport whole = check_mesh(*mesh);
    for (double height : {4.0, 6.0, 100.0}) {
      const MeshCheckReport chunked = chunked_check(*mesh, height);
      EXPECT_TRUE(chunked.self_intersections_checked || !whole.self_intersections_checked) << what << ", " << height;
      expect_same_report(chunked, whole, what + ", bands of " + std::to_string(height) + " mm");
    }
  }
  // A cup taller than two bands: its inner and outer walls meet only at the rim, so the windows below
  // hold them apart (a ray from an inner wall crosses the outer wall: no nesting, it is one component).
  const Recipe cup_recipe = parse_recipe(R"({"lacuna_recipe": 1, "name": "cup", "voxel_size_mm": 0.1,
    "inputs": {"outer": {"type": "box", "min_mm": [-3.02, -3.03, 0.01], "max_mm": [3.01, 3.04, 14.02]},
               "inner": {"type": "box", "min_mm": [-2.01, -2.02, 1.03], "max_mm": [2.03, 2.01, 15]}},
    "operations": [{"name": "cup", "op": "difference", "of": ["outer", "inner"]}],
    "outputs": [{"of": "cup", "file": "cup.stl"}]})", "cup.json");
  TriMesh cup = extract_simplified_surface(evaluate_object(cup_recipe, "cup"), options);
  ASSERT_TRUE(check_mesh(cup).valid());
  // The inner walls' faces first (a chunk's order is the file's, any order): the first ray the check
  // casts for the cup starts on an inner wall.
  auto off_axis = [&](const std::array<uint32_t, 3>& t) {
    const Vec3d c = (cup.positions_mm[t[0]] + cup.positions_mm[t[1]] + cup.positions_mm[t[2]]) / 3.0;
    const bool cavity = c.z > 0.5 && std::max(std::fabs(c.x), std::fabs(c.y)) < 2.5;  // the inner floor and walls
    return cavity ? 0 : 1;
  };
  std::stable_sort(cup.triangles.begin(), cup.triangles.end(),
                   [&](const auto& a, const auto& b) { return off_axis(a) < off_axis(b); });
  // Bands by centroid, each lying above every triangle two bands below it (as the streamed check's
  // chunks are grown to): a triangle reaches 2/3 of its height from its centroid, so a band must be
  // over 4/3 of the tallest triangle; the cup stays taller than two bands.
  double tallest = 0;
  for (const auto& t : cup.triangles) {
    const double z[3] = {cup.positions_mm[t[0]].z, cup.positions_mm[t[1]].z, cup.positions_mm[t[2]].z};
    tallest = std::max(tallest, std::max({z[0], z[1], z[2]}) - std::min({z[0], z[1], z[2]}));
  }
  ASSERT_LT(4.0 / 3.0 * tallest, 4.0);
  for (double height : {4.0, 5.0, 6.0}) {
    const MeshCheckReport chunked = chunked_check(cup, height);
    EXPECT_EQ(chunked.inward_components, 0u) << "bands of " << height << " mm";
    expect_same_report(chunked, check_mesh(cup), "cup, bands of " + std::to_string(height) + " mm");
  }
  EXPECT_TRUE(check_mesh(part).valid());
  EXPECT_TRUE(check_mesh(with_cavity).valid());
  EXPECT_EQ(check_mesh(inward).inward_components, 1u);
  EXPECT_EQ(check_mesh(open).boundary_edges, 3u);
  EXPECT_TRUE(check_mesh(overlapping).self_intersecting);
  // Bands thinner than the triangles: two chunks apart may touch, so the check says it could not test.
  EXPECT_FALSE(chunked_check(menger, 0.3).self_intersections_checked);
}

TEST(Simplify, AnyClosedMeshAndItsBoundaryKept) {
  // A plain mesh (not from blocks) goes through the same guarded regions; every coordinate comes
  // out as one both STL and 3MF store exactly.
  const double h = 0.1;
  const TriMesh plain = extract_surface(voxelize(sphere({0, 0, 0}, 3), VolumeOptions{h, 3.0}));
  SimplifyOptions options;
  options.max_deviation_mm = 0.2 * h;
  const TriMesh compact = simplify_mesh(plain, options);
  const MeshCheckReport r = check_mesh(compact);
  EXPECT_TRUE(r.valid()) << ::testing::PrintToString(r.problems());
  EXPECT_EQ(r.genus, 0);
  EXPECT_LT(compact.triangles.size(), plain.triangles.size() / 4);
  EXPECT_LE(sampled_hausdorff_mm(compact, plain, h * h), 0.2 * h);
  EXPECT_LE(sampled_hausdorff_mm(plain, compact), 0.2 * h);
  for (const Vec3d& p : compact.positions_mm)
    for (int k = 0; k < 3; ++k) ASSERT_EQ(p[k], round_to_output(p[k]));

  // An open surface: the boundary vertices never move, so the boundary loop comes out unchanged.
  TriMesh open = plain;
  std::vector<std::array<uint32_t, 3>> kept;
  for (const auto& t : open.triangles)
    if (open.positions_mm[t[0]].z < 1.5 || open.positions_mm[t[1]].z < 1.5 || open.positions_mm[t[2]].z < 1.5)
      kept.push_back(t);
  open.triangles = kept;
  const MeshCheckReport open_before = check_mesh(open);
  const MeshCheckReport open_after = check_mesh(simplify_mesh(open, options));
  EXPECT_EQ(open_after.boundary_edges, open_before.boundary_edges);
  EXPECT_GT(open_before.boundary_edges, 0u);
}


// The closest point by Voronoi regions, against the distances each region has in closed form: the
// right triangle (0,0,0), (1,0,0), (0,1,0) seen from above its inside, past each corner and each
// edge, and a triangle folded flat onto a segment (nearest of its edges).
TEST(Simplify, PointTriangleDistanceHasItsClosedForms) {
  const Vec3d a{0, 0, 0}, b{1, 0, 0}, c{0, 1, 0};
  struct Case {
    Vec3d p;
    double distance;
  };
  const Case cases[] = {
      {{0.25, 0.25, 0.5}, 0.5},                     // above the inside: the height
      {{-1, -1, 0}, std::sqrt(2.0)},                // past a
      {{3, -1, 2}, 3},                              // past b: (2, -1, 2)
      {{-0.5, 2, 0}, std::sqrt(1.25)},              // past c: (-0.5, 1, 0)
      {{0.5, -2, 0}, 2},                            // beside ab
      {{-3, 0.5, 4}, 5},                            // beside ca: (3, 0, 4)
      {{1, 1, 0}, std::sqrt(0.5)},                  // beside bc: the line x + y = 1
      {{0.75, 0.75, 1}, std::sqrt(0.125 + 1)},      // above beside bc
  };
  for (const Case& k : cases) {
    const double d2 = point_triangle_distance2(k.p, a, b, c);
    EXPECT_NEAR(std::sqrt(d2), k.distance, 1e-15) << k.p.x << " " << k.p.y << " " << k.p.z;
    EXPECT_EQ(point_triangle_distance(k.p, a, b, c), std::sqrt(d2));
    EXPECT_NEAR(point_triangle_distance2(k.p, b, c, a), d2, 1e-15) << "the corners' order does not matter";
  }
  // Degenerate: a, b and the midpoint of ab; the nearest point of the segment.
  EXPECT_NEAR(point_triangle_distance({0.5, 2, 0}, a, b, {0.5, 0, 0}), 2, 1e-15);
  EXPECT_NEAR(point_triangle_distance({3, 0, 4}, a, b, {0.5, 0, 0}), std::sqrt(4.0 + 16), 1e-15);
}

// The shared helpers of geometry.h that the merge, the check, the layers and the fill rely on:
// distances to a segment (each Voronoi region of it, and a segment that is a point) on 3-4-5
// triangles, exact in floating point, and the dominant axis with its ties going to the lower axis.
TEST(Geometry, SegmentDistancesAndDominantAxisHaveTheirClosedForms) {
  const Vec3d a{0, 0, 0}, b{2, 0, 0};
  EXPECT_EQ(point_segment_distance2({1, 3, 4}, a, b), 25);     // beside the segment
  EXPECT_EQ(point_segment_distance2({-3, 0, 4}, a, b), 25);    // past a
  EXPECT_EQ(point_segment_distance2({5, 4, 0}, a, b), 25);     // past b
  EXPECT_EQ(point_segment_distance2({5, 4, 0}, b, a), 25);     // either way round
  EXPECT_EQ(point_segment_distance2({1, 4, 5}, {1, 1, 1}, {1, 1, 1}), 25);  // a point
  const Vec2d u{0, 0}, v{0, 2};
  EXPECT_EQ(point_segment_distance(Vec2d{3, 1}, u, v), 3);
  EXPECT_EQ(point_segment_distance(Vec2d{3, -4}, u, v), 5);
  EXPECT_EQ(point_segment_distance(Vec2d{4, 5}, u, v), 5);
  EXPECT_EQ(point_segment_distance(Vec2d{4, 5}, Vec2d{1, 1}, Vec2d{1, 1}), 5);
  EXPECT_EQ(dominant_axis({1, 0, 0}), 0);
  EXPECT_EQ(dominant_axis({0, -2, 1}), 1);
  EXPECT_EQ(dominant_axis({0.5, 0.5, -3}), 2);
  EXPECT_EQ(dominant_axis({1, -1, 0}), 0);
  EXPECT_EQ(dominant_axis({0, 2, -2}), 1);
  EXPECT_EQ(dominant_axis({-1, 1, 1}), 0);
}

// squared_limit(d) is the largest double whose rounded root is at most d, so comparing a squared
// distance with it decides as comparing the distance with d (the simplifier relies on this to give
// the same surface either way).
TEST(Simplify, SquaredLimitDecidesAsTheDistanceWould) {
  uint64_t state = 12345;
  auto next = [&] {
    state = state * 6364136223846793005ull + 1442695040888963407ull;
    return double(state >> 11) / double(uint64_t(1) << 53);
  };
  for (int i = 0; i < 2000; ++i) {
    const double d = i == 0 ? 0.0125 : std::ldexp(0.5 + next(), int(next() * 40) - 30);
    const double s = squared_limit(d);
    ASSERT_LE(std::sqrt(s), d) << d;
    ASSERT_GT(std::sqrt(std::nextafter(s, HUGE_VAL)), d) << d;
    // Squares near d * d, a few ulps either way, decide alike.
    double x = d * d;
    for (int k = 0; k < 8; ++k) x = std::nextafter(x, 0.0);
    for (int k = 0; k < 16; ++k, x = std::nextafter(x, HUGE_VAL)) ASSERT_EQ(std::sqrt(x) <= d, x <= s) << d << " " << x;
  }
  EXPECT_EQ(squared_limit(0), 0.0);
}

TEST(Simplify, RefusesBadOptions) {
  SimplifyOptions options;
  options.max_deviation_mm = 0;
  EXPECT_THROW(simplify_mesh(TriMesh{}, options), InvalidInput);
  options.max_deviation_mm = std::nan("");
  EXPECT_THROW(simplify_mesh(TriMesh{}, options), InvalidInput);
}

}  // namespace
}  // namespace lacuna
