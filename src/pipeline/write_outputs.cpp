#include "pipeline/write_outputs.h"

#include <tbb/global_control.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>

#include "errors.h"
#include "export/fea.h"
#include "export/mesh_io.h"
#include "export/output_files.h"
#include "export/draco.h"
#include "export/report_page.h"
#include "pipeline/detail/memory.h"
#include "pipeline/draco_output.h"
#include "pipeline/fea_output.h"
#include "pipeline/input_figures.h"
#include "pipeline/mesh_object.h"
#include "pipeline/render_output.h"
#include "pipeline/slice_output.h"
#include "solids/check.h"
#include "solids/components.h"
#include "solids/printability.h"
#include "util/system.h"

namespace lacuna {
namespace {

namespace fs = std::filesystem;

// Material region of every tetrahedron: the first region solid its centroid lies in, else the
// nearest one (tetrahedra straddling an interface go to the side holding their centroid).
void assign_regions(TetMesh& mesh, const std::vector<Volume>& regions) {
  mesh.regions.assign(mesh.tets.size(), 0);
  tbb::parallel_for(size_t(0), mesh.tets.size(), [&](size_t t) {
    const auto& tet = mesh.tets[t];
    Vec3d c = (mesh.nodes_mm[tet[0]] + mesh.nodes_mm[tet[1]] + mesh.nodes_mm[tet[2]] + mesh.nodes_mm[tet[3]]) * 0.25;
    double best = HUGE_VAL;
    for (size_t r = 0; r < regions.size(); ++r) {
      double d = regions[r].distance_at(c);
      if (d < 0) {
        mesh.regions[t] = int(r);
        return;
      }
      if (d < best) {
        best = d;
        mesh.regions[t] = int(r);
      }
    }
  });
}

// Printability of an object before it is meshed; with "fix", thin walls are thickened and drain
// holes drilled from its trapped voids (the object changes), and it is analysed again.
PrintabilityFindings check_printability(Volume& volume, const PrintabilitySettings& settings) {
  PrintabilityOptions options;
  options.min_wall_mm = settings.min_wall_mm;
  options.min_hole_mm = settings.min_hole_mm;
  options.build_direction = settings.build_direction;
  options.critical_angle_deg = settings.critical_angle_deg;
  PrintabilityReport report = analyze_printability(volume, options);
  size_t drilled = 0, thickened = 0;
  if (settings.on_failure == PrintabilitySettings::OnFailure::kFix && !report.ok()) {
    // Thin walls first (growing them can seal nothing new), then drain holes.
    if (!report.thin_walls.empty()) {
      thickened = report.thin_walls.size();
      volume = thicken_thin_walls(volume, report, settings.min_wall_mm);
      report = analyze_printability(volume, options);
    }
    if (!report.trapped_voids.empty()) {
      drilled = report.trapped_voids.size();
      volume = drill_drain_holes(volume, report.trapped_voids, settings.drain_hole_mm, options, settings.drain_down);
      report = analyze_printability(volume, options);
    }
  }
  PrintabilityFindings f;
  f.trapped_voids = report.trapped_voids;
  f.thin_walls = report.thin_walls;
  f.small_holes = report.small_holes;
  f.overhang_area_mm2 = report.overhang_area_mm2;
  f.down_facing_area_mm2 = report.down_facing_area_mm2;
  f.drain_holes = drilled;
  f.thickened_walls = thickened;
  if (settings.on_failure != PrintabilitySettings::OnFailure::kReport) {
    if (!report.trapped_voids.empty())
      f.problems.push_back(std::to_string(report.trapped_voids.size()) + " trapped voids (powder or resin cannot drain)");
    if (!report.thin_walls.empty())
      f.problems.push_back(std::to_string(report.thin_walls.size()) + " walls thinner than " +
                           detail::fixed(settings.min_wall_mm, 4) + " mm");
    if (!report.small_holes.empty())
      f.problems.push_back(std::to_string(report.small_holes.size()) + " holes narrower than " +
                           detail::fixed(settings.min_hole_mm, 4) + " mm");
  }
  return f;
}

ThreeMfInfo package_info(const Recipe& recipe) {
  ThreeMfInfo info;
  info.metadata = {{"Application", "Lacuna " LACUNA_VERSION}, {"Title", recipe.name}};
  if (!recipe.description.empty()) info.metadata.push_back({"Description", recipe.description});
  return info;
}

// Throws an error of the same kind as `e` with another message.
[[noreturn]] void rethrow_with_message(const Error& e, const std::string& message) {
  if (dynamic_cast<const InvalidInput*>(&e)) throw InvalidInput(message);
  if (dynamic_cast<const IoError*>(&e)) throw IoError(message);
  if (dynamic_cast<const ResourceLimit*>(&e)) throw ResourceLimit(message);
  if (dynamic_cast<const CheckFailed*>(&e)) throw CheckFailed(message);
  if (dynamic_cast<const Cancelled*>(&e)) throw Cancelled(message);
  if (dynamic_cast<const InternalError*>(&e)) throw InternalError(message);
  throw Error(message);
}

// The object's surface on report.html: as Draco at the grid the .drc outputs get by default (no
// vertex moves more than a tenth of a voxel), with its printability findings as markers; objects
// too large for a page are listed without a view.
void add_page_mesh(ReportPage& page, const Recipe& recipe, const std::string& object, const TriMesh& mesh,
                   const std::optional<PrintabilityFindings>& printability, double voxel_size_mm) {
  PageMesh m;
  m.object = object;
  for (const RecipeOutput& out : recipe.outputs)
    if (!out.layers && (out.object == object || std::find(out.group.begin(), out.group.end(), object) != out.group.end()))
      m.outputs.push_back(out.file);
  if (mesh.triangles.size() > kPageMaxTriangles) {
    page.skipped.push_back({object, std::to_string(mesh.triangles.size()) + " triangles, more than a page shows (" +
                                        std::to_string(kPageMaxTriangles) + "); open its files instead"});
    return;
  }
  int bits = draco_quantization_bits(mesh, voxel_size_mm / 10);
  // Speed 5: measured on a 2.1 M-triangle part, 0.86 s against 1.59 s at the best compression
  // (speed 0), for a page 12 % larger.
  m.draco = encode_draco(mesh, bits > 0 ? bits : kMaxDracoBits, 5);
  if (printability) {
    for (const auto& [kind, features] : {std::pair{"trapped_voids", &printability->trapped_voids},
                                         std::pair{"thin_walls", &printability->thin_walls},
                                         std::pair{"small_holes", &printability->small_holes}})
      for (const PrintFeature& f : *features) m.markers.push_back({kind, f.location_mm});
  }
  page.meshes.push_back(std::move(m));
}

}  // namespace

std::string output_folder(const Recipe& recipe, const WriteOptions& options) {
  return options.output_dir.empty() ? recipe.name + "-out" : options.output_dir;
}

std::unique_ptr<OutputFolder> hold_output_folder(const Recipe& recipe, const WriteOptions& options) {
  return std::make_unique<OutputFolder>(output_folder(recipe, options));
}

void check_output_folder(const Recipe& recipe, const WriteOptions& options) {
  const fs::path out_dir = output_folder(recipe, options);
  std::error_code ec;
  if (fs::exists(out_dir, ec) && !fs::is_directory(out_dir, ec))
    throw IoError(out_dir.string() + ": exists and is not a folder");
}

RunReport write_outputs(const Recipe& recipe, const Plan& plan, Evaluation&& evaluation, const BuiltInputs& inputs,
                        const WriteOptions& options) {
  ProgressSinkScope progress(options.progress ? options.progress : current_progress_sink());
  ProgressSink* sink = current_progress_sink();
  const VolumeOptions vopt{recipe.voxel_size_mm, recipe.band_voxels};
  const uint64_t budget = evaluation.memory_budget_bytes;
  const fs::path out_dir = output_folder(recipe, options);
  // Created (with its parents) and locked here unless the caller holds it already; removed again
  // when this job created it and fails.
  std::optional<OutputFolder> own_folder;
  if (!options.folder) own_folder.emplace(out_dir.string());
  OutputFolder& folder = options.folder ? *options.folder : *own_folder;

  OutputTransaction transaction;
  RunReport report;
  StageTimer timer;
  ReportPage page;  // report.html: the objects as Draco, the pictures
  page.build_direction = recipe.printability.build_direction;
  try {
    // Each exported object is meshed once and written in every format asked for; then every
    // written file is read back and checked as the file it is.
    // The meshes of a group wait here until its last object is meshed.
    std::map<const RecipeOutput*, std::map<std::string, TriMesh>> pending;
    for (const std::string& object : plan.exported) {
      throw_if_cancelled(sink);
      timer.start("mesh");
      Volume volume = evaluation.take(object);
      auto exports = [&](const RecipeOutput& out) {
        return out.object == object || std::find(out.group.begin(), out.group.end(), object) != out.group.end();
      };
      // Layer outputs are cut from the level set; a mesh is made only for the others.
      double smallest_deviation = HUGE_VAL;
      for (const RecipeOutput& out : recipe.outputs)
        if (exports(out) && !out.layers) smallest_deviation = std::min(smallest_deviation, simplify_deviation_mm(recipe, out));
      const bool meshed = std::isfinite(smallest_deviation);
      if (meshed)
        detail::require_mesh_memory(volume, budget, recipe.file + ": meshing \"" + object + "\"", vopt, smallest_deviation);
      std::optional<PrintabilityFindings> printability;
      if (recipe.printability.enabled) {
        timer.start("printability");
        printability = check_printability(volume, recipe.printability);
        timer.start("mesh");
      }
      const uint64_t voxels = volume.active_voxel_count();
      for (const RecipeOutput& out : recipe.outputs) {
        if (!exports(out) || !out.layers) continue;
        timer.start("slice");
        const std::string final_path = (out_dir / out.file).string();
        LayerSettings settings;
        settings.format = out.format == "cli"   ? (out.layers->binary ? LayerFormat::kCliBinary : LayerFormat::kCli)
                          : out.format == "sl1" ? LayerFormat::kSl1
                                                : LayerFormat::kPngZip;
        settings.name = out.part_name;
        settings.layer_mm = out.layers->layer_mm;
        settings.pixel_mm = out.layers->pixel_mm;
        settings.tolerance_mm = out.layers->tolerance_mm;
        // The pixels over the object's planned box, as `lacuna slice` has them.
        const auto extent = evaluation.extents.find(object);
        const SlicedLayers sliced =
            slice_volume(volume, settings, recipe.file + ": " + out.json_path + " (\"" + object + "\")", budget,
                         extent != evaluation.extents.end() ? &extent->second.box : nullptr);
        const SliceReport& s = sliced.report;
        OutputReport entry;
        entry.file = final_path;
        entry.format = out.format;
        entry.object = out.object;
        entry.part_name = out.part_name;
        entry.voxels = voxels;
        entry.printability = printability;
        LayerOutputReport layers;
        layers.layers = s.layers.size();
        layers.layer_mm = s.layer_mm;
        layers.pixel_mm = s.pixel_mm;
        layers.tolerance_mm = s.tolerance_mm;
        layers.z0_mm = s.z0_mm;
        layers.width = s.width;
        layers.height = s.height;
        for (const LayerFigures& f : s.layers) {
          layers.contours += f.contours;
          layers.max_area_difference_mm2 =
              std::max(layers.max_area_difference_mm2, std::abs(f.image_area_mm2 - f.contour_area_mm2));
        }
        layers.problems = s.problems;
        if (s.valid) {
          timer.start("write");
          const std::string bytes = layers_file(sliced, final_path);
          write_whole_file(transaction.stage(final_path), bytes);
          layers.bytes = bytes.size();
        }
        entry.layers = std::move(layers);
        report.outputs.push_back(std::move(entry));
        timer.start("mesh");
      }
      // One surface per deviation the object's outputs ask for (usually one): the compact mesh is
      // extracted and simplified block by block, so the full marching-tetrahedra mesh never exists.
      std::map<double, ObjectMesh> surfaces;
      for (const RecipeOutput& out : recipe.outputs) {
        const double deviation = simplify_deviation_mm(recipe, out);
        if (!exports(out) || out.layers || surfaces.count(deviation)) continue;
        const ObjectMesh& surface = surfaces[deviation] = extract_object_surface(volume, deviation);
        if (surface.mesh.triangles.empty())
          throw InvalidInput(recipe.file + ": \"" + object + "\" is empty: nothing is left to export");
      }
      volume = Volume();
      // Loose pieces: separate bodies below the recipe's size, reported from the first surface (the others
      // differ only by their deviation) and, with "fix", removed from every one (otherwise only the first
      // is looked at).
      if (printability && recipe.printability.min_piece_mm3 > 0 && !surfaces.empty()) {
        timer.start("printability");
        const PrintabilitySettings& settings = recipe.printability;
        const bool fix = settings.on_failure == PrintabilitySettings::OnFailure::kFix;
        bool first = true;
        for (auto& [deviation, surface] : surfaces) {
          const std::vector<MeshComponent> loose = loose_pieces(surface.mesh, settings.min_piece_mm3);
          if (first) {
            for (const MeshComponent& c : loose) {
              if (fix) {
                ++printability->loose_pieces_removed;
                printability->loose_volume_removed_mm3 += c.signed_volume_mm3;
              } else {
                printability->loose_pieces.push_back({c.signed_volume_mm3, c.centroid_mm, c.box});
              }
            }
            if (!fix && !loose.empty() && settings.on_failure == PrintabilitySettings::OnFailure::kError)
              printability->problems.push_back(std::to_string(loose.size()) + " loose pieces smaller than " +
                                               detail::fixed(settings.min_piece_mm3, 4) +
                                               " mm3 (separate bodies: debris in the powder or resin)");
            first = false;
          }
          if (!fix) break;
          remove_components(surface.mesh, loose);
        }
        timer.start("mesh");
      }
      if (options.write_report && meshed) {
        timer.start("report");
        add_page_mesh(page, recipe, object, surfaces.begin()->second.mesh, printability, vopt.voxel_size_mm);
      } else if (options.write_report) {
        page.skipped.push_back({object, "written as layers only: no mesh was made"});
      }
      auto surface_for = [&](const RecipeOutput& out) -> const ObjectMesh& {
        return surfaces.at(simplify_deviation_mm(recipe, out));
      };
      // What every entry of this object's outputs shares: the mesh's figures, its printability, and
      // the hull volume of the output's object.
      auto entry_for = [&](const RecipeOutput& out, const std::string& final_path) {
        const ObjectMesh& surface = surface_for(out);
        OutputReport entry;
        entry.file = final_path;
        entry.format = out.format;
        entry.object = out.object;
        entry.voxels = voxels;
        entry.subvoxel_cavities_filled = surface.subvoxel_cavities_filled;
        entry.subvoxel_specks_removed = surface.subvoxel_specks_removed;
        entry.simplify_mm = simplify_deviation_mm(recipe, out);
        entry.extracted_triangles = surface.extracted_triangles;
        entry.printability = printability;
        if (out.render) entry.picture = (out_dir / out.render->file).string();
        auto hull = evaluation.hull_volume_mm3.find(out.object);
        if (hull != evaluation.hull_volume_mm3.end()) entry.hull_volume_mm3 = hull->second;
        return entry;
      };
      struct Written {
        const RecipeOutput* out;
        std::string temp;
        std::string final_path;
      };
      std::vector<Written> written;
      // Pictures of this object's outputs that ask for one, with markers at what printability found.
      for (const RecipeOutput& out : recipe.outputs) {
        if (out.object != object || !out.render) continue;
        timer.start("render");
        RenderOptions picture;
        picture.width = out.render->width;
        picture.height = out.render->height;
        picture.views.clear();
        for (const std::string& v : out.render->views) picture.views.push_back(render_view_from_name(v, out.json_path));
        picture.title = out.part_name;
        picture.section = out.render->section;
        if (printability)
          picture.markers = printability_markers(printability->trapped_voids, printability->thin_walls,
                                                 printability->small_holes);
        const std::string path = (out_dir / out.render->file).string();
        const std::string png = encode_picture_png(render_mesh(surface_for(out).mesh, picture));
        write_whole_file(transaction.stage(path), png);
        if (options.write_report) page.pictures.push_back({out.render->file + " (" + object + ")", "image/png", png});
      }
      for (const RecipeOutput& out : recipe.outputs) {
        if (!out.group.empty()) {
          if (std::find(out.group.begin(), out.group.end(), object) == out.group.end()) continue;
          std::map<std::string, TriMesh>& parts = pending[&out];
          parts[object] = surface_for(out).mesh;
          if (parts.size() < out.group.size()) continue;
          timer.start("write");
          const std::string final_path = (out_dir / out.file).string();
          std::string temp = transaction.stage(final_path);
          std::vector<ThreeMfObject> objects3mf;
          for (const std::string& name : out.group) {
            auto color = recipe.display_colors.find(name);
            objects3mf.push_back({&parts[name], name, color == recipe.display_colors.end() ? "" : color->second});
          }
          write_3mf(temp, objects3mf, package_info(recipe));
          pending.erase(&out);
          written.push_back({&out, temp, final_path});
          continue;
        }
        if (out.object != object || out.layers) continue;
        std::string final_path = (out_dir / out.file).string();
        const TriMesh& surface = surface_for(out).mesh;
        if (out.format == "drc") {
          // Written, decoded from the file and checked here: a failing check refines the grid.
          timer.start("write");
          const DracoOutput drc = write_checked_draco(transaction.stage(final_path), surface,
                                                      out.quantize_mm.value_or(vopt.voxel_size_mm / 10), budget);
          OutputReport entry = entry_for(out, final_path);
          entry.check = drc.check;
          entry.draco = drc.figures;
          entry.part_name = out.part_name;
          report.outputs.push_back(std::move(entry));
          continue;
        }
        if (out.format == "stl" || out.format == "3mf") {
          timer.start("write");
          std::string temp = transaction.stage(final_path);
          if (out.format == "stl") {
            write_stl(temp, surface, "Lacuna " LACUNA_VERSION " " + recipe.name + " " + out.part_name);
          } else {
            ThreeMfInfo info = package_info(recipe);
            info.object_name = out.part_name;
            write_3mf(temp, surface, info);
          }
          written.push_back({&out, temp, final_path});
          continue;
        }
        timer.start("tetrahedralize");
        FeaSettings fea_settings = out.fea;
        fea_settings.max_memory_bytes = budget;
        FeaResult fea = make_fea_mesh(surface, fea_settings);
        if (fea.check.valid() && !out.fea.regions.empty()) {
          std::vector<Volume> regions;
          for (const std::string& name : out.fea.regions) regions.push_back(evaluation.volumes.at(name));
          assign_regions(fea.mesh, regions);
        }
        if (fea.check.valid()) {
          timer.start("write");
          write_fea(transaction.stage(final_path), fea_format_from_path(final_path), fea.mesh,
                    fea_write_options(out.fea, surface_for(out).simplify_mm));
        }
        OutputReport entry = entry_for(out, final_path);
        entry.tetrahedra = std::move(fea.check);
        report.outputs.push_back(std::move(entry));
      }
      for (auto& entry : surfaces) entry.second.mesh = TriMesh();  // the figures stay for the entries
      timer.start("check");
      for (const Written& w : written) {
        ReadOptions read;
        read.max_memory_bytes = budget;
        std::vector<std::string> names;
        if (!w.out->group.empty()) read.object_names = &names;
        TriMesh back = read_mesh(w.temp, mesh_format_from_path(w.final_path), read);
        OutputReport entry = entry_for(*w.out, w.final_path);
        entry.check = check_mesh(back);
        entry.group = w.out->group;
        entry.objects = names;
        entry.part_name = w.out->part_name;
        report.outputs.push_back(std::move(entry));
      }
      for (const RecipeOutput& out : recipe.outputs)
        if (out.object == object)
          for (const std::string& name : out.fea.regions)
            if (--evaluation.uses[name] == 0) evaluation.volumes.erase(name);
    }
    timer.stop();

    report.lacuna_version = LACUNA_VERSION;
    report.recipe = recipe.file;
    report.name = recipe.name;
    report.voxel_size_mm = vopt.voxel_size_mm;
    report.band_voxels = vopt.half_band_voxels;
    report.seed = recipe.seed;
    report.valid = std::all_of(report.outputs.begin(), report.outputs.end(), [](const OutputReport& o) { return o.valid(); });
    report.stage_seconds = evaluation.stage_seconds;
    for (const auto& s : timer.seconds()) report.stage_seconds.push_back(s);
    report.peak_memory_bytes = peak_memory_bytes();
    report.peak_memory_children_bytes = peak_child_memory_bytes();
    report.memory_estimate_bytes = evaluation.memory_estimate_bytes;
    report.memory_budget_bytes = budget;
    report.threads = tbb::global_control::active_value(tbb::global_control::max_allowed_parallelism);
    for (size_t i = 0; i < inputs.names.size(); ++i) report.inputs.emplace_back(inputs.names[i], inputs.inputs[i].report);
    if (!report.valid) {
      transaction.rollback();
      return report;
    }
    const std::string report_path = (out_dir / "report.json").string();
    const std::string page_path = (out_dir / "report.html").string();
    if (options.write_report) {
      timer.start("report");
      for (InputFigure& f : input_figures(inputs))
        page.pictures.push_back({std::move(f.caption), std::move(f.type), std::move(f.bytes)});
      timer.stop();
      report.stage_seconds.push_back(timer.seconds().back());
      const nlohmann::json report_json = to_json(report);
      write_text_file_atomically(transaction.stage(report_path), report_json.dump(2) + "\n");
      write_whole_file(transaction.stage(page_path), report_page_html(report_json, page));
    }
    transaction.commit();
    folder.keep();
    for (const OutputReport& o : report.outputs) {
      report.written.push_back(o.file);
      if (!o.picture.empty()) report.written.push_back(o.picture);
    }
    if (options.write_report) {
      report.written.push_back(page_path);
      report.written.push_back(report_path);
    }
    return report;
  } catch (const Error& e) {
    transaction.rollback();
    // Messages name the files the user asked for, not their hidden temporaries.
    const std::string message = transaction.with_final_names(e.what());
    if (message == e.what()) throw;
    rethrow_with_message(e, message);
  } catch (...) {
    transaction.rollback();
    throw;
  }
}

}  // namespace lacuna
