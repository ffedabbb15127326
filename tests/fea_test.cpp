// Tetrahedral meshes for FEA: TetGen options, volumes, formats read back by independent readers
// (and Gmsh), and CalculiX solving a compression of what Lacuna meshed.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <regex>
#include <set>
#include <sstream>

#include "errors.h"
#include "export/fea.h"
#include "export/mesh_io.h"
#include "solids/check.h"
#include "solids/extract.h"
#include "solids/tetrahedralize.h"
#include "solids/voxelize.h"

namespace lacuna {
namespace {

namespace fs = std::filesystem;

TriMesh cube_mesh(double side) {
  TriMesh m;
  for (int i = 0; i < 8; ++i) m.positions_mm.push_back({i & 1 ? side : 0, i & 2 ? side : 0, i & 4 ? side : 0});
  m.triangles = {{0, 2, 3}, {0, 3, 1}, {4, 5, 7}, {4, 7, 6}, {0, 1, 5}, {0, 5, 4},
                 {2, 6, 7}, {2, 7, 3}, {0, 4, 6}, {0, 6, 2}, {1, 3, 7}, {1, 7, 5}};
  return m;
}

struct Scratch {
  fs::path dir;
  Scratch() {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir = fs::temp_directory_path() / ("lacuna-fea-" + std::string(info->name()) + "-" + std::to_string(::getpid()));
    fs::remove_all(dir);
    fs::create_directories(dir);
  }
  ~Scratch() { fs::remove_all(dir); }
  std::string operator/(const std::string& name) const { return (dir / name).string(); }
};

std::string read_text(const std::string& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

bool have(const char* program) { return std::system((std::string("command -v ") + program + " > /dev/null 2>&1").c_str()) == 0; }

int shell(const std::string& command) {
  int status = std::system(command.c_str());
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

TEST(Fea, SwitchStringFromTypedOptions) {
  TetOptions o;
  EXPECT_EQ(tetgen_switches(o, false), "pzQY");
  o.max_radius_edge_ratio = 1.4;
  o.max_tet_volume_mm3 = 0.01;
  EXPECT_EQ(tetgen_switches(o, false), "pzQq1.4a0.01");  // no -Y: TetGen 1.5 would refine nothing
  o.min_dihedral_deg = 15;
  o.preserve_surface = false;
  EXPECT_EQ(tetgen_switches(o, true), "pzQq1.4/15a0.01A");
  TetOptions bad;
  bad.max_radius_edge_ratio = 0.9;
  EXPECT_THROW(tetgen_switches(bad, false), InvalidInput);
  TetOptions angle_only;
  angle_only.min_dihedral_deg = 10;
  EXPECT_THROW(tetgen_switches(angle_only, false), InvalidInput);
  TetOptions negative;
  negative.max_tet_volume_mm3 = -1;
  EXPECT_THROW(tetgen_switches(negative, false), InvalidInput);
}

TEST(Fea, CubeKeepsItsVolumeAndItsSurface) {
  TriMesh cube = cube_mesh(10);
  TetMesh tets = tetrahedralize(cube, TetOptions{});
  TetReport r = tet_report(tets);
  EXPECT_EQ(r.inverted_tets, 0u);
  EXPECT_NEAR(r.volume_mm3, 1000.0, 1e-6 * 1000);
  // Faces used by one tetrahedron only are the boundary: exactly the input's twelve triangles.
  std::map<std::array<uint32_t, 3>, int> faces;
  for (const auto& t : tets.tets)
    for (int skip = 0; skip < 4; ++skip) {
      std::array<uint32_t, 3> f{};
      int k = 0;
      for (int i = 0; i < 4; ++i)
        if (i != skip) f[size_t(k++)] = t[size_t(i)];
      std::sort(f.begin(), f.end());
      ++faces[f];
    }
  std::set<std::array<double, 9>> boundary, input;
  auto key = [](const std::array<Vec3d, 3>& p) {
    std::array<Vec3d, 3> q = p;
    std::sort(q.begin(), q.end(), [](const Vec3d& a, const Vec3d& b) {
      return std::tie(a.x, a.y, a.z) < std::tie(b.x, b.y, b.z);
    });
    return std::array<double, 9>{q[0].x, q[0].y, q[0].z, q[1].x, q[1].y, q[1].z, q[2].x, q[2].y, q[2].z};
  };
  for (const auto& [f, n] : faces)
    if (n == 1) boundary.insert(key({tets.nodes_mm[f[0]], tets.nodes_mm[f[1]], tets.nodes_mm[f[2]]}));
  for (const auto& t : cube.triangles)
    input.insert(key({cube.positions_mm[t[0]], cube.positions_mm[t[1]], cube.positions_mm[t[2]]}));
  EXPECT_EQ(boundary, input);
}

TEST(Fea, VolumeBoundIsRespected) {
  TetOptions o;
  o.max_tet_volume_mm3 = 0.5;
  TetReport r = tet_report(tetrahedralize(cube_mesh(10), o));
  EXPECT_LE(r.max_tet_volume_mm3, 0.5);
  EXPECT_GE(r.tets, 2000u);  // at least 1000 / 0.5
  EXPECT_NEAR(r.volume_mm3, 1000.0, 1e-6 * 1000);
  EXPECT_EQ(r.inverted_tets, 0u);
}

TEST(Fea, CavitiesStayEmpty) {
  GeometrySet set;
  set.spheres.centers_mm = {{0.05, 0.05, 0.05}};
  set.spheres.radii_mm = {5};
  Volume hollow = shell(voxelize(set, VolumeOptions{0.25, 3.0}), 1.5);
  TriMesh surface = extract_surface(hollow);
  MeshCheckReport check = check_mesh(surface);
  ASSERT_TRUE(check.valid());
  ASSERT_EQ(check.components, 2u);
  TetReport r = tet_report(tetrahedralize(surface, TetOptions{}));
  EXPECT_NEAR(r.volume_mm3, check.volume_mm3, 1e-6 * check.volume_mm3);
  EXPECT_EQ(r.inverted_tets, 0u);
}

TEST(Fea, RegionSeedsGiveMaterialRegions) {
  // Two cubes side by side sharing no face: seeds inside each give regions 0 and 1.
  TriMesh a = cube_mesh(4), b = cube_mesh(4);
  for (Vec3d& p : b.positions_mm) p.x += 6;
  TriMesh both = a;
  for (const Vec3d& p : b.positions_mm) both.positions_mm.push_back(p);
  for (auto t : b.triangles) both.triangles.push_back({t[0] + 8, t[1] + 8, t[2] + 8});
  TetMesh tets = tetrahedralize(both, TetOptions{}, {{2, 2, 2}, {8, 2, 2}});
  ASSERT_EQ(tets.regions.size(), tets.tets.size());
  double volume[2] = {0, 0};
  for (size_t t = 0; t < tets.tets.size(); ++t) {
    const auto& q = tets.tets[t];
    const Vec3d &p0 = tets.nodes_mm[q[0]], &p1 = tets.nodes_mm[q[1]], &p2 = tets.nodes_mm[q[2]], &p3 = tets.nodes_mm[q[3]];
    ASSERT_TRUE(tets.regions[t] == 0 || tets.regions[t] == 1);
    volume[tets.regions[t]] += dot(p1 - p0, cross(p2 - p0, p3 - p0)) / 6;
  }
  EXPECT_NEAR(volume[0], 64, 1e-9);
  EXPECT_NEAR(volume[1], 64, 1e-9);
}

// --- formats, read back -------------------------------------------------------------------------

struct ReadBack {
  size_t nodes = 0, elements = 0;
  Vec3d first_node;
  std::vector<std::vector<uint32_t>> connectivity;
};

ReadBack read_inp(const std::string& path) {
  ReadBack r;
  std::ifstream in(path);
  std::string line, section;
  while (std::getline(in, line)) {
    if (line.rfind("**", 0) == 0) continue;
    if (line[0] == '*') {
      section = line;
      continue;
    }
    if (section.rfind("*NODE", 0) != 0 && section.rfind("*ELEMENT", 0) != 0) continue;
    std::stringstream s(line);
    std::vector<double> v;
    std::string item;
    while (std::getline(s, item, ','))
      if (item.find_first_not_of(" ") != std::string::npos) v.push_back(std::stod(item));
    if (section.rfind("*NODE", 0) == 0) {
      if (r.nodes++ == 0) r.first_node = {v[1], v[2], v[3]};
    } else if (section.rfind("*ELEMENT", 0) == 0) {
      ++r.elements;
      std::vector<uint32_t> c;
      for (size_t i = 1; i < v.size(); ++i) c.push_back(uint32_t(v[i]) - 1);
      r.connectivity.push_back(c);
    }
  }
  return r;
}

ReadBack read_medit(const std::string& path) {
  ReadBack r;
  std::ifstream in(path);
  std::string word;
  while (in >> word) {
    if (word == "Vertices") {
      in >> r.nodes;
      for (size_t i = 0; i < r.nodes; ++i) {
        double x, y, z;
        int ref;
        in >> x >> y >> z >> ref;
        if (i == 0) r.first_node = {x, y, z};
      }
    } else if (word == "Tetrahedra") {
      in >> r.elements;
      for (size_t i = 0; i < r.elements; ++i) {
        std::vector<uint32_t> c(4);
        int ref;
        in >> c[0] >> c[1] >> c[2] >> c[3] >> ref;
        for (auto& x : c) --x;
        r.connectivity.push_back(c);
      }
    }
  }
  return r;
}

ReadBack read_vtu(const std::string& path) {
  ReadBack r;
  std::string text = read_text(path);
  std::smatch m;
  std::regex_search(text, m, std::regex("NumberOfPoints=\"([0-9]+)\" NumberOfCells=\"([0-9]+)\""));
  r.nodes = std::stoul(m[1].str());
  r.elements = std::stoul(m[2].str());
  size_t points = text.find("NumberOfComponents=\"3\" format=\"ascii\">\n") + 38;
  std::stringstream p(text.substr(points));
  p >> r.first_node.x >> r.first_node.y >> r.first_node.z;
  size_t cells = text.find("Name=\"connectivity\" format=\"ascii\">\n") + 35;
  std::stringstream c(text.substr(cells));
  for (size_t i = 0; i < r.elements; ++i) {
    std::vector<uint32_t> q(4);
    c >> q[0] >> q[1] >> q[2] >> q[3];
    r.connectivity.push_back(q);
  }
  return r;
}

// Elements of type 4 (tetrahedra) in a Gmsh 2.2 file.
size_t msh22_tets(const std::string& path) {
  std::ifstream in(path);
  std::string line;
  size_t tets = 0;
  bool elements = false;
  while (std::getline(in, line)) {
    if (line == "$Elements") {
      elements = true;
      std::getline(in, line);
      continue;
    }
    if (line == "$EndElements") elements = false;
    if (elements) {
      std::stringstream s(line);
      int id, type;
      s >> id >> type;
      tets += type == 4;
    }
  }
  return tets;
}

TEST(Fea, FormatsReadBack) {
  Scratch dir;
  TetOptions o;
  o.max_tet_volume_mm3 = 20;
  TetMesh tets = tetrahedralize(cube_mesh(10), o);
  const size_t n = tets.nodes_mm.size(), e = tets.tets.size();
  write_fea(dir / "m.inp", FeaFormat::kInp, tets);
  write_fea(dir / "m.mesh", FeaFormat::kMedit, tets);
  write_fea(dir / "m.vtu", FeaFormat::kVtu, tets);
  for (const ReadBack& r : {read_inp(dir / "m.inp"), read_medit(dir / "m.mesh"), read_vtu(dir / "m.vtu")}) {
    EXPECT_EQ(r.nodes, n);
    EXPECT_EQ(r.elements, e);
    EXPECT_LT(norm(r.first_node - tets.nodes_mm[0]), 1e-11);  // .inp keeps 12 digits (CalculiX's field width)
    ASSERT_EQ(r.connectivity.size(), e);
    for (size_t t = 0; t < e; ++t)
      for (size_t k = 0; k < 4; ++k) ASSERT_EQ(r.connectivity[t][k], tets.tets[t][k]);
  }
  // The node sets hold exactly the nodes on the box's planes.
  std::string inp = read_text(dir / "m.inp");
  size_t at = inp.find("*NSET, NSET=NZMAX\n");
  ASSERT_NE(at, std::string::npos);
  std::string body = inp.substr(at + 18, inp.find('*', at + 1) - at - 18);
  std::replace(body.begin(), body.end(), '\n', ',');  // 16 entries per line
  std::stringstream set(body);
  std::set<size_t> listed;
  std::string item;
  while (std::getline(set, item, ','))
    if (item.find_first_not_of(" \n") != std::string::npos) listed.insert(std::stoul(item));
  std::set<size_t> on_top;
  for (size_t i = 0; i < n; ++i)
    if (tets.nodes_mm[i].z == 10) on_top.insert(i + 1);
  EXPECT_EQ(listed, on_top);
  EXPECT_GE(on_top.size(), 4u);
  // With a node set tolerance, a top node lowered by less than it stays in NZMAX, one lowered by
  // more leaves it (the cube's box is still 10 high: the other top nodes hold it).
  auto nzmax = [&](const std::string& text) {
    const size_t from = text.find("*NSET, NSET=NZMAX\n");
    std::string b = text.substr(from + 18, text.find('*', from + 1) - from - 18);
    std::replace(b.begin(), b.end(), '\n', ',');
    std::stringstream list(b);
    std::set<size_t> ids;
    for (std::string i; std::getline(list, i, ',');)
      if (i.find_first_not_of(" \n") != std::string::npos) ids.insert(std::stoul(i));
    return ids;
  };
  TetMesh lowered = tets;
  const size_t a = *on_top.begin() - 1, b = *std::next(on_top.begin()) - 1;
  lowered.nodes_mm[a].z -= 0.01;
  lowered.nodes_mm[b].z -= 0.03;
  FeaWriteOptions tolerant;
  tolerant.node_set_tolerance_mm = 0.02;
  write_fea(dir / "t.inp", FeaFormat::kInp, lowered, tolerant);
  std::set<size_t> expected = on_top;
  expected.erase(b + 1);
  EXPECT_EQ(nzmax(read_text(dir / "t.inp")), expected);

  // C3D10: one mid-side node per edge of the mesh.
  FeaWriteOptions quadratic;
  quadratic.quadratic = true;
  write_fea(dir / "q.inp", FeaFormat::kInp, tets, quadratic);
  std::set<std::pair<uint32_t, uint32_t>> edges;
  for (const auto& t : tets.tets)
    for (int i = 0; i < 4; ++i)
      for (int j = i + 1; j < 4; ++j) edges.insert({std::min(t[size_t(i)], t[size_t(j)]), std::max(t[size_t(i)], t[size_t(j)])});
  ReadBack q = read_inp(dir / "q.inp");
  EXPECT_EQ(q.nodes, n + edges.size());
  ASSERT_EQ(q.connectivity.size(), e);
  EXPECT_EQ(q.connectivity[0].size(), 10u);

  if (!have("gmsh")) GTEST_SKIP() << "gmsh is not installed";
  for (bool version_2 : {false, true}) {
    FeaWriteOptions w;
    w.msh_version_2 = version_2;
    write_fea(dir / "m.msh", FeaFormat::kMsh, tets, w);
    ASSERT_EQ(shell("gmsh -0 '" + (dir / "m.msh") + "' -o '" + (dir / "g.msh") + "' -format msh22 -save_all > '" +
                    (dir / "gmsh.log") + "' 2>&1"),
              0)
        << read_text(dir / "gmsh.log");
    EXPECT_EQ(msh22_tets(dir / "g.msh"), e) << (version_2 ? "2.2" : "4.1");
  }
}

// --- CalculiX ---------------------------------------------------------------------------------------

// Compresses the block meshed in `mesh_inp` by `strain` along z with symmetry conditions on the
// x, y and z minimum faces (uniaxial stress) and returns the reaction force on the top face.
double calculix_top_force(const Scratch& dir, const std::string& mesh_inp, double height, double strain, double modulus) {
  std::ofstream job(dir / "job.inp");
  job << "*INCLUDE, INPUT=" << mesh_inp << "\n"
      << "*MATERIAL, NAME=SOLID\n*ELASTIC\n" << modulus << ", 0.3\n"
      << "*SOLID SECTION, ELSET=EALL, MATERIAL=SOLID\n"
      << "*BOUNDARY\nNZMIN, 3, 3, 0.\nNXMIN, 1, 1, 0.\nNYMIN, 2, 2, 0.\nNZMAX, 3, 3, " << -strain * height << "\n"
      << "*STEP\n*STATIC\n*NODE PRINT, NSET=NZMAX, TOTALS=ONLY\nRF\n*END STEP\n";
  job.close();
  int code = shell("cd '" + dir.dir.string() + "' && ccx job > ccx.log 2>&1");
  EXPECT_EQ(code, 0) << read_text(dir / "ccx.log");
  std::string dat = read_text(dir / "job.dat");
  std::smatch m;
  std::regex total("total force \\(fx,fy,fz\\) for set NZMAX[^\\n]*\\n\\s*\\n?\\s*([-0-9.E+]+)\\s+([-0-9.E+]+)\\s+([-0-9.E+]+)");
  if (!std::regex_search(dat, m, total)) {
    ADD_FAILURE() << "no total force in job.dat:\n" << dat.substr(0, 2000);
    return 0;
  }
  return -std::stod(m[3].str());  // compression: the top pushes back up
}

TEST(Fea, CalculixSolidCubeHasTheBulkModulus) {
  if (!have("ccx")) GTEST_SKIP() << "calculix-ccx is not installed";
  Scratch dir;
  TetOptions o;
  o.max_tet_volume_mm3 = 5;
  write_fea(dir / "cube.inp", FeaFormat::kInp, tetrahedralize(cube_mesh(10), o));
  const double modulus = 2000, strain = 0.001;
  double force = calculix_top_force(dir, dir / "cube.inp", 10, strain, modulus);
  double effective = force / (100 * strain);
  EXPECT_NEAR(effective, modulus, 0.02 * modulus);
}

TEST(Fea, CalculixLatticeIsSofterThanItsDensity) {
  if (!have("ccx")) GTEST_SKIP() << "calculix-ccx is not installed";
  Scratch dir;
  // A 2 x 2 x 2 strut lattice (5 mm cells, 0.7 mm struts) between two 1 mm plates, meshed by Lacuna.
  std::ofstream recipe(dir / "block.json");
  recipe << R"({"voxel_size_mm": 0.25, "inputs": {
      "struts": {"type": "tubes", "polylines": [)";
  bool first = true;
  for (int a = 0; a <= 2; ++a)
    for (int b = 0; b <= 2; ++b) {
      double u = 0.05 + 5 * a, v = 0.05 + 5 * b;
      for (int axis = 0; axis < 3; ++axis) {
        // A strut along `axis` through (u, v) in the other two coordinates.
        double p[2][3];
        for (int end = 0; end < 2; ++end) {
          p[end][axis] = end ? 10.05 : 0.05;
          p[end][(axis + 1) % 3] = u;
          p[end][(axis + 2) % 3] = v;
        }
        recipe << (first ? "" : ",") << "{\"points_mm\": [[" << p[0][0] << "," << p[0][1] << "," << p[0][2] << "],["
               << p[1][0] << "," << p[1][1] << "," << p[1][2] << "]], \"radius_mm\": 0.7}";
        first = false;
      }
    }
  recipe << R"(]},
      "bottom": {"type": "box", "min_mm": [-0.65, -0.65, -0.95], "max_mm": [10.75, 10.75, 0.05]},
      "top": {"type": "box", "min_mm": [-0.65, -0.65, 10.05], "max_mm": [10.75, 10.75, 11.05]}},
    "operations": [{"name": "block", "op": "union", "of": ["struts", "bottom", "top"]}],
    "outputs": [{"of": "block", "file": "block.inp", "decimate_mm": 0.02, "fea": {"max_tet_volume_mm3": 2}}]})";
  recipe.close();
  ASSERT_EQ(shell(std::string("'") + LACUNA_BINARY + "' run '" + (dir / "block.json") + "' -o '" + (dir / "out") +
                  "' --quiet --json > '" + (dir / "report.json") + "'"),
            0)
      << read_text(dir / "report.json");
  auto report = nlohmann::json::parse(read_text(dir / "report.json"));
  const auto& out = report["outputs"][0];
  EXPECT_TRUE(out["checks"]["valid"].get<bool>());
  EXPECT_NEAR(out["volume_mm3"].get<double>(), out["surface_volume_mm3"].get<double>(),
              1e-5 * out["surface_volume_mm3"].get<double>());
  // Box of the block: 11.4 x 11.4 x 12 mm.
  const double area = 11.4 * 11.4, height = 12.0;
  const double density = out["volume_mm3"].get<double>() / (area * height);
  const double modulus = 2000, strain = 0.001;
  double force = calculix_top_force(dir, dir / "out/block.inp", height, strain, modulus);
  double effective = force * height / (area * height * strain);
  EXPECT_GT(effective, 0);
  EXPECT_LT(effective, modulus * density);  // Voigt's bound
}

}  // namespace
}  // namespace lacuna
