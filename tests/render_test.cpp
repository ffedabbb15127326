// Pictures: silhouettes of known size, the scale bar against the scale, markers where their points
// project, back faces, the same pixels for any thread count, and pictures from recipes and the
// command line.
#include "export/render.h"

#include <gtest/gtest.h>
#include <tbb/global_control.h>
#include <zlib.h>

#include <cmath>
#include <map>
#include <string>
#include <vector>

#include "errors.h"
#include "pipeline/pipeline.h"
#include "tests/mesh_fixtures.h"
#include "tests/test_support.h"

namespace lacuna {
namespace {

namespace fs = std::filesystem;
using test::geodesic_sphere;
using test::TempDir;
using test::write_file;

constexpr double kPi = 3.14159265358979323846;

TriMesh box(const Vec3d& lo, const Vec3d& hi) {
  TriMesh m;
  test::append_box(m, lo, hi);
  return m;
}

std::array<uint8_t, 3> pixel(const Picture& p, int x, int y) {
  const size_t at = 3 * (size_t(y) * size_t(p.width) + size_t(x));
  return {p.rgb[at], p.rgb[at + 1], p.rgb[at + 2]};
}

bool background(const std::array<uint8_t, 3>& c) { return c[0] == 250 && c[1] == 250 && c[2] == 250; }

// Pixels of the part in a view: not background, inside the tile between its title and scale lines
// (the first and last 38 pixel rows: margin 8, text 14, margin 8, and 8 more for the ring markers).
size_t part_pixels(const Picture& p, size_t view) {
  const Picture::ViewInfo& v = p.views[view];
  size_t n = 0;
  for (int y = v.y0 + 38; y < v.y1 - 38; ++y)
    for (int x = v.x0; x < v.x1; ++x) n += !background(pixel(p, x, y));
  return n;
}

TEST(Render, SilhouettesHaveTheirProjectedArea) {
  // A ball of radius 10 seen from the front covers pi r^2 (a polyhedron inscribed at level 5 is within
  // 0.3 % of it); a 20 x 10 x 5 box seen from the front shows its 20 x 5 side, from the top its 20 x 10.
  RenderOptions options;
  options.width = 800;
  options.height = 800;
  options.views = {RenderView::kFront};
  const Picture ball = render_mesh(geodesic_sphere({0, 0, 0}, 10, 5), options);
  const double ppm = ball.views[0].pixels_per_mm;
  EXPECT_NEAR(double(part_pixels(ball, 0)), kPi * 100 * ppm * ppm, 0.01 * kPi * 100 * ppm * ppm);
  options.views = {RenderView::kFront, RenderView::kTop};
  const Picture b = render_mesh(box({0, 0, 0}, {20, 10, 5}), options);
  for (size_t v = 0; v < 2; ++v) {
    const double s = b.views[v].pixels_per_mm, h = v == 0 ? 5 : 10;
    // Within one pixel row or column along the outline.
    EXPECT_NEAR(double(part_pixels(b, v)), 20 * h * s * s, 2 * (20 + h) * s) << render_view_name(b.views[v].view);
  }
  // The part fills its tile's width: 20 mm across the drawing area (tile minus 8-pixel margins).
  EXPECT_NEAR(b.views[0].pixels_per_mm * 20, (b.views[0].x1 - b.views[0].x0) - 16, 1e-9);
}

TEST(Render, ASectionCutsAtItsHeightAndShowsTheCutSolid) {
  // A 20 x 10 x 10 box cut at half its height: from the front, 20 x 5 of it is left; from the top,
  // the cut shows the solid (the cap colour) over the whole 20 x 10.
  RenderOptions options;
  options.width = options.height = 600;
  options.views = {RenderView::kFront, RenderView::kTop};
  options.section = 0.5;
  const Picture p = render_mesh(box({0, 0, 0}, {20, 10, 10}), options);
  const double s0 = p.views[0].pixels_per_mm, s1 = p.views[1].pixels_per_mm;
  EXPECT_NEAR(double(part_pixels(p, 0)), 20 * 5 * s0 * s0, 2 * 25 * s0);
  size_t cap = 0;
  const Picture::ViewInfo& top = p.views[1];
  for (int y = top.y0 + 38; y < top.y1 - 38; ++y)
    for (int x = top.x0; x < top.x1; ++x) cap += pixel(p, x, y) == std::array<uint8_t, 3>{230, 170, 90};
  EXPECT_NEAR(double(cap), 20 * 10 * s1 * s1, 2 * 30 * s1);
  options.section = 1.5;
  EXPECT_THROW(render_mesh(box({0, 0, 0}, {1, 1, 1}), options), InvalidInput);
}

TEST(Render, ScaleBarIsARoundLengthAtTheViewsScale) {
  RenderOptions options;
  options.width = 640;
  options.height = 480;
  options.views = {RenderView::kIso, RenderView::kFront, RenderView::kTop, RenderView::kSide};
  const Picture p = render_mesh(geodesic_sphere({0, 0, 0}, 7, 3), options);
  ASSERT_EQ(p.views.size(), 4u);
  for (const Picture::ViewInfo& v : p.views) {
    const double mantissa = v.bar_mm / std::pow(10.0, std::floor(std::log10(v.bar_mm)));
    EXPECT_TRUE(std::fabs(mantissa - 1) < 1e-9 || std::fabs(mantissa - 2) < 1e-9 || std::fabs(mantissa - 5) < 1e-9)
        << v.bar_mm;
    EXPECT_EQ(v.bar_pixels, int(std::lround(v.bar_mm * v.pixels_per_mm)));
    // At most a fifth of the drawing's width, and more than a fifth of that (the next round length is
    // at most 2.5 times larger).
    const double drawing = (v.x1 - v.x0) - 16;
    EXPECT_LE(v.bar_pixels, 0.2 * drawing + 1);
    EXPECT_GT(v.bar_pixels, 0.2 * drawing / 2.5 - 1);
    // The bar is drawn: ink along it, 8 + 7 pixels above the tile's bottom.
    const int y = v.y1 - 8 - 7;
    for (int x = v.x0 + 8; x < v.x0 + 8 + v.bar_pixels; ++x) EXPECT_EQ(pixel(p, x, y)[0], 30) << x;
  }
}

TEST(Render, MarkersAreDrawnWhereTheirPointsProject) {
  RenderOptions options;
  options.width = 600;
  options.height = 600;
  options.views = {RenderView::kTop};
  const Vec3d at{4, -3, 2};
  options.markers = {{RenderMarker::Kind::kTrappedVoid, at}};
  const Picture p = render_mesh(geodesic_sphere({0, 0, 0}, 10, 3), options);
  const Vec2d c = project_to_picture(p, 0, at);
  // Top view: x to the right, y up; the ball's centre is the drawing's centre.
  const Picture::ViewInfo& v = p.views[0];
  EXPECT_NEAR(c.x, v.centre_x + 4 * v.pixels_per_mm, 1e-9);
  EXPECT_NEAR(c.y, v.centre_y + 3 * v.pixels_per_mm, 1e-9);
  // The ring (radius 9) in the trapped-void colour; its centre shows the part.
  const auto ring = pixel(p, int(c.x + 9), int(c.y));
  EXPECT_EQ(ring, (std::array<uint8_t, 3>{200, 0, 200}));
  EXPECT_NE(pixel(p, int(c.x), int(c.y)), (std::array<uint8_t, 3>{200, 0, 200}));
}

TEST(Render, FacesSeenFromBehindAreRed) {
  TriMesh inside_out = geodesic_sphere({0, 0, 0}, 5, 3);
  for (auto& t : inside_out.triangles) std::swap(t[1], t[2]);
  RenderOptions options;
  options.width = options.height = 300;
  const Picture p = render_mesh(inside_out, options);
  const Picture::ViewInfo& v = p.views[0];
  const auto centre = pixel(p, int(v.centre_x), int(v.centre_y));
  EXPECT_GT(int(centre[0]), int(centre[2]) + 50);
  const Picture right = render_mesh(geodesic_sphere({0, 0, 0}, 5, 3), options);
  const auto blue = pixel(right, int(v.centre_x), int(v.centre_y));
  EXPECT_GT(int(blue[2]), int(blue[0]));
}

TEST(Render, SamePixelsForAnyThreadCount) {
  RenderOptions options;
  options.views = {RenderView::kIso, RenderView::kSide};
  const TriMesh ball = geodesic_sphere({0, 0, 0}, 10, 5);
  Picture one, two;
  {
    tbb::global_control c(tbb::global_control::max_allowed_parallelism, 1);
    one = render_mesh(ball, options);
  }
  {
    tbb::global_control c(tbb::global_control::max_allowed_parallelism, 2);
    two = render_mesh(ball, options);
  }
  EXPECT_EQ(one.rgb, two.rgb);
}

TEST(Render, BadSizesAndViewsAreRefused) {
  RenderOptions options;
  options.width = 10;
  EXPECT_THROW(render_mesh(geodesic_sphere({0, 0, 0}, 1, 1), options), InvalidInput);
  EXPECT_THROW(render_view_from_name("back", "--views"), InvalidInput);
}

// The PNG's width and height from its IHDR chunk.
std::pair<int, int> png_size(const fs::path& path) {
  const std::string png = test::read_file(path);
  if (png.size() < 24 || png.substr(1, 3) != "PNG") return {0, 0};
  auto be = [&](size_t at) {
    return int((uint32_t(uint8_t(png[at])) << 24) | (uint32_t(uint8_t(png[at + 1])) << 16) |
               (uint32_t(uint8_t(png[at + 2])) << 8) | uint32_t(uint8_t(png[at + 3])));
  };
  return {be(16), be(20)};
}

TEST(Render, PngIsCompressedAndInflatesToThePixels) {
  RenderOptions options;
  options.width = 320;
  options.height = 200;
  const Picture picture = render_mesh(geodesic_sphere({0, 0, 0}, 3, 3), options);
  TempDir dir;
  write_picture_png((dir / "p.png").string(), picture);
  const std::string png = test::read_file(dir / "p.png");
  // One IDAT chunk after the signature and IHDR (8 + 25 bytes): zlib's inflate gives the scanlines,
  // each a filter byte 0 and the row's pixels.
  ASSERT_EQ(png.substr(37, 4), "IDAT");
  const uint32_t length = (uint32_t(uint8_t(png[33])) << 24) | (uint32_t(uint8_t(png[34])) << 16) |
                          (uint32_t(uint8_t(png[35])) << 8) | uint32_t(uint8_t(png[36]));
  std::vector<uint8_t> raw(size_t(picture.height) * (1 + 3 * size_t(picture.width)));
  uLongf raw_size = uLongf(raw.size());
  ASSERT_EQ(uncompress(raw.data(), &raw_size, reinterpret_cast<const Bytef*>(png.data() + 41), length), Z_OK);
  ASSERT_EQ(raw_size, raw.size());
  for (int y = 0; y < picture.height; ++y) {
    const uint8_t* row = raw.data() + size_t(y) * (1 + 3 * size_t(picture.width));
    ASSERT_EQ(row[0], 0);
    ASSERT_TRUE(std::equal(row + 1, row + 1 + 3 * picture.width, picture.rgb.begin() + 3 * long(y) * picture.width)) << y;
  }
  EXPECT_LT(png.size(), picture.rgb.size() / 10);  // mostly background: far smaller than the pixels
}

TEST(Render, RecipeOutputsWriteTheirPicture) {
  TempDir dir;
  write_file(dir / "ball.json", R"({"voxel_size_mm": 0.25, "inputs": {"ball": {"type": "sphere", "radius_mm": 5}},
      "outputs": [{"of": "ball", "file": "ball.stl",
                   "render": {"file": "ball.png", "views": ["iso", "top"], "size": [400, 300]}}]})");
  RunOptions options;
  options.output_dir = (dir / "out").string();
  const RunReport report = run((dir / "ball.json").string(), options);
  ASSERT_TRUE(report.valid);
  EXPECT_EQ(png_size(dir / "out" / "ball.png"), std::make_pair(400, 300));
  EXPECT_EQ(report.outputs.at(0).picture, (dir / "out" / "ball.png").string());
  EXPECT_NE(std::find(report.written.begin(), report.written.end(), (dir / "out" / "ball.png").string()),
            report.written.end());
  write_file(dir / "bad.json", R"({"inputs": {"ball": {"type": "sphere", "radius_mm": 5}},
      "outputs": [{"of": "ball", "file": "ball.stl", "render": {"file": "ball.png", "views": ["back"]}}]})");
  options.output_dir = (dir / "bad").string();
  EXPECT_THROW(run((dir / "bad.json").string(), options), InvalidInput);
  write_file(dir / "clash.json", R"({"inputs": {"ball": {"type": "sphere", "radius_mm": 5}},
      "outputs": [{"of": "ball", "file": "ball.stl", "render": "ball.stl"}]})");
  EXPECT_THROW(run((dir / "clash.json").string(), options), InvalidInput);
  EXPECT_FALSE(fs::exists(dir / "bad"));
}

