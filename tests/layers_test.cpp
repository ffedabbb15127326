// Layers for printers: contours and images of known cross-sections (disks, annuli, islands in holes)
// against their closed forms, the contour checks against every kind of broken layer, simplification
// within its tolerance, and `lacuna slice` of spheres: per-layer areas against pi (R^2 - z^2), the PNG
// stack and both CLI forms read back, identical bytes for any thread count, refusals.
#include "layers/layers.h"

#include <gtest/gtest.h>
#include <tbb/global_control.h>
#include <zlib.h>

#include <cmath>
#include <condition_variable>
#include <cstring>
#include <mutex>
#include <thread>
#include <nlohmann/json.hpp>
#include <sstream>

#include "errors.h"
#include "export/mesh_io.h"
#include "pipeline/mesh_object.h"
#include "pipeline/slice_output.h"
#include "pipeline/stream_output.h"
#include "solids/check.h"
#include "tests/test_support.h"

namespace lacuna {
namespace {

namespace fs = std::filesystem;
using test::TempDir;
using test::write_file;

constexpr double kPi = 3.14159265358979323846;

// Samples of a signed distance function on a grid.
template <class F>
std::vector<float> sample(const LayerGrid& g, F f) {
  std::vector<float> d(g.pixels());
  for (int j = 0; j < g.height; ++j)
    for (int i = 0; i < g.width; ++i)
      d[size_t(j) * g.width + i] = float(f(g.origin_mm.x + i * g.pixel_mm, g.origin_mm.y + j * g.pixel_mm));
  return d;
}

LayerGrid square_grid(double half, double pixel) {
  LayerGrid g;
  g.pixel_mm = pixel;
  g.origin_mm = {-half, -half};
  g.width = g.height = int(std::round(2 * half / pixel)) + 1;
  return g;
}

double loop_area(const std::vector<Vec2d>& loop) { return contours_area_mm2(Contours{loop}); }

TEST(Layers, DiskContourAndImageMatchTheClosedForm) {
  const LayerGrid g = square_grid(6, 0.05);
  const double r = 4.3;
  const auto d = sample(g, [&](double x, double y) { return std::hypot(x, y) - r; });
  const Contours c = contour_layer(d, g);
  ASSERT_EQ(c.size(), 1u);
  EXPECT_GT(loop_area(c[0]), 0);  // counter-clockwise
  // Chords of a circle through points on it: the polygon's area is short by about perimeter * s^2 / (12 r).
  EXPECT_NEAR(contours_area_mm2(c), kPi * r * r, 2 * kPi * r * 0.05 * 0.05 / r);
  EXPECT_NEAR(contours_length_mm(c), 2 * kPi * r, 1e-3 * 2 * kPi * r);
  // Crossings interpolated linearly along a grid edge, where the distance bends by at most s^2 / (8 r),
  // and kept a hundredth of a pixel off the samples.
  for (const Vec2d& p : c[0]) EXPECT_NEAR(std::hypot(p.x, p.y), r, 0.05 * 0.05 / (8 * r) + 0.01 * 0.05);
  EXPECT_TRUE(check_contours(c).valid());
  // The image: its area within a small fraction of a pixel along the boundary.
  EXPECT_NEAR(image_area_mm2(coverage_image(d, g), g), kPi * r * r, 0.05 * 2 * kPi * r * 0.05);
}

TEST(Layers, AnnulusAndIslandNestAndAlternate) {
  const LayerGrid g = square_grid(8, 0.04);
  // A disk of radius 7 with a hole of radius 4 holding an island of radius 2.
  const auto d = sample(g, [](double x, double y) {
    const double q = std::hypot(x, y);
    return std::min(std::max(q - 7, 4 - q), q - 2);  // the annulus united with the island
  });
  const Contours c = contour_layer(d, g);
  ASSERT_EQ(c.size(), 3u);
  std::vector<double> areas;
  for (const auto& loop : c) areas.push_back(loop_area(loop));
  std::sort(areas.begin(), areas.end());
  EXPECT_NEAR(areas[0], -kPi * 16, 0.01);  // the hole, clockwise
  EXPECT_NEAR(areas[1], kPi * 4, 0.01);    // the island, counter-clockwise
  EXPECT_NEAR(areas[2], kPi * 49, 0.01);
  EXPECT_NEAR(contours_area_mm2(c), kPi * (49 - 16 + 4), 0.03);
  const ContourCheck check = check_contours(c);
  EXPECT_TRUE(check.valid()) << (check.problems.empty() ? "" : check.problems.front());
}

TEST(Layers, SaddlesJoinByTheCellsMean) {
  // Two squares touching corner to corner across one cell: inside corners (0,0) and (1,1) of the cell.
  LayerGrid g;
  g.pixel_mm = 1;
  g.width = g.height = 4;
  auto grid = [&](std::vector<float> v) { return v; };
  // Row-major, j = 0 first; the cell between pixels (1,1) and (2,2) is the saddle.
  std::vector<float> d = grid({1, 1, 1, 1,   //
                               1, -1, 1, 1,  //
                               1, 1, -1, 1,  //
                               1, 1, 1, 1});
  EXPECT_EQ(contour_layer(d, g).size(), 2u);  // the mean (0) is outside: two loops
  d[1 * 4 + 1] = -3;
  d[2 * 4 + 2] = -3;  // the mean is inside now: one loop through the cell
  const Contours joined = contour_layer(d, g);
  ASSERT_EQ(joined.size(), 1u);
  EXPECT_TRUE(check_contours(joined).valid());
}

TEST(Layers, ChecksFindEveryKindOfBrokenLayer) {
  const std::vector<Vec2d> square = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
  EXPECT_TRUE(check_contours({square}).valid());
  // Clockwise with nothing around it.
  const std::vector<Vec2d> backwards(square.rbegin(), square.rend());
  ContourCheck c = check_contours({backwards});
  EXPECT_FALSE(c.oriented);
  // A hole wound like its outer boundary.
  const std::vector<Vec2d> inner = {{0.25, 0.25}, {0.75, 0.25}, {0.75, 0.75}, {0.25, 0.75}};
  EXPECT_FALSE(check_contours({square, inner}).oriented);
  EXPECT_TRUE(check_contours({square, std::vector<Vec2d>(inner.rbegin(), inner.rend())}).valid());
  // A bow tie crosses itself.
  c = check_contours({{{0, 0}, {1, 1}, {1, 0}, {0, 1}}});
  EXPECT_FALSE(c.simple);
  // Two squares overlapping, and two touching at a corner.
  EXPECT_FALSE(check_contours({square, {{0.5, 0.5}, {1.5, 0.5}, {1.5, 1.5}, {0.5, 1.5}}}).disjoint);
  EXPECT_FALSE(check_contours({square, {{1, 1}, {2, 1}, {2, 2}, {1, 2}}}).disjoint);
  // Too few points, and a point at infinity.
  EXPECT_FALSE(check_contours({{{0, 0}, {1, 0}}}).closed);
  EXPECT_FALSE(check_contours({{{0, 0}, {1, 0}, {HUGE_VAL, 1}}}).closed);
  // A spike folding back on its own edge.
  EXPECT_FALSE(check_contours({{{0, 0}, {2, 0}, {1, 0}, {1, 1}}}).simple);
  // Crossings along a straight stretch of a hollow sphere's SL1 layer (as the slicer placed them):
  // in doubles, c lies on the line ab (orientation 0) and b on the line cd, so a test that reads
  // a zero orientation as "between" took the segments ab and cd for meeting. They do not.
  const Vec2d a{0x1.d39d883ba3444p+2, 0x1.3000431bde82dp-3}, b{0x1.d3a858793dd98p+2, 0x1.a0008637bd05bp-4},
      cc{0x1.d3b328b6d86ecp+2, 0x1.c0010c6f7a0b6p-5}, d{0x1.d3bdf8f47304p+2, 0x1.000431bde82d8p-7};
  c = check_contours({{a, b, cc, d, {d.x + 1, d.y}, {a.x + 1, a.y}}});
  EXPECT_TRUE(c.valid()) << ::testing::PrintToString(c.problems);
  // The same stretch continued back over itself does meet.
  EXPECT_FALSE(check_contours({{a, b, cc, d, {d.x + 1, d.y}, {b.x, b.y}, {a.x - 1, a.y}}}).simple);
}

TEST(Layers, SimplifiedContoursStayWithinTheTolerance) {
  const LayerGrid g = square_grid(6, 0.02);
  const auto d = sample(g, [](double x, double y) { return std::max(std::abs(x), std::abs(y)) - 4.01; });
  const Contours plain = contour_layer(d, g);
  const Contours reduced = simplify_contours(plain, 0.005);
  ASSERT_EQ(reduced.size(), 1u);
  // A square's boundary needs little more than its corners' neighbourhoods.
  EXPECT_LT(reduced[0].size(), plain[0].size() / 20);
  EXPECT_TRUE(check_contours(reduced).valid());
  // Every removed vertex within the tolerance of the reduced loop.
  for (const Vec2d& p : plain[0]) {
    double best = HUGE_VAL;
    for (size_t i = 0; i < reduced[0].size(); ++i) {
      const Vec2d a = reduced[0][i], b = reduced[0][(i + 1) % reduced[0].size()];
      const Vec2d ab = b - a, ap = p - a;
      const double t = std::clamp((ap.x * ab.x + ap.y * ab.y) / (ab.x * ab.x + ab.y * ab.y), 0.0, 1.0);
      best = std::min(best, std::hypot(p.x - a.x - t * ab.x, p.y - a.y - t * ab.y));
    }
    EXPECT_LE(best, 0.005 + 1e-12);
  }
  EXPECT_NEAR(contours_area_mm2(reduced), 8.02 * 8.02, 0.02);
}

// --- lacuna slice ------------------------------------------------------------------------------

// The polylines of a CLI file per layer, ASCII or binary, read here independently of the writer.
std::vector<Contours> read_cli(const std::string& bytes, std::vector<double>* tops) {
  std::vector<Contours> layers;
  const size_t end = bytes.find("$$HEADEREND");
  EXPECT_NE(end, std::string::npos);
  if (bytes.find("$$BINARY") < end) {
    size_t at = end + std::strlen("$$HEADEREND");
    auto take = [&](auto v) {
      std::memcpy(&v, bytes.data() + at, sizeof v);
      at += sizeof v;
      return v;
    };
    while (at < bytes.size()) {
      const uint16_t command = take(uint16_t());
      if (command == 127) {
        tops->push_back(take(float()));
        layers.emplace_back();
      } else {
        EXPECT_EQ(command, 130);
        take(int32_t());
        const int32_t direction = take(int32_t()), n = take(int32_t());
        std::vector<Vec2d> loop;
        for (int32_t i = 0; i < n; ++i) {
          const float x = take(float()), y = take(float());
          loop.push_back({x, y});
        }
        EXPECT_TRUE(loop.front() == loop.back());
        loop.pop_back();
        EXPECT_EQ(direction, loop_area(loop) > 0 ? 1 : 0);
        layers.back().push_back(loop);
      }
    }
    return layers;
  }
  std::istringstream in(bytes.substr(end));
  for (std::string line; std::getline(in, line);) {
    if (line.rfind("$$LAYER/", 0) == 0) {
      tops->push_back(std::stod(line.substr(8)));
      layers.emplace_back();
    } else if (line.rfind("$$POLYLINE/", 0) == 0) {
      std::vector<double> v;
      std::stringstream fields(line.substr(11));
      for (std::string f; std::getline(fields, f, ',');) v.push_back(std::stod(f));
      std::vector<Vec2d> loop;
      for (size_t i = 0; i < size_t(v[2]); ++i) loop.push_back({v[3 + 2 * i], v[4 + 2 * i]});
      EXPECT_EQ(v.size(), 3 + 2 * size_t(v[2]));
      EXPECT_TRUE(loop.front() == loop.back());
      loop.pop_back();
      EXPECT_EQ(int(v[1]), loop_area(loop) > 0 ? 1 : 0);
      layers.back().push_back(loop);
    }
  }
  return layers;
}

// An 8-bit greyscale PNG's pixel sum (filter 0 rows, as the layer writer makes them).
uint64_t png_sum(const std::string& png, int* width, int* height) {
  auto be32 = [&](size_t at) {
    return uint32_t(uint8_t(png[at])) << 24 | uint32_t(uint8_t(png[at + 1])) << 16 | uint32_t(uint8_t(png[at + 2])) << 8 |
           uint8_t(png[at + 3]);
  };
  *width = int(be32(16));
  *height = int(be32(20));
  EXPECT_EQ(png[24], 8);  // bits
  EXPECT_EQ(png[25], 0);  // greyscale
  std::string packed;
  for (size_t at = 8; at < png.size();) {
    const uint32_t length = be32(at);
    if (png.compare(at + 4, 4, "IDAT") == 0) packed += png.substr(at + 8, length);
    at += 12 + length;
  }
  std::string raw((size_t(*width) + 1) * size_t(*height), '\0');
  uLongf size = raw.size();
  EXPECT_EQ(uncompress(reinterpret_cast<Bytef*>(raw.data()), &size, reinterpret_cast<const Bytef*>(packed.data()),
                       packed.size()),
            Z_OK);
  uint64_t sum = 0;
  for (int r = 0; r < *height; ++r) {
    EXPECT_EQ(raw[size_t(r) * (*width + 1)], 0);
    for (int i = 0; i < *width; ++i) sum += uint8_t(raw[size_t(r) * (*width + 1) + 1 + i]);
  }
  return sum;
}

std::string sphere_recipe(const TempDir& dir, double radius, double voxel) {
  const fs::path path = dir / "ball.json";
  write_file(path, R"({"lacuna_recipe": 1, "name": "ball", "voxel_size_mm": )" + std::to_string(voxel) +
                       R"(, "inputs": {"ball": {"type": "sphere", "center_mm": [1, 2, 3], "radius_mm": )" +
                       std::to_string(radius) + R"(}}, "outputs": [{"of": "ball", "file": "ball.stl"}]})");
  return path.string();
}

TEST(Slice, SphereLayersMatchTheCrossSections) {
  TempDir dir;
  const std::string recipe = sphere_recipe(dir, 5, 0.05);
  SliceOptions options;
  options.layer_mm = 0.1;
  const SliceReport r = slice_recipe(recipe, (dir / "ball.cli").string(), options);
  ASSERT_TRUE(r.valid) << r.problems.front();
  EXPECT_NEAR(r.z0_mm, 3 - 5, 0.005);
  EXPECT_EQ(r.layers.size(), 100u);
  for (const LayerFigures& f : r.layers) {
    const double z = f.z_mm - 3, rho2 = 25 - z * z;
    ASSERT_GT(rho2, 0);
    const double perimeter = 2 * kPi * std::sqrt(rho2);
    // The level set resolves the sphere within a small fraction of a voxel; near the poles the
    // section's radius is that error over the slope.
    const double allowed = perimeter * 0.01 + (std::abs(z) > 4.8 ? 0.2 : 0.0);
    EXPECT_NEAR(f.contour_area_mm2, kPi * rho2, allowed) << "z " << z;
    EXPECT_NEAR(f.image_area_mm2, kPi * rho2, allowed) << "z " << z;
    EXPECT_EQ(f.contours, 1u);
  }
  // Read back: as many layers, tops at multiples of the layer height, the areas the report gives.
  std::vector<double> tops;
  const std::vector<Contours> back = read_cli(test::read_file(dir / "ball.cli"), &tops);
  ASSERT_EQ(back.size(), r.layers.size());
  for (size_t k = 0; k < back.size(); ++k) {
    EXPECT_NEAR(tops[k], 0.1 * double(k + 1), 1e-5);
    EXPECT_TRUE(check_contours(back[k]).valid());
    // Simplified by a quarter pixel: the area moves by less than that along the boundary.
    EXPECT_NEAR(contours_area_mm2(back[k]), r.layers[k].contour_area_mm2, 0.25 * 0.05 * r.layers[k].contour_length_mm);
  }
  // Binary: the same contours in float32.
  options.binary = true;
  ASSERT_TRUE(slice_recipe(recipe, (dir / "binary.cli").string(), options).valid);
  std::vector<double> binary_tops;
  const std::vector<Contours> binary = read_cli(test::read_file(dir / "binary.cli"), &binary_tops);
  ASSERT_EQ(binary.size(), back.size());
  for (size_t k = 0; k < back.size(); ++k) {
    EXPECT_NEAR(binary_tops[k], tops[k], 1e-6);
    EXPECT_NEAR(contours_area_mm2(binary[k]), contours_area_mm2(back[k]), 1e-3);
  }
}

TEST(Slice, PngStackReadsBackToTheReportedAreas) {
  TempDir dir;
  const std::string recipe = sphere_recipe(dir, 3, 0.05);
  SliceOptions options;
  options.layer_mm = 0.25;
  options.pixel_mm = 0.025;
  const SliceReport r = slice_recipe(recipe, (dir / "stack").string(), options);
  ASSERT_TRUE(r.valid);
  const nlohmann::json manifest = nlohmann::json::parse(test::read_file(dir / "stack" / "manifest.json"));
  EXPECT_EQ(manifest["layers"], r.layers.size());
  EXPECT_EQ(manifest["layer_mm"], 0.25);
  EXPECT_EQ(manifest["pixel_mm"], 0.025);
  EXPECT_EQ(manifest["files"].size(), r.layers.size());
  // The stack's corner: the lowest pixel's edge and the sphere's bottom.
  EXPECT_LT(manifest["origin_mm"][0].get<double>(), 1 - 3);
  EXPECT_NEAR(manifest["origin_mm"][2].get<double>(), 3 - 3, 0.005);
  size_t files = 0;
  for (const auto& entry : fs::directory_iterator(dir / "stack")) files += entry.path().filename().string()[0] != '.';
  EXPECT_EQ(files, r.layers.size() + 1);  // no lock or temporary left
  for (size_t k = 0; k < r.layers.size(); ++k) {
    int w = 0, h = 0;
    const uint64_t sum = png_sum(test::read_file(dir / "stack" / manifest["files"][k].get<std::string>()), &w, &h);
    EXPECT_EQ(w, r.width);
    EXPECT_EQ(h, r.height);
    EXPECT_NEAR(double(sum) / 255 * 0.025 * 0.025, r.layers[k].image_area_mm2, 1e-9);
    const double z = r.layers[k].z_mm - 3;
    EXPECT_NEAR(r.layers[k].image_area_mm2, kPi * (9 - z * z), 2 * kPi * 3 * 0.01 + (std::abs(z) > 2.8 ? 0.2 : 0.0));
  }
}

// A box from z = -2.7 to 0.75 at 0.1 mm layers from its bottom: the layer at z = 0.75 lies on its top face.
// There the surface is parallel to the plane and the samples are rounding noise about 0; the image and the
// contours must read them alike (they once read a half-covered image against inside contours, and the layer
// failed its check). Below the top, every layer is the 4 x 4 mm square within the interpolation's rim.
TEST(Slice, AFaceOnALayersPlaneReadsAlikeInImageAndContours) {
  TempDir dir;
  const fs::path recipe = dir / "box.json";
  write_file(recipe, R"({"lacuna_recipe": 1, "name": "box", "voxel_size_mm": 0.1,
      "inputs": {"b": {"type": "box", "min_mm": [-2, -2, -2.7], "max_mm": [2, 2, 0.75]}},
      "outputs": [{"of": "b", "file": "b.stl"}]})");
  SliceOptions options;
  options.layer_mm = 0.1;
  for (const char* out : {"box.cli", "box.zip"}) {
    const SliceReport r = slice_recipe(recipe.string(), (dir / out).string(), options);
    ASSERT_TRUE(r.valid) << r.problems.front();
    ASSERT_EQ(r.layers.size(), 35u);
    const LayerFigures& top = r.layers.back();
    EXPECT_NEAR(top.z_mm, 0.75, 1e-6);
    EXPECT_NEAR(top.image_area_mm2, top.contour_area_mm2, 0.5 * 0.1 * top.contour_length_mm);
    for (size_t k = 0; k + 1 < r.layers.size(); ++k)
      EXPECT_NEAR(r.layers[k].contour_area_mm2, 16, 0.5 * 0.1 * 16) << k;
  }
}

TEST(Slice, IdenticalBytesForAnyThreadCount) {
  TempDir dir;
  const std::string recipe = sphere_recipe(dir, 2.5, 0.05);
  std::string bytes[3][2];
  for (int threads : {1, 2}) {
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, size_t(threads));
    SliceOptions options;
    options.layer_mm = 0.1;
    const std::string t = std::to_string(threads);
    ASSERT_TRUE(slice_recipe(recipe, (dir / ("a" + t + ".cli")).string(), options).valid);
    ASSERT_TRUE(slice_recipe(recipe, (dir / ("z" + t + ".zip")).string(), options).valid);
    options.binary = true;
    ASSERT_TRUE(slice_recipe(recipe, (dir / ("b" + t + ".cli")).string(), options).valid);
    bytes[0][threads - 1] = test::read_file(dir / ("a" + t + ".cli"));
    bytes[1][threads - 1] = test::read_file(dir / ("z" + t + ".zip"));
    bytes[2][threads - 1] = test::read_file(dir / ("b" + t + ".cli"));
  }
  for (auto& pair : bytes) {
    EXPECT_FALSE(pair[0].empty());
    EXPECT_EQ(pair[0], pair[1]);
  }
}

