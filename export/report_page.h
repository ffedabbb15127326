// report.html: a run's report.json as a page, with every exported object in a 3D viewer (orbit,
// zoom, wireframe, a section plane along the build direction, printability markers) and the run's
// pictures. One self-contained file: the meshes (Draco), the pictures (PNG) and the viewer's script
// (three.js and Draco's decoder from export/viewer, bundled at build time) are inside it, so it opens
// from file:// and makes no request (its Content-Security-Policy forbids any).
#pragma once

#include <nlohmann/json_fwd.hpp>
#include <string>
#include <vector>

#include "geometry.h"

namespace lacuna {

// Objects above this many triangles are listed on the page without a 3D view (the page would pass
// 100 MB); the outputs themselves are unaffected.
constexpr size_t kPageMaxTriangles = 4'000'000;

struct PageMarker {
  std::string kind;  // "trapped_voids", "thin_walls" or "small_holes"
  Vec3d location_mm;
};

struct PageMesh {
  std::string object;
  std::vector<std::string> outputs;  // the files that hold it
  std::string draco;                 // the surface as a Draco file
  std::vector<PageMarker> markers;
};

struct PagePicture {
  std::string caption;
  std::string type = "image/png";  // or "image/svg+xml"
  std::string data;                // the file's bytes
};

struct ReportPage {
  Vec3d build_direction{0, 0, 1};
  std::vector<PageMesh> meshes;
  std::vector<std::pair<std::string, std::string>> skipped;  // object, why it has no 3D view
  std::vector<PagePicture> pictures;
};

// The page for `report` (what report.json holds).
std::string report_page_html(const nlohmann::json& report, const ReportPage& page);

// The viewer's bundled script (generated from export/viewer by its build.mjs).
const char* viewer_script();

// Standard base64 (RFC 4648, with padding).
std::string base64(const std::string& bytes);

}  // namespace lacuna
