#include "cli/app.h"

#include <algorithm>
#include <tbb/global_control.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <csignal>
#include <cstdlib>
#include <cstring>
#include <thread>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <memory>
#include <new>
#include <sstream>

#include "cli/bcifs_commands.h"
#include "cli/cifs_commands.h"
#include "cli/curve_commands.h"
#include "cli/exit_codes.h"
#include "cli/fill_commands.h"
#include "cli/mpi_ranks.h"
#include "pipeline/stream_output.h"
#include "cli/number_checks.h"
#include "cli/terminal_progress.h"
#include "cli/voronoi_commands.h"
#include "errors.h"
#include "export/fea.h"
#include "export/output_files.h"
#include "export/report.h"
#include "pipeline/pipeline.h"
#include "pipeline/render_output.h"
#include "pipeline/slice_output.h"
#include "util/progress.h"
#include "util/system.h"

namespace lacuna {
namespace {

struct CommonFlags {
  int threads = 0;
  bool quiet = false;
  bool json = false;
};

void add_common(CLI::App* command, CommonFlags& flags) {
  command->add_option("--threads", flags.threads, "Worker threads (default: every core)")->check(CLI::Range(1, 4096));
  command->add_flag("--quiet,-q", flags.quiet, "No progress bars and no summary on the terminal");
  command->add_flag("--json", flags.json, "Print the report as JSON on standard output");
}

// Each output's failed checks, from a run's or a streamed run's report, to stderr.
void print_output_problems(const nlohmann::json& report) {
  for (const auto& out : report["outputs"])
    for (const auto& problem : out["checks"]["problems"])
      std::cerr << "  " << out["file"].get<std::string>() << ": " << problem.get<std::string>() << "\n";
}

// `lacuna run --stream`: every output streamed slab by slab into its STL, checked chunk by chunk.
int command_stream(const std::string& recipe, const StreamOptions& options, const CommonFlags& flags) {
  // Under mpirun: one rank of a job; the first prints what the job did.
  const std::unique_ptr<JobRanks> ranks = mpi_ranks();
  StreamOptions job = options;
  job.ranks = ranks.get();
  const StreamReport result = stream_recipe(recipe, job);
  if (ranks && ranks->rank() != 0) return result.valid ? kExitOk : kExitCheckFailed;
  const nlohmann::json r = to_json(result);
  if (flags.json) std::cout << r.dump(2) << "\n";
  if (!result.valid) {
    std::cerr << "lacuna: " << recipe << ": a streamed output failed its checks; nothing was written\n";
    print_output_problems(r);
    return kExitCheckFailed;
  }
  if (!flags.json && !flags.quiet) {
    double seconds = 0;
    for (const auto& s : result.stage_seconds) seconds += s.second;
    std::printf("lacuna: streamed %s in %.2f s\n", recipe.c_str(), seconds);
    for (const StreamedOutput& out : result.outputs)
      std::printf("  wrote %s  (%llu triangles, %.6g mm3, %llu component%s, genus %lld, %zu slab%s, checked in %zu chunk%s)\n",
                  out.file.c_str(), (unsigned long long)out.triangles, out.check.volume_mm3,
                  (unsigned long long)out.check.components, out.check.components == 1 ? "" : "s",
                  (long long)out.check.genus, out.slabs, out.slabs == 1 ? "" : "s", out.check_chunks,
                  out.check_chunks == 1 ? "" : "s");
    if (options.run.write_report) std::printf("  wrote %s/report.json\n", result.output_dir.c_str());
  }
  return kExitOk;
}

int command_run(const std::string& recipe, const RunOptions& options, const CommonFlags& flags) {
  const RunReport result = run(recipe, options);
  const nlohmann::json r = to_json(result);
  if (flags.json) std::cout << r.dump(2) << "\n";
  if (!result.valid) {
    std::cerr << "lacuna: " << recipe << ": an output failed its checks; nothing was written\n";
    print_output_problems(r);
    return kExitCheckFailed;
  }
  if (!flags.json && !flags.quiet) {
    std::printf("lacuna: ran %s in %.2f s, peak memory %s\n", recipe.c_str(), r["total_seconds"].get<double>(),
                format_bytes(r["peak_memory_bytes"].get<uint64_t>()).c_str());
    for (const auto& out : r["outputs"]) {
      if (out.contains("layers"))
        std::printf("  wrote %s  (%llu layers of %.6g mm, %d x %d pixels of %.6g mm, every layer checked)\n",
                    out["file"].get<std::string>().c_str(), (unsigned long long)out["layers"]["count"].get<uint64_t>(),
                    out["layers"]["layer_mm"].get<double>(), out["layers"]["width"].get<int>(),
                    out["layers"]["height"].get<int>(), out["layers"]["pixel_mm"].get<double>());
      else if (out.contains("tets"))
        std::printf("  wrote %s  (%llu nodes, %llu tetrahedra, %.6g mm3, dihedral angles %.3g-%.3g deg)\n",
                    out["file"].get<std::string>().c_str(), (unsigned long long)out["nodes"].get<uint64_t>(),
                    (unsigned long long)out["tets"].get<uint64_t>(), out["volume_mm3"].get<double>(),
                    out["min_dihedral_deg"].get<double>(), out["max_dihedral_deg"].get<double>());
      else
        std::printf("  wrote %s  (%llu triangles, %.6g mm3, %llu component%s, genus %lld, checks passed)\n",
                    out["file"].get<std::string>().c_str(), (unsigned long long)out["triangles"].get<uint64_t>(),
                    out["volume_mm3"].get<double>(), (unsigned long long)out["components"].get<uint64_t>(),
                    out["components"].get<uint64_t>() == 1 ? "" : "s", (long long)out["genus"].get<int64_t>());
      if (out.contains("picture")) std::printf("  wrote %s  (picture)\n", out["picture"].get<std::string>().c_str());
    }
    if (options.write_report) {
      // written ends with report.html, report.json.
      std::printf("  wrote %s\n", result.written.back().c_str());
      std::printf("  wrote %s  (open it in a browser: each object in 3D, its checks and figures)\n",
                  result.written[result.written.size() - 2].c_str());
    }
  }
  return kExitOk;
}

struct PrintArgs {
  bool enabled = false;
  double min_wall = 0, min_hole = 0, critical_angle = 45, voxel = 0;
  std::string build_dir = "z";
};

Vec3d parse_direction(const std::string& text) {
  if (text == "x" || text == "+x") return {1, 0, 0};
  if (text == "y" || text == "+y") return {0, 1, 0};
  if (text == "z" || text == "+z") return {0, 0, 1};
  if (text == "-x") return {-1, 0, 0};
  if (text == "-y") return {0, -1, 0};
  if (text == "-z") return {0, 0, -1};
  double x, y, z;
  char c1, c2;
  std::istringstream in(text);
  if (in >> x >> c1 >> y >> c2 >> z && c1 == ',' && c2 == ',' && (x != 0 || y != 0 || z != 0)) return {x, y, z};
  throw InvalidInput("--build-dir: expected x, y, z, -x, -y, -z or \"dx,dy,dz\", got \"" + text + "\"");
}

int command_check(const std::string& path, const CommonFlags& flags, const PrintArgs& print, uint64_t max_memory_bytes) {
  CheckFileOptions options;
  options.max_memory_bytes = max_memory_bytes;
  options.printability = print.enabled;
  options.min_wall_mm = print.min_wall;
  options.min_hole_mm = print.min_hole;
  if (print.enabled) options.build_direction = parse_direction(print.build_dir);
  options.critical_angle_deg = print.critical_angle;
  options.voxel_size_mm = print.voxel;
  const FileCheck result = check_file(path, options);
  if (flags.json) {
    std::cout << to_json(result).dump(2) << "\n";
  } else if (!flags.quiet) {
    std::cout << path << ":\n" << check_report_text(result.check);
    if (print.enabled) {
      const PrintabilityReport& pr = result.printability;
      auto show = [](const char* what, const std::vector<PrintFeature>& features) {
        for (const PrintFeature& f : features)
          std::printf("  %s: %.4g mm3 at (%.4g, %.4g, %.4g)\n", what, f.volume_mm3, f.location_mm.x, f.location_mm.y, f.location_mm.z);
      };
      show("trapped void", pr.trapped_voids);
      show("thin wall", pr.thin_walls);
      show("small hole", pr.small_holes);
      std::printf("  overhang %.4g mm2 of %.4g mm2 facing down\n  %s\n", pr.overhang_area_mm2, pr.down_facing_area_mm2,
                  pr.ok() ? "printable" : "NOT PRINTABLE as it is");
    }
  }
  return result.valid() ? kExitOk : kExitCheckFailed;
}

struct RenderArgs {
  std::string input, output, views = "iso", size = "1200x900", object, title;
  double section = -1;  // >= 0: cut at this fraction of the height
  PrintArgs print;
};

// `lacuna render`: a mesh file or a recipe's object as a PNG picture.
int command_render(const RenderArgs& args, const RunOptions& base, const CommonFlags& flags) {
  RenderFileOptions options;
  options.run = base;
  options.object = args.object;
  options.picture.views.clear();
  std::stringstream views(args.views);
  for (std::string v; std::getline(views, v, ',');) options.picture.views.push_back(render_view_from_name(v, "--views"));
  if (options.picture.views.empty()) throw InvalidInput("--views: expected one or more of iso, front, top, side");
  int w = 0, h = 0;
  char x = 0, rest = 0;
  if (std::sscanf(args.size.c_str(), "%d%c%d%c", &w, &x, &h, &rest) != 3 || x != 'x')
    throw InvalidInput("--size: expected WIDTHxHEIGHT in pixels, such as 1200x900, got \"" + args.size + "\"");
  options.picture.width = w;
  options.picture.height = h;
  if (args.section >= 0) options.picture.section = args.section;
  options.picture.title = args.title;
  options.printability = args.print.enabled;
  options.print.min_wall_mm = args.print.min_wall;
  options.print.min_hole_mm = args.print.min_hole;
  options.print.voxel_size_mm = args.print.voxel;
  options.print.max_memory_bytes = base.max_memory_bytes;
  if (args.print.enabled) options.print.build_direction = parse_direction(args.print.build_dir);
  const RenderFileResult result = render_file(args.input, args.output, options);
  if (flags.json) {
    std::cout << nlohmann::json{{"file", args.output}, {"width", result.picture.width}, {"height", result.picture.height},
                                {"triangles", result.triangles}, {"markers", result.markers}}
                     .dump(2)
              << "\n";
  } else if (!flags.quiet) {
    std::printf("lacuna: wrote %s  (%d x %d, %zu views, %zu triangles, %zu markers)\n", args.output.c_str(),
                result.picture.width, result.picture.height, result.picture.views.size(), result.triangles,
                result.markers);
  }
  return kExitOk;
}

struct SliceArgs {
  std::string recipe;
  std::string output;
  SliceOptions options;
};

// `lacuna slice`: a recipe's object as layers (PNG stack, zipped or not, or a CLI file).
int command_slice(SliceArgs args, const RunOptions& base, const CommonFlags& flags) {
  args.options.run = base;
  // Under mpirun: one rank of a job; the first prints what the job did.
  const std::unique_ptr<JobRanks> ranks = mpi_ranks();
  args.options.ranks = ranks.get();
  const SliceReport report = slice_recipe(args.recipe, args.output, args.options);
  if (ranks && ranks->rank() != 0) return report.valid ? kExitOk : kExitCheckFailed;
  const nlohmann::json j = to_json(report);
  if (flags.json) std::cout << j.dump(2) << "\n";
  if (!report.valid) {
    std::cerr << "lacuna: " << args.recipe << ": layers failed their checks; nothing was written\n";
    for (size_t i = 0; i < report.problems.size() && i < 20; ++i) std::cerr << "  " << report.problems[i] << "\n";
    if (report.problems.size() > 20) std::cerr << "  ... and " << report.problems.size() - 20 << " more\n";
    return kExitCheckFailed;
  }
  if (!flags.json && !flags.quiet) {
    double seconds = 0;
    for (const auto& s : report.stage_seconds) seconds += s.second;
    std::printf("lacuna: sliced \"%s\" into %zu layers of %.6g mm (%d x %d pixels of %.6g mm) in %.2f s\n",
                report.object.c_str(), report.layers.size(), report.layer_mm, report.width, report.height,
                report.pixel_mm, seconds);
    std::printf("  wrote %s  (%s, %s, every layer checked)\n", report.output.c_str(), j["format"].get<std::string>().c_str(),
                format_bytes(report.bytes).c_str());
  }
  return kExitOk;
}

struct FeaArgs {
  std::string input;
  std::string output;
  std::string format;
  double max_tet_volume = 0;
  double quality = 0;
  double min_dihedral = 0;
  double simplify = -1;  // >= 0: simplification deviation (mm); a recipe's own otherwise, none for a mesh file
  bool msh2 = false;
  bool c3d10 = false;
  bool free_surface = false;
};

// `lacuna fea`: a recipe's first output, or a mesh file, into a tetrahedral mesh.
int command_fea(const FeaArgs& args, const RunOptions& base, const CommonFlags& flags) {
  namespace fs = std::filesystem;
  std::string path = args.output;
  if (!args.format.empty()) {
    const std::string wanted = "." + args.format;
    if (fs::path(path).extension() != wanted) throw InvalidInput("-o " + path + ": expected a file ending in " + wanted);
  }
  fea_format_from_path(path);  // throws for unknown extensions
  RecipeOutput out;
  out.file = fs::path(path).filename().string();
  out.format = fs::path(path).extension().string().substr(1);
  if (args.simplify >= 0) out.simplify_mm = args.simplify;
  out.fea.max_tet_volume_mm3 = args.max_tet_volume;
  out.fea.quality = args.quality;
  out.fea.min_dihedral_deg = args.min_dihedral;
  out.fea.msh_version_2 = args.msh2;
  out.fea.quadratic = args.c3d10;
  out.fea.preserve_surface = !args.free_surface;
  nlohmann::json report;
  if (fs::path(args.input).extension() == ".json") {
    RunOptions options = base;
    options.output_dir = fs::path(path).parent_path().empty() ? "." : fs::path(path).parent_path().string();
    options.write_report = false;
    // The recipe's first output's object, as the one tetrahedral output.
    Recipe recipe = load_recipe(args.input);
    out.object = recipe.outputs.front().object;
    recipe.outputs = {out};
    const RunReport result = run(std::move(recipe), options);
    const nlohmann::json first = to_json(result.outputs.at(0));
    if (!result.valid) {
      for (const auto& problem : first["checks"]["problems"])
        std::cerr << "lacuna: " << path << ": " << problem.get<std::string>() << "\n";
      return kExitCheckFailed;
    }
    report = first;
  } else {
    out.fea.max_memory_bytes = base.max_memory_bytes;
    const TetCheck check = write_tetrahedra(args.input, path, out.fea, std::max(0.0, args.simplify));
    report = fea_report_json(check);
    report["file"] = path;
    if (!check.valid()) {
      for (const std::string& problem : check.problems) std::cerr << "lacuna: " << args.input << ": " << problem << "\n";
      if (flags.json) std::cout << report.dump(2) << "\n";
      return kExitCheckFailed;
    }
  }
  if (flags.json) std::cout << report.dump(2) << "\n";
  else if (!flags.quiet)
    std::printf("lacuna: wrote %s  (%llu nodes, %llu tetrahedra, %.6g mm3, dihedral angles %.3g-%.3g deg)\n", path.c_str(),
                (unsigned long long)report["nodes"].get<uint64_t>(), (unsigned long long)report["tets"].get<uint64_t>(),
                report["volume_mm3"].get<double>(), report["min_dihedral_deg"].get<double>(),
                report["max_dihedral_deg"].get<double>());
  return kExitOk;
}

// SIGINT and SIGTERM end the program after the files of unfinished outputs are removed: both are
// blocked in every thread (threads started later inherit the mask), and one thread waits for them,
// cleans up outside any signal handler, and ends the process by the signal's default action.
void handle_interruptions() {
  sigset_t signals;
  sigemptyset(&signals);
  sigaddset(&signals, SIGINT);
  sigaddset(&signals, SIGTERM);
  if (pthread_sigmask(SIG_BLOCK, &signals, nullptr) != 0) return;
  std::thread([signals] {
    int signal = 0;
    if (sigwait(&signals, &signal) != 0) return;
    remove_unfinished_outputs();
    const char* message = signal == SIGINT ? "lacuna: interrupted; unfinished outputs removed\n"
                                           : "lacuna: terminated; unfinished outputs removed\n";
    if (::write(STDERR_FILENO, message, std::strlen(message)) < 0) {
    }
    std::signal(signal, SIG_DFL);
    sigset_t one;
    sigemptyset(&one);
    sigaddset(&one, signal);
    pthread_sigmask(SIG_UNBLOCK, &one, nullptr);
    std::raise(signal);
    std::_Exit(128 + signal);
  }).detach();
}

}  // namespace

int run_app(int argc, char** argv) {
  handle_interruptions();
  CLI::App app{"Lacuna: volumetric solid modeling for additive manufacturing.\n"
               "Runs recipe files (JSON) into checked, printable STL, 3MF and Draco parts.\n"
               "Exit codes: 0 success, 2 bad usage or input, 3 resource limit, 4 failed validity check."};
  app.set_version_flag("--version", std::string("lacuna " LACUNA_VERSION) +
                                        (built_with_mpi() ? " (slice runs over MPI ranks)" : ""));
  app.require_subcommand(1);

  CommonFlags flags;
  RunOptions run_options;
  std::string recipe;
  double max_memory_gb = 0;
  CLI::App* run_command = app.add_subcommand("run", "Run a recipe: write its outputs and report.json, each output re-read and checked");
  run_command->add_option("RECIPE", recipe, "Recipe file (JSON)")->required();
  run_command->add_option("-o,--output", run_options.output_dir, "Folder for the outputs (default: <recipe name>-out)");
  run_command->add_option("--voxel-size", run_options.voxel_size_mm, "Voxel size in mm, overriding the recipe's")
      ->check(number_in(kMinVoxelSizeMm, kMaxVoxelSizeMm));
  run_command->add_option("--simplify", run_options.simplify_mm,
                          "Deviation in mm of the compact meshes written, overriding the recipe's (0: the plain "
                          "marching-tetrahedra surface; default: a fifth of the voxel)")
      ->check(non_negative_number());
  run_command->add_option("--max-memory", max_memory_gb, "Memory budget in GB (default: half of the machine's memory)")
      ->check(number_in(0, 1e9, true));
  bool stream = false;
  double stream_slab_mm = 0;
  run_command->add_flag("--stream", stream,
                        "Stream the meshes: each object evaluated slab by slab along z and its surface written to\n"
                        "its STL as it comes, then checked chunk by chunk (memory follows the slab, not the part;\n"
                        "STL outputs only, no printability); the same file as a whole run where that fits.\n"
                        "Under mpirun the processes split the slabs (the output's folder on a shared file system)");
  run_command->add_option("--slab-mm", stream_slab_mm,
                          "With --stream: slab height in mm, rounded up to blocks of 32 voxels (default: the whole part\n"
                          "when it fits the budget, otherwise the highest slabs that do)")
      ->check(non_negative_number());
  add_common(run_command, flags);

  std::string mesh_path;
  CLI::App* check = app.add_subcommand(
      "check", "Check a mesh (STL, 3MF, OBJ, PLY, Draco) as a printable solid: closed, manifold, outward-oriented,\n"
               "free of self-intersections and degenerate faces, positive volume. Exit 0 only if valid.");
  check->add_option("MESH", mesh_path, "Mesh file")->required();
  PrintArgs print;
  check->add_flag("--print", print.enabled, "Also analyse printability: trapped voids, thin walls, small holes, overhang");
  check->add_option("--min-wall", print.min_wall, "With --print: thinnest wall allowed, mm")->check(non_negative_number());
  check->add_option("--min-hole", print.min_hole, "With --print: narrowest hole or channel allowed, mm")->check(non_negative_number());
  check->add_option("--build-dir", print.build_dir, "With --print: build direction, x y z -x -y -z or dx,dy,dz (default z)");
  check->add_option("--critical-angle", print.critical_angle, "With --print: down-facing surface flatter than this is overhang, degrees (45)")
      ->check(number_in(0, 90));
  check->add_option("--voxel-size", print.voxel, "With --print: voxel size of the analysis, mm (default: a quarter of the smallest size)")
      ->check(number_in(kMinVoxelSizeMm, kMaxVoxelSizeMm));
  check->add_option("--max-memory", max_memory_gb, "With --print: memory budget in GB (default: half of the machine's memory)")
      ->check(number_in(0, 1e9, true));
  add_common(check, flags);
  FeaArgs fea_args;
  CLI::App* fea = app.add_subcommand(
      "fea", "Tetrahedral mesh for finite elements (TetGen) of a recipe's first output or of a mesh file");
  fea->add_option("INPUT", fea_args.input, "Recipe (.json) or closed mesh (.stl .obj .ply .3mf .drc)")->required();
  fea->add_option("-o,--output", fea_args.output, "Output file: .inp (Abaqus/CalculiX), .msh (Gmsh), .vtu, .mesh (Medit)")
      ->required();
  fea->add_option("--format", fea_args.format, "inp, msh, vtu or mesh (must match the output's extension)")
      ->check(CLI::IsMember({"inp", "msh", "vtu", "mesh"}));
  fea->add_option("--max-tet-volume", fea_args.max_tet_volume, "Largest tetrahedron in mm3 (default: unbounded)")
      ->check(positive_number());
  fea->add_option("--quality", fea_args.quality, "Radius-edge ratio bound, > 1 (e.g. 1.4; default: none)")
      ->check(finite_number());
  fea->add_option("--min-dihedral", fea_args.min_dihedral, "Smallest dihedral angle to aim for, degrees (with --quality)")
      ->check(finite_number());
  fea->add_option("--simplify,--decimate", fea_args.simplify,
                  "Simplify the surface to this deviation in mm first, every collapse guarded (0: not at all; default: "
                  "a recipe's own, none for a mesh file)")
      ->check(non_negative_number());
  fea->add_option("--max-memory", max_memory_gb, "Memory budget in GB, TetGen's included (default: half of the machine's memory)")
      ->check(number_in(0, 1e9, true));
  fea->add_flag("--msh2", fea_args.msh2, "Gmsh format 2.2 instead of 4.1");
  fea->add_flag("--c3d10", fea_args.c3d10, "Quadratic C3D10 elements in .inp (mid-side nodes)");
  fea->add_flag("--free-surface", fea_args.free_surface, "Let TetGen add points on the surface (no -Y)");
  fea->add_option("--voxel-size", run_options.voxel_size_mm, "Voxel size in mm for a recipe, overriding its own")
      ->check(number_in(kMinVoxelSizeMm, kMaxVoxelSizeMm));
  add_common(fea, flags);
  RenderArgs render_args;
  CLI::App* render = app.add_subcommand(
      "render", "Pictures of a mesh file or of a recipe's object (PNG; no GPU or display needed): shaded views with\n"
                "the object's name, a scale bar in mm, and markers at printability findings with --print");
  render->add_option("INPUT", render_args.input, "Mesh (.stl .obj .ply .3mf .drc) or recipe (.json)")->required();
  render->add_option("-o,--output", render_args.output, "Output picture (.png)")->required();
  render->add_option("--views", render_args.views, "Comma-separated views: iso, front, top, side (default iso)");
  render->add_option("--size", render_args.size, "WIDTHxHEIGHT in pixels, 64 to 8192 each (default 1200x900)");
  render->add_option("--object", render_args.object, "A recipe's input or operation (default: its first output's)");
  render->add_option("--title", render_args.title, "The name printed on each view (default: the object's or file's)");
  render->add_option("--section", render_args.section,
                     "Cut away what lies above this fraction of the height (0 to 1, along z) and show the cut solid")
      ->check(number_in(0, 1));
  render->add_flag("--print", render_args.print.enabled, "Analyse printability and mark trapped voids, thin walls, small holes");
  render->add_option("--min-wall", render_args.print.min_wall, "With --print: thinnest wall allowed, mm")->check(non_negative_number());
  render->add_option("--min-hole", render_args.print.min_hole, "With --print: narrowest hole allowed, mm")->check(non_negative_number());
  render->add_option("--print-voxel-size", render_args.print.voxel, "With --print: voxel size of the analysis, mm")
      ->check(number_in(kMinVoxelSizeMm, kMaxVoxelSizeMm));
  render->add_option("--voxel-size", run_options.voxel_size_mm, "Voxel size in mm for a recipe, overriding its own")
      ->check(number_in(kMinVoxelSizeMm, kMaxVoxelSizeMm));
  render->add_option("--max-memory", max_memory_gb, "Memory budget in GB (default: half of the machine's memory)")
      ->check(number_in(0, 1e9, true));
  add_common(render, flags);
  SliceArgs slice_args;
  CLI::App* slice = app.add_subcommand(
      "slice", "A recipe's object as layers for printers, cut from its level set with no mesh: a folder (or .zip) of\n"
               "greyscale PNG layers with manifest.json, or a CLI file of contours; every layer checked first");
  slice->add_option("RECIPE", slice_args.recipe, "Recipe (.json)")->required();
  slice->add_option("-o,--output", slice_args.output,
                    "A folder (PNG layers), FILE.zip (them zipped), FILE.sl1 (resin printers, as PrusaSlicer writes it) or FILE.cli")
      ->required();
  slice->add_option("--layer-mm", slice_args.options.layer_mm, "Layer height in mm (default: the voxel size)")
      ->check(number_in(kMinVoxelSizeMm, kMaxVoxelSizeMm));
  slice->add_option("--pixel-mm", slice_args.options.pixel_mm, "Pixel size in mm (default: the voxel size)")
      ->check(number_in(kMinVoxelSizeMm, kMaxVoxelSizeMm));
  slice->add_option("--tolerance-mm", slice_args.options.tolerance_mm,
                    "CLI: contours simplified within this distance (default: a quarter pixel; 0: not simplified)")
      ->check(non_negative_number());
  slice->add_flag("--binary", slice_args.options.binary, "CLI: binary rather than ASCII");
  slice->add_option("--object", slice_args.options.object, "The recipe's input or operation (default: its first output's)");
  slice->add_option("--voxel-size", run_options.voxel_size_mm, "Voxel size in mm, overriding the recipe's")
      ->check(number_in(kMinVoxelSizeMm, kMaxVoxelSizeMm));
  slice->add_option("--max-memory", max_memory_gb,
                    "Memory budget in GB (default: half of the machine's memory); a part whose level set does not\n"
                    "fit is evaluated slab by slab, each as high as fits")
      ->check(number_in(0, 1e9, true));
  slice->add_option("--slab-mm", slice_args.options.slab_mm,
                    "Evaluate slab by slab, this high in mm (default: the whole part when it fits the budget;\n"
                    "under mpirun -np K, the slabs are split over the ranks, K of them when the whole part fits)")
      ->check(non_negative_number());
  add_common(slice, flags);
  std::function<int()> cifs_command = add_cifs_commands(app);
  std::function<int()> curve_command = add_curve_commands(app);
  std::function<int()> fill_command = add_fill_commands(app);
  std::function<int()> voronoi_command = add_voronoi_commands(app);
  std::function<int()> bcifs_command = add_bcifs_commands(app);

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    int code = app.exit(e);
    return code == 0 ? kExitOk : kExitBadInput;
  }