TEST(Slice, RefusesClearlyAndLeavesNothing) {
  TempDir dir;
  const std::string recipe = sphere_recipe(dir, 2, 0.1);
  SliceOptions options;
  EXPECT_THROW(slice_recipe(recipe, (dir / "x.pwmx").string(), options), InvalidInput);
  EXPECT_THROW(slice_recipe(recipe, (dir / "x.stl").string(), options), InvalidInput);
  options.object = "nothing";
  EXPECT_THROW(slice_recipe(recipe, (dir / "x.cli").string(), options), InvalidInput);
  options.object.clear();
  options.pixel_mm = 1e-4;  // 40 000 x 40 000 pixels per layer
  try {
    slice_recipe(recipe, (dir / "x.cli").string(), options);
    ADD_FAILURE() << "expected a refusal";
  } catch (const ResourceLimit& e) {
    EXPECT_NE(std::string(e.what()).find("--pixel-mm"), std::string::npos) << e.what();
  }
  // The command line: exit 2 for a bad extension, nothing on disk.
  const test::Result bad = test::lacuna("slice " + test::quote(recipe) + " -o " + test::quote((dir / "x.pwmx").string()),
                                        dir.path());
  EXPECT_EQ(bad.code, 2);
  EXPECT_NE(bad.err.find("x.pwmx"), std::string::npos) << bad.err;
  for (const auto& entry : fs::directory_iterator(dir.path())) EXPECT_EQ(entry.path().filename(), "ball.json");
  const test::Result ok = test::lacuna("slice " + test::quote(recipe) + " -o " + test::quote((dir / "x.cli").string()) +
                                           " --layer-mm 0.2",
                                       dir.path());
  EXPECT_EQ(ok.code, 0) << ok.err;
  EXPECT_NE(ok.out.find("20 layers of 0.2 mm"), std::string::npos) << ok.out;
}

