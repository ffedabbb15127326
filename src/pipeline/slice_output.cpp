#include "pipeline/slice_output.h"

#include <tbb/global_control.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <memory>
#include <mutex>
#include <nlohmann/json.hpp>
#include <limits>
#include <optional>

#include "errors.h"
#include "export/layers_io.h"
#include "export/output_files.h"
#include "export/zip_archive.h"
#include "pipeline/detail/memory.h"
#include "pipeline/detail/slabs.h"
#include "pipeline/build_inputs.h"
#include "pipeline/evaluate.h"
#include "pipeline/mesh_object.h"
#include "pipeline/plan.h"
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


// Length-prefixed texts in one string (what processes hand each other).
void append_text(std::string& out, const std::string& text) {
  const uint64_t n = text.size();
  out.append(reinterpret_cast<const char*>(&n), sizeof n);
  out += text;
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

LayerSlicer::LayerSlicer(const LayerSettings& settings, double voxel_size_mm, std::string what, uint64_t max_memory_bytes)
    : settings_(settings), what_(std::move(what)) {
  SliceReport& report = out_.report;
  report.format = settings.format;
  report.voxel_size_mm = voxel_size_mm;
  report.layer_mm = settings.layer_mm > 0 ? settings.layer_mm : voxel_size_mm;
  report.pixel_mm = settings.pixel_mm > 0 ? settings.pixel_mm : voxel_size_mm;
  report.tolerance_mm = settings.tolerance_mm >= 0 ? settings.tolerance_mm : report.pixel_mm / 4;
  for (const auto& [name, v] : {std::pair{"layer_mm", report.layer_mm}, std::pair{"pixel_mm", report.pixel_mm}})
    if (!std::isfinite(v) || v < kMinVoxelSizeMm || v > kMaxVoxelSizeMm)
      throw InvalidInput(what_ + ": " + name + ": expected a length between " + std::to_string(kMinVoxelSizeMm) +
                         " and " + std::to_string(kMaxVoxelSizeMm) + " mm");
  if (!std::isfinite(report.tolerance_mm)) throw InvalidInput(what_ + ": tolerance_mm: expected a finite length");
  budget_ = max_memory_bytes ? max_memory_bytes : available_memory_bytes() / 2;
}

void LayerSlicer::start(const Box3& box, double z0_mm) {
  SliceReport& report = out_.report;
  const LayerFormat format = settings_.format;
  // The pixels: a margin beyond the solid's box (at least a voxel, the box's own error) keeps the
  // grid's border outside, so every contour closes.
  double p = report.pixel_mm;
  const double margin = p * (std::ceil(report.voxel_size_mm / p) + 1);
  LayerGrid& grid = out_.stack.grid;
  grid.pixel_mm = p;
  grid.origin_mm = {std::floor((box.min.x - margin) / p) * p, std::floor((box.min.y - margin) / p) * p};
  double width = std::ceil((box.max.x + margin - grid.origin_mm.x) / p) + 1;
  double height = std::ceil((box.max.y + margin - grid.origin_mm.y) / p) + 1;
  const Sl1Printer& printer = settings_.printer;
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
      throw InvalidInput(what_ + " (" + detail::fixed(box.max.x - box.min.x, 4) + " x " +
                         detail::fixed(box.max.y - box.min.y, 4) + " mm) does not fit the printer's display (" +
                         detail::fixed(bed_x, 4) + " x " + detail::fixed(printer.display_height_mm, 4) + " mm)");
  }
  // Up to the box's top and a voxel (the interpolation's reach); empty layers on top are dropped.
  const double layers = std::max(1.0, std::ceil((box.max.z + report.voxel_size_mm - z0_mm) / report.layer_mm - 1e-9));
  if (width * height > kMaxLayerPixels)
    throw ResourceLimit(what_ + " at " + detail::fixed(p, 4) + " mm pixels needs " + std::to_string(int64_t(width)) +
                        " x " + std::to_string(int64_t(height)) +
                        " pixels per layer, more than 2^28; use larger pixels (--pixel-mm, pixel_mm)");
  if (layers > kMaxLayers)
    throw ResourceLimit(what_ + " needs " + std::to_string(int64_t(layers)) + " layers of " +
                        detail::fixed(report.layer_mm, 4) + " mm, more than a million; use thicker layers (--layer-mm, layer_mm)");
  grid.width = int(width);
  grid.height = int(height);
  report.width = grid.width;
  report.height = grid.height;
  report.z0_mm = z0_mm;
  LayerStack& stack = out_.stack;
  stack.name = settings_.name;
  stack.layer_mm = report.layer_mm;
  stack.z0_mm = report.z0_mm;
  stack.layers = size_t(layers);
  const bool cli = format == LayerFormat::kCli || format == LayerFormat::kCliBinary;
  out_.pngs.resize(cli ? 0 : stack.layers);
  out_.contours.resize(cli ? stack.layers : 0);
  report.layers.resize(stack.layers);
  problems_.resize(stack.layers);
  done_.assign(stack.layers, 0);
  started_ = true;
}

