#include "solids/volume.h"

#include <algorithm>
#include <cmath>
#include <atomic>
#include <mutex>
#include <utility>
#include <openvdb/tools/Composite.h>
#include <openvdb/tools/Interpolation.h>
#include <openvdb/tools/MeshToVolume.h>
#include <openvdb/tools/Prune.h>
#include <openvdb/tools/ValueTransformer.h>

#include "errors.h"
#include "solids/check.h"
#include "solids/components.h"
#include "solids/extract.h"
#include "solids/vdb_internal.h"
#include "util/progress.h"

namespace lacuna {

void ensure_openvdb_initialized() {
  static std::once_flag once;
  std::call_once(once, [] { openvdb::initialize(); });
}

openvdb::math::Transform::Ptr make_transform(double voxel_size_mm) {
  return openvdb::math::Transform::createLinearTransform(voxel_size_mm);
}

openvdb::FloatGrid::Ptr make_level_set_grid(const VolumeOptions& options) {
  ensure_openvdb_initialized();
  if (!(options.voxel_size_mm >= kMinVoxelSizeMm && options.voxel_size_mm <= kMaxVoxelSizeMm))
    throw InvalidInput("voxel size must be from 0.0001 to 1000 mm");
  if (!(options.half_band_voxels >= 2))
    throw InvalidInput("the narrow band must be at least 2 voxels wide on each side");
  auto grid = openvdb::FloatGrid::create(static_cast<float>(options.voxel_size_mm * options.half_band_voxels));
  grid->setTransform(make_transform(options.voxel_size_mm));
  grid->setGridClass(openvdb::GRID_LEVEL_SET);
  return grid;
}

Volume wrap_grid(openvdb::FloatGrid::Ptr grid, const VolumeOptions& options) {
  auto impl = std::make_shared<Volume::Impl>();
  impl->grid = std::move(grid);
  impl->options = options;
  return Volume(std::move(impl));
}

namespace {

const VolumeOptions& default_options() {
  static const VolumeOptions options;
  return options;
}

// Subtracts `shift` from every value, then re-forms a narrow band of half width `band` (mm):
// values clamped to [-band, band], active only inside it, interior tiles at -band.
void rebuild_band(openvdb::FloatGrid& grid, float shift, float band) {
  openvdb::tools::foreach(grid.beginValueAll(), [shift, band](const openvdb::FloatGrid::ValueAllIter& it) {
    float v = *it - shift;
    if (std::fabs(v) < band) {
      it.setValue(v);
      if (it.isVoxelValue()) it.setActiveState(true);
      else it.setActiveState(false);  // a tile inside the band would be too coarse; keep sign only
    } else {
      it.setValue(v < 0 ? -band : band);
      it.setActiveState(false);
    }
  });
  grid.tree().root().setBackground(band, /*updateChildNodes=*/false);
  openvdb::tools::pruneLevelSet(grid.tree());
}

struct TriMeshAdapter {
  const TriMesh& mesh;
  double inv_h;
  size_t polygonCount() const { return mesh.triangles.size(); }
  size_t pointCount() const { return mesh.positions_mm.size(); }
  size_t vertexCount(size_t) const { return 3; }
  void getIndexSpacePoint(size_t n, size_t v, openvdb::Vec3d& pos) const {
    const Vec3d& p = mesh.positions_mm[mesh.triangles[n][v]];
    pos = openvdb::Vec3d(p.x * inv_h, p.y * inv_h, p.z * inv_h);
  }
};

// Turns meshToVolume's percentages into a progress bar; never interrupts.
class ProgressInterrupter : public openvdb::util::NullInterrupter {
 public:
  explicit ProgressInterrupter(const char* stage) : progress_(stage, 100) {}
  bool wasInterrupted(int percent = -1) override {
    int last = last_.load();
    while (percent > last && !last_.compare_exchange_weak(last, percent)) {
    }
    if (percent > last) progress_.advance(uint64_t(percent - last));
    return false;
  }

