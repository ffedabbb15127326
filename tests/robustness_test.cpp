// Hostile and careless use of the `lacuna` program: degenerate and deeply nested input, non-finite
// options, files that never end, names that leave the output folder, budgets that must hold before
// anything large is allocated, interruption by signals, and two runs into one folder.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <regex>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "errors.h"
#include "export/output_files.h"
#include "geometry.h"
#include "solids/region.h"
#include "tests/test_support.h"

namespace lacuna {
namespace {

namespace fs = std::filesystem;

using test::lacuna;
using test::quote;
using test::read_file;
using test::run;
using test::Result;
using test::TempDir;
using test::write_file;

// Every entry of a folder, hidden ones included.
std::vector<std::string> entries(const fs::path& dir) {
  std::vector<std::string> names;
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(dir, ec)) names.push_back(e.path().filename().string());
  std::sort(names.begin(), names.end());
  return names;
}

// A message a user can read: short, and without numbers printed to 309 digits.
void expect_short_message(const std::string& err, const std::string& what) {
  EXPECT_LT(err.size(), 600u) << what << ": " << err;
  EXPECT_FALSE(std::regex_search(err, std::regex("[0-9]{20}"))) << what << ": " << err;
}

std::string nested_products(int levels) {
  std::string s = "\"sierpinski_triangle\"";
  for (int i = 0; i < levels; ++i) s = "{\"product\": [" + s + ", \"koch_curve\"]}";
  return s;
}

std::string nested_restricts(int levels) {
  std::string s = "\"sierpinski_triangle\"";
  for (int i = 0; i < levels; ++i) s = "{\"restrict\": " + s + ", \"drop_symbols\": []}";
  return s;
}

std::string region_recipe(const std::string& loops) {
  return R"({"voxel_size_mm": 0.2, "inputs": {"r": {"type": "region", "loops_mm": )" + loops +
         R"(, "height_mm": 1}}, "outputs": [{"of": "r", "file": "r.stl"}]})";
}

const char* kSphere = R"({"voxel_size_mm": 0.2, "inputs": {"s": {"type": "sphere", "radius_mm": 2}},
                          "outputs": [{"of": "s", "file": "s.stl"}]})";

struct HostileCase {
  const char* name;
  std::string recipe;
  int code;            // the exit code expected
  const char* expect;  // a fragment the message must hold
};

