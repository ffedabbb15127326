// Pictures of a part without a GPU or a display: a software rasterizer of the mesh (orthographic
// views, depth buffer, Lambert shading, parallel over bands of rows), with the part's name, a scale
// bar in millimetres and markers at printability findings, written as PNG.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "geometry.h"

namespace lacuna {

enum class RenderView { kIso, kFront, kTop, kSide };

// "iso", "front", "top", "side"; throws InvalidInput naming `what` for anything else.
RenderView render_view_from_name(const std::string& name, const std::string& what);
const char* render_view_name(RenderView view);

struct RenderMarker {
  enum class Kind { kTrappedVoid, kThinWall, kSmallHole };
  Kind kind;
  Vec3d location_mm;
};

struct RenderOptions {
  int width = 1200, height = 900;  // pixels of the whole picture (views are tiled in it)
  std::vector<RenderView> views = {RenderView::kIso};
  std::string title;               // the object's name, printed on every view
  std::vector<RenderMarker> markers;
  // A section: everything above this fraction of the part's height (0 bottom, 1 top, along z) is
  // cut away and the cut solid shown in a cap colour; unset: the whole part.
  std::optional<double> section;
};

struct Picture {
  int width = 0, height = 0;
  std::vector<uint8_t> rgb;  // 3 bytes per pixel, rows from the top
  // Per view, in order: its tile (pixels), its scale (pixels per mm) and the scale bar drawn.
  struct ViewInfo {
    RenderView view;
    int x0, y0, x1, y1;
    double pixels_per_mm;
    double bar_mm;       // the scale bar's length in mm (1, 2 or 5 times a power of ten)
    int bar_pixels;      // and in pixels
    Vec3d right, up;     // the camera's axes: picture x = centre_x + (p.right - mid_right) * scale, y likewise up
    double mid_right, mid_up, centre_x, centre_y;
  };
  std::vector<ViewInfo> views;
};

// Where a point lands in a view of the picture (pixel coordinates, x right, y down); for tests and
// markers.
Vec2d project_to_picture(const Picture& picture, size_t view, const Vec3d& point_mm);

// Renders the mesh. Sizes 64 x 64 to 8192 x 8192 (InvalidInput otherwise); an empty mesh gives the
// background with the title. Identical pixels for any thread count.
Picture render_mesh(const TriMesh& mesh, const RenderOptions& options);

// The picture as an 8-bit RGB PNG file's bytes.
std::string encode_picture_png(const Picture& picture);

// Writes the picture as an 8-bit RGB PNG (IoError on failure).
void write_picture_png(const std::string& path, const Picture& picture);

}  // namespace lacuna
