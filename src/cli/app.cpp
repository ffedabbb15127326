#include "cli/app.h"

#include <tbb/global_control.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <cstdio>
#include <iostream>
#include <memory>
#include <new>

#include "cli/cifs_commands.h"
#include "cli/run_recipe.h"
#include "errors.h"
#include "export/mesh_io.h"
#include "export/report.h"
#include "solids/check.h"
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

int command_run(const std::string& recipe, const RunOptions& options, const CommonFlags& flags) {
  RunResult result = run_recipe(recipe, options);
  if (flags.json) std::cout << result.report.dump(2) << "\n";
  if (result.exit_code != kExitOk) {
    std::cerr << "lacuna: " << recipe << ": an output failed its checks; nothing was written\n";
    for (const auto& out : result.report["outputs"])
      for (const auto& problem : out["checks"]["problems"])
        std::cerr << "  " << out["file"].get<std::string>() << ": " << problem.get<std::string>() << "\n";
    return result.exit_code;
  }
  if (!flags.json && !flags.quiet) {
    const auto& r = result.report;
    std::printf("lacuna: ran %s in %.2f s, peak memory %s\n", recipe.c_str(), r["total_seconds"].get<double>(),
                format_bytes(r["peak_memory_bytes"].get<uint64_t>()).c_str());
    for (const auto& out : r["outputs"])
      std::printf("  wrote %s  (%llu triangles, %.6g mm3, %llu component%s, genus %lld, checks passed)\n",
                  out["file"].get<std::string>().c_str(), (unsigned long long)out["triangles"].get<uint64_t>(),
                  out["volume_mm3"].get<double>(), (unsigned long long)out["components"].get<uint64_t>(),
                  out["components"].get<uint64_t>() == 1 ? "" : "s", (long long)out["genus"].get<int64_t>());
    std::printf("  wrote %s\n", result.written.back().c_str());
  }
  return kExitOk;
}

int command_check(const std::string& path, const CommonFlags& flags) {
  TriMesh mesh = read_mesh(path);
  MeshCheckReport report = check_mesh(mesh);
  if (flags.json) {
    nlohmann::json j = check_report_json(report);
    j["file"] = path;
    std::cout << j.dump(2) << "\n";
  } else if (!flags.quiet) {
    std::cout << path << ":\n" << check_report_text(report);
  }
  return report.valid() ? kExitOk : kExitCheckFailed;
}

}  // namespace

int run_app(int argc, char** argv) {
  CLI::App app{"Lacuna: volumetric solid modeling for additive manufacturing.\n"
               "Runs recipe files (JSON) into checked, printable STL and 3MF parts.\n"
               "Exit codes: 0 success, 2 bad usage or input, 3 resource limit, 4 failed validity check."};
  app.set_version_flag("--version", "lacuna " LACUNA_VERSION);
  app.require_subcommand(1);

  CommonFlags flags;
  RunOptions run_options;
  std::string recipe;
  double max_memory_gb = 0;
  CLI::App* run = app.add_subcommand("run", "Run a recipe: write its outputs and report.json, each output re-read and checked");
  run->add_option("RECIPE", recipe, "Recipe file (JSON)")->required();
  run->add_option("-o,--output", run_options.output_dir, "Folder for the outputs (default: <recipe name>-out)");
  run->add_option("--voxel-size", run_options.voxel_size_mm, "Voxel size in mm, overriding the recipe's")
      ->check(CLI::PositiveNumber);
  run->add_option("--max-memory", max_memory_gb, "Memory budget in GB (default: half of the machine's memory)")
      ->check(CLI::PositiveNumber);
  add_common(run, flags);

  std::string mesh_path;
  CLI::App* check = app.add_subcommand(
      "check", "Check a mesh (STL, 3MF, OBJ, PLY) as a printable solid: closed, manifold, outward-oriented,\n"
               "free of self-intersections and degenerate faces, positive volume. Exit 0 only if valid.");
  check->add_option("MESH", mesh_path, "Mesh file")->required();
  add_common(check, flags);
  std::function<int()> cifs_command = add_cifs_commands(app);

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    int code = app.exit(e);
    return code == 0 ? kExitOk : kExitBadInput;
  }

  set_progress_enabled(!flags.quiet && isatty(STDERR_FILENO));
  std::unique_ptr<tbb::global_control> threads;
  if (flags.threads > 0)
    threads = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism, flags.threads);
  try {
    if (*run) {
      run_options.max_memory_bytes = uint64_t(max_memory_gb * 1e9);
      return command_run(recipe, run_options, flags);
    }
    if (*check) return command_check(mesh_path, flags);
    return cifs_command();
  } catch (const Error& e) {
    std::cerr << "lacuna: error: " << e.what() << "\n";
    return e.exit_code();
  } catch (const std::bad_alloc&) {
    std::cerr << "lacuna: error: out of memory; use a larger voxel size or a lower --max-memory estimate\n";
    return kExitResourceLimit;
  } catch (const std::exception& e) {
    std::cerr << "lacuna: internal error: " << e.what() << "\n";
    return kExitInternal;
  }
}

}  // namespace lacuna