 private:
  Progress progress_;
  std::atomic<int> last_{0};
};

// Signed distance to a closed mesh, exact within `outside_mm` outside and `inside_mm` inside.
openvdb::FloatGrid::Ptr mesh_distance(const TriMesh& mesh, double h, double outside_mm, double inside_mm,
                                      const char* stage) {
  ensure_openvdb_initialized();
  TriMeshAdapter adapter{mesh, 1.0 / h};
  auto xform = make_transform(h);
  ProgressInterrupter interrupter(stage);
  auto grid = openvdb::tools::meshToVolume<openvdb::FloatGrid>(
      interrupter, adapter, *xform, static_cast<float>(outside_mm / h + 1.0), static_cast<float>(inside_mm / h + 1.0),
      openvdb::tools::DISABLE_RENORMALIZATION);
  grid->setGridClass(openvdb::GRID_LEVEL_SET);
  return grid;
}

void require_same_grid(const Volume& a, const Volume& b, const char* op) {
  if (a.voxel_size_mm() != b.voxel_size_mm() || a.band_mm() != b.band_mm())
    throw InvalidInput(std::string(op) + ": volumes have different voxel sizes (" +
                       message_number(a.voxel_size_mm()) + " mm and " + message_number(b.voxel_size_mm()) +
                       " mm); build both with the same voxel size");
}

// How far offsets by these distances reach outwards and inwards (mm, >= 0). Throws InvalidInput
// for a distance that is not finite.
std::pair<double, double> offset_reach(const std::vector<double>& distances_mm) {
  double outside = 0, inside = 0;
  for (double d : distances_mm) {
    if (!std::isfinite(d)) throw InvalidInput("offset distance must be a finite length in mm");
    outside = std::max(outside, d);
    inside = std::max(inside, -d);
  }
  return {outside, inside};
}

// Narrow bands of half width `band` (mm) of the distance shifted by each distance: copies, and the
// distance itself for the last.
std::vector<Volume> shifted_bands(const openvdb::FloatGrid::Ptr& distance, const std::vector<double>& distances_mm,
                                  double band, const VolumeOptions& options) {
  std::vector<Volume> result(distances_mm.size());
  for (size_t i = 0; i < distances_mm.size(); ++i) {
    openvdb::FloatGrid::Ptr grid = i + 1 == distances_mm.size() ? distance : distance->deepCopy();
    rebuild_band(*grid, static_cast<float>(distances_mm[i]), static_cast<float>(band));
    result[i] = wrap_grid(grid, options);
  }
  return result;
}

}  // namespace

Volume::Volume() = default;
Volume::Volume(std::shared_ptr<const Impl> impl) : impl_(std::move(impl)) {}

const VolumeOptions& Volume::options() const { return impl_ ? impl_->options : default_options(); }

uint64_t Volume::active_voxel_count() const { return impl_ ? impl_->grid->tree().activeVoxelCount() : 0; }

uint64_t Volume::leaf_count() const { return impl_ ? impl_->grid->tree().leafCount() : 0; }

uint64_t Volume::memory_bytes() const { return impl_ ? impl_->grid->tree().memUsage() : 0; }

Box3 Volume::bounding_box() const {
  Box3 box;
  if (empty()) return box;
  openvdb::CoordBBox b = impl_->grid->evalActiveVoxelBoundingBox();
  double h = voxel_size_mm();
  box.expand(Vec3d{b.min().x() * h, b.min().y() * h, b.min().z() * h});
  box.expand(Vec3d{b.max().x() * h, b.max().y() * h, b.max().z() * h});
  return box;
}

double Volume::distance_at(const Vec3d& p) const {
  if (!impl_) return band_mm();
  double inv_h = 1.0 / voxel_size_mm();
  openvdb::Vec3d index(p.x * inv_h, p.y * inv_h, p.z * inv_h);
  return openvdb::tools::BoxSampler::sample(impl_->grid->tree(), index);
}

double Volume::voxel_volume_mm3() const {
  if (!impl_) return 0;
  const double h = voxel_size_mm();
  long double voxels = 0;
  for (auto it = impl_->grid->cbeginValueAll(); it; ++it) {
    double v = *it;
    double inside = std::clamp(0.5 - v / h, 0.0, 1.0);
    voxels += static_cast<long double>(inside) * static_cast<long double>(it.getVoxelCount());
  }
  return static_cast<double>(voxels) * h * h * h;
}

namespace {

Volume closed_mesh_volume(const TriMesh& mesh, const VolumeOptions& options) {
  auto grid = make_level_set_grid(options);  // validates the options
  double band = options.voxel_size_mm * options.half_band_voxels;
  grid = mesh_distance(mesh, options.voxel_size_mm, band, band, "mesh to volume");
  rebuild_band(*grid, 0.0f, static_cast<float>(band));
  return wrap_grid(grid, options);
}

}  // namespace

Volume mesh_to_volume(const TriMesh& mesh, const VolumeOptions& options) {
  if (mesh.triangles.empty()) throw InvalidInput("mesh has no triangles");
  // meshToVolume fills whatever the outside cannot reach, cavities included. A mesh with
  // inward-facing shells (cavities, and islands inside them) is built level by level of nesting:
  // shells at even depth added, at odd depth taken away.
  std::vector<MeshComponent> components = mesh_components(mesh);
  bool cavities = false;
  for (const MeshComponent& c : components) cavities = cavities || c.signed_volume_mm3 < 0;
  if (!cavities) return closed_mesh_volume(mesh, options);
  std::vector<uint32_t> depth = component_depths(mesh);
  uint32_t deepest = *std::max_element(depth.begin(), depth.end());
  Volume result;
  for (uint32_t d = 0; d <= deepest; ++d) {
    TriMesh level;
    std::vector<int64_t> index(mesh.positions_mm.size(), -1);
    for (size_t c = 0; c < components.size(); ++c) {
      if (depth[c] != d) continue;
      for (uint32_t f : components[c].triangles) {
        std::array<uint32_t, 3> t{};
        for (int k = 0; k < 3; ++k) {
          uint32_t v = mesh.triangles[f][size_t(k)];
          if (index[v] < 0) {
            index[v] = int64_t(level.positions_mm.size());
            level.positions_mm.push_back(mesh.positions_mm[v]);
          }
          t[size_t(k)] = uint32_t(index[v]);
        }
        level.triangles.push_back(t);
      }
    }
    if (level.triangles.empty()) continue;
    Volume v = closed_mesh_volume(level, options);
    result = d % 2 == 0 ? unite(result, v) : subtract(result, v);
  }
  return result;
}

Volume unite(const Volume& a, const Volume& b) {
  if (a.empty()) return b;
  if (b.empty()) return a;
  require_same_grid(a, b, "union");
  return wrap_grid(openvdb::tools::csgUnionCopy(*a.impl().grid, *b.impl().grid), a.options());
}

Volume subtract(const Volume& a, const Volume& b) {
  if (a.empty() || b.empty()) return a;
  require_same_grid(a, b, "difference");
  return wrap_grid(openvdb::tools::csgDifferenceCopy(*a.impl().grid, *b.impl().grid), a.options());
}

Volume intersect(const Volume& a, const Volume& b) {
  if (a.empty()) return a;
  if (b.empty()) return b;
  require_same_grid(a, b, "intersection");
  return wrap_grid(openvdb::tools::csgIntersectionCopy(*a.impl().grid, *b.impl().grid), a.options());
}

Volume offset(const Volume& v, double distance_mm) { return offsets(v, {distance_mm}).front(); }

std::vector<Volume> offsets(const Volume& v, const std::vector<double>& distances_mm) {
  const auto [outside, inside] = offset_reach(distances_mm);
  if (v.empty() || (outside == 0 && inside == 0)) return std::vector<Volume>(distances_mm.size(), v);
  // Exact Euclidean offsets: distances to the extracted surface over a band wide enough to hold
  // every moved surface, then shifted. (Re-distancing a narrow band with LevelSetFilter::offset or
  // levelSetRebuild was 30-50x slower on OpenVDB 10; see README.)
  const double band = v.band_mm();
  openvdb::FloatGrid::Ptr distance;
  {
    TriMesh surface = extract_surface(v);
    distance = mesh_distance(surface, v.voxel_size_mm(), outside + band, inside + band, "offset");
  }
  std::vector<Volume> result = shifted_bands(distance, distances_mm, band, v.options());
  for (size_t i = 0; i < distances_mm.size(); ++i)
    if (distances_mm[i] == 0) result[i] = v;
  return result;
}

std::vector<Volume> mesh_offsets(const TriMesh& mesh, const VolumeOptions& options,
                                 const std::vector<double>& distances_mm) {
  if (mesh.triangles.empty()) throw InvalidInput("mesh has no triangles");
  make_level_set_grid(options);  // validates the options
  const auto [outside, inside] = offset_reach(distances_mm);
  for (const MeshComponent& c : mesh_components(mesh))
    if (c.signed_volume_mm3 < 0) throw InvalidInput("a mesh with a cavity cannot be offset from its triangles alone");
  const double band = options.voxel_size_mm * options.half_band_voxels;
  return shifted_bands(mesh_distance(mesh, options.voxel_size_mm, outside + band, inside + band, "offset"),
                       distances_mm, band, options);
}

namespace {

void require_shell_thickness(double thickness_mm) {
  if (!(thickness_mm > 0) || !std::isfinite(thickness_mm))
    throw InvalidInput("shell thickness must be a positive length in mm");
}

}  // namespace

Volume shell(const Volume& v, double thickness_mm) {
  require_shell_thickness(thickness_mm);
  return subtract(v, offset(v, -thickness_mm));
}

Volume shell(const Volume& v, double thickness_mm, const Volume& inward_offset) {
  require_shell_thickness(thickness_mm);
  return subtract(v, inward_offset);
}

}  // namespace lacuna
