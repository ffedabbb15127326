#include "export/mesh_io.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <initializer_list>
#include <iterator>
#include <string>
#include <vector>

#include "errors.h"
#include "export/output_files.h"
#include "geometry.h"
#include "util/random.h"

namespace lacuna {
namespace {

namespace fs = std::filesystem;

// The corner of the unit cube: volume 1/6.
TriMesh tetrahedron() {
  return {{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}},
          {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}}};
}

// |x - c.x| + |y - c.y| + |z - c.z| <= r: volume 4/3 r^3. Coordinates are exact in float.
TriMesh octahedron(const Vec3d& c, double r) {
  TriMesh mesh;
  for (int axis = 0; axis < 3; ++axis) {
    for (double sign : {1.0, -1.0}) {
      Vec3d p = c;
      p[axis] += sign * r;
      mesh.positions_mm.push_back(p);  // index 2 * axis + (sign < 0)
    }
  }
  for (uint32_t sx = 0; sx < 2; ++sx) {
    for (uint32_t sy = 0; sy < 2; ++sy) {
      for (uint32_t sz = 0; sz < 2; ++sz) {
        std::array<uint32_t, 3> t{sx, 2 + sy, 4 + sz};
        if ((sx + sy + sz) % 2 == 1) std::swap(t[1], t[2]);
        mesh.triangles.push_back(t);
      }
    }
  }
  return mesh;
}

// The unit cube as 8 corners and 6 outward quads (0-based).
const double kCubeCorners[8][3] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0},
                                   {0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}};
const int kCubeQuads[6][4] = {{0, 3, 2, 1}, {4, 5, 6, 7}, {0, 1, 5, 4},
                              {2, 3, 7, 6}, {0, 4, 7, 3}, {1, 2, 6, 5}};

struct Bytes {
  std::string data;

  // `value` as `size` little-endian (or big-endian) bytes.
  void put(uint64_t value, size_t size, bool big_endian = false) {
    for (size_t i = 0; i < size; ++i) {
      data += static_cast<char>(value >> (8 * (big_endian ? size - 1 - i : i)) & 0xff);
    }
  }
  // Little-endian fields given as {value, size in bytes}.
  void fields(std::initializer_list<std::pair<uint64_t, size_t>> values) {
    for (auto [value, size] : values) put(value, size);
  }
  void f32(float v) {
    uint32_t bits;
    std::memcpy(&bits, &v, 4);
    put(bits, 4);
  }
  // A PLY value of the given type (uchar, short, int, uint, float or double).
  void ply(double v, const std::string& type, bool big_endian) {
    uint64_t bits = uint64_t(int64_t(v));  // integers: the low bytes are the two's complement
    size_t size = type == "uchar" ? 1 : type == "short" ? 2 : 4;
    if (type == "float") {
      float f = float(v);
      uint32_t narrow;
      std::memcpy(&narrow, &f, 4);
      bits = narrow;
    } else if (type == "double") {
      std::memcpy(&bits, &v, 8);
      size = 8;
    }
    put(bits, size, big_endian);
  }
};

// A binary STL record by record, with whatever count the header should claim.
std::string binary_stl(const std::vector<std::array<float, 9>>& triangles, uint32_t declared) {
  Bytes b;
  b.data.assign(80, ' ');
  b.put(declared, 4);
  for (const auto& t : triangles) {
    for (int i = 0; i < 3; ++i) b.f32(0);
    for (float v : t) b.f32(v);
    b.put(0, 2);
  }
  return b.data;
}

uint32_t crc32(const std::string& data) {
  uint32_t crc = 0xffffffff;
  for (unsigned char c : data) {
    crc ^= c;
    for (int k = 0; k < 8; ++k) crc = (crc >> 1) ^ (0xedb88320u & (0u - (crc & 1)));
  }
  return ~crc;
}

// A zip archive with uncompressed ("stored") entries, enough for hand-made 3MF packages.
std::string stored_zip(const std::vector<std::pair<std::string, std::string>>& files) {
  Bytes out, directory;
  for (const auto& [name, content] : files) {
    uint64_t offset = out.data.size(), crc = crc32(content), size = content.size();
    // Signature, versions, flags, method, time, date (1980-01-01), crc, sizes, name length...
    out.fields({{0x04034b50, 4},
                {20, 2},
                {0, 2},
                {0, 2},
                {0, 2},
                {0x21, 2},
                {crc, 4},
                {size, 4},
                {size, 4},
                {name.size(), 2},
                {0, 2}});
    out.data += name + content;
    directory.fields({{0x02014b50, 4},
                      {20, 2},
                      {20, 2},
                      {0, 2},
                      {0, 2},
                      {0, 2},
                      {0x21, 2},
                      {crc, 4},
                      {size, 4},
                      {size, 4},
                      {name.size(), 2},
                      {0, 2},
                      {0, 2},
                      {0, 2},
                      {0, 2},
                      {0, 4},
                      {offset, 4}});
    directory.data += name;
  }
  uint64_t directory_offset = out.data.size();
  out.data += directory.data;
  out.fields({{0x06054b50, 4},
              {0, 2},
              {0, 2},
              {files.size(), 2},
              {files.size(), 2},
              {directory.data.size(), 4},
              {directory_offset, 4},
              {0, 2}});
  return out.data;
}

