// report.html as text: base64 against RFC 4648's vectors and against Draco's decoder, the page's data
// kept inside its <script> elements whatever a name holds, no request allowed by its policy, and the
// page of a run beside its report.json. (What the page does in a browser: tests/browser.)
#include "export/report_page.h"

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include <string>

#include "export/draco.h"
#include "pipeline/pipeline.h"
#include "tests/mesh_fixtures.h"
#include "tests/test_support.h"

namespace lacuna {
namespace {

namespace fs = std::filesystem;

std::string unbase64(const std::string& text) {
  std::string out;
  uint32_t bits = 0;
  int count = 0;
  for (char c : text) {
    if (c == '=') break;
    const std::string digits = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    bits = bits << 6 | uint32_t(digits.find(c));
    if ((count += 6) >= 8) {
      count -= 8;
      out += char((bits >> count) & 0xff);
    }
  }
  return out;
}

// The text of the <script> element with this id.
std::string script_text(const std::string& html, const std::string& id) {
  const std::string open = "id=\"" + id + "\">";
  const size_t begin = html.find(open);
  EXPECT_NE(begin, std::string::npos) << id;
  const size_t end = html.find("</script>", begin);
  return html.substr(begin + open.size(), end - begin - open.size());
}

TEST(ReportPage, Base64Rfc4648Vectors) {
  EXPECT_EQ(base64(""), "");
  EXPECT_EQ(base64("f"), "Zg==");
  EXPECT_EQ(base64("fo"), "Zm8=");
  EXPECT_EQ(base64("foo"), "Zm9v");
  EXPECT_EQ(base64("foob"), "Zm9vYg==");
  EXPECT_EQ(base64("fooba"), "Zm9vYmE=");
  EXPECT_EQ(base64("foobar"), "Zm9vYmFy");
  std::string all;
  for (int i = 0; i < 256; ++i) all += char(i);
  EXPECT_EQ(unbase64(base64(all)), all);
}

TEST(ReportPage, DataStaysInsideItsScripts) {
  // A name that would close the element and run a script of its own if written as it is.
  const std::string hostile = "</script><script>alert(1)</script>";
  const nlohmann::json report = {{"name", hostile}, {"outputs", nlohmann::json::array()}};
  ReportPage page;
  page.meshes.push_back({hostile, {"a</script>.stl"}, std::string("\0\1</script>", 11), {}});
  const std::string html = report_page_html(report, page);
  EXPECT_EQ(nlohmann::json::parse(script_text(html, "lacuna-report")), report);
  const nlohmann::json data = nlohmann::json::parse(script_text(html, "lacuna-page-data"));
  EXPECT_EQ(data["meshes"][0]["object"], hostile);
  EXPECT_EQ(unbase64(data["meshes"][0]["draco"].get<std::string>()), std::string("\0\1</script>", 11));
  EXPECT_NE(html.find("<title>&lt;/script&gt;&lt;script&gt;alert(1)&lt;/script&gt;: Lacuna report</title>"),
            std::string::npos);
  // Nothing may be fetched: the policy allows no source but the page's own scripts and data: images.
  EXPECT_NE(html.find("default-src 'none'"), std::string::npos);
  EXPECT_EQ(html.find("src=\"http"), std::string::npos);
  // The bundled viewer is in, and cannot close its own element early.
  const std::string script = viewer_script();
  EXPECT_GT(script.size(), 100000u);
  EXPECT_EQ(script.find("</script"), std::string::npos);
  EXPECT_NE(html.find(script), std::string::npos);
}

TEST(ReportPage, RunWritesThePageBesideReportJson) {
  test::TempDir dir;
  test::write_file(dir / "r.json", R"({"lacuna_recipe": 1, "name": "r", "voxel_size_mm": 0.1,
    "inputs": {"s": {"type": "sphere", "radius_mm": 2}},
    "outputs": [{"of": "s", "file": "s.stl"}, {"of": "s", "file": "s.drc"}]})");
  RunOptions options;
  options.output_dir = (dir / "out").string();
  const RunReport report = run((dir / "r.json").string(), options);
  ASSERT_TRUE(report.valid);
  ASSERT_GE(report.written.size(), 2u);
  EXPECT_EQ(report.written[report.written.size() - 2], (dir / "out" / "report.html").string());
  EXPECT_EQ(report.written.back(), (dir / "out" / "report.json").string());
  const std::string html = test::read_file(dir / "out" / "report.html");
  EXPECT_EQ(nlohmann::json::parse(script_text(html, "lacuna-report")),
            nlohmann::json::parse(test::read_file(dir / "out" / "report.json")));
  // One mesh for the object of both files, decoding (here, with Draco's own decoder) to their triangles.
  const nlohmann::json data = nlohmann::json::parse(script_text(html, "lacuna-page-data"));
  ASSERT_EQ(data["meshes"].size(), 1u);
  EXPECT_EQ(data["meshes"][0]["outputs"], (nlohmann::json{"s.stl", "s.drc"}));
  const TriMesh decoded = decode_draco(unbase64(data["meshes"][0]["draco"].get<std::string>()), "page");
  EXPECT_EQ(decoded.triangles.size(), report.outputs[0].check->triangles);
  EXPECT_EQ(report.outputs[0].check->triangles, report.outputs[1].check->triangles);