std::vector<HostileCase> hostile_cases() {
  const std::string deep_json = "{\"inputs\": {\"c\": {\"type\": \"cifs\", \"level\": 1, \"radius_mm\": 0.1, \"system\": " +
                                nested_products(6000) + "}}, \"outputs\": [{\"of\": \"c\", \"file\": \"c.stl\"}]}";
  const std::string deep_system = "{\"inputs\": {\"c\": {\"type\": \"cifs\", \"level\": 1, \"as\": \"edges\", \"radius_mm\": 0.1, "
                                  "\"system\": " + nested_restricts(20) + "}}, \"outputs\": [{\"of\": \"c\", \"file\": \"c.stl\"}]}";
  std::string nul_output = R"({"inputs": {"s": {"type": "sphere", "radius_mm": 1}},
      "outputs": [{"of": "s", "file": "a.stl"}, {"of": "s", "file": "a.stl\u0000.3mf"}]})";
  return {
      {"collinear_loop", region_recipe("[[[0, 0], [1, 0], [2, 0]]]"), 2, "lie on one line"},
      {"repeated_point_loop", region_recipe("[[[0, 0], [0, 0], [0, 0]]]"), 2, "lie on one line"},
      {"identical_loops", region_recipe("[[[0, 0], [5, 0], [5, 5], [0, 5]], [[0, 0], [5, 0], [5, 5], [0, 5]]]"), 2,
       "enclose no area"},
      {"deep_json", deep_json, 2, "nested deeper than 64 levels"},
      {"deep_system", deep_system, 2, "systems nest deeper than 16 levels"},
      {"name_escapes", R"({"name": "../../escaped", "inputs": {"s": {"type": "sphere", "radius_mm": 1}},
          "outputs": [{"of": "s", "file": "s.stl"}]})", 2, "expected a plain name"},
      {"name_absolute", R"({"name": "/tmp/escaped", "inputs": {"s": {"type": "sphere", "radius_mm": 1}},
          "outputs": [{"of": "s", "file": "s.stl"}]})", 2, "expected a plain name"},
      {"nul_in_output_name", nul_output, 2, "NUL character"},
      {"control_in_output_name", R"({"inputs": {"s": {"type": "sphere", "radius_mm": 1}},
          "outputs": [{"of": "s", "file": "x\u0001.stl"}]})", 2, "control characters"},
      {"nul_in_report_name", R"({"inputs": {"s": {"type": "sphere", "radius_mm": 1}},
          "outputs": [{"of": "s", "file": "report.json\u0000.stl"}]})", 2, "NUL character"},
      {"tiny_lattice_period_in_infill", R"({"voxel_size_mm": 0.3, "inputs": {"hull": {"type": "sphere", "radius_mm": 5},
          "lat": {"type": "lattice", "cell": "cubic", "period_mm": 1e-300, "strut_radius_mm": 0.3, "fit_to": "hull"}},
          "operations": [{"name": "p", "op": "infill", "hull": "hull", "structure": "lat", "skin_mm": 1}],
          "outputs": [{"of": "p", "file": "p.stl"}]})", 2, "more than 10 000 000 struts"},
      {"huge_conforming_inset", R"({"voxel_size_mm": 0.3, "inputs": {"hull": {"type": "sphere", "radius_mm": 5},
          "lat": {"type": "lattice", "cell": "cubic", "period_mm": 2, "strut_radius_mm": 0.3, "fit_to": "hull",
                  "layout": "conforming", "inset_mm": 1e9}},
          "operations": [{"name": "p", "op": "infill", "hull": "hull", "structure": "lat", "skin_mm": 1}],
          "outputs": [{"of": "p", "file": "p.stl"}]})", 2, "no strut is left"},
      {"one_radius_for_two_centres", R"({"inputs": {"s": {"type": "spheres", "centers_mm": [[0, 0, 0], [3, 0, 0]],
          "radii_mm": [1]}}, "outputs": [{"of": "s", "file": "s.stl"}]})", 2, "one radius per centre (2)"},
      {"one_radius_for_three_points", R"({"inputs": {"t": {"type": "tubes", "polylines": [{"points_mm":
          [[0, 0, 0], [3, 0, 0], [3, 3, 0]], "radii_mm": [1]}]}}, "outputs": [{"of": "t", "file": "t.stl"}]})", 2,
       "one radius per point (3)"},
      {"fit_to_itself", R"({"inputs": {"a": {"type": "lattice", "cell": "cubic", "period_mm": 2, "strut_radius_mm": 0.3,
          "fit_to": "a"}}, "outputs": [{"of": "a", "file": "a.stl"}]})", 2, "refers to itself"},
      {"huge_voxel", R"({"voxel_size_mm": 1e308, "inputs": {"s": {"type": "sphere", "radius_mm": 1}},
          "outputs": [{"of": "s", "file": "s.stl"}]})", 2, "0.0001 to 1000 mm"},
      {"attractor_without_pieces", R"({"inputs": {"c": {"type": "cifs", "level": 2, "as": "edges", "radius_mm": 0.1,
          "system": {"restrict": "sierpinski_triangle", "drop_symbols": [0, 1, 2]}}},
          "outputs": [{"of": "c", "file": "c.stl"}]})", 2, "makes no geometry"},
      {"offset_deeper_than_the_part", R"({"inputs": {"s": {"type": "sphere", "radius_mm": 1}},
          "operations": [{"name": "o", "op": "offset", "of": "s", "distance_mm": -1e9}],
          "outputs": [{"of": "o", "file": "o.stl"}]})", 2, "leaves nothing of \"s\""},
      {"cifs_pieces_far_below_a_voxel", R"({"inputs": {"c": {"type": "cifs", "system": "sierpinski_triangle",
          "level": 14, "as": "edges", "radius_mm": 0.1}}, "outputs": [{"of": "c", "file": "c.stl"}]})", 2,
       "change no voxel"},
      {"cifs_pieces_beyond_the_stream_bound", R"({"inputs": {"c": {"type": "cifs", "system": "koch_curve", "level": 14,
          "as": "edges", "radius_mm": 0.01}}, "outputs": [{"of": "c", "file": "c.stl"}]})", 3, "more than 20000000"},
  };
}