std::string package_3mf(const std::string& model_xml) {
  const char* types =
      "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
      "<Types xmlns=\"http://schemas.openxmlformats.org/package/2006/content-types\">"
      "<Default Extension=\"rels\" "
      "ContentType=\"application/vnd.openxmlformats-package.relationships+xml\"/>"
      "<Default Extension=\"model\" "
      "ContentType=\"application/vnd.ms-package.3dmanufacturing-3dmodel+xml\"/>"
      "</Types>";
  const char* rels =
      "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
      "<Relationships xmlns=\"http://schemas.openxmlformats.org/package/2006/relationships\">"
      "<Relationship Target=\"/3D/3dmodel.model\" Id=\"rel0\" "
      "Type=\"http://schemas.microsoft.com/3dmanufacturing/2013/01/3dmodel\"/></Relationships>";
  return stored_zip(
      {{"[Content_Types].xml", types}, {"_rels/.rels", rels}, {"3D/3dmodel.model", model_xml}});
}

// A 3MF model document around `body` (resources and build), in `unit`.
std::string model_xml(const std::string& unit, const std::string& body) {
  return "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<model unit=\"" + unit +
         "\" xml:lang=\"en-US\" "
         "xmlns=\"http://schemas.microsoft.com/3dmanufacturing/core/2015/02\">" +
         body + "</model>";
}

const char* kTetrahedronObject =
    "<object id=\"1\" type=\"model\"><mesh><vertices>"
    "<vertex x=\"0\" y=\"0\" z=\"0\"/><vertex x=\"1\" y=\"0\" z=\"0\"/>"
    "<vertex x=\"0\" y=\"1\" z=\"0\"/><vertex x=\"0\" y=\"0\" z=\"1\"/></vertices><triangles>"
    "<triangle v1=\"0\" v2=\"2\" v3=\"1\"/><triangle v1=\"0\" v2=\"1\" v3=\"3\"/>"
    "<triangle v1=\"0\" v2=\"3\" v3=\"2\"/><triangle v1=\"1\" v2=\"2\" "
    "v3=\"3\"/></triangles></mesh></object>";

std::string ascii_stl_facet(const char* a, const char* b, const char* c) {
  return std::string("  facet normal 0 0 0\n    outer loop\n      vertex ") + a +
         "\n      vertex " + b + "\n      vertex " + c + "\n    endloop\n  endfacet\n";
}

std::string ascii_ply_cube(const std::string& newline) {
  std::string s = "ply" + newline + "format ascii 1.0" + newline + "comment made by hand" +
                  newline + "element vertex 8" + newline + "property float x" + newline +
                  "property float y" + newline + "property float z" + newline + "element face 6" +
                  newline + "property list uchar int vertex_indices" + newline + "end_header" +
                  newline;
  for (const auto& p : kCubeCorners) {
    s += std::to_string(int(p[0])) + " " + std::to_string(int(p[1])) + " " +
         std::to_string(int(p[2])) + newline;
  }
  for (const auto& q : kCubeQuads) {
    s += "4 " + std::to_string(q[0]) + " " + std::to_string(q[1]) + " " + std::to_string(q[2]) +
         " " + std::to_string(q[3]) + newline;
  }
  return s;
}

// A binary cube whose vertex coordinates have the given types, with a colour property and an
// "edge" element that the reader must skip; each face record takes 18 bytes.
std::string binary_ply_cube(bool big_endian, const std::string& x, const std::string& y,
                            const std::string& z, size_t drop_last_bytes = 0) {
  Bytes b;
  b.data =
      std::string("ply\nformat ") + (big_endian ? "binary_big_endian" : "binary_little_endian") +
      " 1.0\nelement vertex 8\nproperty " + x + " x\nproperty uchar red\nproperty " + y +
      " y\nproperty " + z +
      " z\nelement edge 2\nproperty int vertex1\nproperty int vertex2\n"
      "element face 6\nproperty uchar flags\nproperty list uchar uint vertex_index\nend_header\n";
  for (const auto& p : kCubeCorners) {
    b.ply(p[0], x, big_endian);
    b.ply(200, "uchar", big_endian);
    b.ply(p[1], y, big_endian);
    b.ply(p[2], z, big_endian);
  }
  for (int e = 0; e < 4; ++e) b.ply(e, "int", big_endian);
  for (const auto& q : kCubeQuads) {
    b.ply(7, "uchar", big_endian);
    b.ply(4, "uchar", big_endian);
    for (int v : q) b.ply(v, "uint", big_endian);
  }
  b.data.resize(b.data.size() - drop_last_bytes);
  return b.data;
}

