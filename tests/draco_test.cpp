// Draco files: the quantization bound against Draco's grid, the round trip vertex by vertex, the
// reference decoder's reading, malformed files, the refinement that keeps close shells apart, and
// .drc outputs of a run.
#include "export/draco.h"

#include <gtest/gtest.h>
#include <sys/wait.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <set>
#include <string>
#include <vector>

#include "errors.h"
#include "export/mesh_io.h"
#include "pipeline/draco_output.h"
#include "pipeline/pipeline.h"
#include "solids/check.h"
#include "tests/mesh_fixtures.h"
#include "tests/test_support.h"

namespace lacuna {
namespace {

namespace fs = std::filesystem;
using test::geodesic_sphere;
using test::TempDir;
using test::write_file;



// Each decoded vertex's nearest original vertex (brute force: small meshes only).
std::vector<uint32_t> nearest_originals(const TriMesh& original, const TriMesh& decoded, double* farthest) {
  std::vector<uint32_t> match;
  *farthest = 0;
  for (const Vec3d& p : decoded.positions_mm) {
    uint32_t best = 0;
    double best_d = HUGE_VAL;
    for (uint32_t i = 0; i < original.positions_mm.size(); ++i) {
      const double d = norm(original.positions_mm[i] - p);
      if (d < best_d) best_d = d, best = i;
    }
    match.push_back(best);
    *farthest = std::max(*farthest, best_d);
  }
  return match;
}

// A triangle as its corners rotated to start at the smallest (orientation kept).
std::array<uint32_t, 3> canonical(std::array<uint32_t, 3> t) {
  std::rotate(t.begin(), std::min_element(t.begin(), t.end()), t.end());
  return t;
}

TEST(Draco, QuantizationBitsAreTheFewestWithinTheBound) {
  // A 20 mm ball: Draco's grid has 2^b - 1 steps over 20 mm and a vertex moves at most sqrt(3)/2 of
  // a step (plus float rounding, under 1e-5 mm here). 0.005 mm needs 20 * sqrt(3)/2 / 0.005 = 3464
  // steps: 12 bits (4095), 11 bits (2047) do not suffice.
  const TriMesh ball = geodesic_sphere({0, 0, 0}, 10, 3);
  EXPECT_EQ(draco_quantization_bits(ball, 0.005), 12);
  // Half a step, and four float32 units in the last place of the largest coordinate (10 mm).
  EXPECT_NEAR(draco_move_bound_mm(ball, 12), std::sqrt(3.0) * (0.5 * 20 / 4095 + 4 * 10 * std::ldexp(1.0, -23)), 1e-12);
  EXPECT_LE(draco_move_bound_mm(ball, 12), 0.005);
  EXPECT_GT(draco_move_bound_mm(ball, 11), 0.005);
  // A bound below float32's resolution of the coordinates cannot be met at any number of bits.
  EXPECT_EQ(draco_quantization_bits(ball, 1e-9), 0);
}

TEST(Draco, RoundTripMovesNoVertexFurtherThanTheBoundAndKeepsEveryTriangle) {
  const TriMesh ball = geodesic_sphere({3, -2, 5}, 10, 4);
  const int bits = draco_quantization_bits(ball, 0.005);
  const TriMesh back = decode_draco(encode_draco(ball, bits), "ball.drc");
  ASSERT_EQ(back.positions_mm.size(), ball.positions_mm.size());
  ASSERT_EQ(back.triangles.size(), ball.triangles.size());
  double farthest = 0;
  const std::vector<uint32_t> match = nearest_originals(ball, back, &farthest);
  EXPECT_LE(farthest, draco_move_bound_mm(ball, bits));
  EXPECT_GT(farthest, 0.0);  // quantized, not copied
  // One decoded vertex per original, and the same triangles, each turning the same way.
  EXPECT_EQ(std::set<uint32_t>(match.begin(), match.end()).size(), ball.positions_mm.size());
  std::set<std::array<uint32_t, 3>> original, decoded;
  for (const auto& t : ball.triangles) original.insert(canonical(t));
  for (const auto& t : back.triangles) decoded.insert(canonical({match[t[0]], match[t[1]], match[t[2]]}));
  EXPECT_EQ(decoded, original);
  EXPECT_TRUE(check_mesh(back).valid());
  EXPECT_NEAR(signed_volume(back), signed_volume(ball), 1e-3 * signed_volume(ball));
  // Deterministic: the same mesh gives the same bytes.
  EXPECT_EQ(encode_draco(ball, bits), encode_draco(ball, bits));
}

TEST(Draco, MalformedFilesAreRefusedWithTheirName) {
  const std::string good = encode_draco(geodesic_sphere({0, 0, 0}, 5, 2), 14);
  EXPECT_THROW(decode_draco("DRAC", "a.drc"), InvalidInput);
  EXPECT_THROW(decode_draco("solid ascii\nendsolid\n", "a.drc"), InvalidInput);
  for (size_t cut : {size_t(11), size_t(16), good.size() / 2, good.size() - 1}) {
    try {
      decode_draco(good.substr(0, cut), "cut.drc");
      ADD_FAILURE() << "a file cut to " << cut << " bytes was read";
    } catch (const InvalidInput& e) {
      EXPECT_EQ(std::string(e.what()).rfind("cut.drc: ", 0), 0u) << e.what();
    }
  }
  // Other bitstream versions and files with metadata: their counts cannot be bounded before Draco
  // allocates (a 100-byte version 1.254 file found by fuzzing asked for gigabytes).
  std::string old = good;
  old[5] = 1, old[6] = char(254);
  EXPECT_THROW(decode_draco(old, "old.drc"), InvalidInput);
  std::string with_metadata = good;
  with_metadata[10] = char(0x80);
  EXPECT_THROW(decode_draco(with_metadata, "meta.drc"), InvalidInput);
  std::string cloud = good;
  cloud[7] = 0;  // encoder type: point cloud
  EXPECT_THROW(decode_draco(cloud, "cloud.drc"), InvalidInput);
  // A header that declares 2^28 - 1 triangles and vertices: refused before Draco allocates for them.
  std::string huge = good.substr(0, 12);
  huge += std::string("\xff\xff\xff\x7f\xff\xff\xff\x7f", 8);
  huge += std::string(64, '\0');
  ReadOptions small;
  small.max_memory_bytes = uint64_t{1} << 30;
  try {
    decode_draco(huge, "huge.drc", small);
    ADD_FAILURE() << "declared counts beyond the budget were decoded";
  } catch (const ResourceLimit& e) {
    EXPECT_NE(std::string(e.what()).find("268435455 triangles"), std::string::npos) << e.what();
  }
}

TEST(Draco, ReferenceDecoderReadsTheFile) {
  if (std::system("command -v draco_decoder > /dev/null 2>&1") != 0)
    GTEST_SKIP() << "draco_decoder (Debian package draco) is not installed";
  TempDir dir;
  const TriMesh ball = geodesic_sphere({1, 2, 3}, 8, 4);
  const DracoOutput written = write_checked_draco((dir / "ball.drc").string(), ball, 0.002, uint64_t{1} << 30);
  ASSERT_TRUE(written.check.valid());
  const std::string command = "draco_decoder -i " + (dir / "ball.drc").string() + " -o " + (dir / "ball.obj").string() +
                              " > /dev/null 2>&1";
  ASSERT_EQ(std::system(command.c_str()), 0) << command;
  const TriMesh theirs = read_mesh((dir / "ball.obj").string());
  const TriMesh ours = read_mesh((dir / "ball.drc").string());
  EXPECT_EQ(theirs.triangles.size(), ball.triangles.size());
  EXPECT_EQ(theirs.positions_mm.size(), ball.positions_mm.size());
  // The reference decoder's OBJ (printed with six digits) holds the same solid as ours.
  EXPECT_NEAR(signed_volume(theirs), signed_volume(ours), 1e-4 * signed_volume(ours));
  EXPECT_TRUE(check_mesh(theirs).valid());
}

TEST(Draco, AGridThatJoinsCloseShellsIsRefined) {
  // Two boxes 30 mm high, their facing sides a fifth of a grid step apart inside one step of the
  // coarsest grid: quantized, the sides coincide and the file fails its check; a finer grid keeps
  // them apart.
  TriMesh probe;
  test::append_box(probe, {0, 0, 0}, {20, 30, 30});
  const double bound = 0.05;
  const int bits = draco_quantization_bits(probe, bound);
  const double step = 30.0 / double((1 << bits) - 1);
  const double k = std::floor(10 / step);
  TriMesh boxes;
  test::append_box(boxes, {0, 0, 0}, {(k + 0.1) * step, 30, 30});
  test::append_box(boxes, {(k + 0.3) * step, 0, 0}, {20, 30, 30});
  ASSERT_TRUE(check_mesh(boxes).valid());
  ASSERT_EQ(draco_quantization_bits(boxes, bound), bits);
  TempDir dir;
  const DracoOutput out = write_checked_draco((dir / "boxes.drc").string(), boxes, bound, uint64_t{1} << 30);
  EXPECT_GE(out.figures.refinements, 1);
  EXPECT_GT(out.figures.quantization_bits, bits);
  EXPECT_TRUE(out.check.valid());
  EXPECT_EQ(out.check.components, 2u);
  EXPECT_TRUE(check_mesh(read_mesh((dir / "boxes.drc").string())).valid());
  // No grid reaches a bound below float32's resolution: refused, with the reason.
  EXPECT_THROW(write_checked_draco((dir / "fine.drc").string(), boxes, 1e-9, uint64_t{1} << 30), InvalidInput);
}

TEST(Draco, RunWritesACheckedDracoOutputSmallerThanItsStl) {
  TempDir dir;
  write_file(dir / "ball.json", R"({"voxel_size_mm": 0.1, "inputs": {"ball": {"type": "sphere", "radius_mm": 6}},
      "outputs": [{"of": "ball", "file": "ball.stl"}, {"of": "ball", "file": "ball.drc"}]})");
  RunOptions options;
  options.output_dir = (dir / "out").string();
  const RunReport report = run((dir / "ball.json").string(), options);
  ASSERT_TRUE(report.valid);
  const OutputReport* drc = nullptr;
  for (const OutputReport& o : report.outputs)
    if (o.format == "drc") drc = &o;
  ASSERT_NE(drc, nullptr);
  ASSERT_TRUE(drc->draco.has_value());
  ASSERT_TRUE(drc->check.has_value());
  EXPECT_TRUE(drc->check->valid());
  // Within a tenth of the voxel by default; the figures are the files'.
  EXPECT_LE(drc->draco->max_move_mm, 0.01);
  EXPECT_EQ(drc->draco->file_bytes, fs::file_size(dir / "out" / "ball.drc"));
  const TriMesh stl = read_mesh((dir / "out" / "ball.stl").string());
  const TriMesh back = read_mesh((dir / "out" / "ball.drc").string());
  EXPECT_EQ(back.triangles.size(), stl.triangles.size());
  EXPECT_EQ(drc->draco->binary_stl_bytes, fs::file_size(dir / "out" / "ball.stl"));
  EXPECT_GE(double(fs::file_size(dir / "out" / "ball.stl")) / double(fs::file_size(dir / "out" / "ball.drc")), 8.0);
  EXPECT_NEAR(signed_volume(back), signed_volume(stl), 1e-3 * signed_volume(stl));
  // A quantization asked of a file that is not Draco is refused.
  write_file(dir / "bad.json", R"({"inputs": {"ball": {"type": "sphere", "radius_mm": 6}},
      "outputs": [{"of": "ball", "file": "ball.stl", "quantize_mm": 0.01}]})");
  options.output_dir = (dir / "bad").string();
  EXPECT_THROW(run((dir / "bad.json").string(), options), InvalidInput);
  EXPECT_FALSE(fs::exists(dir / "bad"));
}