TEST(Robustness, HostileRecipesAreRefusedWithShortMessagesAndNothingWritten) {
  for (const HostileCase& c : hostile_cases()) {
    TempDir dir;
    const fs::path recipe = dir / (std::string(c.name) + ".json");
    write_file(recipe, c.recipe);
    Result r = lacuna("run " + quote(recipe.string()) + " -o " + quote((dir / "out").string()), dir.path());
    EXPECT_EQ(r.code, c.code) << c.name << ": " << r.err;
    EXPECT_NE(r.err.find(c.expect), std::string::npos) << c.name << ": expected \"" << c.expect << "\" in: " << r.err;
    EXPECT_NE(r.err.find(c.name), std::string::npos) << c.name << ": the message should name the file: " << r.err;
    EXPECT_EQ(r.err.find("did you mean \"a\""), std::string::npos) << c.name << ": " << r.err;
    expect_short_message(r.err, c.name);
    EXPECT_FALSE(fs::exists(dir / "out")) << c.name;
    EXPECT_EQ(entries(dir.path()), std::vector<std::string>{recipe.filename().string()}) << c.name;
  }
  // The recipe's name stays inside the working folder: nothing appeared two levels up either.
  EXPECT_FALSE(fs::exists(fs::temp_directory_path().parent_path() / "escaped-out"));
}

TEST(Robustness, TwoIdenticalLoopsCancelUnderTheEvenOddRule) {
  Region2 region;
  const std::vector<Vec2d> square = {{0, 0}, {4, 0}, {4, 4}, {0, 4}}, hole = {{1, 1}, {3, 1}, {3, 3}, {1, 3}};
  region.loops_mm = {square, hole};
  region.height_mm = 1;
  EXPECT_DOUBLE_EQ(region_area_mm2(region), 16.0 - 4.0);
  // The hole twice is no hole at all; the square twice leaves only the hole's square... of nothing.
  region.loops_mm = {square, hole, hole};
  EXPECT_DOUBLE_EQ(region_area_mm2(region), 16.0);
  region.loops_mm = {square, square, hole};
  EXPECT_DOUBLE_EQ(region_area_mm2(region), 4.0);
  region.loops_mm = {square, square};
  EXPECT_THROW(extrude_region(region), InvalidInput);
  region.loops_mm = {{{0, 0}, {1, 0}, {2, 0}}};
  EXPECT_THROW(extrude_region(region), InvalidInput);
}

TEST(Robustness, NonFiniteAndOutOfRangeOptionsNameTheOption) {
  TempDir dir;
  write_file(dir / "s.json", kSphere);
  const std::string recipe = quote((dir / "s.json").string());
  struct Case {
    std::string args;
    int code;
    const char* expect;
  };
  const std::vector<Case> cases = {
      {"run " + recipe + " --voxel-size nan", 2, "--voxel-size: expected a finite number"},
      {"run " + recipe + " --voxel-size inf", 2, "--voxel-size: expected a finite number"},
      {"run " + recipe + " --voxel-size -1", 2, "--voxel-size: expected a number of at least 0.0001"},
      {"run " + recipe + " --max-memory nan", 2, "--max-memory: expected a finite number"},
      {"run " + recipe + " --simplify nan", 2, "--simplify: expected a finite number"},
      {"fill pattern --count 1000000000000", 2, "--count"},
      {"fill pattern --c nan", 2, "--c: expected a finite number"},
      {"curve points --surface sphere --tolerance nan", 2, "--tolerance: expected a finite number"},
      {"curve fill-rate --width -1", 2, "--width: expected a number above 0"},
      {"nurbs tessellate --degree 2 --knots 0,nan,2,3 --control-points x.json", 2, "\"nan\" is not a number"},
  };
  for (const Case& c : cases) {
    Result r = lacuna(c.args, dir.path());
    EXPECT_EQ(r.code, c.code) << c.args << ": " << r.err;
    EXPECT_NE(r.err.find(c.expect), std::string::npos) << c.args << ": " << r.err;
    expect_short_message(r.err, c.args);
  }
  EXPECT_EQ(entries(dir.path()), std::vector<std::string>{"s.json"});
}