TEST(Render, CommandLineRendersMeshesAndMarksPrintabilityFindings) {
  TempDir dir;
  const std::string hull = (fs::path(LACUNA_SOURCE_DIR) / "samples/meshes/egg_hull.stl").string();
  test::Result r = test::lacuna("render " + test::quote(hull) + " -o " + test::quote((dir / "egg.png").string()) +
                                    " --views iso,front --size 640x480 --json",
                                dir.path());
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(png_size(dir / "egg.png"), std::make_pair(640, 480));
  EXPECT_NE(r.out.find("\"markers\": 0"), std::string::npos) << r.out;
  // A hollow ball has a trapped void: --print marks it.
  write_file(dir / "hollow.json", R"({"voxel_size_mm": 0.25, "inputs": {"outer": {"type": "sphere", "radius_mm": 6},
      "inner": {"type": "sphere", "radius_mm": 4}}, "operations": [{"name": "shell", "op": "difference",
      "of": ["outer", "inner"]}], "outputs": [{"of": "shell", "file": "shell.stl"}]})");
  r = test::lacuna("render " + test::quote((dir / "hollow.json").string()) + " -o " +
                       test::quote((dir / "hollow.png").string()) + " --print --json",
                   dir.path());
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("\"markers\": 1"), std::string::npos) << r.out;
  for (const char* bad : {"--size 10x10", "--size big", "--views iso,back"}) {
    r = test::lacuna("render " + test::quote(hull) + " -o " + test::quote((dir / "x.png").string()) + " " + bad, dir.path());
    EXPECT_EQ(r.code, 2) << bad << ": " << r.err;
  }
  r = test::lacuna("render " + test::quote(hull) + " -o " + test::quote((dir / "x.jpg").string()), dir.path());
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_FALSE(fs::exists(dir / "x.png"));
  EXPECT_FALSE(fs::exists(dir / "x.jpg"));
}

}  // namespace
}  // namespace lacuna