double LayerSlicer::layer_z_mm(size_t k) const {
  return out_.report.z0_mm + (double(k) + 0.5) * out_.report.layer_mm;
}

void LayerSlicer::sample(const Volume& volume, double z_end_mm) {
  if (!started_) throw InternalError("LayerSlicer::sample before start");
  SliceReport& report = out_.report;
  const LayerStack& stack = out_.stack;
  const LayerGrid& grid = stack.grid;
  const LayerFormat format = settings_.format;
  const bool cli = format == LayerFormat::kCli || format == LayerFormat::kCliBinary;
  const double p = report.pixel_mm;
  size_t end = next_;
  while (end < stack.layers && layer_z_mm(end) < z_end_mm) ++end;
  if (end == next_) return;
  // Memory: a layer's samples and image per thread at a time, beside the level set.
  const uint64_t per_layer = uint64_t(grid.pixels()) * 6;
  const uint64_t concurrency = uint64_t(tbb::global_control::active_value(tbb::global_control::max_allowed_parallelism));
  if (per_layer * concurrency + volume.memory_bytes() > budget_)
    throw ResourceLimit("slicing " + what_ + " needs about " + format_bytes(per_layer * concurrency) +
                        " for the layers in progress beyond its level set, more than the budget of " + format_bytes(budget_));
  if (!bar_) bar_ = std::make_unique<Progress>("slice", stack.layers);
  tbb::parallel_for(next_, end, [&](size_t k) {
    LayerFigures& figures = report.layers[k];
    figures.z_mm = layer_z_mm(k);
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
      problems_[k].push_back(where + ": the image covers " + detail::fixed(figures.image_area_mm2, 6) + " mm2, its contours " +
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
      for (const std::string& problem : check.problems) problems_[k].push_back(where + ": " + problem);
    figures.contours = kept.size();
    if (cli) {
      out_.contours[k] = std::move(kept);
    } else if (format == LayerFormat::kSl1) {
      // The display's image: rows from the bed's far x end, columns along y (as PrusaSlicer 2.5).
      const size_t w = size_t(grid.width), h = size_t(grid.height);
      std::vector<uint8_t> rows(image.size());
      for (size_t r = 0; r < w; ++r)
        for (size_t c = 0; c < h; ++c) rows[r * h + c] = image[c * w + (w - 1 - r)];
      out_.pngs[k] = encode_grey_png(int(h), int(w), rows);
    } else {
      out_.pngs[k] = encode_layer_png(image, grid);
    }
    if (spool_ && !cli) {
      spool_(k, out_.pngs[k]);
      out_.pngs[k] = std::string();
    }
    done_[k] = 1;
    bar_->advance();
  });
  next_ = end;
}

void LayerSlicer::skip_to(double z_mm) {
  if (!started_ || next_ != first_) throw InternalError("LayerSlicer::skip_to after sampling");
  while (next_ < out_.stack.layers && layer_z_mm(next_) < z_mm) ++next_;
  first_ = next_;
}

namespace {

template <typename T>
void put(std::string& out, const T& v) {
  out.append(reinterpret_cast<const char*>(&v), sizeof v);
}

struct Reader {
  const std::string& bytes;
  size_t at = 0;
  template <typename T>
  T get() {
    T v;
    if (at + sizeof v > bytes.size()) throw InternalError("a process's layers were cut short");
    std::memcpy(&v, bytes.data() + at, sizeof v);
    at += sizeof v;
    return v;
  }
  std::string text() {
    const uint64_t n = get<uint64_t>();
    if (at + n > bytes.size()) throw InternalError("a process's layers were cut short");
    std::string t = bytes.substr(at, n);
    at += n;
    return t;
  }
};

}  // namespace

std::string LayerSlicer::pack() const {
  std::string out;
  put<uint64_t>(out, first_);
  put<uint64_t>(out, next_);
  for (size_t k = first_; k < next_; ++k) {
    const LayerFigures& f = out_.report.layers[k];
    put(out, f.z_mm);
    put(out, f.image_area_mm2);
    put(out, f.contour_area_mm2);
    put(out, f.contour_length_mm);
    put<uint64_t>(out, f.contours);
    put<uint8_t>(out, f.simplified ? 1 : 0);
    put<uint64_t>(out, problems_[k].size());
    for (const std::string& problem : problems_[k]) append_text(out, problem);
    const Contours none;
    const Contours& loops = k < out_.contours.size() ? out_.contours[k] : none;
    put<uint64_t>(out, loops.size());
    for (const auto& loop : loops) {
      put<uint64_t>(out, loop.size());
      for (const Vec2d& p : loop) {
        put(out, p.x);
        put(out, p.y);
      }
    }
  }
  return out;
}

std::vector<std::string> LayerSlicer::unpack(const std::string& bytes) {
  Reader in{bytes};
  const uint64_t first = in.get<uint64_t>(), end = in.get<uint64_t>();
  if (first > end || end > out_.stack.layers) throw InternalError("a process's layers do not fit the stack");
  for (size_t k = first; k < end; ++k) {
    LayerFigures& f = out_.report.layers[k];
    f.z_mm = in.get<double>();
    f.image_area_mm2 = in.get<double>();
    f.contour_area_mm2 = in.get<double>();
    f.contour_length_mm = in.get<double>();
    f.contours = in.get<uint64_t>();
    f.simplified = in.get<uint8_t>() != 0;
    problems_[k].resize(in.get<uint64_t>());
    for (std::string& problem : problems_[k]) problem = in.text();
    Contours loops(in.get<uint64_t>());
    for (auto& loop : loops) {
      loop.resize(in.get<uint64_t>());
      for (Vec2d& p : loop) {
        p.x = in.get<double>();
        p.y = in.get<double>();
      }
    }
    if (k < out_.contours.size()) out_.contours[k] = std::move(loops);
    if (done_[k]) throw InternalError("layer " + std::to_string(k) + " was cut twice");
    done_[k] = 1;
  }
  std::vector<std::string> texts;
  while (in.at < bytes.size()) texts.push_back(in.text());
  return texts;
}

SlicedLayers LayerSlicer::finish() {
  if (!started_) throw InternalError("LayerSlicer::finish before start");
  if (std::count(done_.begin(), done_.end(), 0) != 0) throw InternalError("LayerSlicer::finish with layers not sampled");
  bar_.reset();
  SliceReport& report = out_.report;
  LayerStack& stack = out_.stack;
  const bool cli = report.format == LayerFormat::kCli || report.format == LayerFormat::kCliBinary;
  // The box may reach a little past the solid: empty layers on top are dropped.
  while (stack.layers > 1 && report.layers.back().contours == 0 && report.layers.back().image_area_mm2 == 0) {
    --stack.layers;
    report.layers.pop_back();
    problems_.pop_back();
    if (cli) out_.contours.pop_back();
    else out_.pngs.pop_back();
  }
  for (auto& layer : problems_)
    for (auto& problem : layer) report.problems.push_back(std::move(problem));
  report.valid = report.problems.empty();
  if (report.format == LayerFormat::kSl1) {
    const Sl1Printer& printer = settings_.printer;
    out_.printer = printer;
    out_.job.name = settings_.name;
    out_.job.layer_mm = report.layer_mm;
    out_.job.layers = stack.layers;
    std::vector<double> areas;
    for (const LayerFigures& f : report.layers) {
      areas.push_back(f.image_area_mm2);
      out_.job.used_ml += f.image_area_mm2 * report.layer_mm / 1000;
    }
    out_.job.print_s = sl1_print_seconds(areas, report.layer_mm, printer, &out_.job.slow_layers);
  }
  return std::move(out_);
}

SlicedLayers slice_volume(const Volume& volume, const LayerSettings& settings, const std::string& what,
                          uint64_t max_memory_bytes, const Box3* planned_box) {
  LayerSlicer slicer(settings, volume.voxel_size_mm(), what, max_memory_bytes);
  const Box3 box = solid_box(volume);
  if (box.empty()) throw InvalidInput(what + " is empty: nothing is left to slice");
  slicer.start(planned_box ? *planned_box : box, box.min.z);
  slicer.sample(volume, std::numeric_limits<double>::infinity());
  return slicer.finish();
}

std::vector<ZipEntry> layer_archive_entries(const SlicedLayers& sliced, std::vector<std::string>& texts,
                                            const std::vector<std::string>* image_files) {
  std::vector<ZipEntry> entries;
  texts.clear();
  texts.reserve(2);  // the entries point into them
  std::vector<std::string> names;
  if (sliced.report.format == LayerFormat::kSl1) {
    texts.push_back(sl1_config_ini(sliced.job, sliced.printer));
    texts.push_back(sl1_prusaslicer_ini(sliced.job, sliced.printer));
    entries = {{"config.ini", texts[0], true}, {"prusaslicer.ini", texts[1], true}};
    for (size_t k = 0; k < sliced.stack.layers; ++k) names.push_back(sl1_layer_name(sliced.job.name, k));
  } else {
    texts.push_back(layer_manifest(sliced.stack));
    entries = {{"manifest.json", texts[0], true}};
    for (size_t k = 0; k < sliced.stack.layers; ++k) names.push_back(layer_file_name(k));
  }
  for (size_t k = 0; k < sliced.stack.layers; ++k)
    entries.push_back({names[k], image_files ? std::string_view() : std::string_view(sliced.pngs[k]), false,
                       image_files ? (*image_files)[k] : std::string()});
  return entries;
}

std::string layers_file(const SlicedLayers& sliced, const std::string& where) {
  switch (sliced.report.format) {
    case LayerFormat::kCli: return cli_file(sliced.stack, sliced.contours, false);
    case LayerFormat::kCliBinary: return cli_file(sliced.stack, sliced.contours, true);
    case LayerFormat::kPngZip:
    case LayerFormat::kSl1: {
      std::vector<std::string> texts;
      return zip_archive(layer_archive_entries(sliced, texts), where);
    }
    case LayerFormat::kPng: break;
  }
  throw InternalError("layers_file: a PNG folder is many files");
}

SliceReport slice_recipe(const std::string& recipe_path, const std::string& output, const SliceOptions& options) {
  layer_format_from_path(output, options.binary);  // a bad output is refused before the recipe is read
  return slice_recipe(load_recipe(recipe_path), output, options);
}

SliceReport slice_recipe(Recipe recipe, const std::string& output, const SliceOptions& options) {
  LayerSettings settings;
  settings.format = layer_format_from_path(output, options.binary);
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
  timer.start("build");
  // A job over several processes: each takes a block of the slabs (split into as many as there are
  // processes, when the part is that many leaves high, if the whole would fit one). They agree on
  // the budget (the least of theirs), so that they cut the same slabs.
  JobRanks* ranks = options.ranks && options.ranks->size() > 1 ? options.ranks : nullptr;
  const int rank_count = ranks ? ranks->size() : 1, me = ranks ? ranks->rank() : 0;
  uint64_t budget = options.run.max_memory_bytes ? options.run.max_memory_bytes : available_memory_bytes() / 2;
  if (ranks) budget = uint64_t(ranks->min(double(budget)));
  Recipe only = recipe_for_object(recipe, settings.name);
  only.outputs.front().layers = RecipeOutput::Layers{};  // cut from the level set: no mesh to reserve memory for
  const std::string what = recipe.file + ": \"" + settings.name + "\"";
  if (options.slab_mm < 0 || !std::isfinite(options.slab_mm))
    throw InvalidInput(what + ": slab_mm: expected a positive height in mm, or 0 to choose one");
  const double h = only.voxel_size_mm, band = h * only.band_voxels, leaf = 8 * h;
  std::optional<BuiltInputs> inputs;
  std::optional<Plan> p;
  std::optional<MemoryEstimator> estimator;
  std::optional<OutputFolder> folder;
  ObjectExtent extent;
  // Slabs of whole leaves (8 voxels) stacked from below the box; each is evaluated with a halo on
  // both sides deep enough that the object there equals the whole run's, and a band and a voxel
  // more for the layers' interpolation and the lowest point's search.
  detail::SlabLayout layout;
  in_every_rank(ranks, [&] {
    inputs.emplace(build_inputs(only, budget));
    p.emplace(plan(only));
    estimator.emplace(only, *p, *inputs);
    extent = estimator->extents().at(settings.name);
    layout = detail::slab_layout(*estimator, extent, h, band, leaf, options.slab_mm, budget, what);
    if (settings.format == LayerFormat::kPng && me == 0) folder.emplace(output);
  });
  const double halo = layout.halo, whole = layout.whole;
  double& slab_height = layout.height;  // 0: the whole part at once
  if (ranks && (slab_height == 0 || slab_height * rank_count > whole))
    slab_height = std::ceil(whole / leaf / rank_count) * leaf;
  if (slab_height >= whole) slab_height = 0;
  // The first slab reaches down and the last up without end (their layers are theirs).
  const std::vector<double> cuts = layout.cuts();
  const std::vector<ZSlab> slabs = layout.slabs();
  const size_t first_slab = slabs.size() * size_t(me) / size_t(rank_count);
  const size_t end_slab = slabs.size() * size_t(me + 1) / size_t(rank_count);
  auto slab_lo = [&](size_t i) { return i == 0 ? -std::numeric_limits<double>::infinity() : cuts[i]; };
  auto slab_hi = [&](size_t i) { return i + 1 == slabs.size() ? std::numeric_limits<double>::infinity() : cuts[i + 1]; };

  LayerSlicer slicer(settings, h, what, budget);
  // Images go to disk as they are made, hidden beside the output, so memory holds a slab and the
  // layers in progress only; they become the output when every layer passed.
  const bool images = settings.format != LayerFormat::kCli && settings.format != LayerFormat::kCliBinary;
  const fs::path spool_dir = fs::path(output).parent_path();
  OutputTransaction spool;
  std::vector<std::string> spooled;
  std::mutex spool_mutex;
  if (images)
    slicer.spool_images([&](size_t k, const std::string& png) {
      std::string path;
      {
        std::lock_guard<std::mutex> lock(spool_mutex);
        if (spooled.size() <= k) spooled.resize(k + 1);
        path = spooled[k] = spool.stage((spool_dir / ("spool-" + fs::path(output).filename().string() + "-" +
                                                      layer_file_name(k))).string());
      }
      write_whole_file(path, png);
      // An archive's entry takes the file's mode: the same as an entry made in memory. (A folder's
      // layers keep the mode the process makes files with.)
      std::error_code error;
      if (settings.format != LayerFormat::kPng) fs::permissions(path, fs::perms(0666), error);
      if (error) throw IoError(output + ": cannot set up a layer's image: " + error.message());
    });
  uint64_t estimate = 0;
  std::map<std::string, Volume> converted_meshes;  // a streamed run's imported meshes, converted once
  std::map<std::string, std::vector<Volume>> mesh_offsets;  // and their offsets, made once
  auto evaluate_slab = [&](size_t i) {
    throw_if_cancelled(sink);
    EvaluateOptions evaluate_options;
    evaluate_options.max_memory_bytes = budget;
    evaluate_options.slab = slab_height > 0 ? &slabs[i] : nullptr;
    evaluate_options.converted_meshes = slab_height > 0 ? &converted_meshes : nullptr;
    evaluate_options.mesh_offsets = slab_height > 0 ? &mesh_offsets : nullptr;
    evaluate_options.estimator = &*estimator;
    timer.start("evaluate");
    Evaluation evaluation = evaluate(only, *p, *inputs, evaluate_options);
    estimate = std::max(estimate, evaluation.memory_estimate_bytes);
    Volume volume = evaluation.take(settings.name);
    timer.start("slice");
    return volume;
  };

  // 1. Up to the first slab holding solid (the ones below are dropped): the solid's lowest point,
  // where no voxel above that slab's band reaches below its top. Over several processes, the lowest
  // of theirs, and the lowest process that found one.
  size_t kept_slab = end_slab;
  Volume kept;
  double lowest = std::numeric_limits<double>::infinity(), first_rank = 0;
  in_every_rank(ranks, [&] {
    for (size_t i = first_slab; i < end_slab; ++i) {
      Volume volume = evaluate_slab(i);
      const Box3 found = solid_box(volume, slab_lo(i), slab_hi(i) + band + h);
      if (!found.empty()) {
        lowest = found.min.z;
        kept_slab = i;
        kept = std::move(volume);
        break;
      }
    }
  });
  if (ranks) {
    first_rank = ranks->min(std::isfinite(lowest) ? double(me) : double(rank_count));
    lowest = ranks->min(lowest);
  }
  if (!std::isfinite(lowest)) throw InvalidInput(what + " is empty: nothing is left to slice");
  slicer.start(extent.box, lowest);

  // 2. Every layer cut from the slab its plane lies in (the first slab holding solid also cuts those
  // below it). A later process whose first slab held no solid goes back over its slabs (one slab in
  // memory at a time: the one it kept is dropped).
  in_every_rank(ranks, [&] {
    // Nothing of the solid below: its layers are the next process's.
    if (first_slab == end_slab || me < int(first_rank)) return;
    if (me > int(first_rank)) {
      slicer.skip_to(slab_lo(first_slab));
      if (kept_slab != first_slab) {
        kept = Volume();
        for (size_t i = first_slab; i < end_slab; ++i) slicer.sample(evaluate_slab(i), slab_hi(i));
        return;
      }
    }
    slicer.sample(kept, slab_hi(kept_slab));
    kept = Volume();
    for (size_t i = kept_slab + 1; i < end_slab; ++i) slicer.sample(evaluate_slab(i), slab_hi(i));
  });
  converted_meshes.clear();
  mesh_offsets.clear();

  // 3. The first process gathers every layer (figures, problems, contours, where the images are).
  if (ranks) {
    std::vector<std::string> gathered;
    in_every_rank(ranks, [&] {
      std::string mine = slicer.pack();
      for (size_t k = 0; k < spooled.size(); ++k)
        if (!spooled[k].empty()) append_text(mine, std::to_string(k) + "\n" + spooled[k]);
      gathered = ranks->gather(mine);
    });
    in_every_rank(ranks, [&] {
      for (size_t r = 1; r < gathered.size(); ++r) {
        for (const std::string& entry : slicer.unpack(gathered[r])) {
          const size_t split = entry.find('\n');
          const size_t k = std::stoul(entry.substr(0, split));
          if (spooled.size() <= k) spooled.resize(k + 1);
          spooled[k] = entry.substr(split + 1);
        }
      }
    });
    if (me != 0) {
      // The first process writes; the images stay until it has.
      SliceReport report;
      report.output = output;
      report.object = settings.name;
      in_every_rank(ranks, [] {});
      report.valid = ranks->max(0) == 0;
      timer.stop();
      report.stage_seconds = detail::stage_totals(timer);
      return report;
    }
  }
  SliceReport report;
  in_every_rank(ranks, [&] {
    SlicedLayers sliced = slicer.finish();
    sliced.report.slabs = slabs.size();
    sliced.report.slab_mm = slab_height;
    sliced.report.halo_mm = slab_height > 0 ? halo : 0;
    sliced.report.memory_estimate_bytes = estimate;
    sliced.report.output = output;
    sliced.report.object = settings.name;
    timer.start("write");
    if (sliced.report.valid) {
      throw_if_cancelled(sink);
      OutputTransaction transaction;
      if (settings.format == LayerFormat::kPng) {
        for (size_t k = 0; k < sliced.stack.layers; ++k) {
          const std::string staged = transaction.stage((fs::path(output) / layer_file_name(k)).string());
          std::error_code error;
          fs::rename(spooled[k], staged, error);
          const uint64_t size = error ? 0 : uint64_t(fs::file_size(staged, error));
          if (error) throw IoError(output + ": cannot move " + layer_file_name(k) + " into place: " + error.message());
          sliced.report.bytes += size;
        }
        const std::string manifest = layer_manifest(sliced.stack);
        write_whole_file(transaction.stage((fs::path(output) / "manifest.json").string()), manifest);
        sliced.report.bytes += manifest.size();
        transaction.commit();
        folder->keep();
      } else if (images) {
        std::vector<std::string> texts;
        const std::string staged = transaction.stage(output);
        write_zip_archive(layer_archive_entries(sliced, texts, &spooled), staged, output);
        std::error_code error;
        sliced.report.bytes = uint64_t(fs::file_size(staged, error));
        if (error) throw IoError(output + ": cannot read the archive's size back: " + error.message());
        transaction.commit();
      } else {
        const std::string bytes = layers_file(sliced, output);
        write_whole_file(transaction.stage(output), bytes);
        sliced.report.bytes = bytes.size();
        transaction.commit();
      }
    }
    report = std::move(sliced.report);
  });
  if (ranks) ranks->max(report.valid ? 0 : 1);
  spool.rollback();
  timer.stop();
  report.stage_seconds = detail::stage_totals(timer);
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
          {"slabs", r.slabs},         {"slab_mm", r.slab_mm},            {"halo_mm", r.halo_mm},
          {"memory_estimate_bytes", r.memory_estimate_bytes},
          {"layers", layers}};
}

}  // namespace lacuna