TEST(Robustness, CheckPrintIsBoundedAndBlamesTheInput) {
  TempDir dir;
  const std::string mesh = quote((fs::path(LACUNA_SOURCE_DIR) / "samples/meshes/egg_hull.stl").string());
  Result nan = lacuna("check " + mesh + " --print --voxel-size nan", dir.path());
  EXPECT_EQ(nan.code, 2) << nan.err;
  Result tiny = lacuna("check " + mesh + " --print --voxel-size 1e-5", dir.path());
  EXPECT_EQ(tiny.code, 2) << tiny.err;
  Result hole = lacuna("check " + mesh + " --print --min-hole 1e-9", dir.path());
  EXPECT_EQ(hole.code, 2) << hole.err;
  EXPECT_NE(hole.err.find("2.5e-10 mm"), std::string::npos) << hole.err;
  EXPECT_EQ(hole.err.find("ArithmeticError"), std::string::npos) << hole.err;
  // 0.001 mm voxels over a 24 mm part: refused before the level set exists, well within a second of
  // work and far below the memory it would take.
  Result fine = lacuna("check " + mesh + " --print --voxel-size 0.001 --max-memory 1", dir.path());
  EXPECT_EQ(fine.code, 3) << fine.err;
  EXPECT_NE(fine.err.find("more than the budget of 1.0 GB"), std::string::npos) << fine.err;
  // A wall thicker than the part: all of it is too thin (3139 mm3, the egg's volume).
  Result wall = lacuna("check " + mesh + " --print --min-wall 1e9 --json", dir.path());
  EXPECT_EQ(wall.code, 4) << wall.err;
  const nlohmann::json j = nlohmann::json::parse(wall.out);
  ASSERT_EQ(j["thin_walls"].size(), 1u);
  EXPECT_NEAR(j["thin_walls"][0]["volume_mm3"].get<double>(), j["volume_mm3"].get<double>(),
              0.03 * j["volume_mm3"].get<double>());
}

TEST(Robustness, FilesThatNeverEndAreRefusedBeforeReading) {
  TempDir dir;
  const fs::path fifo = dir / "fifo.json", mesh_fifo = dir / "fifo.stl";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  ASSERT_EQ(::mkfifo(mesh_fifo.c_str(), 0600), 0);
  for (const std::string& args : {"run " + quote(fifo.string()), std::string("run /dev/zero"),
                                  "cifs info " + quote(fifo.string()),
                                  std::string("nurbs tessellate --degree 2 --knots 0,1,2,3 --control-points /dev/zero"),
                                  "check " + quote(mesh_fifo.string())}) {
    Result r = run("timeout 20 " + quote(LACUNA_BINARY) + " " + args, dir.path());
    EXPECT_EQ(r.code, 2) << args << ": " << r.err;
    EXPECT_NE(r.err.find("not a regular file"), std::string::npos) << args << ": " << r.err;
  }
}

TEST(Robustness, DeepSystemsAreRefusedByTheCifsCommand) {
  TempDir dir;
  write_file(dir / "deep.json", nested_products(6000));
  Result deep = lacuna("cifs info " + quote((dir / "deep.json").string()), dir.path());
  EXPECT_EQ(deep.code, 2) << deep.err;
  EXPECT_NE(deep.err.find("nested deeper than 64 levels"), std::string::npos) << deep.err;
  expect_short_message(deep.err, "deep.json");
  write_file(dir / "nested.json", nested_restricts(17));
  Result nested = lacuna("cifs info " + quote((dir / "nested.json").string()), dir.path());
  EXPECT_EQ(nested.code, 2) << nested.err;
  EXPECT_NE(nested.err.find("systems nest deeper than 16 levels"), std::string::npos) << nested.err;
  write_file(dir / "ok.json", nested_restricts(16));
  EXPECT_EQ(lacuna("cifs info " + quote((dir / "ok.json").string()), dir.path()).code, 0);
}

