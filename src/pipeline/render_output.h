// Pictures of parts for people: a mesh file or a recipe's object rendered to PNG, with markers at
// the printability findings, written all or nothing (`lacuna render`, a recipe output's "render").
#pragma once

#include <string>
#include <vector>

#include "export/render.h"
#include "pipeline/check_file.h"
#include "pipeline/pipeline.h"

namespace lacuna {

struct PrintabilityFindings;

// Markers for every trapped void, thin wall and small hole found.
std::vector<RenderMarker> printability_markers(const std::vector<PrintFeature>& trapped_voids,
                                               const std::vector<PrintFeature>& thin_walls,
                                               const std::vector<PrintFeature>& small_holes);

struct RenderFileOptions {
  RenderOptions picture;           // size and views; the title defaults to the object's name
  std::string object;              // a recipe's object (default: its first output's)
  bool printability = false;       // analyse printability and mark the findings
  CheckFileOptions print;          // the analysis's settings (printability is set from the flag above)
  RunOptions run;                  // a recipe's voxel size, budget, threads, simplification, progress
};

struct RenderFileResult {
  Picture picture;
  size_t triangles = 0;
  size_t markers = 0;
};

// Renders a mesh file (.stl .obj .ply .3mf .drc) or a recipe (.json) to `png_path` through a
// temporary file. Throws what reading, building and meshing throw, InvalidInput for bad sizes or views.
RenderFileResult render_file(const std::string& input, const std::string& png_path, const RenderFileOptions& options);

}  // namespace lacuna
