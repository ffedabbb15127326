#include "export/render.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cctype>
#include <array>
#include <cmath>
#include <cstdio>
#include <limits>

#include "bcifs/realize.h"
#include "util/bitmap_font.h"
#include "export/output_files.h"
#include "errors.h"

namespace lacuna {
namespace {

using Rgb = std::array<uint8_t, 3>;

constexpr Rgb kBackground{250, 250, 250}, kInk{30, 30, 30};
constexpr int kFontScale = 2;                 // 5 x 7 glyphs drawn at 10 x 14 pixels
constexpr int kGlyphW = kGlyphWidth, kGlyphH = kGlyphHeight;
constexpr int kTextH = kGlyphH * kFontScale;  // 14
constexpr int kMargin = 8;

struct Canvas {
  int width, height;
  std::vector<uint8_t>& rgb;
  void set(int x, int y, const Rgb& c) {
    if (x < 0 || y < 0 || x >= width || y >= height) return;
    std::copy(c.begin(), c.end(), rgb.begin() + long(3 * (size_t(y) * size_t(width) + size_t(x))));
  }
  void fill(int x0, int y0, int x1, int y1, const Rgb& c) {
    for (int y = std::max(y0, 0); y < std::min(y1, height); ++y)
      for (int x = std::max(x0, 0); x < std::min(x1, width); ++x) set(x, y, c);
  }
  // Text from (x, y) at its top left; returns the x after it.
  int text(int x, int y, const std::string& s, const Rgb& c) {
    draw_text(s, [&](int b, int r) {
      fill(x + b * kFontScale, y + r * kFontScale, x + (b + 1) * kFontScale, y + (r + 1) * kFontScale, c);
    });
    return x + int(s.size()) * (kGlyphW + 1) * kFontScale;
  }
  void ring(double cx, double cy, double radius, double thickness, const Rgb& c) {
    const int r = int(std::ceil(radius + thickness));
    for (int y = int(cy) - r; y <= int(cy) + r; ++y)
      for (int x = int(cx) - r; x <= int(cx) + r; ++x) {
        const double d = std::hypot(x + 0.5 - cx, y + 0.5 - cy);
        if (std::fabs(d - radius) <= thickness / 2) set(x, y, c);
      }
  }
};

int text_width(const std::string& s) { return int(s.size()) * (kGlyphW + 1) * kFontScale - kFontScale; }

struct Camera {
  Vec3d forward, right, up;
};

Camera camera(RenderView view) {
  Vec3d forward, world_up{0, 0, 1};
  switch (view) {
    case RenderView::kFront: forward = {0, 1, 0}; break;
    case RenderView::kSide: forward = {-1, 0, 0}; break;
    case RenderView::kTop: forward = {0, 0, -1}, world_up = {0, 1, 0}; break;
    case RenderView::kIso: forward = Vec3d{-1, 1, -1} / std::sqrt(3.0); break;
  }
  Vec3d right = cross(forward, world_up);
  right = right / norm(right);
  return {forward, right, cross(right, forward)};
}

// 1, 2 or 5 times a power of ten, the largest not above `mm`.
double round_length(double mm) {
  const double p = std::pow(10.0, std::floor(std::log10(mm)));
  for (double m : {5.0, 2.0, 1.0})
    if (m * p <= mm * (1 + 1e-12)) return m * p;
  return p;
}

std::string length_label(double mm) {
  char text[32];
  std::snprintf(text, sizeof text, "%g mm", mm);
  return text;
}

Rgb marker_colour(RenderMarker::Kind kind) {
  switch (kind) {
    case RenderMarker::Kind::kTrappedVoid: return {200, 0, 200};
    case RenderMarker::Kind::kThinWall: return {240, 120, 0};
    case RenderMarker::Kind::kSmallHole: return {0, 170, 200};
  }
  return kInk;
}

const char* marker_name(RenderMarker::Kind kind) {
  switch (kind) {
    case RenderMarker::Kind::kTrappedVoid: return "trapped void";
    case RenderMarker::Kind::kThinWall: return "thin wall";
    case RenderMarker::Kind::kSmallHole: return "small hole";
  }
  return "";
}

}  // namespace

RenderView render_view_from_name(const std::string& name, const std::string& what) {
  if (name == "iso") return RenderView::kIso;
  if (name == "front") return RenderView::kFront;
  if (name == "top") return RenderView::kTop;
  if (name == "side") return RenderView::kSide;
  throw InvalidInput(what + ": expected a view \"iso\", \"front\", \"top\" or \"side\", got \"" + name + "\"");
}

const char* render_view_name(RenderView view) {
  switch (view) {
    case RenderView::kIso: return "iso";
    case RenderView::kFront: return "front";
    case RenderView::kTop: return "top";
    case RenderView::kSide: return "side";
  }
  return "";
}

namespace {

// Where a point lands in a view (pixels, x right, y down).
Vec2d project(const Picture::ViewInfo& v, const Vec3d& p) {
  return {v.centre_x + (dot(p, v.right) - v.mid_right) * v.pixels_per_mm,
          v.centre_y - (dot(p, v.up) - v.mid_up) * v.pixels_per_mm};
}

}  // namespace

Vec2d project_to_picture(const Picture& picture, size_t view, const Vec3d& p) {
  return project(picture.views.at(view), p);
}

Picture render_mesh(const TriMesh& mesh, const RenderOptions& options) {
  if (options.width < 64 || options.height < 64 || options.width > 8192 || options.height > 8192)
    throw InvalidInput("a picture is 64 x 64 to 8192 x 8192 pixels, not " + std::to_string(options.width) + " x " +
                       std::to_string(options.height));
  if (options.views.empty()) throw InvalidInput("a picture needs at least one view");
  // The section's height (mm along z); faces seen from behind through the cut are the cut solid.
  double cut = HUGE_VAL;
  const bool capped = options.section.has_value();
  if (capped) {
    if (!(*options.section >= 0 && *options.section <= 1))
      throw InvalidInput("a section is a fraction of the part's height, 0 to 1");
    double lo = HUGE_VAL, hi = -HUGE_VAL;
    for (const Vec3d& p : mesh.positions_mm) lo = std::min(lo, p.z), hi = std::max(hi, p.z);
    cut = lo + *options.section * (hi - lo);
  }
  Picture picture;
  picture.width = options.width;
  picture.height = options.height;
  picture.rgb.resize(3 * size_t(options.width) * size_t(options.height));
  for (size_t i = 0; i < picture.rgb.size(); i += 3) std::copy(kBackground.begin(), kBackground.end(), picture.rgb.begin() + long(i));
  Canvas canvas{picture.width, picture.height, picture.rgb};

  const int n = int(options.views.size());
  const int cols = int(std::ceil(std::sqrt(double(n)))), rows = (n + cols - 1) / cols;
  const int tile_w = options.width / cols, tile_h = options.height / rows;
  for (int i = 0; i < n; ++i) {
    const RenderView view = options.views[size_t(i)];
    const Camera cam = camera(view);
    Picture::ViewInfo info{};
    info.view = view;
    info.x0 = (i % cols) * tile_w;
    info.y0 = (i / cols) * tile_h;
    info.x1 = info.x0 + tile_w;
    info.y1 = info.y0 + tile_h;
    info.right = cam.right;
    info.up = cam.up;
    // The drawing area: below the title line, above the scale bar's line.
    const int ax0 = info.x0 + kMargin, ax1 = info.x1 - kMargin;
    const int ay0 = info.y0 + kMargin + kTextH + kMargin, ay1 = info.y1 - kMargin - kTextH - kMargin;
    double lo_r = HUGE_VAL, hi_r = -HUGE_VAL, lo_u = HUGE_VAL, hi_u = -HUGE_VAL;
    for (const Vec3d& p : mesh.positions_mm) {
      lo_r = std::min(lo_r, dot(p, cam.right)), hi_r = std::max(hi_r, dot(p, cam.right));
      lo_u = std::min(lo_u, dot(p, cam.up)), hi_u = std::max(hi_u, dot(p, cam.up));
    }
    if (mesh.positions_mm.empty()) lo_r = lo_u = -1, hi_r = hi_u = 1;
    const double extent = std::max({hi_r - lo_r, hi_u - lo_u, 1e-9});
    info.pixels_per_mm = std::min(double(ax1 - ax0) / std::max(hi_r - lo_r, extent * 1e-3),
                                  double(ay1 - ay0) / std::max(hi_u - lo_u, extent * 1e-3));
    info.mid_right = 0.5 * (lo_r + hi_r);
    info.mid_up = 0.5 * (lo_u + hi_u);
    info.centre_x = 0.5 * (ax0 + ax1);
    info.centre_y = 0.5 * (ay0 + ay1);

    // Vertices in pixels (x right, y down) and depth along the view.
    std::vector<std::array<double, 3>> screen(mesh.positions_mm.size());
    tbb::parallel_for(tbb::blocked_range<size_t>(0, screen.size(), 1 << 14), [&](const tbb::blocked_range<size_t>& r) {
      for (size_t k = r.begin(); k < r.end(); ++k) {
        const Vec2d at = project(info, mesh.positions_mm[k]);
        screen[k] = {at.x, at.y, dot(mesh.positions_mm[k], cam.forward)};
      }
    });
    // Light from over the viewer's left shoulder; faces seen from behind (inside-out or open) in red.
    Vec3d light = cam.up * 0.5 - cam.forward - cam.right * 0.3;
    light = light / norm(light);
    const int width = ax1 - ax0, height = ay1 - ay0;
    std::vector<float> depth(size_t(width) * size_t(height), std::numeric_limits<float>::infinity());
    constexpr int kBand = 16;
    const int bands = (height + kBand - 1) / kBand;
    tbb::parallel_for(0, bands, [&](int band) {
      const int by0 = band * kBand, by1 = std::min(height, by0 + kBand);
      for (const auto& t : mesh.triangles) {
        const auto &a = screen[t[0]], &b = screen[t[1]], &c = screen[t[2]];
        const double miny = std::min({a[1], b[1], c[1]}) - ay0, maxy = std::max({a[1], b[1], c[1]}) - ay0;
        if (maxy < by0 || miny >= by1) continue;
        const double area = (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
        if (area == 0) continue;
        const Vec3d& pa = mesh.positions_mm[t[0]];
        Vec3d normal = cross(mesh.positions_mm[t[1]] - pa, mesh.positions_mm[t[2]] - pa);
        const double len = norm(normal);
        if (!(len > 0)) continue;
        normal = normal / len;
        const bool front = dot(normal, cam.forward) < 0;
        const double lambert = std::fabs(dot(normal, light));
        const double shade = 0.3 + 0.7 * lambert;
        const Rgb colour = front     ? Rgb{uint8_t(130 * shade + 20), uint8_t(150 * shade + 20), uint8_t(185 * shade + 25)}
                           : capped ? Rgb{230, 170, 90}
                                    : Rgb{uint8_t(200 * shade + 30), uint8_t(50 * shade + 10), uint8_t(50 * shade + 10)};
        const double za = mesh.positions_mm[t[0]].z, zb = mesh.positions_mm[t[1]].z, zc = mesh.positions_mm[t[2]].z;
        if (std::min({za, zb, zc}) > cut) continue;
        const bool clipped = std::max({za, zb, zc}) > cut;
        const int x_lo = std::max(0, int(std::floor(std::min({a[0], b[0], c[0]}) - ax0)));
        const int x_hi = std::min(width - 1, int(std::ceil(std::max({a[0], b[0], c[0]}) - ax0)));
        const int y_lo = std::max(by0, int(std::floor(miny))), y_hi = std::min(by1 - 1, int(std::ceil(maxy)));
        for (int y = y_lo; y <= y_hi; ++y) {
          const double py = ay0 + y + 0.5;
          for (int x = x_lo; x <= x_hi; ++x) {
            const double px = ax0 + x + 0.5;
            // Barycentric weights from edge functions; a pixel centre on an edge belongs to both sides.
            const double w0 = ((b[0] - px) * (c[1] - py) - (b[1] - py) * (c[0] - px)) / area;
            const double w1 = ((c[0] - px) * (a[1] - py) - (c[1] - py) * (a[0] - px)) / area;
            const double w2 = 1 - w0 - w1;
            if (w0 < 0 || w1 < 0 || w2 < 0) continue;
            if (clipped && w0 * za + w1 * zb + w2 * zc > cut) continue;
            const float z = float(w0 * a[2] + w1 * b[2] + w2 * c[2]);
            float& d = depth[size_t(y) * size_t(width) + size_t(x)];
            // Ties go to the smaller triangle index order as met: the same for any thread count,
            // since each band is one task that visits triangles in order.
            if (z < d) {
              d = z;
              canvas.set(ax0 + x, ay0 + y, colour);
            }
          }
        }
      }
    });
    // Markers over the part, with a legend of the kinds shown.
    std::vector<RenderMarker::Kind> shown;
    for (const RenderMarker& m : options.markers) {
      const Vec2d at = project(info, m.location_mm);
      canvas.ring(at.x, at.y, 9, 4, kInk);
      canvas.ring(at.x, at.y, 9, 2.5, marker_colour(m.kind));
      if (std::find(shown.begin(), shown.end(), m.kind) == shown.end()) shown.push_back(m.kind);
    }
    // Title and view at the top left; legend at the top right.
    std::string title = options.title.empty() ? std::string(render_view_name(view))
                                              : options.title + " - " + render_view_name(view);
    for (char& ch : title) ch = char(std::toupper(static_cast<unsigned char>(ch)));  // one case: "FOAM", not "FOAm"
    canvas.text(info.x0 + kMargin, info.y0 + kMargin, title, kInk);
    int lx = info.x1 - kMargin;
    for (auto it = shown.rbegin(); it != shown.rend(); ++it) {
      const std::string name = marker_name(*it);
      lx -= text_width(name);
      canvas.text(lx, info.y0 + kMargin, name, marker_colour(*it));
      lx -= 3 * kFontScale * (kGlyphW + 1);
    }
    // The scale bar: a round length about a fifth of the drawing's width.
    info.bar_mm = round_length(0.2 * width / info.pixels_per_mm);
    info.bar_pixels = int(std::lround(info.bar_mm * info.pixels_per_mm));
    const int bar_y = info.y1 - kMargin - kTextH / 2;
    const int bar_x = info.x0 + kMargin;
    canvas.fill(bar_x, bar_y - 2, bar_x + info.bar_pixels, bar_y + 2, kInk);
    canvas.fill(bar_x, bar_y - 6, bar_x + 2, bar_y + 6, kInk);
    canvas.fill(bar_x + info.bar_pixels - 2, bar_y - 6, bar_x + info.bar_pixels, bar_y + 6, kInk);
    canvas.text(bar_x + info.bar_pixels + 3 * kFontScale, bar_y - kTextH / 2, length_label(info.bar_mm), kInk);
    picture.views.push_back(info);
  }
  return picture;
}

std::string encode_picture_png(const Picture& picture) {
  const std::vector<uint8_t> png = bcifs::encode_png(picture.width, picture.height, picture.rgb, 6);
  return std::string(png.begin(), png.end());
}

void write_picture_png(const std::string& path, const Picture& picture) {
  write_whole_file(path, encode_picture_png(picture));
}

}  // namespace lacuna