TEST(Robustness, CurvePointsCountAgainstTheBudget) {
  TempDir dir;
  write_file(dir / "c.json", R"({"inputs": {"c": {"type": "curve", "kind": "hilbert", "orders": "1..5", "radius_mm": 0.5,
      "scale_mm": 10, "surface": "sphere", "tolerance_mm": 1e-13}}, "outputs": [{"of": "c", "file": "c.stl"}]})");
  Result r = lacuna("run " + quote((dir / "c.json").string()) + " -o " + quote((dir / "out").string()) +
                        " --max-memory 0.5 --json",
                    dir.path());
  EXPECT_EQ(r.code, 3) << r.err;
  // 0.5 GB / 128 bytes per point.
  EXPECT_NE(r.err.find("more than 3906250 points"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("raise tolerance_mm"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir / "out"));
}

// A 3MF of a sphere with its model part rewritten by the Python lines `python_edit` (on the text t).
fs::path edited_3mf(const TempDir& dir, const std::string& name, const std::string& python_edit) {
  write_file(dir / "s3.json", R"({"voxel_size_mm": 0.4, "inputs": {"s": {"type": "sphere", "radius_mm": 2}},
                                  "outputs": [{"of": "s", "file": "s.3mf"}]})");
  EXPECT_EQ(lacuna("run " + quote((dir / "s3.json").string()) + " -o " + quote((dir / "m").string()), dir.path()).code, 0);
  const fs::path out = dir / name;
  const std::string script =
      "import zipfile,sys\n"
      "src=zipfile.ZipFile(sys.argv[1]); dst=zipfile.ZipFile(sys.argv[2],'w',zipfile.ZIP_DEFLATED)\n"
      "for e in src.infolist():\n"
      "  d=src.read(e.filename)\n"
      "  if e.filename.endswith('.model'):\n"
      "    t=d.decode()\n" +
      python_edit +
      "    d=t.encode()\n"
      "  dst.writestr(e.filename,d)\n"
      "dst.close()\n";
  write_file(dir / "edit.py", script);
  EXPECT_EQ(run("/usr/bin/python3 " + quote((dir / "edit.py").string()) + " " + quote((dir / "m/s.3mf").string()) + " " +
                    quote(out.string()),
                dir.path())
                .code,
            0);
  return out;
}

TEST(Robustness, MeshReadersAreStrict) {
  TempDir dir;
  // 3MF coordinates that are not numbers: lib3mf alone reads "abc" as 0 and "10abc" as 10.
  for (const char* bad : {"abc", "10abc"}) {
    const fs::path file = edited_3mf(dir, std::string("bad_") + bad + ".3mf",
                                     std::string("    i=t.index('<vertex x=\"')+len('<vertex x=\"'); j=t.index('\"',i)\n") +
                                         "    t=t[:i]+'" + bad + "'+t[j:]\n");
    Result r = lacuna("check " + quote(file.string()), dir.path());
    EXPECT_EQ(r.code, 2) << bad << ": " << r.err;
    EXPECT_NE(r.err.find(std::string("vertex 0: coordinate x=\"") + bad + "\" is not a number"), std::string::npos)
        << r.err;
  }
  const fs::path dtd = edited_3mf(dir, "dtd.3mf", "    i=t.index('<model'); t=t[:i]+'<!DOCTYPE model [ <!ENTITY a \"b\"> ]>'+t[i:]\n");
  Result d = lacuna("check " + quote(dtd.string()), dir.path());
  EXPECT_EQ(d.code, 2) << d.err;
  EXPECT_NE(d.err.find("document type declaration"), std::string::npos) << d.err;
  // A PLY with a face more than its header declares.
  const std::string tetrahedron =
      "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\n"
      "element face 4\nproperty list uchar int vertex_indices\nend_header\n"
      "0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n";
  write_file(dir / "ok.ply", tetrahedron);
  EXPECT_EQ(lacuna("check " + quote((dir / "ok.ply").string()), dir.path()).code, 0);
  write_file(dir / "extra.ply", tetrahedron + "3 1 2 3\n");
  Result extra = lacuna("check " + quote((dir / "extra.ply").string()), dir.path());
  EXPECT_EQ(extra.code, 2) << extra.err;
  EXPECT_NE(extra.err.find("line 18: more data than the header declares 4 vertices and 4 faces"), std::string::npos)
      << extra.err;
  // Found by mesh_fuzz: a property line of the wrong length after a longer line read freed memory.
  write_file(dir / "short.ply", "ply\nformat ascii 1.0\ncomment a line of many words before\nelement vertex 1\n"
                                "property float\nend_header\n");
  Result short_line = lacuna("check " + quote((dir / "short.ply").string()), dir.path());
  EXPECT_EQ(short_line.code, 2) << short_line.err;
  EXPECT_NE(short_line.err.find("expected 'property <type> <name>'"), std::string::npos) << short_line.err;
}