bool contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

// The message of the exception of type E that `f` throws, or a description of what happened.
template <typename E>
std::string error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const E& e) {
    return e.what();
  } catch (const std::exception& e) {
    return std::string("unexpected exception: ") + e.what();
  }
  return "no exception";
}

class MeshIoTest : public ::testing::Test {
 protected:
  void SetUp() override {
    static int counter = 0;
    dir_ = fs::temp_directory_path() /
           ("lacuna_mesh_io_test_" + std::to_string(::getpid()) + "_" + std::to_string(counter++));
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  std::string path(const std::string& name) const { return (dir_ / name).string(); }

  std::string write(const std::string& name, const std::string& bytes) const {
    std::ofstream(path(name), std::ios::binary) << bytes;
    return path(name);
  }

  static std::string read(const std::string& file) {
    std::ifstream in(file, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(in), {});
  }

  fs::path dir_;
};

// Each triangle of `read` has the same corner positions as the same triangle of `written`.
void expect_same_triangles(const TriMesh& written, const TriMesh& read) {
  ASSERT_EQ(written.triangles.size(), read.triangles.size());
  for (size_t t = 0; t < written.triangles.size(); ++t) {
    for (int k = 0; k < 3; ++k) {
      EXPECT_EQ(written.positions_mm[written.triangles[t][k]],
                read.positions_mm[read.triangles[t][k]])
          << "triangle " << t << " corner " << k;
    }
  }
}

TEST_F(MeshIoTest, BinaryStlRoundTripWeldsTetrahedron) {
  TriMesh mesh = tetrahedron();
  std::string file = path("tetra.stl");
  write_stl(file, mesh, "solid tetra");
  std::string bytes = read(file);
  ASSERT_EQ(bytes.size(), 84u + 50u * 4u);
  // A header beginning with "solid" would make other readers take the file for ASCII.
  EXPECT_EQ(bytes.substr(0, 19), "binary solid tetra ");
  // The first triangle (0, 2, 1) lies in z = 0 and faces down.
  float normal[3];
  std::memcpy(normal, bytes.data() + 84, 12);
  EXPECT_EQ(normal[0], 0.0f);
  EXPECT_EQ(normal[1], 0.0f);
  EXPECT_EQ(normal[2], -1.0f);

  TriMesh back = read_mesh(file);
  EXPECT_EQ(back.positions_mm.size(), 4u);
  EXPECT_EQ(back.triangles.size(), 4u);
  expect_same_triangles(mesh, back);
  EXPECT_DOUBLE_EQ(signed_volume(back), 1.0 / 6.0);
}

TEST_F(MeshIoTest, BinaryStlRoundTripWeldsOctahedron) {
  TriMesh mesh = octahedron({10.25, -3.5, 7.125}, 2.5);
  std::string file = path("octa.STL");  // the extension is case-insensitive
  write_stl(file, mesh, "octahedron");
  TriMesh back = read_mesh(file);
  EXPECT_EQ(back.positions_mm.size(), 6u);
  EXPECT_EQ(back.triangles.size(), 8u);
  expect_same_triangles(mesh, back);
  EXPECT_NEAR(signed_volume(back), 4.0 / 3.0 * 2.5 * 2.5 * 2.5, 1e-12);
}

TEST_F(MeshIoTest, AsciiStlParsesAndWeldsFloatRoundedCoordinates) {
  // "1.00000001" rounds to the same float as "1", so those two corners weld into one vertex.
  std::string text =
      "solid tetra\n" + ascii_stl_facet("0 0 0", "0 1 0", "1 0 0") +
      ascii_stl_facet("0 0 0", "1.00000001 0 0", "0 0 1") +
      "FACET NORMAL nan nan nan\nOUTER LOOP\nVERTEX 0 0 0\nVERTEX 0 0 1e0\nVERTEX 0 1 0\n"
      "ENDLOOP\nENDFACET\n" +
      ascii_stl_facet("+1 0 0", "0 1 0", "0 0 1") + "endsolid tetra\n";
  TriMesh mesh = read_mesh(write("tetra.stl", text));
  EXPECT_EQ(mesh.positions_mm.size(), 4u);
  EXPECT_EQ(mesh.triangles.size(), 4u);
  EXPECT_EQ(mesh.triangles[1], (std::array<uint32_t, 3>{0, 2, 3}));
  EXPECT_DOUBLE_EQ(signed_volume(mesh), 1.0 / 6.0);

  // The same triangles in binary give the same mesh.
  std::string file = path("binary.stl");
  write_stl(file, mesh, "");
  TriMesh binary = read_mesh(file);
  EXPECT_EQ(binary.positions_mm, mesh.positions_mm);
  EXPECT_EQ(binary.triangles, mesh.triangles);
}

TEST_F(MeshIoTest, ObjCubeOfQuadsWithAllIndexForms) {
  std::string text =
      "# a cube\nmtllib cube.mtl\no cube\n"
      "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 1 1 1 1.0\nv 0 1 1\n\n"
      "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nvn 0 0 1\nvn 0 0 -1\ng side\nusemtl grey\ns off\n"
      "f 1/1/1 4/2/1 3/3/1 2/4/1\n"
      "f 5//2 6//2 7//2 8//2  # top\n"
      "f 1/1 2/2 6/3 5/4\n"
      "f -6 -5 -1 -2\n"
      "f -8/1/1 -4/2/1 -1/3/1 -5/4/1\n"
      "f 2 3 \\\n 7 6\n";
  TriMesh mesh = read_mesh(write("cube.obj", text));
  EXPECT_EQ(mesh.positions_mm.size(), 8u);
  EXPECT_EQ(mesh.triangles.size(), 12u);
  EXPECT_EQ(mesh.triangles[0], (std::array<uint32_t, 3>{0, 3, 2}));
  EXPECT_EQ(mesh.triangles[1], (std::array<uint32_t, 3>{0, 2, 1}));
  EXPECT_EQ(mesh.triangles[6], (std::array<uint32_t, 3>{2, 3, 7}));  // "-6 -5 -1 -2"
  EXPECT_DOUBLE_EQ(signed_volume(mesh), 1.0);
}

TEST_F(MeshIoTest, ObjRelativeIndicesCountFromTheVerticesSoFar) {
  std::string text =
      "v 0 0 0\nv 1 0 0\nv 0 1 0\nf -3 -1 -2\n"  // (0, 2, 1)
      "v 0 0 1\nf -4 -3 -1\nf -4 -1 -2\nf -3 -2 -1\n";
  TriMesh mesh = read_mesh(write("tetra.obj", text));
  EXPECT_EQ(mesh.triangles, tetrahedron().triangles);
  EXPECT_DOUBLE_EQ(signed_volume(mesh), 1.0 / 6.0);
}

TEST_F(MeshIoTest, PlyAsciiLittleAndBigEndianGiveTheSameCube) {
  TriMesh ascii = read_mesh(write("ascii.ply", ascii_ply_cube("\n")));
  TriMesh crlf = read_mesh(write("crlf.ply", ascii_ply_cube("\r\n")));
  TriMesh little =
      read_mesh(write("little.ply", binary_ply_cube(false, "float", "float", "float")));
  TriMesh big = read_mesh(write("big.ply", binary_ply_cube(true, "float", "float", "float")));
  TriMesh mixed = read_mesh(write("mixed.ply", binary_ply_cube(true, "short", "uchar", "double")));
  EXPECT_EQ(ascii.positions_mm.size(), 8u);
  EXPECT_EQ(ascii.triangles.size(), 12u);
  EXPECT_DOUBLE_EQ(signed_volume(ascii), 1.0);
  for (const TriMesh* other : {&crlf, &little, &big, &mixed}) {
    EXPECT_EQ(other->positions_mm, ascii.positions_mm);
    EXPECT_EQ(other->triangles, ascii.triangles);
  }
}

TEST_F(MeshIoTest, ThreeMfRoundTripKeepsCoordinates) {
  TriMesh mesh = octahedron({10.25, -3.5, 7.125}, 2.5);
  std::string file = path("octa.3mf");
  write_3mf(file, mesh,
            {"octahedron", {{"Application", "Lacuna"}, {"Description", "a < b & c > \"d\""}}});
  TriMesh back = read_mesh(file);
  // 3MF stores indices, so nothing is welded or reordered.
  EXPECT_EQ(back.positions_mm, mesh.positions_mm);
  EXPECT_EQ(back.triangles, mesh.triangles);
  EXPECT_NEAR(signed_volume(back), 4.0 / 3.0 * 2.5 * 2.5 * 2.5, 1e-12);
}

TEST_F(MeshIoTest, ThreeMfAndStlKeepEveryFloatCoordinate) {
  // Coordinates from 1e-3 to 1e3 mm with every bit of a float32 in use (89.57946014 is one that
  // six printed decimals would turn into another float): both formats read back bit for bit.
  Random random(11);
  TriMesh mesh;
  for (int i = 0; i < 3000; ++i) {
    const double scale = std::pow(10.0, double(random.next() % 7) - 3);
    mesh.positions_mm.push_back(round_to_output(Vec3d{scale * (2 * random.uniform() - 1), scale * (2 * random.uniform() - 1),
                                                      scale * (2 * random.uniform() - 1)}));
  }
  mesh.positions_mm.push_back(round_to_output(Vec3d{40.33958, 28.509774, -89.57946}));
  while (mesh.positions_mm.size() % 3) mesh.positions_mm.push_back(Vec3d{1, 2, 3 + double(mesh.positions_mm.size())});
  for (uint32_t i = 0; i + 2 < mesh.positions_mm.size(); i += 3) mesh.triangles.push_back({i, i + 1, i + 2});
  write_3mf(path("floats.3mf"), mesh, {});
  const TriMesh back = read_mesh(path("floats.3mf"));
  EXPECT_EQ(back.positions_mm, mesh.positions_mm);
  EXPECT_EQ(back.triangles, mesh.triangles);
}

TEST_F(MeshIoTest, ThreeMfComponentsTransformsAndUnits) {
  // Two instances of the unit tetrahedron in inches: one rotated by 90 degrees about z and moved,
  // one mirrored in x (its triangles must be reversed to stay outward); the build item lifts both.
  std::string body = std::string("<resources>") + kTetrahedronObject +
                     "<object id=\"2\" type=\"model\"><components>"
                     "<component objectid=\"1\" transform=\"0 1 0 -1 0 0 0 0 1 10 20 30\"/>"
                     "<component objectid=\"1\" transform=\"-1 0 0 0 1 0 0 0 1 0 0 0\"/>"
                     "</components></object></resources>"
                     "<build><item objectid=\"2\" transform=\"1 0 0 0 1 0 0 0 1 0 0 5\"/></build>";
  TriMesh mesh = read_mesh(write("parts.3mf", package_3mf(model_xml("inch", body))));
  ASSERT_EQ(mesh.positions_mm.size(), 8u);
  ASSERT_EQ(mesh.triangles.size(), 8u);
  // (1, 0, 0) turns to (0, 1, 0), then moves by (10, 20, 30 + 5) inches.
  EXPECT_DOUBLE_EQ(mesh.positions_mm[1].x, 10 * 25.4);
  EXPECT_DOUBLE_EQ(mesh.positions_mm[1].y, 21 * 25.4);
  EXPECT_DOUBLE_EQ(mesh.positions_mm[1].z, 35 * 25.4);
  EXPECT_DOUBLE_EQ(mesh.positions_mm[5].x, -25.4);
  EXPECT_EQ(mesh.triangles[4], (std::array<uint32_t, 3>{4, 5, 6}));  // (0, 2, 1) reversed
  EXPECT_NEAR(signed_volume(mesh), 2 * 25.4 * 25.4 * 25.4 / 6, 1e-9);

  TriMesh microns = read_mesh(write(
      "micron.3mf",
      package_3mf(model_xml("micron", std::string("<resources>") + kTetrahedronObject +
                                          "</resources><build><item objectid=\"1\"/></build>"))));
  EXPECT_DOUBLE_EQ(microns.positions_mm[3].z, 0.001);
}

TEST_F(MeshIoTest, WritersAreDeterministic) {
  TriMesh mesh = octahedron({1, 2, 3}, 0.75);
  ThreeMfInfo info{"part", {{"Application", "Lacuna"}}};
  write_stl(path("a.stl"), mesh, "Lacuna");
  write_stl(path("b.stl"), mesh, "Lacuna");
  write_3mf(path("a.3mf"), mesh, info);
  write_3mf(path("b.3mf"), mesh, info);
  EXPECT_EQ(read(path("a.stl")), read(path("b.stl")));
  EXPECT_EQ(read(path("a.3mf")), read(path("b.3mf")));
  EXPECT_GT(read(path("a.3mf")).size(), 100u);
  // A different mesh gives different UUIDs, so the packages differ.
  mesh.positions_mm[0].x += 1;
  write_3mf(path("c.3mf"), mesh, info);
  EXPECT_NE(read(path("a.3mf")), read(path("c.3mf")));
}

TEST_F(MeshIoTest, WritersRejectInvalidMeshesAndPaths) {
  TriMesh broken = tetrahedron();
  broken.triangles[2][1] = 9;
  EXPECT_TRUE(contains(error_of<InvalidInput>([&] { write_stl(path("x.stl"), broken, ""); }),
                       "triangle 2 refers to vertex 9"));
  EXPECT_TRUE(contains(error_of<InvalidInput>([&] { write_3mf(path("x.3mf"), broken, {}); }),
                       "triangle 2 refers to vertex 9"));
  EXPECT_TRUE(contains(error_of<InvalidInput>([&] {
                         write_3mf(path("x.3mf"), tetrahedron(), {"p", {{"Recipe", "r"}}});
                       }),
                       "'Recipe' is not a 3MF metadata name"));
  std::string nowhere = path("missing_dir/out.stl");
  EXPECT_TRUE(contains(error_of<IoError>([&] { write_stl(nowhere, tetrahedron(), ""); }), nowhere));
  nowhere = path("missing_dir/out.3mf");
  EXPECT_TRUE(contains(error_of<IoError>([&] { write_3mf(nowhere, tetrahedron(), {}); }), nowhere));
  // Every write and the final close are checked, and a device is not removed after a failure.
  if (fs::exists("/dev/full")) {
    EXPECT_TRUE(contains(error_of<IoError>([&] { write_stl("/dev/full", tetrahedron(), ""); }),
                         "cannot write '/dev/full': No space left on device"));
    EXPECT_TRUE(contains(error_of<IoError>([&] { write_3mf("/dev/full", tetrahedron(), {}); }),
                         "cannot write '/dev/full': No space left on device"));
    EXPECT_TRUE(fs::exists("/dev/full"));
  }
}

struct BadFile {
  std::string name;
  std::string content;
  std::string expected;  // part of the message
};

TEST_F(MeshIoTest, MalformedFilesThrowInvalidInputNamingTheProblem) {
  std::array<float, 9> t0{0, 0, 0, 0, 1, 0, 1, 0, 0}, t1{0, 0, 0, 1, 0, 0, 0, 0, NAN};
  std::string obj_vertices = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";
  std::string ply_header =
      "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
      "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n";
  std::string solid =
      "solid s\n  facet normal 0 0 1\n    outer loop\n      vertex 0 0 0\n      vertex 1 0 0\n";
  std::string binary_solid = binary_stl({t0, t0}, 2);
  binary_solid.replace(0, 5, "solid");
  binary_solid.resize(binary_solid.size() - 10);
  std::string bad_index_3mf = std::string(kTetrahedronObject);
  bad_index_3mf.replace(bad_index_3mf.find("v3=\"3\"/></triangles>"), 6, "v3=\"9\"");

  std::string deep_3mf = std::string("<resources>") + kTetrahedronObject;
  for (int id = 2; id <= 40; ++id) {
    deep_3mf += "<object id=\"" + std::to_string(id) +
                "\" type=\"model\"><components><component objectid=\"" + std::to_string(id - 1) +
                "\"/></components></object>";
  }
  deep_3mf += "</resources><build><item objectid=\"40\"/></build>";

  const std::vector<BadFile> cases = {
      {"truncated.stl", binary_stl({t0}, 2),
       "binary STL declares 2 triangles (184 bytes) but the file has 134 bytes"},
      {"count_too_large.stl", binary_stl({t0}, 1000000),
       "declares 1000000 triangles (50000084 bytes)"},
      {"solid_header_wrong_size.stl", binary_solid, "binary STL declares 2 triangles"},
      {"nan.stl", binary_stl({t0, t1}, 2),
       "triangle 1 (byte offset 134): vertex 2 has a non-finite coordinate"},
      {"no_triangles.stl", binary_stl({}, 0), "has no triangles"},
      {"short.stl", "abc", "the file has 3 bytes: too short for a binary STL"},
      {"empty.stl", "", "the file is empty"},
      {"missing_endloop.stl", solid + "      vertex 0 1 0\n    endfacet\n",
       "line 7: expected 'endloop', got 'endfacet'"},
      {"two_vertices.stl", solid + "    endloop\n",
       "line 6: expected 'vertex x y z', got 'endloop'"},
      {"short_vertex.stl", solid + "      vertex 1 2\n",
       "line 6: expected 'vertex x y z', got 'vertex 1 2'"},
      {"overflow.stl", solid + "      vertex 1e39 0 0\n",
       "line 6: vertex 2 of facet 0 has a coordinate that is not a finite float"},
      {"no_endsolid.stl", solid + "      vertex 0 1 0\n    endloop\n  endfacet\n",
       "expected 'facet normal nx ny nz' or 'endsolid' but the file ends after line 8"},
      {"face_index_zero.obj", obj_vertices + "f 0 1 2\n", "line 4: vertex index 0"},
      {"index_beyond.obj", obj_vertices + "f 1 2 3\nf 1 2 9\n",
       "line 5: vertex index 9 is beyond the 3 vertices"},
      {"two_corners.obj", obj_vertices + "f 1 2\n",
       "line 4: a face needs at least 3 vertices, got 2"},
      {"bad_number.obj", "v 0 0 0\nv 1 0 zero\n",
       "line 2: expected 'v x y z [w]', got 'v 1 0 zero'"},
      {"bad_corner.obj", obj_vertices + "f 1/x 2 3\n",
       "line 4: expected a face vertex 'i', 'i/t', 'i//n' or 'i/t/n', got '1/x'"},
      {"relative_too_far.obj", obj_vertices + "f -1 -2 -4\n",
       "line 4: relative vertex index -4 reaches before the first vertex"},
      {"nan.obj", "v nan 0 0\n", "line 1: vertex 1 has a non-finite coordinate"},
      {"unknown.obj", obj_vertices + "bogus 1 2\n", "line 4: unknown statement 'bogus'"},
      {"no_faces.obj", obj_vertices, "has no triangles"},
      {"no_end_header.ply", "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\n",
       "expected 'end_header' but the file ends after line 4"},
      {"huge_count.ply",
       "ply\nformat ascii 1.0\nelement vertex 4000000000\nproperty float x\nproperty float y\n"
       "property float z\nelement face 0\nproperty list uchar int vertex_indices\nend_header\n"
       "0 0 0\n",
       "line 3: declares 4000000000 vertex records of at least 2 bytes, but only 6 bytes remain"},
      {"huge_count_binary.ply",
       "ply\nformat binary_little_endian 1.0\nelement vertex 4000000000\nproperty float x\n"
       "property float y\nproperty float z\nelement face 0\n"
       "property list uchar int vertex_indices\nend_header\n0123456789AB",
       "declares 4000000000 vertex records of at least 12 bytes, but only 12 bytes remain"},
      {"truncated_binary.ply", binary_ply_cube(false, "float", "float", "float", 30),
       "binary data ends inside face 4 of 6 (byte offset"},
      {"face_out_of_range.ply", ply_header + "0 0 0\n1 0 0\n0 1 0\n3 0 1 3\n",
       "line 13: face 0: vertex index 3 is out of range (3 vertices)"},
      {"bad_value.ply", ply_header + "0 0 0\n1 0 0\n0 1 x\n3 0 1 2\n",
       "line 12: vertex 2: expected a number, got 'x'"},
      {"extra_value.ply", ply_header + "0 0 0 7\n",
       "line 10: vertex 0: more values than its properties"},
      {"unknown_format.ply", "ply\nformat binary_middle_endian 1.0\nend_header\n",
       "line 2: unknown format 'binary_middle_endian'"},
      {"no_face.ply",
       "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\n"
       "property float z\nend_header\n0 0 0\n",
       "the header declares no 'face' element"},
      {"not_ply.ply", "solid cube\n", "line 1: expected 'ply', got 'solid cube'"},
      {"not_a_zip.3mf", "this is not a zip archive", "not a readable 3MF package"},
      {"empty.3mf", "", "the file is empty"},
      {"bad_xml.3mf", package_3mf("<model unit=\"millimeter\"><resources><object"),
       "not a readable 3MF package"},
      {"bad_index.3mf",
       package_3mf(model_xml(
           "millimeter",
           "<resources>" + bad_index_3mf + "</resources><build><item objectid=\"1\"/></build>")),
       "not a readable 3MF package"},
      {"deep.3mf", package_3mf(model_xml("millimeter", deep_3mf)),
       "components nest more than 32 levels deep"},
      {"part.xyz", "0 0 0\n", "unknown mesh format '.xyz' (expected .stl, .obj, .ply, .3mf or .drc)"},
      {"no_extension", "solid\n", "the file name has no extension"},
  };
  ASSERT_GE(cases.size(), 20u);
  for (const BadFile& bad : cases) {
    std::string file = write(bad.name, bad.content);
    std::string message = error_of<InvalidInput>([&] { read_mesh(file); });
    EXPECT_TRUE(contains(message, file) && contains(message, bad.expected))
        << bad.name << ": expected '" << bad.expected << "', got '" << message << "'";
  }
}

TEST_F(MeshIoTest, MissingFilesAndDirectoriesThrowIoError) {
  std::string missing = path("missing.stl");
  EXPECT_TRUE(contains(error_of<IoError>([&] { read_mesh(missing); }), missing));
  fs::create_directory(path("folder.obj"));
  std::string message = error_of<IoError>([&] { read_mesh(path("folder.obj")); });
  EXPECT_TRUE(contains(message, "folder.obj") && contains(message, "directory")) << message;
}

TEST_F(MeshIoTest, AbsurdSizesThrowResourceLimitBeforeAllocating) {
  ReadOptions tiny;
  tiny.max_memory_bytes = 1000;
  std::array<float, 9> t{0, 0, 0, 0, 1, 0, 1, 0, 0};
  std::string message;
  std::string stl = write("many.stl", binary_stl(std::vector<std::array<float, 9>>(100, t), 100));
  EXPECT_TRUE(contains(error_of<ResourceLimit>([&] { read_mesh(stl, tiny); }),
                       "many.stl: 100 triangles need about"));
  std::string ply = write("many.ply", binary_ply_cube(false, "float", "float", "float"));
  tiny.max_memory_bytes = 100;
  EXPECT_TRUE(contains(error_of<ResourceLimit>([&] { read_mesh(ply, tiny); }),
                       "many.ply: 8 vertices and 6 faces"));
  std::string package = path("big.3mf");
  write_3mf(package, octahedron({0, 0, 0}, 1), {});
  tiny.max_memory_bytes = 1000;
  message = error_of<ResourceLimit>([&] { read_mesh(package, tiny); });
  EXPECT_TRUE(contains(message, "big.3mf: the 3MF package unpacks to")) << message;
  // Five levels of ten components each place 10^5 tetrahedra, counted before any is copied.
  std::string objects = kTetrahedronObject;
  for (int id = 2; id <= 6; ++id) {
    objects += "<object id=\"" + std::to_string(id) + "\" type=\"model\"><components>";
    for (int k = 0; k < 10; ++k) {
      objects += "<component objectid=\"" + std::to_string(id - 1) +
                 "\" transform=\"1 0 0 0 1 0 0 0 1 " + std::to_string(2 * k) + " 0 0\"/>";
    }
    objects += "</components></object>";
  }
  std::string instances =
      write("instances.3mf", package_3mf(model_xml("millimeter", "<resources>" + objects +
                                                                     "</resources><build><item "
                                                                     "objectid=\"6\"/></build>")));
  tiny.max_memory_bytes = 1 << 20;
  message = error_of<ResourceLimit>([&] { read_mesh(instances, tiny); });
  EXPECT_TRUE(
      contains(message, "instances.3mf: the build holds 400000 vertices and 400000 triangles"))
      << message;
  std::string obj = write("many.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nv 1 1 1\n");
  tiny.max_memory_bytes = 100;
  EXPECT_TRUE(
      contains(error_of<ResourceLimit>([&] { read_mesh(obj, tiny); }), "many.obj: 5 vertices"));
}

TEST_F(MeshIoTest, ComponentBombIsRefusedBeforeLib3mfExpandsIt) {
  // Twelve levels of ten components: 10^12 instances in a few kilobytes. lib3mf 1.8 would walk
  // every path while reading; the scan before it refuses the file at once.
  std::string objects = kTetrahedronObject;
  for (int id = 2; id <= 13; ++id) {
    objects += "<object id=\"" + std::to_string(id) + "\" type=\"model\"><components>";
    for (int k = 0; k < 10; ++k) objects += "<component objectid=\"" + std::to_string(id - 1) + "\"/>";
    objects += "</components></object>";
  }
  std::string bomb = write("bomb.3mf", package_3mf(model_xml("millimeter", "<resources>" + objects +
                                                                              "</resources><build><item "
                                                                              "objectid=\"13\"/></build>")));
  auto start = std::chrono::steady_clock::now();
  std::string message = error_of<ResourceLimit>([&] { read_mesh(bomb); });
  EXPECT_TRUE(contains(message, "bomb.3mf: the build expands to 1e+12 object instances")) << message;
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), 2.0);
  // A cycle of components is an error of the file.
  std::string cycle = write("cycle.3mf", package_3mf(model_xml(
      "millimeter", std::string("<resources>") + kTetrahedronObject +
                        "<object id=\"2\" type=\"model\"><components><component objectid=\"3\"/></components></object>"
                        "<object id=\"3\" type=\"model\"><components><component objectid=\"2\"/></components></object>"
                        "</resources><build><item objectid=\"2\"/></build>")));
  EXPECT_TRUE(contains(error_of<InvalidInput>([&] { read_mesh(cycle); }), "refer back to themselves"));
}

