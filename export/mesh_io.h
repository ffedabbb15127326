// Reading and writing triangle meshes: binary and ASCII STL, OBJ, PLY (ASCII and binary), 3MF
// and Draco (export/draco.h). Readers validate everything and throw InvalidInput naming the file,
// the line or byte offset, and what was expected; they never crash on malformed input.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "geometry.h"

namespace lacuna {

enum class MeshFormat { kStl, kObj, kPly, k3mf, kDrc };

// The format named by the file's extension (case-insensitive .stl .obj .ply .3mf .drc); throws
// InvalidInput for any other extension.
MeshFormat mesh_format_from_path(const std::string& path);
const char* mesh_format_name(MeshFormat format);

struct ReadOptions {
  // Refuse files whose declared or implied size would need more memory than this (bytes); the
  // check happens before the large allocation. ResourceLimit is thrown beyond it.
  uint64_t max_memory_bytes = uint64_t{8} << 30;
  // 3MF: when set, receives the name of each build item's object, in build order.
  std::vector<std::string>* object_names = nullptr;
};

// Reads a mesh. STL vertices are welded where their float coordinates are identical (STL stores
// no indices); OBJ polygons with more than three corners are fanned into triangles. The result
// keeps every triangle of the file in file order. Throws IoError if the file cannot be opened,
// InvalidInput if it is malformed, ResourceLimit if it is absurdly large.
TriMesh read_mesh(const std::string& path, const ReadOptions& options = {});
// The same with the format given, whatever the file's extension (used for temporary files).
TriMesh read_mesh(const std::string& path, MeshFormat format, const ReadOptions& options = {});

// Writes a binary STL (float32 coordinates, little-endian). The 80-byte header holds `header`
// (truncated). Throws IoError on failure.
void write_stl(const std::string& path, const TriMesh& mesh, const std::string& header);

// A binary STL written triangle by triangle, as they come (the count goes in when it is finished):
// the same bytes write_stl writes for the same triangles. A writer not finished removes its file.
class StlWriter {
 public:
  StlWriter(const std::string& path, const std::string& header);  // throws IoError
  ~StlWriter();
  StlWriter(const StlWriter&) = delete;
  StlWriter& operator=(const StlWriter&) = delete;
  void add(const std::array<Vec3d, 3>& corners);  // counter-clockwise seen from outside; throws IoError, ResourceLimit
  void finish();                                  // throws IoError
  uint64_t triangles() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// Triangles [first, first + count) of a binary STL, in file order (float32 corners as written).
// Throws IoError, or InvalidInput when the file holds fewer.
std::vector<std::array<Vec3d, 3>> read_stl_triangles(const std::string& path, uint64_t first, uint64_t count);

struct ThreeMfInfo {
  std::string object_name = "part";
  std::vector<std::pair<std::string, std::string>> metadata;  // e.g. {"Application", "Lacuna"}
};

// Writes a 3MF package (unit millimetre) with one mesh object and one build item.
// Byte-identical output for identical input. Throws IoError on failure.
void write_3mf(const std::string& path, const TriMesh& mesh, const ThreeMfInfo& info);

// One object of a package with several (the mesh is not copied; it must outlive the call).
struct ThreeMfObject {
  const TriMesh* mesh = nullptr;
  std::string name;
  std::string display_color;  // "#rrggbb": the object's base material shows it (multi-material); empty: none
};

// The same with one mesh object and one build item per part, in order (info.object_name unused). Parts
// with a display colour reference one base material each of a <basematerials> group (3MF core).
void write_3mf(const std::string& path, const std::vector<ThreeMfObject>& parts, const ThreeMfInfo& info);

}  // namespace lacuna