TEST(Draco, CheckFeaAndMeshInputsReadDracoFiles) {
  TempDir dir;
  const TriMesh ball = geodesic_sphere({0, 0, 0}, 4, 3);
  ASSERT_TRUE(write_checked_draco((dir / "ball.drc").string(), ball, 0.001, uint64_t{1} << 30).check.valid());
  test::Result r = test::lacuna("check " + test::quote((dir / "ball.drc").string()) + " --json", dir.path());
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("\"triangles\": " + std::to_string(ball.triangles.size())), std::string::npos) << r.out;
  r = test::lacuna("fea " + test::quote((dir / "ball.drc").string()) + " -o " + test::quote((dir / "ball.msh").string()),
                   dir.path());
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_TRUE(fs::exists(dir / "ball.msh"));
  write_file(dir / "hull.json", R"({"voxel_size_mm": 0.2, "inputs": {"hull": {"type": "mesh", "file": "ball.drc"}},
      "outputs": [{"of": "hull", "file": "hull.stl"}]})");
  r = test::lacuna("run " + test::quote((dir / "hull.json").string()) + " -o " + test::quote((dir / "out").string()),
                   dir.path());
  EXPECT_EQ(r.code, 0) << r.err;
  const TriMesh hull = read_mesh((dir / "out" / "hull.stl").string());
  EXPECT_NEAR(signed_volume(hull), signed_volume(ball), 0.02 * signed_volume(ball));
}

}  // namespace
}  // namespace lacuna
