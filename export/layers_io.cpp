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

std::string sl1_layer_name(const std::string& job, size_t layer) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%05zu.png", layer);
  return job + buf;
}

namespace {

std::string number(double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.10g", v);
  return buf;
}

std::string fixed6(double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.6f", v);
  return buf;
}

}  // namespace

std::string sl1_config_ini(const Sl1Job& job, const Sl1Printer& printer) {
  const std::pair<const char*, std::string> keys[] = {
      {"action", "print"},
      {"expTime", number(printer.exposure_s)},
      {"expTimeFirst", number(printer.initial_exposure_s)},
      {"expUserProfile", "0"},
      // Fixed, so that one recipe gives one archive byte for byte.
      {"fileCreationTimestamp", "1970-01-01 at 00:00:00 UTC"},
      {"hollow", "0"},
      {"jobDir", job.name},
      {"layerHeight", number(job.layer_mm)},
      {"materialName", ""},
      {"numFade", std::to_string(printer.faded_layers)},
      {"numFast", std::to_string(job.layers - job.slow_layers)},
      {"numSlow", std::to_string(job.slow_layers)},
      {"printProfile", ""},
      {"printTime", fixed6(job.print_s)},
      {"printerModel", ""},
      {"printerProfile", ""},
      {"printerVariant", ""},
      {"prusaSlicerVersion", "Lacuna-" LACUNA_VERSION},
      {"usedMaterial", fixed6(job.used_ml)},
  };
  std::string out;
  for (const auto& [key, value] : keys) out += std::string(key) + " = " + value + "\n";
  return out;
}

std::string sl1_prusaslicer_ini(const Sl1Job& job, const Sl1Printer& p) {
  const std::string w = number(p.display_width_mm), h = number(p.display_height_mm);
  const std::pair<const char*, std::string> keys[] = {
      {"absolute_correction", "0"}, {"area_fill", number(p.area_fill_percent)},
      {"bed_shape", "0x0," + w + "x0," + w + "x" + h + ",0x" + h}, {"bottle_cost", "0"}, {"bottle_volume", "1000"},
      {"bottle_weight", "1"}, {"display_height", h}, {"display_mirror_x", "1"}, {"display_mirror_y", "0"},
      {"display_orientation", "portrait"}, {"display_pixels_x", std::to_string(p.display_pixels_x)},
      {"display_pixels_y", std::to_string(p.display_pixels_y)}, {"display_width", w},
      {"elefant_foot_compensation", "0"}, {"elefant_foot_min_width", "0.2"}, {"exposure_time", number(p.exposure_s)},
      {"faded_layers", std::to_string(p.faded_layers)}, {"fast_tilt_time", number(p.fast_tilt_s)},
      {"gamma_correction", "1"}, {"high_viscosity_tilt_time", "10"}, {"hollowing_closing_distance", "2"},
      {"hollowing_enable", "0"}, {"hollowing_min_thickness", "3"}, {"hollowing_quality", "0.5"},
      {"initial_exposure_time", number(p.initial_exposure_s)}, {"initial_layer_height", number(job.layer_mm)},
      {"layer_height", number(job.layer_mm)}, {"material_correction", "1,1,1"}, {"material_correction_x", "1"},
      {"material_correction_y", "1"}, {"material_correction_z", "1"}, {"material_density", "1"},
      {"material_print_speed", "fast"}, {"max_exposure_time", "100"}, {"max_initial_exposure_time", "150"},
      {"max_print_height", "200"}, {"min_exposure_time", "0"}, {"min_initial_exposure_time", "0"},
      {"output_filename_format", "[input_filename_base].sl1"}, {"pad_around_object", "0"},
      {"pad_around_object_everywhere", "0"}, {"pad_brim_size", "1.6"}, {"pad_enable", "0"},
      {"pad_max_merge_distance", "50"}, {"pad_object_connector_penetration", "0.3"},
      {"pad_object_connector_stride", "10"}, {"pad_object_connector_width", "0.5"}, {"pad_object_gap", "1"},
      {"pad_wall_height", "0"}, {"pad_wall_slope", "90"}, {"pad_wall_thickness", "2"},
      {"physical_printer_settings_id", ""}, {"printer_settings_id", ""}, {"printer_technology", "SLA"},
      {"relative_correction", "1,1"}, {"relative_correction_x", "1"}, {"relative_correction_y", "1"},
      {"relative_correction_z", "1"}, {"sla_material_settings_id", ""}, {"sla_print_settings_id", ""},
      {"slice_closing_radius", "0.049"}, {"slicing_mode", "regular"}, {"slow_tilt_time", number(p.slow_tilt_s)},
      {"support_base_diameter", "4"}, {"support_base_height", "1"}, {"support_base_safety_distance", "1"},
      {"support_buildplate_only", "0"}, {"support_critical_angle", "45"}, {"support_head_front_diameter", "0.4"},
      {"support_head_penetration", "0.2"}, {"support_head_width", "1"}, {"support_max_bridge_length", "15"},
      {"support_max_bridges_on_pillar", "3"}, {"support_max_pillar_link_distance", "10"},
      {"support_object_elevation", "5"}, {"support_pillar_connection_mode", "dynamic"},
      {"support_pillar_diameter", "1"}, {"support_pillar_widening_factor", "0"},
      {"support_points_density_relative", "100"}, {"support_points_minimal_distance", "1"},
      {"support_small_pillar_diameter_percent", "50%"}, {"supports_enable", "0"},
  };
  std::string out;
  for (const auto& [key, value] : keys) out += std::string(key) + " = " + value + "\n";
  return out;
}

double sl1_print_seconds(const std::vector<double>& areas, double layer_mm, const Sl1Printer& p, size_t* slow_layers) {
  const double display_mm2 = p.display_width_mm * p.display_height_mm;
  double seconds = 0;
  *slow_layers = 0;
  for (size_t k = 0; k < areas.size(); ++k) {
    const bool slow = areas[k] > p.area_fill_percent / 100 * display_mm2;
    *slow_layers += slow;
    seconds += (k < size_t(p.faded_layers) ? p.initial_exposure_s : p.exposure_s) + (slow ? p.slow_tilt_s : p.fast_tilt_s) +
               5 * layer_mm;
  }
  return seconds;
}

}  // namespace lacuna