  // Without a report, neither file.
  options.output_dir = (dir / "quiet").string();
  options.write_report = false;
  ASSERT_TRUE(run((dir / "r.json").string(), options).valid);
  EXPECT_FALSE(fs::exists(dir / "quiet" / "report.html"));
  EXPECT_FALSE(fs::exists(dir / "quiet" / "report.json"));
}

// A PNG's width and height from its IHDR chunk.
std::pair<uint32_t, uint32_t> png_size(const std::string& png) {
  EXPECT_EQ(png.substr(0, 8), std::string("\x89PNG\r\n\x1a\n", 8));
  auto be32 = [&](size_t at) {
    return uint32_t(uint8_t(png[at])) << 24 | uint32_t(uint8_t(png[at + 1])) << 16 | uint32_t(uint8_t(png[at + 2])) << 8 |
           uint8_t(png[at + 3]);
  };
  return {be32(16), be32(20)};
}

size_t count(const std::string& text, const std::string& what) {
  size_t n = 0;
  for (size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
  return n;
}

// Runs dir/r.json with its outputs in dir/out.
RunReport run_recipe(const test::TempDir& dir) {
  RunOptions options;
  options.output_dir = (dir / "out").string();
  return run((dir / "r.json").string(), options);
}

// The pictures the page in dir/out carries.
nlohmann::json page_pictures(const test::TempDir& dir) {
  return nlohmann::json::parse(script_text(test::read_file(dir / "out" / "report.html"), "lacuna-page-data"))["pictures"];
}

TEST(ReportPage, InputFiguresOfPlatesAndPatterns) {
  test::TempDir dir;
  // A lacunar hexagon at level 2 and a p4m pattern of circles over 2 x 2 cells.
  test::write_file(dir / "r.json", R"({"lacuna_recipe": 1, "name": "r", "voxel_size_mm": 0.3,
    "inputs": {
      "plate": {"type": "bcifs_plate", "face": {"boundary": "C2 B2 C2 B2 C2 B2"}, "radius_mm": 10, "level": 2},
      "holes": {"type": "fill_motifs", "motif": "circle", "count": 20, "c": 1.15, "N": 2, "min_area_mm2": 0.2,
                "gap_mm": 0.3, "seed": 7, "height_mm": 2,
                "wallpaper": {"group": "p4m", "a_mm": [20, 0], "b_mm": [0, 20], "cells": [2, 2], "policy": "snap"}}},
    "outputs": [{"of": "plate", "file": "plate.stl"}, {"of": "holes", "file": "holes.stl"}]})");
  const RunReport report = run_recipe(dir);
  ASSERT_TRUE(report.valid);
  const nlohmann::json pictures = page_pictures(dir);
  ASSERT_EQ(pictures.size(), 3u);
  // In the order of the recipe's inputs (read as a JSON object: by name).
  // The pattern over 3 x 3 cells: every cell holds the images the 2 x 2 cells of the solid hold a
  // quarter of, so 9/4 of the motifs the report counts.
  EXPECT_EQ(pictures[0]["type"], "image/svg+xml");
  const std::string svg = unbase64(pictures[0]["data"].get<std::string>());
  // The plate: its density map (1024 x 1024) and its measure plot (1200 x 400), as PNG.
  EXPECT_EQ(pictures[1]["type"], "image/png");
  EXPECT_EQ(pictures[1]["caption"], "plate: density at level 2 (windows of 31 of 1024 pixels)");
  EXPECT_EQ(png_size(unbase64(pictures[1]["data"].get<std::string>())), (std::pair<uint32_t, uint32_t>{1024, 1024}));
  EXPECT_EQ(png_size(unbase64(pictures[2]["data"].get<std::string>())), (std::pair<uint32_t, uint32_t>{1200, 400}));
  const nlohmann::json inputs = to_json(report)["inputs"];
  const size_t motifs = inputs["holes"]["motifs"].get<size_t>();
  ASSERT_EQ(motifs % 4, 0u);
  EXPECT_EQ(count(svg, "<circle "), motifs / 4 * 9);
}

// A lacunar volume: its three middle sections' density maps (1024 x 1024) and its measure plot (1200 x 400).
TEST(ReportPage, InputFiguresOfVolumes) {
  test::TempDir dir;
  test::write_file(dir / "r.json", R"({"lacuna_recipe": 1, "name": "r", "voxel_size_mm": 0.3,
    "inputs": {"v": {"type": "bcifs_volume", "cell": "hexahedron", "edge_mm": 8, "edge": "B2", "params": "B2 B2 B2",
                     "level": 1, "center_mm": [0, 0, 4]}},
    "outputs": [{"of": "v", "file": "v.stl"}]})");
  const RunReport report = run_recipe(dir);
  ASSERT_TRUE(report.valid);
  const nlohmann::json pictures = page_pictures(dir);
  ASSERT_EQ(pictures.size(), 4u);
  EXPECT_EQ(pictures[0]["caption"], "v: density of the section x = 0 mm at level 1 (windows of 31 of 1024 pixels)");
  EXPECT_EQ(pictures[2]["caption"], "v: density of the section z = 4 mm at level 1 (windows of 31 of 1024 pixels)");
  for (size_t i = 0; i < 3; ++i)
    EXPECT_EQ(png_size(unbase64(pictures[i]["data"].get<std::string>())), (std::pair<uint32_t, uint32_t>{1024, 1024}));
  EXPECT_EQ(png_size(unbase64(pictures[3]["data"].get<std::string>())), (std::pair<uint32_t, uint32_t>{1200, 400}));
}

}  // namespace
}  // namespace lacuna
