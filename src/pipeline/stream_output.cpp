#include "pipeline/stream_output.h"

#include <tbb/global_control.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <unordered_map>
#include <unordered_set>

#include "errors.h"
#include "export/mesh_io.h"
#include "export/output_files.h"
#include "pipeline/build_inputs.h"
#include "pipeline/detail/slabs.h"
#include "pipeline/evaluate.h"
#include "pipeline/mesh_object.h"
#include "pipeline/plan.h"
#include "export/report.h"
#include "pipeline/write_outputs.h"
#include "solids/simplify.h"
#include "util/progress.h"
#include "util/system.h"

namespace lacuna {
namespace {

namespace fs = std::filesystem;

// Triangles [first, first + count) of the file, emitted together, and their z range.
struct Batch {
  uint64_t first = 0, count = 0;
  double z_lo = HUGE_VAL, z_hi = -HUGE_VAL;
};

// The vertices' components as the triangles come: union-find over the stream's vertex numbers.
class VertexSets {
 public:
  explicit VertexSets(uint64_t budget) : budget_(budget) {}
  void join(const std::array<uint64_t, 3>& n, const std::string& what) {
    const uint64_t top = std::max({n[0], n[1], n[2]});
    if (top >= parent_.size()) {
      if (top >= UINT32_MAX || (top + 1) * sizeof(uint32_t) > budget_ / 4)
        throw ResourceLimit(what + ": more vertices than the components of a streamed mesh can be followed for (" +
                            std::to_string(top + 1) + "); use a larger voxel size or a coarser simplification");
      const size_t old = parent_.size();
      parent_.resize(size_t(std::max<uint64_t>(top + 1, 2 * old)));
      for (size_t i = old; i < parent_.size(); ++i) parent_[i] = uint32_t(i);
    }
    unite(uint32_t(n[0]), uint32_t(n[1]));
    unite(uint32_t(n[0]), uint32_t(n[2]));
  }
  uint32_t find(uint32_t a) {
    while (parent_[a] != a) a = parent_[a] = parent_[parent_[a]];
    return a;
  }

 private:
  void unite(uint32_t a, uint32_t b) {
    a = find(a), b = find(b);
    if (a != b) parent_[std::max(a, b)] = std::min(a, b);
  }
  uint64_t budget_;
  std::vector<uint32_t> parent_;
};

// The vertex numbers of every triangle, spooled beside the file (three uint32 per triangle) and
// removed when done.
class NumberSpool {
 public:
  explicit NumberSpool(const std::string& path) : scratch_(path), path_(path) {
    file_ = std::fopen(path_.c_str(), "w+b");
    if (!file_) throw IoError("cannot create '" + path_ + "': " + std::strerror(errno));
  }
  ~NumberSpool() {
    if (file_) std::fclose(file_);
  }
  void put(const std::array<uint64_t, 3>& n) {
    const uint32_t v[3] = {uint32_t(n[0]), uint32_t(n[1]), uint32_t(n[2])};
    if (std::fwrite(v, sizeof v, 1, file_) != 1) throw IoError("cannot write '" + path_ + "': " + std::strerror(errno));
  }
  void rewind() {
    if (std::fflush(file_) != 0 || std::fseek(file_, 0, SEEK_SET) != 0)
      throw IoError("cannot read '" + path_ + "': " + std::strerror(errno));
  }
  std::array<uint32_t, 3> get() {
    std::array<uint32_t, 3> v;
    if (std::fread(v.data(), sizeof v, 1, file_) != 1) throw IoError("cannot read '" + path_ + "': it ended early");
    return v;
  }

