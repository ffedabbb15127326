#include "export/fea.h"

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <map>
#include <memory>
#include <set>

#include "errors.h"

namespace lacuna {
namespace {

class Writer {
 public:
  explicit Writer(const std::string& path) : path_(path), file_(std::fopen(path.c_str(), "wb")) {
    if (!file_) throw IoError(path + ": cannot open for writing");
    std::setvbuf(file_, nullptr, _IOFBF, 1 << 20);
  }
  ~Writer() {
    if (file_) std::fclose(file_);
  }
  template <typename... Args>
  void line(const char* format, Args... args) {
    if (std::fprintf(file_, format, args...) < 0) throw IoError(path_ + ": write failed");
  }
  void close() {
    std::FILE* f = file_;
    file_ = nullptr;
    if (std::fflush(f) != 0 || std::ferror(f) || std::fclose(f) != 0) throw IoError(path_ + ": write failed");
  }

 private:
  std::string path_;
  std::FILE* file_;
};

int region_of(const TetMesh& m, size_t t) { return m.regions.empty() ? 0 : m.regions[t]; }

// Mid-side nodes of every tetrahedron edge, numbered after the corner nodes, in order of first use.
struct MidNodes {
  std::vector<Vec3d> positions;
  std::vector<std::array<uint32_t, 6>> per_tet;  // edges 01, 12, 02, 03, 13, 23 (Abaqus order)
};

MidNodes mid_nodes(const TetMesh& m) {
  MidNodes out;
  std::map<std::pair<uint32_t, uint32_t>, uint32_t> index;
  static const int kEdges[6][2] = {{0, 1}, {1, 2}, {0, 2}, {0, 3}, {1, 3}, {2, 3}};
  for (const auto& t : m.tets) {
    std::array<uint32_t, 6> ids{};
    for (int e = 0; e < 6; ++e) {
      uint32_t a = t[size_t(kEdges[e][0])], b = t[size_t(kEdges[e][1])];
      auto key = std::make_pair(std::min(a, b), std::max(a, b));
      auto [it, fresh] = index.emplace(key, uint32_t(m.nodes_mm.size() + out.positions.size()));
      if (fresh) out.positions.push_back((m.nodes_mm[a] + m.nodes_mm[b]) * 0.5);
      ids[size_t(e)] = it->second;
    }
    out.per_tet.push_back(ids);
  }
  return out;
}

void write_msh(const std::string& path, const TetMesh& m, bool version_2) {
  Writer w(path);
  const size_t n = m.nodes_mm.size(), e = m.tets.size();
  if (version_2) {
    w.line("$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n%zu\n", n);
    for (size_t i = 0; i < n; ++i) w.line("%zu %.17g %.17g %.17g\n", i + 1, m.nodes_mm[i].x, m.nodes_mm[i].y, m.nodes_mm[i].z);
    w.line("$EndNodes\n$Elements\n%zu\n", e);
    for (size_t t = 0; t < e; ++t) {
      const int tag = region_of(m, t) + 1;
      w.line("%zu 4 2 %d %d %u %u %u %u\n", t + 1, tag, tag, m.tets[t][0] + 1, m.tets[t][1] + 1, m.tets[t][2] + 1,
             m.tets[t][3] + 1);
    }
    w.line("$EndElements\n");
  } else {
    // One volume entity per region; nodes in one block.
    std::set<int> regions;
    for (size_t t = 0; t < e; ++t) regions.insert(region_of(m, t) + 1);
    w.line("$MeshFormat\n4.1 0 8\n$EndMeshFormat\n");
    w.line("$Entities\n0 0 0 %zu\n", regions.size());
    for (int r : regions) w.line("%d 0 0 0 0 0 0 0 0\n", r);
    w.line("$EndEntities\n");
    w.line("$Nodes\n1 %zu 1 %zu\n3 %d 0 %zu\n", n, n, *regions.begin(), n);
    for (size_t i = 0; i < n; ++i) w.line("%zu\n", i + 1);
    for (size_t i = 0; i < n; ++i) w.line("%.17g %.17g %.17g\n", m.nodes_mm[i].x, m.nodes_mm[i].y, m.nodes_mm[i].z);
    w.line("$EndNodes\n$Elements\n%zu %zu 1 %zu\n", regions.size(), e, e);
    for (int r : regions) {
      size_t count = 0;
      for (size_t t = 0; t < e; ++t) count += region_of(m, t) + 1 == r;
      w.line("3 %d 4 %zu\n", r, count);
      for (size_t t = 0; t < e; ++t)
        if (region_of(m, t) + 1 == r)
          w.line("%zu %u %u %u %u\n", t + 1, m.tets[t][0] + 1, m.tets[t][1] + 1, m.tets[t][2] + 1, m.tets[t][3] + 1);
    }
    w.line("$EndElements\n");
  }
  w.close();
}

void write_inp(const std::string& path, const TetMesh& m, bool quadratic, double node_set_tolerance_mm) {
  Writer w(path);
  MidNodes mids;
  if (quadratic) mids = mid_nodes(m);
  w.line("** Lacuna " LACUNA_VERSION ": %zu nodes, %zu %s elements (mm)\n", m.nodes_mm.size() + mids.positions.size(),
         m.tets.size(), quadratic ? "C3D10" : "C3D4");
  w.line("*NODE, NSET=NALL\n");
  // CalculiX reads at most 20 characters per number: 12 significant digits (1e-9 mm at 1 m).
  for (size_t i = 0; i < m.nodes_mm.size(); ++i)
    w.line("%zu, %.12g, %.12g, %.12g\n", i + 1, m.nodes_mm[i].x, m.nodes_mm[i].y, m.nodes_mm[i].z);
  for (size_t i = 0; i < mids.positions.size(); ++i)
    w.line("%zu, %.12g, %.12g, %.12g\n", m.nodes_mm.size() + i + 1, mids.positions[i].x, mids.positions[i].y,
           mids.positions[i].z);
  std::set<int> regions;
  for (size_t t = 0; t < m.tets.size(); ++t) regions.insert(region_of(m, t));
  for (int r : regions) {
    w.line("*ELEMENT, TYPE=%s, ELSET=EREGION%d\n", quadratic ? "C3D10" : "C3D4", r);
    for (size_t t = 0; t < m.tets.size(); ++t) {
      if (region_of(m, t) != r) continue;
      const auto& c = m.tets[t];
      if (quadratic) {
        const auto& x = mids.per_tet[t];
        w.line("%zu, %u, %u, %u, %u, %u, %u, %u, %u, %u, %u\n", t + 1, c[0] + 1, c[1] + 1, c[2] + 1, c[3] + 1, x[0] + 1,
               x[1] + 1, x[2] + 1, x[3] + 1, x[4] + 1, x[5] + 1);
      } else {
        w.line("%zu, %u, %u, %u, %u\n", t + 1, c[0] + 1, c[1] + 1, c[2] + 1, c[3] + 1);
      }
    }
  }
  w.line("*ELSET, ELSET=EALL\n");
  size_t on_line = 0;
  for (int r : regions) {
    w.line("%sEREGION%d", on_line++ ? ", " : "", r);
  }
  w.line("\n");
  // Nodes on the bounding box's planes, corner and mid-side alike, for boundary conditions.
  Box3 box;
  for (const Vec3d& p : m.nodes_mm) box.expand(p);
  const double tolerance = std::max(1e-6 * std::max(norm(box.size()), 1e-300), node_set_tolerance_mm);
  const char* names[3][2] = {{"NXMIN", "NXMAX"}, {"NYMIN", "NYMAX"}, {"NZMIN", "NZMAX"}};
  const size_t total = m.nodes_mm.size() + mids.positions.size();
  auto node = [&](size_t i) { return i < m.nodes_mm.size() ? m.nodes_mm[i] : mids.positions[i - m.nodes_mm.size()]; };
  for (int axis = 0; axis < 3; ++axis)
    for (int side = 0; side < 2; ++side) {
      w.line("*NSET, NSET=%s\n", names[axis][side]);
      const double plane = side ? box.max[axis] : box.min[axis];
      size_t count = 0;
      for (size_t i = 0; i < total; ++i)
        if (std::fabs(node(i)[axis] - plane) <= tolerance) w.line("%zu%s", i + 1, ++count % 16 == 0 ? "\n" : ", ");
      if (count % 16 != 0) w.line("\n");
    }
  w.close();
}

void write_vtu(const std::string& path, const TetMesh& m) {
  Writer w(path);
  w.line("<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\" version=\"0.1\" byte_order=\"LittleEndian\">\n");
  w.line("<UnstructuredGrid>\n<Piece NumberOfPoints=\"%zu\" NumberOfCells=\"%zu\">\n", m.nodes_mm.size(), m.tets.size());
  w.line("<Points>\n<DataArray type=\"Float64\" NumberOfComponents=\"3\" format=\"ascii\">\n");
  for (const Vec3d& p : m.nodes_mm) w.line("%.17g %.17g %.17g\n", p.x, p.y, p.z);
  w.line("</DataArray>\n</Points>\n<Cells>\n<DataArray type=\"Int64\" Name=\"connectivity\" format=\"ascii\">\n");
  for (const auto& t : m.tets) w.line("%u %u %u %u\n", t[0], t[1], t[2], t[3]);
  w.line("</DataArray>\n<DataArray type=\"Int64\" Name=\"offsets\" format=\"ascii\">\n");
  for (size_t t = 0; t < m.tets.size(); ++t) w.line("%zu\n", 4 * (t + 1));
  w.line("</DataArray>\n<DataArray type=\"UInt8\" Name=\"types\" format=\"ascii\">\n");
  for (size_t t = 0; t < m.tets.size(); ++t) w.line("10\n");
  w.line("</DataArray>\n</Cells>\n<CellData Scalars=\"region\">\n<DataArray type=\"Int32\" Name=\"region\" format=\"ascii\">\n");
  for (size_t t = 0; t < m.tets.size(); ++t) w.line("%d\n", region_of(m, t));
  w.line("</DataArray>\n</CellData>\n</Piece>\n</UnstructuredGrid>\n</VTKFile>\n");
  w.close();
}

void write_medit(const std::string& path, const TetMesh& m) {
  Writer w(path);
  w.line("MeshVersionFormatted 2\nDimension 3\nVertices\n%zu\n", m.nodes_mm.size());
  for (const Vec3d& p : m.nodes_mm) w.line("%.17g %.17g %.17g 0\n", p.x, p.y, p.z);
  w.line("Tetrahedra\n%zu\n", m.tets.size());
  for (size_t t = 0; t < m.tets.size(); ++t)
    w.line("%u %u %u %u %d\n", m.tets[t][0] + 1, m.tets[t][1] + 1, m.tets[t][2] + 1, m.tets[t][3] + 1, region_of(m, t) + 1);
  w.line("End\n");
  w.close();
}

std::string lower_extension(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  for (char& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
  return ext;
}

}  // namespace

bool is_fea_path(const std::string& path) {
  std::string ext = lower_extension(path);
  return ext == ".msh" || ext == ".inp" || ext == ".vtu" || ext == ".mesh";
}

FeaFormat fea_format_from_path(const std::string& path) {
  std::string ext = lower_extension(path);
  if (ext == ".msh") return FeaFormat::kMsh;
  if (ext == ".inp") return FeaFormat::kInp;
  if (ext == ".vtu") return FeaFormat::kVtu;
  if (ext == ".mesh") return FeaFormat::kMedit;
  throw InvalidInput(path + ": unknown FEA mesh format (expected .msh, .inp, .vtu or .mesh)");
}

void write_fea(const std::string& path, FeaFormat format, const TetMesh& mesh, const FeaWriteOptions& options) {
  switch (format) {
    case FeaFormat::kMsh: return write_msh(path, mesh, options.msh_version_2);
    case FeaFormat::kInp: return write_inp(path, mesh, options.quadratic, options.node_set_tolerance_mm);
    case FeaFormat::kVtu: return write_vtu(path, mesh);
    case FeaFormat::kMedit: return write_medit(path, mesh);
  }
}

}  // namespace lacuna
