// The all-or-nothing output transaction: every exported object meshed once, written in every format
// asked for under a temporary name, read back and checked as the file it is; only when every output
// passes are the files renamed into the output folder, with report.json.
#pragma once

#include <memory>
#include <string>

#include "export/output_files.h"
#include "pipeline/build_inputs.h"
#include "pipeline/evaluate.h"
#include "pipeline/plan.h"
#include "pipeline/report.h"
#include "recipe/recipe.h"
#include "util/progress.h"

namespace lacuna {

struct WriteOptions {
  std::string output_dir;            // empty: "<recipe name>-out" in the working folder
  OutputFolder* folder = nullptr;    // the output folder, already held (created, locked); null: held here
  bool write_report = true;          // report.json and report.html next to the outputs
  ProgressSink* progress = nullptr;  // null: the sink current on this thread
};

// The folder the outputs go to.
std::string output_folder(const Recipe& recipe, const WriteOptions& options);

// Throws IoError when the output folder's path exists and is not a folder.
void check_output_folder(const Recipe& recipe, const WriteOptions& options);

// Creates (with missing parents) and locks the output folder for a job; see export/output_files.h.
// Throws IoError when it cannot be created, ResourceLimit when another job is writing into it.
std::unique_ptr<OutputFolder> hold_output_folder(const Recipe& recipe, const WriteOptions& options);

// Meshes, writes, re-reads and checks every output of the plan, releasing each level set of
// `evaluation` after its last use. Returns the run's report: when an output failed its checks it is
// not valid and nothing was left on disk (a folder created for it is removed again). Throws
// InvalidInput when an object is empty, ResourceLimit before meshing a surface that would not fit
// the budget or when another job holds the output folder, IoError when a file cannot be written;
// nothing is left behind then either. Messages name the output files, not their temporaries.
RunReport write_outputs(const Recipe& recipe, const Plan& plan, Evaluation&& evaluation, const BuiltInputs& inputs,
                        const WriteOptions& options = {});

}  // namespace lacuna
