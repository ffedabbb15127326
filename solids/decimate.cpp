#include "solids/decimate.h"

// MeshIO before the kernels (OpenMesh's rule), although no file is read here.
#include <OpenMesh/Core/IO/MeshIO.hh>
#include <OpenMesh/Core/Mesh/TriMesh_ArrayKernelT.hh>
#include <OpenMesh/Tools/Decimater/DecimaterT.hh>
#include <OpenMesh/Tools/Decimater/ModNormalFlippingT.hh>
#include <OpenMesh/Tools/Decimater/ModQuadricT.hh>

#include <cmath>
#include <string>

#include "errors.h"
#include "util/progress.h"

namespace lacuna {
namespace {

struct DoubleTraits : public OpenMesh::DefaultTraits {
  typedef OpenMesh::Vec3d Point;
  typedef OpenMesh::Vec3d Normal;
  VertexAttributes(OpenMesh::Attributes::Status);
  EdgeAttributes(OpenMesh::Attributes::Status);
  FaceAttributes(OpenMesh::Attributes::Status | OpenMesh::Attributes::Normal);
};
using Mesh = OpenMesh::TriMesh_ArrayKernelT<DoubleTraits>;

}  // namespace

TriMesh decimate(const TriMesh& in, const DecimateOptions& options) {
  if (!(options.max_deviation_mm > 0) || !std::isfinite(options.max_deviation_mm))
    throw InvalidInput("decimation needs a positive maximum deviation in mm");
  Progress progress("decimate", 3);
  Mesh mesh;
  std::vector<Mesh::VertexHandle> handles;
  handles.reserve(in.positions_mm.size());
  for (const Vec3d& p : in.positions_mm) handles.push_back(mesh.add_vertex(Mesh::Point(p.x, p.y, p.z)));
  for (const auto& t : in.triangles) {
    auto f = mesh.add_face(handles[t[0]], handles[t[1]], handles[t[2]]);
    if (!f.is_valid()) throw InvalidInput("decimation needs an edge-manifold, consistently oriented triangle mesh");
  }
  mesh.update_face_normals();
  progress.advance();

  OpenMesh::Decimater::DecimaterT<Mesh> decimater(mesh);
  OpenMesh::Decimater::ModQuadricT<Mesh>::Handle quadric;
  OpenMesh::Decimater::ModNormalFlippingT<Mesh>::Handle flipping;
  decimater.add(quadric);
  decimater.add(flipping);
  // The quadric error of a vertex is the sum of its squared distances to the planes of the
  // original faces merged into it, so bounding it by deviation^2 keeps every vertex within the
  // deviation of each of those planes. (OpenMesh's Hausdorff module bounds the true distance but
  // took over five minutes on 830 000 triangles.)
  decimater.module(quadric).set_max_err(options.max_deviation_mm * options.max_deviation_mm);
  decimater.module(flipping).set_max_normal_deviation(options.max_normal_change_deg);
  if (!decimater.initialize()) throw std::logic_error("the decimater did not initialise");
  decimater.decimate();
  mesh.garbage_collection();
  progress.advance();

  TriMesh out;
  out.positions_mm.reserve(mesh.n_vertices());
  for (auto v : mesh.vertices()) {
    const Mesh::Point& p = mesh.point(v);
    out.positions_mm.push_back(Vec3d{p[0], p[1], p[2]});
  }
  out.triangles.reserve(mesh.n_faces());
  for (auto f : mesh.faces()) {
    std::array<uint32_t, 3> t{};
    int k = 0;
    for (auto v : mesh.fv_range(f)) t[size_t(k++)] = uint32_t(v.idx());
    out.triangles.push_back(t);
  }
  return out;
}

}  // namespace lacuna
