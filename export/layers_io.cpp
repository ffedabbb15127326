#include "export/layers_io.h"

#include <zlib.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <nlohmann/json.hpp>

#include "errors.h"

namespace lacuna {
namespace {

void put_u32(std::string& out, uint32_t v) {
  const char b[4] = {char(v >> 24), char(v >> 16), char(v >> 8), char(v)};
  out.append(b, 4);
}

void put_chunk(std::string& out, const char* type, const std::string& data) {
  put_u32(out, uint32_t(data.size()));
  const size_t start = out.size();
  out.append(type, 4);
  out += data;
  put_u32(out, uint32_t(crc32(0, reinterpret_cast<const Bytef*>(out.data() + start), uInt(out.size() - start))));
}

template <class T>
void put_le(std::string& out, T v) {
  char b[sizeof(T)];
  std::memcpy(b, &v, sizeof(T));  // x86-64 and every target Lacuna builds for are little-endian
  out.append(b, sizeof(T));
}

std::string format(const char* pattern, double a) {
  char buf[64];
  std::snprintf(buf, sizeof buf, pattern, a);
  return buf;
}

}  // namespace

std::string encode_grey_png(int width, int height, const std::vector<uint8_t>& rows) {
  if (width < 1 || height < 1 || rows.size() != size_t(width) * size_t(height))
    throw InternalError("encode_grey_png: expected " + std::to_string(width) + " x " + std::to_string(height) + " pixels");
  std::string raw;
  raw.reserve((size_t(width) + 1) * size_t(height));
  for (int r = 0; r < height; ++r) {
    raw += '\0';  // filter: none
    raw.append(reinterpret_cast<const char*>(rows.data()) + size_t(r) * size_t(width), size_t(width));
  }
  uLongf packed_size = compressBound(uLong(raw.size()));
  std::string packed(packed_size, '\0');
  if (compress2(reinterpret_cast<Bytef*>(packed.data()), &packed_size, reinterpret_cast<const Bytef*>(raw.data()),
                uLong(raw.size()), 6) != Z_OK)
    throw ResourceLimit("cannot compress a layer image");
  packed.resize(packed_size);
  std::string png("\x89PNG\r\n\x1a\n", 8);
  std::string header;
  put_u32(header, uint32_t(width));
  put_u32(header, uint32_t(height));
  header += std::string("\x08\x00\x00\x00\x00", 5);  // 8 bits, greyscale, deflate, no filter choice, no interlace
  put_chunk(png, "IHDR", header);
  put_chunk(png, "IDAT", packed);
  put_chunk(png, "IEND", "");
  return png;
}

std::string encode_layer_png(const std::vector<uint8_t>& image, const LayerGrid& grid) {
  std::vector<uint8_t> rows(image.size());
  const size_t w = size_t(grid.width);
  for (int j = 0; j < grid.height; ++j)
    std::memcpy(rows.data() + size_t(grid.height - 1 - j) * w, image.data() + size_t(j) * w, w);
  return encode_grey_png(grid.width, grid.height, rows);
}

std::string layer_file_name(size_t layer) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "layer_%05zu.png", layer);
  return buf;
}

std::string layer_manifest(const LayerStack& s) {
  nlohmann::json files = nlohmann::json::array();
  for (size_t k = 0; k < s.layers; ++k) files.push_back(layer_file_name(k));
  const double half = s.grid.pixel_mm / 2;
  nlohmann::json j = {
      {"format", "lacuna png layers"},
      {"version", 1},
      {"object", s.name},
      {"layer_mm", s.layer_mm},
      {"pixel_mm", s.grid.pixel_mm},
      {"layers", s.layers},
      {"width", s.grid.width},
      {"height", s.grid.height},
      // The corner of the stack: the low-x, low-y corner of the images at the bottom of layer 0.
      {"origin_mm", {s.grid.origin_mm.x - half, s.grid.origin_mm.y - half, s.z0_mm}},
      {"rows", "top row first, at the highest y (the part seen from above)"},
      {"grey", "255 * clamp(1/2 - d2 / pixel_mm, 0, 1) for the in-plane distance d2 from the pixel's centre to the section's boundary (solid: 255)"},
      {"files", files},
  };
  return j.dump(2) + "\n";
}

std::string cli_file(const LayerStack& stack, const std::vector<Contours>& layers, bool binary) {
  Box3 box;
  for (const Contours& layer : layers)
    for (const auto& loop : layer)
      for (const Vec2d& p : loop) box.expand(Vec3d{p.x, p.y, 0});
  if (box.empty()) box = Box3{{0, 0, 0}, {0, 0, 0}};
  std::string out = "$$HEADERSTART\n";
  out += binary ? "$$BINARY\n" : "$$ASCII\n";
  out += "$$UNITS/00000001.000000\n$$VERSION/200\n";
  std::string label = stack.name;
  for (char& c : label)
    if (c == ',' || c == '/' || c == '\n' || c == '\r' || c == '$') c = '_';
  out += "$$LABEL/1," + label + "\n";
  char buf[256];
  std::snprintf(buf, sizeof buf, "$$DIMENSION/%.6f,%.6f,%.6f,%.6f,%.6f,%.6f\n", box.min.x, box.min.y, 0.0, box.max.x,
                box.max.y, double(layers.size()) * stack.layer_mm);
  out += buf;
  out += "$$LAYERS/" + std::to_string(layers.size()) + "\n";
  out += binary ? "$$HEADEREND" : "$$HEADEREND\n$$GEOMETRYSTART\n";
  for (size_t k = 0; k < layers.size(); ++k) {
    const double top = double(k + 1) * stack.layer_mm;
    if (binary) {
      put_le<uint16_t>(out, 127);
      put_le<float>(out, float(top));
    } else {
      out += format("$$LAYER/%.6f\n", top);
    }
    for (const auto& loop : layers[k]) {
      double twice = 0;
      for (size_t i = 0, n = loop.size(); i < n; ++i)
        twice += loop[i].x * loop[(i + 1) % n].y - loop[i].y * loop[(i + 1) % n].x;
      const int direction = twice > 0 ? 1 : 0;
      const size_t n = loop.size() + 1;  // closed: the first point again
      if (binary) {
        put_le<uint16_t>(out, 130);
        put_le<int32_t>(out, 1);
        put_le<int32_t>(out, direction);
        put_le<int32_t>(out, int32_t(n));
        for (size_t i = 0; i < n; ++i) {
          put_le<float>(out, float(loop[i % loop.size()].x));
          put_le<float>(out, float(loop[i % loop.size()].y));
        }
      } else {
        out += "$$POLYLINE/1," + std::to_string(direction) + "," + std::to_string(n);
        for (size_t i = 0; i < n; ++i) {
          std::snprintf(buf, sizeof buf, ",%.6f,%.6f", loop[i % loop.size()].x, loop[i % loop.size()].y);
          out += buf;
        }
        out += "\n";
      }
    }
  }
  if (!binary) out += "$$GEOMETRYEND\n";
  return out;
}

}  // namespace lacuna