// Every operation kind between the inputs, a converted region among them: what a slab must
// evaluate with its halo to equal the whole run.
std::string operations_recipe(const TempDir& dir) {
  const fs::path path = dir / "ops.json";
  write_file(path, R"({"lacuna_recipe": 1, "name": "ops", "voxel_size_mm": 0.1,
    "inputs": {
      "ball": {"type": "sphere", "center_mm": [0, 0, 0.3], "radius_mm": 3},
      "bar": {"type": "box", "center_mm": [0, 0, 0], "size_mm": [8, 1.5, 1.44]},
      "plate": {"type": "region", "loops_mm": [[[-4, -4], [4, -4], [4, 4], [-4, 4]], [[-1, -1], [-1, 1], [1, 1], [1, -1]]],
                "height_mm": 1, "origin_mm": [0, 0, -2.6]},
      "hole": {"type": "cylinder", "center_mm": [0, 0, 0], "axis": [1, 0, 0], "radius_mm": 0.6, "height_mm": 10},
      "cap": {"type": "box", "min_mm": [-5, -5, -5], "max_mm": [5, 5, 2.2]}},
    "operations": [
      {"name": "joined", "op": "union", "of": ["ball", "bar", "plate"]},
      {"name": "drilled", "op": "difference", "of": ["joined", "hole"]},
      {"name": "cut", "op": "intersection", "of": ["drilled", "cap"]},
      {"name": "grown", "op": "offset", "of": "cut", "distance_mm": 0.3},
      {"name": "shrunk", "op": "offset", "of": "grown", "distance_mm": -0.5},
      {"name": "walls", "op": "shell", "of": "shrunk", "thickness_mm": 0.4}],
    "outputs": [{"of": "walls", "file": "walls.stl"}]})");
  return path.string();
}