// --- interruption and concurrency ---------------------------------------------------------------

// Starts `lacuna args...` with its output in `log`; returns its process id.
pid_t start_lacuna(const std::vector<std::string>& args, const fs::path& log) {
  const pid_t pid = ::fork();
  if (pid == 0) {
    const int fd = ::open(log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    ::dup2(fd, 1);
    ::dup2(fd, 2);
    std::vector<char*> argv{const_cast<char*>(LACUNA_BINARY)};
    for (const std::string& a : args) argv.push_back(const_cast<char*>(a.c_str()));
    argv.push_back(nullptr);
    ::execv(LACUNA_BINARY, argv.data());
    ::_exit(127);
  }
  return pid;
}

bool has_temporary(const fs::path& dir) {
  for (const std::string& name : entries(dir))
    if (is_output_temporary(name)) return true;
  return false;
}

// A recipe that takes a few seconds and writes two large files.
const char* kSlowRecipe = R"({"voxel_size_mm": 0.15, "simplify_mm": 0,
  "inputs": {"c": {"type": "cifs", "system": "menger_sponge", "level": 3, "fit_to": "box"},
             "box": {"type": "box", "size_mm": [20, 20, 20]}},
  "outputs": [{"of": "c", "file": "sponge.stl"}, {"of": "c", "file": "sponge.3mf"}]})";

TEST(Robustness, SigintAndSigtermLeaveNothingBehind) {
  TempDir dir;
  write_file(dir / "slow.json", kSlowRecipe);
  for (int signal : {SIGINT, SIGTERM}) {
    for (bool while_writing : {false, true}) {
      const fs::path out = dir / "n1";
      const pid_t pid = start_lacuna({"run", (dir / "slow.json").string(), "-o", (out / "n2/n3").string()}, dir / "log");
      // Early: while it reads and voxelizes; late: once its temporaries exist.
      const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(120);
      if (while_writing) {
        while (!has_temporary(out / "n2/n3") && std::chrono::steady_clock::now() < deadline)
          std::this_thread::sleep_for(std::chrono::milliseconds(20));
        EXPECT_TRUE(has_temporary(out / "n2/n3")) << "the run never wrote";
      } else {
        while (!fs::exists(out / "n2/n3") && std::chrono::steady_clock::now() < deadline)
          std::this_thread::sleep_for(std::chrono::milliseconds(20));
      }
      ::kill(pid, signal);
      int status = 0;
      ::waitpid(pid, &status, 0);
      ASSERT_TRUE(WIFSIGNALED(status)) << read_file(dir / "log");
      EXPECT_EQ(WTERMSIG(status), signal);
      EXPECT_NE(read_file(dir / "log").find("unfinished outputs removed"), std::string::npos) << read_file(dir / "log");
      // The folders it created (n1/n2/n3) went with the files.
      EXPECT_FALSE(fs::exists(out)) << signal << " " << while_writing;
    }
  }
  // Into a folder that was there before: the folder and what it held stay, nothing else.
  fs::create_directories(dir / "kept");
  write_file(dir / "kept/old.txt", "old");
  const pid_t pid = start_lacuna({"run", (dir / "slow.json").string(), "-o", (dir / "kept").string()}, dir / "log");
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(120);
  while (!has_temporary(dir / "kept") && std::chrono::steady_clock::now() < deadline)
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  ::kill(pid, SIGTERM);
  ::waitpid(pid, nullptr, 0);
  EXPECT_EQ(entries(dir / "kept"), std::vector<std::string>{"old.txt"});
}

