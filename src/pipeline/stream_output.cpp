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
#include "pipeline/ranks.h"
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
    grow(std::max({n[0], n[1], n[2]}), what);
    unite(uint32_t(n[0]), uint32_t(n[1]));
    unite(uint32_t(n[0]), uint32_t(n[2]));
  }
  void join_pair(uint64_t a, uint64_t b, const std::string& what) {
    grow(std::max(a, b), what);
    unite(uint32_t(a), uint32_t(b));
  }
  uint32_t find(uint32_t a) {
    while (parent_[a] != a) a = parent_[a] = parent_[parent_[a]];
    return a;
  }

 private:
  void grow(uint64_t top, const std::string& what) {
    if (top >= parent_.size()) {
      if (top >= UINT32_MAX || (top + 1) * sizeof(uint32_t) > budget_ / 4)
        throw ResourceLimit(what + ": more vertices than the components of a streamed mesh can be followed for (" +
                            std::to_string(top + 1) + "); use a larger voxel size or a coarser simplification");
      const size_t old = parent_.size();
      parent_.resize(size_t(std::max<uint64_t>(top + 1, 2 * old)));
      for (size_t i = old; i < parent_.size(); ++i) parent_[i] = uint32_t(i);
    }
  }
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

// What one process of a job streamed of an output (all of it when alone): its batches in its part
// of the file, how many vertex numbers it gave, and the window's vertices after its lead-in and
// after its last slab (to join the components across the parts).
struct Part {
  uint64_t numbers = 0, extracted = 0, estimate = 0;
  bool streamed = false;  // it had slabs of its own
  std::vector<Batch> batches;
  std::vector<StreamedSurface::WindowVertex> lead, tail;
};

template <typename T>
void pack_values(std::string& out, const std::vector<T>& values) {
  const uint64_t n = values.size();
  out.append(reinterpret_cast<const char*>(&n), sizeof n);
  out.append(reinterpret_cast<const char*>(values.data()), n * sizeof(T));
}

template <typename T>
std::vector<T> unpack_values(const std::string& in, size_t& at) {
  uint64_t n = 0;
  if (in.size() - at < sizeof n) throw InternalError("a process's streamed part came garbled");
  std::memcpy(&n, in.data() + at, sizeof n);
  at += sizeof n;
  if ((in.size() - at) / sizeof(T) < n) throw InternalError("a process's streamed part came garbled");
  std::vector<T> values(static_cast<size_t>(n));
  std::memcpy(values.data(), in.data() + at, size_t(n) * sizeof(T));
  at += size_t(n) * sizeof(T);
  return values;
}

std::string pack_part(const Part& part) {
  std::string out;
  pack_values(out, std::vector<uint64_t>{part.numbers, part.extracted, part.estimate, part.streamed ? 1u : 0u});
  pack_values(out, part.batches);
  pack_values(out, part.lead);
  pack_values(out, part.tail);
  return out;
}

Part unpack_part(const std::string& in) {
  Part part;
  size_t at = 0;
  const std::vector<uint64_t> figures = unpack_values<uint64_t>(in, at);
  if (figures.size() != 4) throw InternalError("a process's streamed part came garbled");
  part.numbers = figures[0], part.extracted = figures[1], part.estimate = figures[2], part.streamed = figures[3] != 0;
  part.batches = unpack_values<Batch>(in, at);
  part.lead = unpack_values<StreamedSurface::WindowVertex>(in, at);
  part.tail = unpack_values<StreamedSurface::WindowVertex>(in, at);
  return part;
}

// Where process `rank` (> 0) of a job streams its part of `final_path`, beside it.
std::string part_path(const std::string& final_path, int rank) {
  const fs::path path(final_path);
  return (path.parent_path() / ("." + path.filename().string() + ".rank" + std::to_string(rank))).string();
}

// The slabs of a job over `count` processes, each a block of them: cuts on whole units (blocks of
// 32 voxels) from the layout's bottom, each process's blocks as equal in work as they can be (a later
// process also meshes the three blocks below its first cut again, its lead-in), each block cut into
// slabs no higher than the layout's (when it has any).
struct JobSlabs {
  std::vector<double> cuts;  // slab i: [cuts[i], cuts[i + 1])
  std::vector<size_t> first; // process r's slabs: [first[r], first[r + 1])
  double tallest = 0;
};

