#include "pipeline/render_output.h"

#include <filesystem>

#include "errors.h"
#include "export/mesh_io.h"
#include "export/output_files.h"
#include "pipeline/mesh_object.h"
#include "recipe/recipe.h"

namespace lacuna {

std::vector<RenderMarker> printability_markers(const std::vector<PrintFeature>& trapped_voids,
                                               const std::vector<PrintFeature>& thin_walls,
                                               const std::vector<PrintFeature>& small_holes) {
  std::vector<RenderMarker> markers;
  for (const PrintFeature& f : trapped_voids) markers.push_back({RenderMarker::Kind::kTrappedVoid, f.location_mm});
  for (const PrintFeature& f : thin_walls) markers.push_back({RenderMarker::Kind::kThinWall, f.location_mm});
  for (const PrintFeature& f : small_holes) markers.push_back({RenderMarker::Kind::kSmallHole, f.location_mm});
  return markers;
}

RenderFileResult render_file(const std::string& input, const std::string& png_path, const RenderFileOptions& options) {
  namespace fs = std::filesystem;
  std::string ext = fs::path(png_path).extension().string();
  for (char& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
  if (ext != ".png") throw InvalidInput(png_path + ": expected a file name ending in .png");
  TriMesh mesh;
  RenderOptions picture = options.picture;
  if (fs::path(input).extension() == ".json") {
    Recipe recipe = load_recipe(input);
    if (options.run.voxel_size_mm > 0) recipe.voxel_size_mm = options.run.voxel_size_mm;
    ObjectOptions o;
    o.simplify_mm = options.run.simplify_mm;
    o.max_memory_bytes = options.run.max_memory_bytes;
    o.threads = options.run.threads;
    o.progress = options.run.progress;
    const std::string object = options.object.empty() ? recipe.outputs.front().object : options.object;
    mesh = mesh_object(recipe, object, o).mesh;
    if (picture.title.empty()) picture.title = object;
  } else {
    if (!options.object.empty()) throw InvalidInput("--object names an object of a recipe, not of a mesh file");
    ReadOptions read;
    if (options.run.max_memory_bytes) read.max_memory_bytes = options.run.max_memory_bytes;
    mesh = read_mesh(input, read);
    if (picture.title.empty()) picture.title = fs::path(input).stem().string();
  }
  if (options.printability) {
    CheckFileOptions print = options.print;
    print.printability = true;
    const FileCheck found = check_solid(mesh, input, print);
    const PrintabilityReport& p = found.printability;
    const auto markers = printability_markers(p.trapped_voids, p.thin_walls, p.small_holes);
    picture.markers.insert(picture.markers.end(), markers.begin(), markers.end());
  }
  RenderFileResult result;
  result.picture = render_mesh(mesh, picture);
  result.triangles = mesh.triangles.size();
  result.markers = picture.markers.size();
  OutputTransaction transaction;
  write_picture_png(transaction.stage(png_path), result.picture);
  transaction.commit();
  return result;
}

}  // namespace lacuna