// Offsets and a shell of an imported closed mesh, distanced from its own triangles: made whole once
// and clipped to each slab, with no halo of their own (the core 4.5 mm deep: the halo a slab gets
// anyway, 3.2 mm at 0.2 mm voxels, would not hold offsets of the slab's own surface that deep).
std::string mesh_offsets_recipe(const TempDir& dir) {
  const fs::path path = dir / "mesh_ops.json";
  write_file(path, std::string(R"({"lacuna_recipe": 1, "name": "mesh_ops", "voxel_size_mm": 0.2,
    "inputs": {"hull": {"type": "mesh", "file": ")") + LACUNA_SOURCE_DIR + R"(/samples/meshes/egg_hull.stl"}},
    "operations": [
      {"name": "walls", "op": "shell", "of": "hull", "thickness_mm": 0.8},
      {"name": "core", "op": "offset", "of": "hull", "distance_mm": -4.5},
      {"name": "grown", "op": "offset", "of": "hull", "distance_mm": 0.6},
      {"name": "nested", "op": "union", "of": ["walls", "core"]},
      {"name": "cut", "op": "difference", "of": ["grown", "nested"]}],
    "outputs": [{"of": "cut", "file": "cut.stl"}]})");
  return path.string();
}

TEST(Slice, SlabBySlabGivesTheWholeRunsBytes) {
  TempDir dir;
  struct Case {
    std::string recipe, object;
    double voxel_mm, slab_mm;
  };
  const std::string source = LACUNA_SOURCE_DIR;
  const Case cases[] = {
      {operations_recipe(dir), "walls", 0, 1.6},
      {operations_recipe(dir), "cut", 0, 0.8},
      // An imported hull filled with a lattice: a mesh converted once and clipped per slab, an infill's skin.
      {source + "/samples/egg_infill.json", "part", 0.3, 2.4},
      {mesh_offsets_recipe(dir), "cut", 0, 1.6},
      // A streamed CIFS input (cells), no operation: the halo is a band.
      {source + "/samples/menger_sponge.json", "sponge", 0, 2.0},
  };
  for (size_t i = 0; i < std::size(cases); ++i) {
    const Case& c = cases[i];
    SCOPED_TRACE(c.recipe + " " + c.object);
    {
      const char* name = i % 2 == 0 ? "layers.zip" : "layers.cli";  // images and contours
      SliceOptions options;
      options.object = c.object;
      options.run.voxel_size_mm = c.voxel_mm;
      const SliceReport whole = slice_recipe(c.recipe, (dir / ("whole-" + std::string(name))).string(), options);
      options.slab_mm = c.slab_mm;
      const SliceReport slabs = slice_recipe(c.recipe, (dir / ("slabs-" + std::string(name))).string(), options);
      ASSERT_TRUE(whole.valid && slabs.valid);
      EXPECT_EQ(whole.slabs, 1u);
      EXPECT_GE(slabs.slabs, 4u);
      EXPECT_GT(slabs.halo_mm, 0);
      EXPECT_GT(whole.layers.size(), 20u);
      EXPECT_EQ(test::read_file(dir / ("whole-" + std::string(name))), test::read_file(dir / ("slabs-" + std::string(name))));
    }
  }
}