 private:
  ScratchFile scratch_;  // removed last, after the file is closed
  std::string path_;
  std::FILE* file_ = nullptr;
};

// Batches grouped into the chunks the check reads, two at a time: a chunk starts where every
// triangle still to come lies above the chunk before the last one (so no triangle meets one two
// chunks away). Returns the first batch of each chunk, then the batch count.
std::vector<size_t> check_chunks(const std::vector<Batch>& batches) {
  const size_t n = batches.size();
  std::vector<double> lowest_after(n + 1, HUGE_VAL);
  for (size_t b = n; b-- > 0;) lowest_after[b] = std::min(lowest_after[b + 1], batches[b].z_lo);
  std::vector<size_t> starts;
  if (n == 0) return {0};
  starts.push_back(0);
  size_t s = 1;
  double top_before = batches[0].z_hi;  // of the chunk before the one being grown
  while (s < n) {
    size_t t = s + 1;
    while (t < n && !(lowest_after[t] > top_before)) ++t;
    starts.push_back(s);
    top_before = -HUGE_VAL;
    for (size_t b = s; b < t; ++b) top_before = std::max(top_before, batches[b].z_hi);
    s = t;
  }
  starts.push_back(n);
  return starts;
}

StreamedOutput stream_output(const Recipe& recipe, const RecipeOutput& out, const std::string& final_path,
                             OutputTransaction& transaction, double slab_mm, uint64_t budget, StageTimer& timer) {
  ProgressSink* sink = current_progress_sink();
  Recipe only = recipe_for_object(recipe, out.object);
  only.outputs.front().simplify_mm = out.simplify_mm;
  const std::string what = recipe.file + ": \"" + out.object + "\"";
  StreamedOutput result;
  result.object = out.object;
  result.file = final_path;
  result.simplify_mm = simplify_deviation_mm(only, only.outputs.front());
  if (!(result.simplify_mm > 0))
    throw InvalidInput(recipe.file + ": " + out.json_path + ": a streamed mesh is simplified as it is made: " +
                       "simplify_mm must be positive (or run without --stream)");
  const double h = only.voxel_size_mm, band = h * only.band_voxels, unit = StreamedSurface::kSlabVoxels * h;

  timer.start("build");
  const BuiltInputs inputs = build_inputs(only, budget);
  const Plan p = plan(only);
  const MemoryEstimator estimator(only, p, inputs);
  const ObjectExtent extent = estimator.extents().at(out.object);
  detail::SlabLayout layout = detail::slab_layout(estimator, extent, h, band, unit, slab_mm, budget, what);
  if (layout.height >= layout.whole) layout.height = 0;
  const std::vector<double> cuts = layout.cuts();
  const std::vector<ZSlab> slabs = layout.slabs();
  result.slabs = slabs.size();
  result.slab_mm = layout.height;
  result.halo_mm = layout.height > 0 ? layout.halo : 0;

  // The file, the vertex numbers beside it, the components as they come.
  const std::string temp = transaction.stage(final_path);
  const std::string header = "Lacuna " LACUNA_VERSION " " + recipe.name + " " + out.part_name;
  std::optional<StlWriter> writer(std::in_place, temp, header);
  NumberSpool numbers(temp + ".numbers");
  VertexSets sets(budget);
  std::vector<Batch> batches;
  SimplifyOptions simplify;
  simplify.max_deviation_mm = result.simplify_mm;
  StreamedSurface surface(simplify, h, [&](const EmittedTriangles& emitted) {
    Batch batch;
    batch.first = writer->triangles();
    batch.count = emitted.corners.size();
    for (size_t t = 0; t < emitted.corners.size(); ++t) {
      writer->add(emitted.corners[t]);
      numbers.put(emitted.numbers[t]);
      sets.join(emitted.numbers[t], what);
      for (const Vec3d& c : emitted.corners[t]) {
        batch.z_lo = std::min(batch.z_lo, c.z);
        batch.z_hi = std::max(batch.z_hi, c.z);
      }
    }
    batches.push_back(batch);
  });
  std::map<std::string, Volume> converted_meshes;  // a streamed run's imported meshes, converted once
  for (size_t i = 0; i < slabs.size(); ++i) {
    throw_if_cancelled(sink);
    EvaluateOptions evaluate_options;
    evaluate_options.max_memory_bytes = budget;
    evaluate_options.slab = layout.height > 0 ? &slabs[i] : nullptr;
    evaluate_options.converted_meshes = layout.height > 0 ? &converted_meshes : nullptr;
    evaluate_options.estimator = &estimator;
    timer.start("evaluate");
    Evaluation evaluation = evaluate(only, p, inputs, evaluate_options);
    result.memory_estimate_bytes = std::max(result.memory_estimate_bytes, evaluation.memory_estimate_bytes);
    const Volume volume = evaluation.take(out.object);
    timer.start("mesh");
    auto voxel_index = [&](double mm) {
      const int64_t k = std::llround(mm / h);
      if (k % StreamedSurface::kSlabVoxels != 0) throw InternalError(what + ": a slab cut off the surface's blocks");
      return k;
    };
    const int64_t z0 = i == 0 ? -StreamedSurface::kUnbounded : voxel_index(cuts[i]);
    const int64_t z1 = i + 1 == slabs.size() ? StreamedSurface::kUnbounded : voxel_index(cuts[i + 1]);
    surface.add(volume, z0, z1);
  }
  converted_meshes.clear();
  surface.finish();
  result.extracted_triangles = surface.stats().input_triangles;
  const uint64_t written = writer->triangles();
  writer->finish();
  writer.reset();
  if (written == 0) throw InvalidInput(what + " is empty: nothing is left to mesh");

  // Shells enclosing less than a voxel, as a whole run removes them (solids/components.h,
  // remove_small_shells): each shell's volume from its first triangle's first corner.
  timer.start("shells");
  numbers.rewind();
  struct Shell {
    Vec3d anchor;
    double volume6 = 0;
  };
  std::unordered_map<uint32_t, Shell> shells;
  for (const Batch& b : batches) {
    const std::vector<std::array<Vec3d, 3>> corners = read_stl_triangles(temp, b.first, b.count);
    for (const auto& c : corners) {
      const uint32_t root = sets.find(numbers.get()[0]);
      auto [it, inserted] = shells.try_emplace(root);
      if (inserted) it->second.anchor = c[0];
      const Vec3d& o = it->second.anchor;
      it->second.volume6 += dot(c[0] - o, cross(c[1] - o, c[2] - o));
    }
  }
  const double smallest = h * h * h;
  std::unordered_set<uint32_t> dropped;
  for (const auto& [root, shell] : shells) {
    const double v = shell.volume6 / 6;
    if (v < 0 && -v < smallest) {
      dropped.insert(root);
      ++result.cavities_filled;
    } else if (v >= 0 && v < smallest) {
      dropped.insert(root);
      ++result.specks_removed;
    }
  }
  if (!dropped.empty()) {
    const ScratchFile kept_file(temp + ".kept");
    const std::string& kept_path = kept_file.path();
    numbers.rewind();
    {
      StlWriter kept(kept_path, header);
      for (Batch& b : batches) {
        const std::vector<std::array<Vec3d, 3>> corners = read_stl_triangles(temp, b.first, b.count);
        b.first = kept.triangles();
        for (const auto& c : corners)
          if (!dropped.count(sets.find(numbers.get()[0]))) kept.add(c);
        b.count = kept.triangles() - b.first;
      }
      kept.finish();
    }
    std::error_code error;
    fs::rename(kept_path, temp, error);
    if (error) throw IoError(final_path + ": cannot replace the streamed file: " + error.message());
    batches.erase(std::remove_if(batches.begin(), batches.end(), [](const Batch& b) { return b.count == 0; }),
                  batches.end());
    if (batches.empty()) throw InvalidInput(what + " is empty: nothing is left to mesh");
  }

  // The file as written, chunk by chunk.
  timer.start("check");
  const std::vector<size_t> starts = check_chunks(batches);
  result.check_chunks = starts.size() - 1;
  ChunkedCheck check;
  Progress progress("check", result.check_chunks);
  for (size_t c = 0; c + 1 < starts.size(); ++c) {
    throw_if_cancelled(sink);
    const uint64_t first = batches[starts[c]].first;
    const uint64_t end = starts[c + 1] < batches.size() ? batches[starts[c + 1]].first
                                                        : batches.back().first + batches.back().count;
    check.add(read_stl_triangles(temp, first, end - first), c + 2 == starts.size());
    progress.advance();
  }
  result.check = check.finish();
  result.triangles = result.check.triangles;
  std::error_code error;
  result.bytes = uint64_t(fs::file_size(temp, error));
  timer.stop();
  return result;
}

// Throws InvalidInput for options no streamed run can use (before a recipe is read).
void check_stream_options(const StreamOptions& options) {
  check_run_options(options.run);
  if (!(options.slab_mm >= 0) || !std::isfinite(options.slab_mm))
    throw InvalidInput("slab height: expected a positive height in mm, or 0 to choose one, got " +
                       message_number(options.slab_mm));
}

// stream_recipe with the options checked.
StreamReport stream_checked(Recipe recipe, const StreamOptions& options) {
  const RunOptions& run = options.run;
  apply_run_options(recipe, run);
  std::optional<tbb::global_control> threads;
  if (run.threads > 0) threads.emplace(tbb::global_control::max_allowed_parallelism, size_t(run.threads));
  ProgressSinkScope progress(run.progress ? run.progress : current_progress_sink());
  if (recipe.printability.enabled)
    throw InvalidInput(recipe.file + ": printability: a streamed run does not analyse printability (that needs "
                       "the whole part); run without --stream");
  for (const RecipeOutput& out : recipe.outputs)
    if (out.format != "stl" || !out.group.empty() || out.render || out.layers || !out.fea.regions.empty())
      throw InvalidInput(recipe.file + ": " + out.json_path + " (" + out.file +
                         "): a streamed run writes STL meshes of one object, without a render; run without --stream");
  const uint64_t budget = run.max_memory_bytes ? run.max_memory_bytes : available_memory_bytes() / 2;
  WriteOptions write_options;
  write_options.output_dir = run.output_dir;
  const std::unique_ptr<OutputFolder> folder = hold_output_folder(recipe, write_options);
  const fs::path out_dir = output_folder(recipe, write_options);

  StreamReport report;
  report.recipe = recipe.file;
  report.output_dir = out_dir.string();
  report.voxel_size_mm = recipe.voxel_size_mm;
  OutputTransaction transaction;
  StageTimer timer;
  for (const RecipeOutput& out : recipe.outputs)
    report.outputs.push_back(
        stream_output(recipe, out, (out_dir / out.file).string(), transaction, options.slab_mm, budget, timer));
  report.stage_seconds = detail::stage_totals(timer);
  report.valid = std::all_of(report.outputs.begin(), report.outputs.end(),
                             [](const StreamedOutput& o) { return o.check.valid(); });
  if (!report.valid) return report;  // the transaction removes every file
  if (run.write_report) write_whole_file(transaction.stage((out_dir / "report.json").string()), to_json(report).dump(2) + "\n");
  transaction.commit();
  folder->keep();
  return report;
}

}  // namespace

StreamReport stream_recipe(const std::string& recipe_path, const StreamOptions& options) {
  check_stream_options(options);
  return stream_checked(load_recipe(recipe_path), options);
}

StreamReport stream_recipe(Recipe recipe, const StreamOptions& options) {
  check_stream_options(options);
  return stream_checked(std::move(recipe), options);
}

nlohmann::json to_json(const StreamReport& report) {
  nlohmann::json outputs = nlohmann::json::array();
  for (const StreamedOutput& o : report.outputs) {
    // The check's figures at the top, its verdicts under "checks", as a run's report has them.
    nlohmann::json entry = check_report_json(o.check);
    entry["file"] = o.file;
    entry["object"] = o.object;
    entry["format"] = "stl";
    entry["extracted_triangles"] = o.extracted_triangles;
    entry["simplify_mm"] = o.simplify_mm;
    entry["specks_removed"] = o.specks_removed;
    entry["cavities_filled"] = o.cavities_filled;
    entry["slabs"] = o.slabs;
    entry["slab_mm"] = o.slab_mm;
    entry["halo_mm"] = o.halo_mm;
    entry["memory_estimate_bytes"] = o.memory_estimate_bytes;
    entry["bytes"] = o.bytes;
    entry["check_chunks"] = o.check_chunks;
    outputs.push_back(std::move(entry));
  }
  nlohmann::json stages = nlohmann::json::object();
  for (const auto& [name, seconds] : report.stage_seconds) stages[name] = seconds;
  return {{"lacuna_version", LACUNA_VERSION}, {"recipe", report.recipe},   {"output_dir", report.output_dir},
          {"streamed", true},                {"voxel_size_mm", report.voxel_size_mm}, {"valid", report.valid},
          {"outputs", outputs},              {"stage_seconds", stages}};
}

}  // namespace lacuna