TEST(Robustness, TemporariesOfDeadProcessesAreRemovedAtStart) {
  TempDir dir;
  write_file(dir / "s.json", kSphere);
  const pid_t dead = ::fork();
  if (dead == 0) ::_exit(0);
  ::waitpid(dead, nullptr, 0);
  fs::create_directories(dir / "out");
  const std::string stale = ".s.stl.tmp-" + std::to_string(dead) + "-0";
  const std::string alive = ".s.stl.tmp-" + std::to_string(::getpid()) + "-7";  // this test's: still running
  write_file(dir / "out" / stale, "partial");
  write_file(dir / "out" / alive, "partial");
  write_file(dir / "out" / "notes.txt", "mine");
  Result r = lacuna("run " + quote((dir / "s.json").string()) + " -o " + quote((dir / "out").string()), dir.path());
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(entries(dir / "out"), (std::vector<std::string>{alive, "notes.txt", "report.html", "report.json", "s.stl"}));
}

TEST(Robustness, ABusyOutputFolderIsRefusedClearly) {
  TempDir dir;
  write_file(dir / "s.json", kSphere);
  fs::create_directories(dir / "out");
  // Another run holds the folder (its lock, as a run takes it).
  const int fd = ::open((dir / "out" / kOutputLockName).c_str(), O_RDWR | O_CREAT, 0644);
  ASSERT_GE(fd, 0);
  ASSERT_EQ(::flock(fd, LOCK_EX), 0);
  ASSERT_EQ(::write(fd, "4242", 4), 4);
  Result busy = lacuna("run " + quote((dir / "s.json").string()) + " -o " + quote((dir / "out").string()), dir.path());
  EXPECT_EQ(busy.code, 3) << busy.err;
  EXPECT_NE(busy.err.find("the output folder is busy: another Lacuna run (process 4242) is writing to it"),
            std::string::npos)
      << busy.err;
  EXPECT_EQ(entries(dir / "out"), std::vector<std::string>{kOutputLockName});
  ::close(fd);
  Result free = lacuna("run " + quote((dir / "s.json").string()) + " -o " + quote((dir / "out").string()), dir.path());
  EXPECT_EQ(free.code, 0) << free.err;
  EXPECT_EQ(entries(dir / "out"), (std::vector<std::string>{"report.html", "report.json", "s.stl"}));
}