// The recipe with one STL output of `object` and nothing a streamed run refuses.
Recipe one_stl(const std::string& path, const std::string& object, double voxel_mm) {
  Recipe recipe = recipe_for_object(load_recipe(path), object);
  if (voxel_mm > 0) recipe.voxel_size_mm = voxel_mm;
  recipe.printability = PrintabilitySettings{};
  return recipe;
}

TEST(Stream, MeshSlabBySlabIsTheWholeRunsFile) {
  TempDir dir;
  struct Case {
    std::string recipe, object;
    double voxel_mm, slab_mm;
  };
  const std::string source = LACUNA_SOURCE_DIR;
  const Case cases[] = {
      {operations_recipe(dir), "walls", 0, 1.6},
      {operations_recipe(dir), "cut", 0, 3.2},
      {source + "/samples/egg_infill.json", "part", 0.3, 9.6},
      {mesh_offsets_recipe(dir), "cut", 0, 6.4},
      {source + "/samples/menger_sponge.json", "sponge", 1.0 / 9, 2.0},
  };
  for (size_t i = 0; i < std::size(cases); ++i) {
    const Case& c = cases[i];
    SCOPED_TRACE(c.recipe + " " + c.object);
    const Recipe recipe = one_stl(c.recipe, c.object, c.voxel_mm);
    RunOptions whole_options;
    whole_options.output_dir = (dir / ("whole-" + std::to_string(i))).string();
    whole_options.write_report = false;
    const RunReport whole = run(recipe, whole_options);
    ASSERT_TRUE(whole.valid);
    StreamOptions options;
    options.run.output_dir = (dir / ("stream-" + std::to_string(i))).string();
    options.slab_mm = c.slab_mm;
    const StreamReport streamed = stream_recipe(recipe, options);
    ASSERT_TRUE(streamed.valid);
    ASSERT_EQ(streamed.outputs.size(), 1u);
    const StreamedOutput& o = streamed.outputs[0];
    EXPECT_GE(o.slabs, 2u);
    // Chunks start where every triangle to come lies above the one before the last.
    EXPECT_GE(o.check_chunks, i == 3 ? 2u : 1u);
    EXPECT_GT(o.halo_mm, 0);
    const std::string name = c.object + ".stl";
    const std::string bytes = test::read_file(fs::path(whole_options.output_dir) / name);
    EXPECT_TRUE(bytes == test::read_file(fs::path(options.run.output_dir) / name)) << "the files differ";
    // The chunked check's figures are the whole file's.
    const MeshCheckReport check = check_mesh(read_mesh((fs::path(options.run.output_dir) / name).string()));
    EXPECT_EQ(o.check.triangles, check.triangles);
    EXPECT_EQ(o.check.vertices, check.vertices);
    EXPECT_EQ(o.check.components, check.components);
    EXPECT_EQ(o.check.genus, check.genus);
    EXPECT_NEAR(o.check.volume_mm3, check.volume_mm3, 1e-9 * check.volume_mm3);
    EXPECT_TRUE(o.check.valid()) << ::testing::PrintToString(o.check.problems());
    EXPECT_EQ(o.triangles, whole.outputs.at(0).check->triangles);
    EXPECT_TRUE(fs::exists(fs::path(options.run.output_dir) / "report.json"));
  }
}