JobSlabs job_slabs(const detail::SlabLayout& layout, double unit, int count) {
  constexpr int64_t kLeadIn = 3;
  const int64_t units = std::max<int64_t>(1, std::llround(layout.whole / unit));
  const int64_t most = layout.height > 0 ? std::max<int64_t>(1, std::llround(layout.height / unit)) : units;
  // Process 0 meshes b units, each later one b - 3 and its lead-in: b = (units + 3 (count - 1)) / count.
  const double share = double(units + kLeadIn * (count - 1)) / count;
  std::vector<int64_t> bounds{0};
  for (int r = 1; r < count; ++r) {
    const int64_t next = std::llround(share + double(r - 1) * (share - kLeadIn));
    bounds.push_back(std::min(std::max(next, bounds.back() + 1), units));
  }
  bounds.push_back(units);
  JobSlabs job;
  std::vector<int64_t> at{0};  // the cuts, in units
  for (int r = 0; r < count; ++r) {
    job.first.push_back(at.size() - 1);
    const int64_t lo = bounds[size_t(r)], hi = std::max(lo, bounds[size_t(r) + 1]), pieces = (hi - lo + most - 1) / most;
    for (int64_t j = 1; j <= pieces; ++j) at.push_back(lo + (hi - lo) * j / pieces);
  }
  job.first.push_back(at.size() - 1);
  for (size_t i = 0; i < at.size(); ++i) {
    job.cuts.push_back(layout.bottom + double(at[i]) * unit);  // each computed, as the layout's are
    if (i > 0) job.tallest = std::max(job.tallest, double(at[i] - at[i - 1]) * unit);
  }
  return job;
}