TEST(Robustness, TwoRunsIntoOneFolderLeaveAConsistentReport) {
  TempDir dir;
  write_file(dir / "a.json", R"({"voxel_size_mm": 0.1, "inputs": {"s": {"type": "sphere", "radius_mm": 3}},
                                 "outputs": [{"of": "s", "file": "a.stl"}]})");
  write_file(dir / "b.json", R"({"voxel_size_mm": 0.1, "inputs": {"s": {"type": "box", "size_mm": [5, 5, 5]}},
                                 "outputs": [{"of": "s", "file": "b.stl"}]})");
  for (int round = 0; round < 3; ++round) {
    fs::remove_all(dir / "out");
    const pid_t a = start_lacuna({"run", (dir / "a.json").string(), "-o", (dir / "out").string()}, dir / "a.log");
    const pid_t b = start_lacuna({"run", (dir / "b.json").string(), "-o", (dir / "out").string()}, dir / "b.log");
    int sa = 0, sb = 0;
    ::waitpid(a, &sa, 0);
    ::waitpid(b, &sb, 0);
    ASSERT_TRUE(WIFEXITED(sa) && WIFEXITED(sb));
    const int ca = WEXITSTATUS(sa), cb = WEXITSTATUS(sb);
    // Each succeeded or was refused as busy; at least one succeeded.
    for (const auto& [code, log] : {std::pair{ca, dir / "a.log"}, std::pair{cb, dir / "b.log"}}) {
      EXPECT_TRUE(code == 0 || code == 3) << read_file(log);
      if (code == 3) {
        EXPECT_NE(read_file(log).find("the output folder is busy"), std::string::npos) << read_file(log);
      }
    }
    EXPECT_TRUE(ca == 0 || cb == 0);
    // report.json (and report.html) describes files that are there, as they are; no lock or temporary is left.
    const nlohmann::json report = nlohmann::json::parse(read_file(dir / "out/report.json"));
    for (const auto& o : report["outputs"]) {
      const std::string file = o["file"].get<std::string>();
      ASSERT_TRUE(fs::exists(file)) << file;
      EXPECT_EQ(fs::file_size(file), 84 + 50 * o["triangles"].get<uint64_t>()) << file;
    }
    const std::vector<std::string> names = entries(dir / "out");
    EXPECT_EQ(names.size(), 2 + size_t(ca == 0) + size_t(cb == 0));
    for (const std::string& name : names) EXPECT_NE(name[0], '.') << name;
  }
}

TEST(Robustness, TetgenStaysWithinTheBudgetAndDiesWithItsParent) {
  TempDir dir;
  write_file(dir / "t.json", R"({"voxel_size_mm": 0.25, "inputs": {"b": {"type": "box", "size_mm": [10, 10, 10]}},
      "outputs": [{"of": "b", "file": "b.inp", "fea": {"max_tet_volume_mm3": 1e-12}}]})");
  Result r = lacuna("run " + quote((dir / "t.json").string()) + " -o " + quote((dir / "out").string()) +
                        " --max-memory 0.4",
                    dir.path());
  EXPECT_EQ(r.code, 3) << r.err;
  EXPECT_NE(r.err.find("TetGen ran out of its memory budget of 0.4 GB"), std::string::npos) << r.err;
  EXPECT_LT(r.seconds, 300);
  EXPECT_FALSE(fs::exists(dir / "out"));

  // Killed (SIGKILL: nothing of it runs), its TetGen child goes too.
  write_file(dir / "u.json", R"({"voxel_size_mm": 0.25, "inputs": {"b": {"type": "box", "size_mm": [10, 10, 10]}},
      "outputs": [{"of": "b", "file": "b.inp", "fea": {"max_tet_volume_mm3": 1e-7}}]})");
  const pid_t parent = start_lacuna({"run", (dir / "u.json").string(), "-o", (dir / "out2").string()}, dir / "log");
  pid_t child = 0;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  while (child == 0 && std::chrono::steady_clock::now() < deadline) {
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
    std::error_code ec;
    for (const auto& process : fs::directory_iterator("/proc", ec)) {
      const std::string stat = read_file(process.path() / "stat");
      const size_t close = stat.rfind(')');
      if (close == std::string::npos) continue;
      std::istringstream fields(stat.substr(close + 1));
      std::string state;
      long ppid = 0;
      if (fields >> state >> ppid && ppid == parent) child = pid_t(std::stol(process.path().filename().string()));
    }
  }
  ASSERT_NE(child, 0) << "TetGen never started: " << read_file(dir / "log");
  ::kill(parent, SIGKILL);
  ::waitpid(parent, nullptr, 0);
  bool gone = false;
  for (int i = 0; i < 100 && !gone; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
    const std::string stat = read_file("/proc/" + std::to_string(child) + "/stat");
    // Gone, or a zombie waiting for init to reap it.
    gone = stat.empty() || stat.find(") Z") != std::string::npos;
  }
  EXPECT_TRUE(gone);
  if (!gone) ::kill(child, SIGKILL);
}

}  // namespace
}  // namespace lacuna