TEST(Stream, TheBudgetPicksTheSlabsAndWhatItCannotStreamIsRefused) {
  TempDir dir;
  const std::string recipe_path = std::string(LACUNA_SOURCE_DIR) + "/samples/menger_sponge.json";
  const Recipe recipe = one_stl(recipe_path, "sponge", 1.0 / 9);
  StreamOptions options;
  options.run.output_dir = (dir / "whole").string();
  const StreamReport whole = stream_recipe(recipe, options);
  ASSERT_TRUE(whole.valid);
  EXPECT_EQ(whole.outputs.at(0).slabs, 1u);
  EXPECT_EQ(whole.outputs.at(0).check_chunks, 1u);
  options.run.output_dir = (dir / "slabs").string();
  options.run.max_memory_bytes = whole.outputs.at(0).memory_estimate_bytes / 2;
  const StreamReport slabs = stream_recipe(recipe, options);
  ASSERT_TRUE(slabs.valid);
  EXPECT_GE(slabs.outputs.at(0).slabs, 2u);
  EXPECT_LE(slabs.outputs.at(0).memory_estimate_bytes, options.run.max_memory_bytes);
  EXPECT_TRUE(test::read_file(dir / "whole" / "sponge.stl") == test::read_file(dir / "slabs" / "sponge.stl"));
  // Refused by name, before anything is made: other formats, printability, no simplification.
  auto refusal = [&](Recipe r, const std::string& expected) {
    StreamOptions o;
    o.run.output_dir = (dir / "refused").string();
    try {
      stream_recipe(r, o);
      ADD_FAILURE() << "expected a refusal naming " << expected;
    } catch (const InvalidInput& e) {
      EXPECT_NE(std::string(e.what()).find(expected), std::string::npos) << e.what();
    }
    EXPECT_FALSE(fs::exists(dir / "refused"));
  };
  Recipe three_mf = load_recipe(recipe_path);
  refusal(three_mf, "outputs[1] (menger_sponge.3mf): a streamed run writes STL meshes");
  Recipe printability = recipe;
  printability.printability.enabled = true;
  refusal(printability, "printability: a streamed run does not analyse printability");
  Recipe plain = recipe;
  plain.simplify_mm = 0;
  refusal(plain, "outputs[0]: a streamed mesh is simplified as it is made");
  // From the command line: --slab-mm alone is refused; --stream writes the file and its report.
  const std::string fixed = (dir / "sponge.json").string();
  nlohmann::json j = nlohmann::json::parse(test::read_file(recipe_path));
  j["outputs"] = nlohmann::json::array({j["outputs"][0]});
  test::write_file(fixed, j.dump());
  const test::Result alone = test::lacuna("run " + test::quote(fixed) + " -o " + test::quote((dir / "cli").string()) +
                                              " --slab-mm 4", dir.path());
  EXPECT_EQ(alone.code, 2) << alone.err;
  EXPECT_NE(alone.err.find("--slab-mm: needs --stream"), std::string::npos) << alone.err;
  const test::Result cli = test::lacuna("run " + test::quote(fixed) + " -o " + test::quote((dir / "cli").string()) +
                                            " --stream --slab-mm 4 --json", dir.path());
  ASSERT_EQ(cli.code, 0) << cli.err;
  const nlohmann::json report = nlohmann::json::parse(cli.out);
  EXPECT_TRUE(report["valid"].get<bool>());
  EXPECT_GE(report["outputs"][0]["slabs"].get<int>(), 3);
  EXPECT_TRUE(report["outputs"][0]["checks"]["valid"].get<bool>());
  const test::Result check = test::lacuna("check " + test::quote((dir / "cli" / "menger_sponge.stl").string()), dir.path());
  EXPECT_EQ(check.code, 0) << check.out << check.err;
}

TEST(Slice, TheBudgetPicksTheSlabsAndNothingIsLeftBehind) {
  TempDir dir;
  const std::string recipe = std::string(LACUNA_SOURCE_DIR) + "/samples/menger_sponge.json";
  SliceOptions options;
  options.run.voxel_size_mm = 1.0 / 9;
  const SliceReport whole = slice_recipe(recipe, (dir / "whole.zip").string(), options);
  ASSERT_TRUE(whole.valid);
  EXPECT_EQ(whole.slabs, 1u);
  // A third of the whole part's estimate: the slabs are as high as fits, and no higher.
  options.run.max_memory_bytes = whole.memory_estimate_bytes / 3;
  const SliceReport slabs = slice_recipe(recipe, (dir / "slabs.zip").string(), options);
  ASSERT_TRUE(slabs.valid);
  EXPECT_GE(slabs.slabs, 3u);
  EXPECT_LE(slabs.memory_estimate_bytes, options.run.max_memory_bytes);
  EXPECT_EQ(test::read_file(dir / "whole.zip"), test::read_file(dir / "slabs.zip"));
  // A PNG folder streams its images into place: the same images, no spooled file left.
  const SliceReport folder = slice_recipe(recipe, (dir / "folder").string(), options);
  ASSERT_TRUE(folder.valid);
  size_t files = 0;
  for (const auto& entry : fs::directory_iterator(dir / "folder")) {
    const std::string name = entry.path().filename().string();
    EXPECT_TRUE(name == "manifest.json" || name.rfind("layer_", 0) == 0) << name;
    ++files;
  }
  EXPECT_EQ(files, folder.layers.size() + 1);
  // Too small a budget for even one slab: refused before building, nothing on disk.
  options.run.max_memory_bytes = 1000000;
  try {
    slice_recipe(recipe, (dir / "tiny.zip").string(), options);
    ADD_FAILURE() << "expected a refusal";
  } catch (const ResourceLimit& e) {
    EXPECT_NE(std::string(e.what()).find("slabs of"), std::string::npos) << e.what();
  }
  for (const auto& entry : fs::directory_iterator(dir.path())) {
    const std::string name = entry.path().filename().string();
    EXPECT_TRUE(name == "whole.zip" || name == "slabs.zip" || name == "folder") << name;
  }
}

