#include "pipeline/slice_output.h"

#include <tbb/global_control.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <filesystem>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>

#include "errors.h"
#include "export/layers_io.h"
#include "export/output_files.h"
#include "export/zip_archive.h"
#include "pipeline/detail/memory.h"
#include "pipeline/mesh_object.h"
#include "solids/slice.h"
#include "util/system.h"

namespace lacuna {
namespace {

namespace fs = std::filesystem;

// The most layers and pixels per layer a slice may have (beyond, no printer and no memory).
constexpr double kMaxLayers = 1e6;
constexpr double kMaxLayerPixels = 1 << 28;

std::string lower_extension(const std::string& path) {
  std::string ext = fs::path(path).extension().string();
  for (char& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
  return ext;
}

// Coordinates as the file stores them: 6 decimals (ASCII CLI) or float32 (binary), consecutive
// repeats dropped, so the checks judge what is written; images keep them as they are.
Contours as_written(const Contours& contours, LayerFormat format) {
  if (format == LayerFormat::kPng || format == LayerFormat::kPngZip) return contours;
  const bool binary = format == LayerFormat::kCliBinary;
  Contours out;
  out.reserve(contours.size());
  for (const auto& loop : contours) {
    std::vector<Vec2d> kept;
    kept.reserve(loop.size());
    for (const Vec2d& p : loop) {
      const Vec2d q = binary ? Vec2d{double(float(p.x)), double(float(p.y))}
                             : Vec2d{std::round(p.x * 1e6) / 1e6, std::round(p.y * 1e6) / 1e6};
      if (kept.empty() || !(kept.back() == q)) kept.push_back(q);
    }
    while (kept.size() > 1 && kept.front() == kept.back()) kept.pop_back();
    // A loop smaller than the file's resolution (a hole around one sample) is left out.
    if (kept.size() >= 3) out.push_back(std::move(kept));
  }
  return out;
}

const char* format_name(LayerFormat f) {
  switch (f) {
    case LayerFormat::kPng: return "png";
    case LayerFormat::kPngZip: return "png zip";
    case LayerFormat::kCli: return "cli";
    case LayerFormat::kCliBinary: return "cli binary";
    case LayerFormat::kSl1: return "sl1";
  }
  return "";
}

}  // namespace

LayerFormat layer_format_from_path(const std::string& path, bool binary) {
  const std::string ext = lower_extension(path);
  if (ext == ".cli") return binary ? LayerFormat::kCliBinary : LayerFormat::kCli;
  if (binary) throw InvalidInput(path + ": --binary is for CLI files (.cli)");
  if (ext == ".zip") return LayerFormat::kPngZip;
  if (ext == ".sl1") return LayerFormat::kSl1;
  if (ext == ".sl1s" || ext == ".pwmx" || ext == ".ctb")
    throw InvalidInput(path + ": " + ext + " archives are not written; use .sl1, a folder or a .zip of PNG layers, or a .cli file");
  if (!ext.empty() && ext != ".layers")
    throw InvalidInput(path + ": expected a folder for PNG layers, a .zip of them, or a .cli file");
  return LayerFormat::kPng;
}

SlicedLayers slice_volume(const Volume& volume, const LayerSettings& settings, const std::string& what,
                          uint64_t max_memory_bytes) {
  SlicedLayers out;
  SliceReport& report = out.report;
  report.format = settings.format;
  report.voxel_size_mm = volume.voxel_size_mm();
  report.layer_mm = settings.layer_mm > 0 ? settings.layer_mm : volume.voxel_size_mm();
  report.pixel_mm = settings.pixel_mm > 0 ? settings.pixel_mm : volume.voxel_size_mm();
  report.tolerance_mm = settings.tolerance_mm >= 0 ? settings.tolerance_mm : report.pixel_mm / 4;
  for (const auto& [name, v] : {std::pair{"layer_mm", report.layer_mm}, std::pair{"pixel_mm", report.pixel_mm}})
    if (!std::isfinite(v) || v < kMinVoxelSizeMm || v > kMaxVoxelSizeMm)
      throw InvalidInput(what + ": " + name + ": expected a length between " + std::to_string(kMinVoxelSizeMm) +
                         " and " + std::to_string(kMaxVoxelSizeMm) + " mm");
  if (!std::isfinite(report.tolerance_mm)) throw InvalidInput(what + ": tolerance_mm: expected a finite length");
  const LayerFormat format = settings.format;
  const Box3 box = solid_box(volume);
  if (box.empty()) throw InvalidInput(what + " is empty: nothing is left to slice");

  // The pixels: a margin beyond the solid's box (at least a voxel, the box's own error) keeps the
  // grid's border outside, so every contour closes.
  double p = report.pixel_mm;
  const double margin = p * (std::ceil(volume.voxel_size_mm() / p) + 1);
  LayerGrid grid;
  grid.pixel_mm = p;
  grid.origin_mm = {std::floor((box.min.x - margin) / p) * p, std::floor((box.min.y - margin) / p) * p};
  double width = std::ceil((box.max.x + margin - grid.origin_mm.x) / p) + 1;
  double height = std::ceil((box.max.y + margin - grid.origin_mm.y) / p) + 1;
  const Sl1Printer& printer = settings.printer;
  if (format == LayerFormat::kSl1) {
    // The printer's display: the part's box centred on the bed as PrusaSlicer arranges it, pixel
    // (i, j) at bed x = (i + 1/2) * row step, y = (j + 1/2) * column step.
    const double bed_x = printer.display_pixels_x * printer.row_step_mm();
    grid.pixel_mm = printer.row_step_mm();
    grid.pixel_height_mm = printer.column_step_mm();
    report.pixel_mm = p = std::max(grid.pixel_mm, grid.pixel_height_mm);
    const Vec3d centre = (box.min + box.max) * 0.5;
    grid.origin_mm = {centre.x - printer.display_width_mm / 2 + grid.pixel_mm / 2,
                      centre.y - printer.display_height_mm / 2 + grid.pixel_height_mm / 2};
    width = printer.display_pixels_x;
    height = printer.display_pixels_y;
    const double margin_x = grid.pixel_mm, margin_y = grid.pixel_height_mm;
    if (box.min.x - margin_x < grid.origin_mm.x || box.max.x + margin_x > grid.origin_mm.x + (width - 1) * grid.pixel_mm ||
        box.min.y - margin_y < grid.origin_mm.y || box.max.y + margin_y > grid.origin_mm.y + (height - 1) * grid.pixel_height_mm)
      throw InvalidInput(what + " (" + detail::fixed(box.max.x - box.min.x, 4) + " x " +
                         detail::fixed(box.max.y - box.min.y, 4) + " mm) does not fit the printer's display (" +
                         detail::fixed(bed_x, 4) + " x " + detail::fixed(printer.display_height_mm, 4) + " mm)");
  }
  const double layers = std::max(1.0, std::ceil((box.max.z - box.min.z) / report.layer_mm - 1e-9));
  if (width * height > kMaxLayerPixels)
    throw ResourceLimit(what + " at " + detail::fixed(p, 4) + " mm pixels needs " + std::to_string(int64_t(width)) +
                        " x " + std::to_string(int64_t(height)) +
                        " pixels per layer, more than 2^28; use larger pixels (--pixel-mm, pixel_mm)");
  if (layers > kMaxLayers)
    throw ResourceLimit(what + " needs " + std::to_string(int64_t(layers)) + " layers of " +
                        detail::fixed(report.layer_mm, 4) + " mm, more than a million; use thicker layers (--layer-mm, layer_mm)");
  grid.width = int(width);
  grid.height = int(height);
  report.width = grid.width;
  report.height = grid.height;
  report.z0_mm = box.min.z;
  // Memory: a layer's samples and image per thread at a time, beside the level set.
  const uint64_t budget = max_memory_bytes ? max_memory_bytes : available_memory_bytes() / 2;
  const uint64_t per_layer = uint64_t(grid.pixels()) * 6;
  const uint64_t concurrency = uint64_t(tbb::global_control::active_value(tbb::global_control::max_allowed_parallelism));
  if (per_layer * concurrency + volume.memory_bytes() > budget)
    throw ResourceLimit("slicing " + what + " needs about " + format_bytes(per_layer * concurrency) +
                        " for the layers in progress beyond its level set, more than the budget of " + format_bytes(budget));

  LayerStack& stack = out.stack;
  stack.name = settings.name;
  stack.layer_mm = report.layer_mm;
  stack.z0_mm = report.z0_mm;
  stack.layers = size_t(layers);
  stack.grid = grid;
  const bool cli = format == LayerFormat::kCli || format == LayerFormat::kCliBinary;
  std::vector<std::string>& pngs = out.pngs;
  std::vector<Contours>& contours = out.contours;
  pngs.resize(cli ? 0 : stack.layers);
  contours.resize(cli ? stack.layers : 0);
  report.layers.resize(stack.layers);
  std::vector<std::vector<std::string>> problems(stack.layers);
  {
    Progress bar("slice", stack.layers);
    tbb::parallel_for(size_t(0), stack.layers, [&](size_t k) {
      LayerFigures& figures = report.layers[k];
      figures.z_mm = report.z0_mm + (double(k) + 0.5) * report.layer_mm;
      std::vector<float> distance = sample_layer(volume, figures.z_mm, grid);
      const std::vector<uint8_t> image = coverage_image(distance, grid);
      figures.image_area_mm2 = image_area_mm2(image, grid);
      const Contours plain = as_written(contour_layer(distance, grid), format);
      distance = {};
      figures.contour_area_mm2 = contours_area_mm2(plain);
      figures.contour_length_mm = contours_length_mm(plain);
      const std::string where = "layer " + std::to_string(k) + " (z " + detail::fixed(figures.z_mm, 6) + " mm)";
      // The image and the contours are two readings of one cross-section: their areas differ by
      // less than a pixel's width along the boundary (measured: under a tenth of that).
      const double allowed = 0.5 * p * figures.contour_length_mm + p * p;  // p: the larger pixel side
      if (std::abs(figures.image_area_mm2 - figures.contour_area_mm2) > allowed)
        problems[k].push_back(where + ": the image covers " + detail::fixed(figures.image_area_mm2, 6) + " mm2, its contours " +
                              detail::fixed(figures.contour_area_mm2, 6) + " mm2");
      Contours kept = plain;
      if (cli && report.tolerance_mm > 0) kept = as_written(simplify_contours(plain, report.tolerance_mm), format);
      ContourCheck check = check_contours(kept);
      if (!check.valid() && cli && report.tolerance_mm > 0) {
        figures.simplified = false;
        kept = plain;
        check = check_contours(kept);
      }
      if (!check.valid())
        for (const std::string& problem : check.problems) problems[k].push_back(where + ": " + problem);
      figures.contours = kept.size();
      if (cli) {
        contours[k] = std::move(kept);
      } else if (format == LayerFormat::kSl1) {
        // The display's image: rows from the bed's far x end, columns along y (as PrusaSlicer 2.5).
        const size_t w = size_t(grid.width), h = size_t(grid.height);
        std::vector<uint8_t> rows(image.size());
        for (size_t r = 0; r < w; ++r)
          for (size_t c = 0; c < h; ++c) rows[r * h + c] = image[c * w + (w - 1 - r)];
        pngs[k] = encode_grey_png(int(h), int(w), rows);
      } else {
        pngs[k] = encode_layer_png(image, grid);
      }
      bar.advance();
    });
  }
  // The box may reach a little past the solid (its interpolation): empty layers on top are dropped.
  while (stack.layers > 1 && report.layers.back().contours == 0 && report.layers.back().image_area_mm2 == 0) {
    --stack.layers;
    report.layers.pop_back();
    problems.pop_back();
    if (cli) contours.pop_back();
    else pngs.pop_back();
  }
  for (auto& layer : problems)
    for (auto& problem : layer) report.problems.push_back(std::move(problem));
  report.valid = report.problems.empty();
  if (format == LayerFormat::kSl1) {
    out.printer = printer;
    out.job.name = settings.name;
    out.job.layer_mm = report.layer_mm;
    out.job.layers = stack.layers;
    std::vector<double> areas;
    for (const LayerFigures& f : report.layers) {
      areas.push_back(f.image_area_mm2);
      out.job.used_ml += f.image_area_mm2 * report.layer_mm / 1000;
    }
    out.job.print_s = sl1_print_seconds(areas, report.layer_mm, printer, &out.job.slow_layers);
  }
  return out;
}

std::string layers_file(const SlicedLayers& sliced, const std::string& where) {
  switch (sliced.report.format) {
    case LayerFormat::kCli: return cli_file(sliced.stack, sliced.contours, false);
    case LayerFormat::kCliBinary: return cli_file(sliced.stack, sliced.contours, true);
    case LayerFormat::kPngZip: {
      const std::string manifest = layer_manifest(sliced.stack);
      std::vector<ZipEntry> entries;
      entries.push_back({"manifest.json", manifest, true});
      for (size_t k = 0; k < sliced.stack.layers; ++k) entries.push_back({layer_file_name(k), sliced.pngs[k], false});
      return zip_archive(entries, where);
    }
    case LayerFormat::kSl1: {
      const std::string config = sl1_config_ini(sliced.job, sliced.printer);
      const std::string profile = sl1_prusaslicer_ini(sliced.job, sliced.printer);
      std::vector<std::string> names;
      for (size_t k = 0; k < sliced.stack.layers; ++k) names.push_back(sl1_layer_name(sliced.job.name, k));
      std::vector<ZipEntry> entries = {{"config.ini", config, true}, {"prusaslicer.ini", profile, true}};
      for (size_t k = 0; k < sliced.stack.layers; ++k) entries.push_back({names[k], sliced.pngs[k], false});
      return zip_archive(entries, where);
    }
    case LayerFormat::kPng: break;
  }
  throw InternalError("layers_file: a PNG folder is many files");
}

SliceReport slice_recipe(const std::string& recipe_path, const std::string& output, const SliceOptions& options) {
  LayerSettings settings;
  settings.format = layer_format_from_path(output, options.binary);
  Recipe recipe = load_recipe(recipe_path);
  if (options.run.voxel_size_mm > 0) recipe.voxel_size_mm = options.run.voxel_size_mm;
  std::optional<tbb::global_control> threads;
  if (options.run.threads > 0)
    threads.emplace(tbb::global_control::max_allowed_parallelism, size_t(options.run.threads));
  ProgressSinkScope progress(options.run.progress ? options.run.progress : current_progress_sink());
  ProgressSink* sink = current_progress_sink();
  settings.name = options.object.empty() ? recipe.outputs.front().object : options.object;
  settings.layer_mm = options.layer_mm;
  settings.pixel_mm = options.pixel_mm;
  settings.tolerance_mm = options.tolerance_mm;

  StageTimer timer;
  ObjectOptions object_options;
  object_options.max_memory_bytes = options.run.max_memory_bytes;
  object_options.progress = sink;
  const Volume volume = evaluate_object(recipe, settings.name, object_options);
  timer.start("slice");
  SlicedLayers sliced =
      slice_volume(volume, settings, recipe.file + ": \"" + settings.name + "\"", options.run.max_memory_bytes);
  SliceReport& report = sliced.report;
  report.output = output;
  report.object = settings.name;
  timer.start("write");
  if (report.valid) {
    throw_if_cancelled(sink);
    OutputTransaction transaction;
    if (settings.format == LayerFormat::kPng) {
      OutputFolder folder(output);
      for (size_t k = 0; k < sliced.stack.layers; ++k) {
        write_whole_file(transaction.stage((fs::path(output) / layer_file_name(k)).string()), sliced.pngs[k]);
        report.bytes += sliced.pngs[k].size();
      }
      const std::string manifest = layer_manifest(sliced.stack);
      write_whole_file(transaction.stage((fs::path(output) / "manifest.json").string()), manifest);
      report.bytes += manifest.size();
      transaction.commit();
      folder.keep();
    } else {
      const std::string bytes = layers_file(sliced, output);
      write_whole_file(transaction.stage(output), bytes);
      report.bytes = bytes.size();
      transaction.commit();
    }
  }
  timer.stop();
  report.stage_seconds = timer.seconds();
  return report;
}

nlohmann::json to_json(const SliceReport& r) {
  nlohmann::json layers = nlohmann::json::array();
  for (const LayerFigures& f : r.layers)
    layers.push_back({{"z_mm", f.z_mm},
                      {"image_area_mm2", f.image_area_mm2},
                      {"contour_area_mm2", f.contour_area_mm2},
                      {"contour_length_mm", f.contour_length_mm},
                      {"contours", f.contours},
                      {"simplified", f.simplified}});
  nlohmann::json stages = nlohmann::json::object();
  for (const auto& [name, s] : r.stage_seconds) stages[name] = s;
  return {{"output", r.output},       {"format", format_name(r.format)}, {"object", r.object},
          {"layer_mm", r.layer_mm},   {"pixel_mm", r.pixel_mm},          {"tolerance_mm", r.tolerance_mm},
          {"voxel_size_mm", r.voxel_size_mm}, {"z0_mm", r.z0_mm},        {"width", r.width},
          {"height", r.height},       {"layer_count", r.layers.size()},  {"bytes", r.bytes},
          {"valid", r.valid},         {"problems", r.problems},          {"stage_seconds", stages},
          {"layers", layers}};
}

}  // namespace lacuna