TEST_F(MeshIoTest, FormatNamesAndExtensions) {
  EXPECT_EQ(mesh_format_from_path("a/b.Obj"), MeshFormat::kObj);
  EXPECT_EQ(mesh_format_from_path("part.3MF"), MeshFormat::k3mf);
  EXPECT_STREQ(mesh_format_name(MeshFormat::kPly), "PLY");
  EXPECT_THROW(mesh_format_from_path("part.stl.gz"), InvalidInput);
}

TEST_F(MeshIoTest, OutputTransactionCommitsAllOrNothing) {
  std::string kept = write("kept.txt", "old");
  std::string fresh = path("fresh.txt");
  {
    OutputTransaction transaction;
    std::string temp = transaction.stage(kept);
    EXPECT_EQ(fs::path(temp).parent_path(), dir_);
    EXPECT_EQ(fs::path(temp).filename().string().rfind(".kept.txt.tmp-", 0), 0u) << temp;
    std::ofstream(temp) << "new";
    std::ofstream(transaction.stage(fresh)) << "fresh";
    EXPECT_THROW(transaction.stage(kept), InvalidInput);
  }  // destroyed without commit: rolls back
  EXPECT_EQ(read(kept), "old");
  EXPECT_FALSE(fs::exists(fresh));
  EXPECT_EQ(std::distance(fs::directory_iterator(dir_), fs::directory_iterator()), 1);

  OutputTransaction transaction;
  std::ofstream(transaction.stage(kept)) << "new";
  std::ofstream(transaction.stage(fresh)) << "fresh";
  transaction.commit();
  EXPECT_EQ(read(kept), "new");
  EXPECT_EQ(read(fresh), "fresh");
  EXPECT_EQ(std::distance(fs::directory_iterator(dir_), fs::directory_iterator()), 2);

  // A staged file that was never written cannot be renamed.
  OutputTransaction unwritten;
  unwritten.stage(path("never.txt"));
  EXPECT_TRUE(contains(error_of<IoError>([&] { unwritten.commit(); }), "never.txt"));

  write_text_file_atomically(path("report.json"), "{}\n");
  EXPECT_EQ(read(path("report.json")), "{}\n");
  EXPECT_EQ(std::distance(fs::directory_iterator(dir_), fs::directory_iterator()), 3);
  EXPECT_THROW(write_text_file_atomically(path("missing_dir/report.json"), "{}"), IoError);
}

}  // namespace
}  // namespace lacuna