// Processes of one job played by threads: every exchange waits for all of them (a barrier per call).
class ThreadRanks : public JobRanks {
 public:
  struct Shared {
    explicit Shared(int n) : slots(size_t(n)) {}
    std::mutex mutex;
    std::condition_variable changed;
    std::vector<std::string> slots, result;
    int arrived = 0;
    uint64_t round = 0;
  };
  ThreadRanks(Shared& shared, int rank) : shared_(shared), rank_(rank) {}
  int rank() const override { return rank_; }
  int size() const override { return int(shared_.slots.size()); }
  double min(double value) override {
    double out = value;
    for (const std::string& v : all(std::to_string(value))) out = std::min(out, std::stod(v));
    return out;
  }
  int64_t max(int64_t value) override {
    int64_t out = value;
    for (const std::string& v : all(std::to_string(value))) out = std::max<int64_t>(out, std::stoll(v));
    return out;
  }
  std::vector<std::string> gather(const std::string& bytes) override {
    std::vector<std::string> every = all(bytes);
    return rank_ == 0 ? every : std::vector<std::string>();
  }

 private:
  std::vector<std::string> all(const std::string& mine) {
    std::unique_lock<std::mutex> lock(shared_.mutex);
    const uint64_t round = shared_.round;
    shared_.slots[size_t(rank_)] = mine;
    if (++shared_.arrived == size()) {
      shared_.result = shared_.slots;
      shared_.arrived = 0;
      ++shared_.round;
      shared_.changed.notify_all();
    } else {
      shared_.changed.wait(lock, [&] { return shared_.round != round; });
    }
    return shared_.result;
  }
  Shared& shared_;
  int rank_;
};

// A sink that asks to stop (a process interrupted by its user).
struct StopAtOnce : ProgressSink {
  void begin(const std::string&, uint64_t) override {}
  void advance(uint64_t) override {}
  void end() override {}
  bool cancelled() const override { return true; }
};

TEST(Slice, ProcessesShareTheSlabsAndFailTogether) {
  TempDir dir;
  const std::string recipe = std::string(LACUNA_SOURCE_DIR) + "/samples/hollow_sphere.json";
  SliceOptions alone;
  alone.layer_mm = 0.4;
  ASSERT_TRUE(slice_recipe(recipe, (dir / "alone.zip").string(), alone).valid);
  // Three processes (threads here; `mpirun` in tests/python/test_mpi.py): the same bytes.
  {
    ThreadRanks::Shared shared(3);
    std::vector<SliceReport> reports(3);
    std::vector<std::thread> threads;
    for (int r = 0; r < 3; ++r)
      threads.emplace_back([&, r] {
        ThreadRanks ranks(shared, r);
        SliceOptions options = alone;
        options.ranks = &ranks;
        reports[size_t(r)] = slice_recipe(recipe, (dir / "ranks.zip").string(), options);
      });
    for (std::thread& t : threads) t.join();
    for (const SliceReport& report : reports) EXPECT_TRUE(report.valid);
    EXPECT_EQ(reports[0].slabs, 3u);
    EXPECT_EQ(reports[0].layers.size(), 50u);
    EXPECT_EQ(test::read_file(dir / "alone.zip"), test::read_file(dir / "ranks.zip"));
  }
  // Process 1 is stopped while it evaluates its slabs: it ends with its own error, the others with one
  // naming it, and nothing is written.
  ThreadRanks::Shared shared(2);
  std::vector<std::string> errors(2);
  std::vector<std::thread> threads;
  StopAtOnce stop;
  for (int r = 0; r < 2; ++r)
    threads.emplace_back([&, r] {
      ThreadRanks ranks(shared, r);
      SliceOptions options = alone;
      options.ranks = &ranks;
      if (r == 1) options.run.progress = &stop;
      try {
        slice_recipe(recipe, (dir / "failed.zip").string(), options);
      } catch (const Cancelled& e) {
        errors[size_t(r)] = e.what();
      }
    });
  for (std::thread& t : threads) t.join();
  EXPECT_NE(errors[0].find("process 1 of 2 failed"), std::string::npos) << errors[0];
  EXPECT_FALSE(errors[1].empty());
  EXPECT_EQ(errors[1].find("process 1 of 2"), std::string::npos) << errors[1];
  for (const auto& entry : fs::directory_iterator(dir.path())) {
    const std::string name = entry.path().filename().string();
    EXPECT_TRUE(name == "alone.zip" || name == "ranks.zip") << name;
  }
}