StreamedOutput stream_output(const Recipe& recipe, const RecipeOutput& out, const std::string& final_path,
                             OutputTransaction& transaction, double slab_mm, uint64_t budget, StageTimer& timer,
                             JobRanks* ranks) {
  ProgressSink* sink = current_progress_sink();
  const int rank_count = ranks ? ranks->size() : 1, me = ranks ? ranks->rank() : 0;
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

  // Every process plans the same slabs; the first stages the file.
  timer.start("build");
  std::optional<BuiltInputs> inputs;
  std::optional<Plan> p;
  std::optional<MemoryEstimator> estimator;
  detail::SlabLayout layout;
  std::string temp;
  in_every_rank(ranks, [&] {
    inputs.emplace(build_inputs(only, budget));
    p.emplace(plan(only));
    estimator.emplace(only, *p, *inputs);
    const ObjectExtent extent = estimator->extents().at(out.object);
    layout = detail::slab_layout(*estimator, extent, h, band, unit, slab_mm, budget, what);
    if (me == 0) temp = transaction.stage(final_path);
  });
  if (layout.height >= layout.whole) layout.height = 0;
  std::vector<double> cuts = layout.cuts();
  std::vector<ZSlab> slabs = layout.slabs();
  size_t first_slab = 0, end_slab = slabs.size();
  if (ranks) {
    const JobSlabs job = job_slabs(layout, unit, rank_count);
    cuts = job.cuts;
    slabs.clear();
    for (size_t i = 0; i + 1 < cuts.size(); ++i) slabs.push_back({cuts[i] - layout.halo, cuts[i + 1] + layout.halo});
    first_slab = job.first[size_t(me)];
    end_slab = job.first[size_t(me) + 1];
    layout.height = slabs.size() > 1 ? job.tallest : 0;
  }
  result.slabs = slabs.size();
  result.slab_mm = layout.height;
  result.halo_mm = layout.height > 0 ? layout.halo : 0;
  auto voxel_index = [&](double mm) {
    const int64_t k = std::llround(mm / h);
    if (k % StreamedSurface::kSlabVoxels != 0) throw InternalError(what + ": a slab cut off the surface's blocks");
    return k;
  };
  auto slab_z0 = [&](size_t i) { return i == 0 ? -StreamedSurface::kUnbounded : voxel_index(cuts[i]); };
  auto slab_z1 = [&](size_t i) { return i + 1 == slabs.size() ? StreamedSurface::kUnbounded : voxel_index(cuts[i + 1]); };

  // The file (the first process's part of it), the vertex numbers beside it, the components as they
  // come. Another process streams its part beside the output and keeps it until the first has
  // taken it.
  const std::string header = "Lacuna " LACUNA_VERSION " " + recipe.name + " " + out.part_name;
  const std::string mine = me == 0 ? temp : part_path(final_path, me);
  std::optional<ScratchFile> mine_scratch;
  std::optional<StlWriter> writer;
  std::optional<NumberSpool> numbers;
  VertexSets sets(budget);
  Part part;
  in_every_rank(ranks, [&] {
    if (me != 0) mine_scratch.emplace(mine);
    writer.emplace(mine, header);
    numbers.emplace(mine + ".numbers");
    if (first_slab == end_slab) return;
    part.streamed = true;
    SimplifyOptions simplify;
    simplify.max_deviation_mm = result.simplify_mm;
    StreamedSurface surface(simplify, h, [&](const EmittedTriangles& emitted) {
      Batch batch;
      batch.first = writer->triangles();
      batch.count = emitted.corners.size();
      for (size_t t = 0; t < emitted.corners.size(); ++t) {
        writer->add(emitted.corners[t]);
        numbers->put(emitted.numbers[t]);
        if (me == 0) sets.join(emitted.numbers[t], what);
        for (const Vec3d& c : emitted.corners[t]) {
          batch.z_lo = std::min(batch.z_lo, c.z);
          batch.z_hi = std::max(batch.z_hi, c.z);
        }
      }
      part.batches.push_back(batch);
    });
    std::map<std::string, Volume> converted_meshes;  // a streamed run's imported meshes, converted once
    std::map<std::string, std::vector<Volume>> mesh_offsets;  // and their offsets, made once
    auto evaluate_slab = [&](const ZSlab* slab) {
      throw_if_cancelled(sink);
      EvaluateOptions evaluate_options;
      evaluate_options.max_memory_bytes = budget;
      evaluate_options.slab = slab;
      evaluate_options.converted_meshes = slab ? &converted_meshes : nullptr;
      evaluate_options.mesh_offsets = slab ? &mesh_offsets : nullptr;
      evaluate_options.estimator = &*estimator;
      timer.start("evaluate");
      Evaluation evaluation = evaluate(only, *p, *inputs, evaluate_options);
      part.estimate = std::max(part.estimate, evaluation.memory_estimate_bytes);
      Volume volume = evaluation.take(out.object);
      timer.start("mesh");
      return volume;
    };
    // A later process's lead-in: the three blocks below its first cut (whose regions the process
    // before it runs), evaluated as one more slab with the same halo.
    uint64_t lead_extracted = 0;
    if (first_slab > 0) {
      const double cut = cuts[first_slab], lead_lo = std::max(cuts[0], cut - 3 * unit);
      surface.begin_after(voxel_index(cut));
      const ZSlab lead{lead_lo - layout.halo, cut + layout.halo};
      surface.add(evaluate_slab(&lead), lead_lo <= cuts[0] ? -StreamedSurface::kUnbounded : voxel_index(lead_lo),
                  voxel_index(cut));
      part.lead = surface.window_vertices();
      lead_extracted = surface.stats().input_triangles;
    }
    for (size_t i = first_slab; i < end_slab; ++i)
      surface.add(evaluate_slab(layout.height > 0 ? &slabs[i] : nullptr), slab_z0(i), slab_z1(i));
    if (end_slab == slabs.size())
      surface.finish();
    else
      part.tail = surface.window_vertices();
    part.extracted = surface.stats().input_triangles - lead_extracted;
    part.numbers = surface.numbers_given();
    if (me != 0) {
      writer->finish();
      numbers->rewind();  // flushed for the first process to read
    }
  });

  // The first process appends the others' parts to its own, in order, their vertex numbers after
  // its own, and joins the components a vertex two parts both have (the same vertex, known by its
  // identity in the whole surface).
  std::vector<Batch>& batches = part.batches;
  if (ranks) {
    std::vector<std::string> gathered;
    in_every_rank(ranks, [&] { gathered = ranks->gather(pack_part(part)); });
    in_every_rank(ranks, [&] {
      if (me != 0) return;
      timer.start("gather");
      std::vector<Part> parts;
      for (const std::string& bytes : gathered) parts.push_back(unpack_part(bytes));
      parts[0] = std::move(part);
      std::vector<uint64_t> offset(parts.size(), 0);
      for (size_t r = 1; r < parts.size(); ++r) {
        offset[r] = offset[r - 1] + parts[r - 1].numbers;
        if (parts[r].batches.empty()) continue;
        const std::string path = part_path(final_path, int(r));
        std::FILE* spooled = std::fopen((path + ".numbers").c_str(), "rb");
        if (!spooled) throw IoError("cannot read '" + path + ".numbers': " + std::strerror(errno));
        std::unique_ptr<std::FILE, int (*)(std::FILE*)> closer(spooled, std::fclose);
        for (Batch b : parts[r].batches) {
          const std::vector<std::array<Vec3d, 3>> corners = read_stl_triangles(path, b.first, b.count);
          b.first = writer->triangles();
          for (const auto& c : corners) {
            uint32_t v[3];
            if (std::fread(v, sizeof v, 1, spooled) != 1) throw IoError("cannot read '" + path + ".numbers': it ended early");
            const std::array<uint64_t, 3> n = {offset[r] + v[0], offset[r] + v[1], offset[r] + v[2]};
            writer->add(c);
            numbers->put(n);
            sets.join(n, what);
          }
          parts[0].batches.push_back(b);
        }
      }
      std::optional<size_t> before;  // the last process so far that streamed slabs
      for (size_t r = 0; r < parts.size(); ++r) {
        if (!parts[r].streamed) continue;
        if (before) {
          const auto hash = [](const std::array<uint64_t, 2>& id) { return id[0] * 0x9E3779B97F4A7C15ull ^ id[1]; };
          std::unordered_map<std::array<uint64_t, 2>, uint64_t, decltype(hash)> earlier(16, hash);
          for (const auto& v : parts[*before].tail) earlier.emplace(v.identity, offset[*before] + v.number);
          for (const auto& v : parts[r].lead) {
            const auto it = earlier.find(v.identity);
            if (it != earlier.end()) sets.join_pair(it->second, offset[r] + v.number, what);
          }
        }
        before = r;
      }
      for (const Part& q : parts) {
        result.extracted_triangles += q.extracted;
        result.memory_estimate_bytes = std::max(result.memory_estimate_bytes, q.estimate);
      }
      part.batches = std::move(parts[0].batches);
    });
    if (me != 0) {
      in_every_rank(ranks, [] {});  // the first shells and checks the file
      timer.stop();
      return result;
    }
  } else {
    result.extracted_triangles = part.extracted;
    result.memory_estimate_bytes = part.estimate;
  }

  in_every_rank(ranks, [&] {
    const uint64_t written = writer->triangles();
    writer->finish();
    writer.reset();
    if (written == 0) throw InvalidInput(what + " is empty: nothing is left to mesh");

    // Shells enclosing less than a voxel, as a whole run removes them (solids/components.h,
    // remove_small_shells): each shell's volume from its first triangle's first corner.
    timer.start("shells");
    numbers->rewind();
    struct Shell {
      Vec3d anchor;
      double volume6 = 0;
    };
    std::unordered_map<uint32_t, Shell> shells;
    for (const Batch& b : batches) {
      const std::vector<std::array<Vec3d, 3>> corners = read_stl_triangles(temp, b.first, b.count);
      for (const auto& c : corners) {
        const uint32_t root = sets.find(numbers->get()[0]);
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
      numbers->rewind();
      {
        StlWriter kept(kept_path, header);
        for (Batch& b : batches) {
          const std::vector<std::array<Vec3d, 3>> corners = read_stl_triangles(temp, b.first, b.count);
          b.first = kept.triangles();
          for (const auto& c : corners)
            if (!dropped.count(sets.find(numbers->get()[0]))) kept.add(c);
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
  });
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
  // A job over several processes: they agree on the budget (the least of theirs) so that they cut
  // the same slabs; the first holds the folder and writes.
  JobRanks* ranks = options.ranks && options.ranks->size() > 1 ? options.ranks : nullptr;
  const int me = ranks ? ranks->rank() : 0;
  uint64_t budget = run.max_memory_bytes ? run.max_memory_bytes : available_memory_bytes() / 2;
  if (ranks) budget = uint64_t(ranks->min(double(budget)));
  WriteOptions write_options;
  write_options.output_dir = run.output_dir;
  std::unique_ptr<OutputFolder> folder;
  in_every_rank(ranks, [&] {
    if (me == 0) folder = hold_output_folder(recipe, write_options);
  });
  const fs::path out_dir = output_folder(recipe, write_options);

  StreamReport report;
  report.recipe = recipe.file;
  report.output_dir = out_dir.string();
  report.voxel_size_mm = recipe.voxel_size_mm;
  OutputTransaction transaction;
  StageTimer timer;
  for (const RecipeOutput& out : recipe.outputs)
    report.outputs.push_back(stream_output(recipe, out, (out_dir / out.file).string(), transaction, options.slab_mm,
                                           budget, timer, ranks));
  report.stage_seconds = detail::stage_totals(timer);
  // The first process checked every file; the others agree with its verdict below.
  report.valid = me != 0 || std::all_of(report.outputs.begin(), report.outputs.end(),
                                        [](const StreamedOutput& o) { return o.check.valid(); });
  in_every_rank(ranks, [&] {
    if (me != 0 || !report.valid) return;  // the transaction removes every file
    if (run.write_report) write_whole_file(transaction.stage((out_dir / "report.json").string()), to_json(report).dump(2) + "\n");
    transaction.commit();
    folder->keep();
  });
  if (ranks) report.valid = ranks->max(report.valid ? 0 : 1) == 0;
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