  // Bars only where someone watches: a terminal, without --quiet.
  TerminalProgress bars;
  ProgressSinkScope progress(!flags.quiet && isatty(STDERR_FILENO) ? &bars : nullptr);
  std::unique_ptr<tbb::global_control> threads;
  if (flags.threads > 0)
    threads = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism, flags.threads);
  run_options.threads = flags.threads;
  run_options.progress = current_progress_sink();
  try {
    run_options.max_memory_bytes = uint64_t(max_memory_gb * 1e9);
    if (*run_command && (stream || stream_slab_mm > 0)) {
      if (!stream) throw InvalidInput("--slab-mm: needs --stream");
      StreamOptions stream_options;
      stream_options.run = run_options;
      stream_options.slab_mm = stream_slab_mm;
      return command_stream(recipe, stream_options, flags);
    }
    if (*run_command) return command_run(recipe, run_options, flags);
    if (*check) return command_check(mesh_path, flags, print, run_options.max_memory_bytes);
    if (*fea) return command_fea(fea_args, run_options, flags);
    if (*render) return command_render(render_args, run_options, flags);
    if (*slice) return command_slice(slice_args, run_options, flags);
    for (const auto& command : {cifs_command, curve_command, fill_command, voronoi_command, bcifs_command}) {
      const int code = command();
      if (code >= 0) return code;
    }
    return kExitBadInput;
  } catch (const InternalError& e) {
    std::cerr << "lacuna: internal error: " << e.what() << "\n";
    return exit_code(e);
  } catch (const Error& e) {
    std::cerr << "lacuna: error: " << e.what() << "\n";
    return exit_code(e);
  } catch (const std::bad_alloc& e) {
    // The estimates made before allocating missed this one, so the cause is not known here.
    std::cerr << "lacuna: error: out of memory: the machine could not give this job what it asked for; use coarser "
                 "settings (voxel size, tolerances, levels, counts) or a smaller input\n";
    return exit_code(e);
  } catch (const std::exception& e) {
    std::cerr << "lacuna: internal error: " << e.what() << "\n";
    return exit_code(e);
  }
}

}  // namespace lacuna