TEST(Stream, ProcessesShareTheSlabsAndFailTogether) {
  TempDir dir;
  const Recipe recipe = one_stl(std::string(LACUNA_SOURCE_DIR) + "/samples/hollow_sphere.json", "hollow", 0.15);
  StreamOptions alone;
  alone.run.output_dir = (dir / "alone").string();
  const StreamReport single = stream_recipe(recipe, alone);
  ASSERT_TRUE(single.valid);
  // Three processes (threads here; `mpirun` in tests/python/test_mpi.py): the part is six blocks of
  // 32 voxels high (4.8 mm), so the first meshes four, the others one each after their lead-ins of
  // three (the work even: four blocks each).
  {
    ThreadRanks::Shared shared(3);
    std::vector<StreamReport> reports(3);
    std::vector<std::thread> threads;
    for (int r = 0; r < 3; ++r)
      threads.emplace_back([&, r] {
        ThreadRanks ranks(shared, r);
        StreamOptions options;
        options.run.output_dir = (dir / "ranks").string();
        options.ranks = &ranks;
        reports[size_t(r)] = stream_recipe(recipe, options);
      });
    for (std::thread& t : threads) t.join();
    for (const StreamReport& report : reports) EXPECT_TRUE(report.valid);
    ASSERT_EQ(reports[0].outputs.size(), 1u);
    const StreamedOutput &o = reports[0].outputs[0], &one = single.outputs[0];
    EXPECT_EQ(o.slabs, 3u);
    EXPECT_NEAR(o.slab_mm, 4 * 4.8, 1e-9);  // the tallest
    EXPECT_EQ(o.triangles, one.triangles);
    EXPECT_EQ(o.extracted_triangles, one.extracted_triangles);
    EXPECT_EQ(o.check.components, 2u);
    EXPECT_EQ(o.check.genus, one.check.genus);
    EXPECT_TRUE(test::read_file(dir / "alone" / "hollow.stl") == test::read_file(dir / "ranks" / "hollow.stl"));
    std::vector<std::string> names;
    for (const auto& entry : fs::directory_iterator(dir / "ranks")) names.push_back(entry.path().filename().string());
    std::sort(names.begin(), names.end());
    EXPECT_EQ(names, (std::vector<std::string>{"hollow.stl", "report.json"}));  // no part left beside it
  }
  // Process 1 is stopped while it streams its part: it ends with its own error, the other with one
  // naming it, and nothing is written.
  ThreadRanks::Shared shared(2);
  std::vector<std::string> errors(2);
  std::vector<std::thread> threads;
  StopAtOnce stop;
  for (int r = 0; r < 2; ++r)
    threads.emplace_back([&, r] {
      ThreadRanks ranks(shared, r);
      StreamOptions options;
      options.run.output_dir = (dir / "failed").string();
      options.ranks = &ranks;
      if (r == 1) options.run.progress = &stop;
      try {
        stream_recipe(recipe, options);
      } catch (const Cancelled& e) {
        errors[size_t(r)] = e.what();
      }
    });
  for (std::thread& t : threads) t.join();
  EXPECT_NE(errors[0].find("process 1 of 2 failed"), std::string::npos) << errors[0];
  EXPECT_FALSE(errors[1].empty());
  EXPECT_FALSE(fs::exists(dir / "failed"));
}

TEST(Slice, RecipeOutputsAreTheSameLayersWithoutAMesh) {
  TempDir dir;
  write_file(dir / "r.json", R"({"lacuna_recipe": 1, "name": "r", "voxel_size_mm": 0.1,
    "inputs": {"ball": {"type": "sphere", "center_mm": [0, 0, 0], "radius_mm": 3}},
    "operations": [{"name": "hollow", "op": "shell", "of": "ball", "thickness_mm": 1}],
    "outputs": [{"of": "hollow", "file": "hollow.cli", "layers": {"layer_mm": 0.2, "binary": true}},
                {"of": "hollow", "file": "hollow.zip", "layers": {"layer_mm": 0.2, "pixel_mm": 0.05}}]})");
  RunOptions run_options;
  run_options.output_dir = (dir / "out").string();
  const RunReport report = run((dir / "r.json").string(), run_options);
  ASSERT_TRUE(report.valid);
  ASSERT_EQ(report.outputs.size(), 2u);
  ASSERT_TRUE(report.outputs[0].layers);
  EXPECT_EQ(report.outputs[0].layers->layers, 30u);
  EXPECT_FALSE(report.outputs[0].check);  // no mesh was made
  // The same bytes as `lacuna slice` of the object with the same settings.
  SliceOptions options;
  options.object = "hollow";
  options.layer_mm = 0.2;
  options.binary = true;
  ASSERT_TRUE(slice_recipe((dir / "r.json").string(), (dir / "alone.cli").string(), options).valid);
  EXPECT_EQ(test::read_file(dir / "out" / "hollow.cli"), test::read_file(dir / "alone.cli"));
  options.binary = false;
  options.pixel_mm = 0.05;
  ASSERT_TRUE(slice_recipe((dir / "r.json").string(), (dir / "alone.zip").string(), options).valid);
  EXPECT_EQ(test::read_file(dir / "out" / "hollow.zip"), test::read_file(dir / "alone.zip"));
  const nlohmann::json j = nlohmann::json::parse(test::read_file(dir / "out" / "report.json"));
  EXPECT_EQ(j["outputs"][1]["layers"]["count"], 30);
  EXPECT_EQ(j["outputs"][1]["layers"]["pixel_mm"], 0.05);
  EXPECT_TRUE(j["outputs"][1]["checks"]["valid"].get<bool>());
  EXPECT_FALSE(j["outputs"][1].contains("triangles"));

  // Settings that belong to meshes, or to another format, are refused with the key named.
  const std::pair<const char*, const char*> bad[] = {
      {R"({"of": "ball", "file": "b.cli", "simplify_mm": 0.01})", "simplify_mm"},
      {R"({"of": "ball", "file": "b.zip", "layers": {"binary": true}})", "binary"},
      {R"({"of": "ball", "file": "b.stl", "layers": {"layer_mm": 0.1}})", "layers"},
      {R"({"of": "ball", "file": "b.cli", "layers": {"layer_mm": -1}})", "layer_mm"},
      {R"({"of": "ball", "file": "b.cli", "layers": {"thickness": 1}})", "thickness"}};
  for (const auto& [output, key] : bad) {
    write_file(dir / "bad.json", std::string(R"({"lacuna_recipe": 1, "voxel_size_mm": 0.1,
      "inputs": {"ball": {"type": "sphere", "radius_mm": 3}}, "outputs": [)") + output + "]}");
    try {
      load_recipe((dir / "bad.json").string());
      ADD_FAILURE() << output;
    } catch (const InvalidInput& e) {
      EXPECT_NE(std::string(e.what()).find(key), std::string::npos) << e.what();
    }
  }
}

}  // namespace
}  // namespace lacuna
