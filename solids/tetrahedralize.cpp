#include "solids/tetrahedralize.h"

#include <poll.h>
#include <pthread.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <tetgen.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cerrno>
#include <cstring>
#include <new>
#include <stdexcept>

#include "errors.h"
#include "solids/components.h"
#include "util/progress.h"

namespace lacuna {
namespace {

std::string number(double v) {
  char text[64];
  std::snprintf(text, sizeof text, "%.10g", v);
  return text;
}

// TetGen (built with TETLIBRARY) throws an int; these are its codes.
std::string tetgen_error(int code) {
  switch (code) {
    case 1: return "TetGen ran out of memory";
    case 2: return "TetGen hit an internal error on this surface";
    case 3: return "TetGen found a self-intersection in the surface";
    case 4: return "TetGen found an input feature too small for its tolerance";
    case 5: return "TetGen found two facets too close to each other";
    case 10: return "TetGen rejected the input";
    default: return "TetGen failed with code " + std::to_string(code);
  }
}

// The result as the child process sends it through the pipe.
struct Header {
  int32_t status;  // 0, or TetGen's error code (-1: out of memory)
  int32_t has_attributes;
  uint64_t points;
  uint64_t tets;
};

bool write_all(int fd, const void* data, size_t size) {
  const char* p = static_cast<const char*>(data);
  while (size > 0) {
    ssize_t n = ::write(fd, p, size);
    if (n <= 0) return false;
    p += n;
    size -= size_t(n);
  }
  return true;
}

// The address space the process maps now (bytes), from /proc/self/statm; 0 where unknown.
uint64_t mapped_bytes() {
  std::FILE* file = std::fopen("/proc/self/statm", "r");
  if (!file) return 0;
  unsigned long long pages = 0;
  const bool read = std::fscanf(file, "%llu", &pages) == 1;
  std::fclose(file);
  return read ? uint64_t(pages) * uint64_t(::sysconf(_SC_PAGESIZE)) : 0;
}

// What the child does first: die with its parent (also if the parent is gone already), take the
// default action for the signals a front end may have blocked or caught, and stay within
// `address_limit` bytes of address space (0: no limit), so that TetGen's allocations fail cleanly.
void prepare_child(pid_t parent, uint64_t address_limit) {
  ::prctl(PR_SET_PDEATHSIG, SIGKILL);
  if (::getppid() != parent) ::_exit(5);
  ::signal(SIGINT, SIG_DFL);
  ::signal(SIGTERM, SIG_DFL);
  sigset_t none;
  sigemptyset(&none);
  ::pthread_sigmask(SIG_SETMASK, &none, nullptr);
  if (address_limit) {
    rlimit limit{rlim_t(address_limit), rlim_t(address_limit)};
    ::setrlimit(RLIMIT_AS, &limit);
  }
}

[[noreturn]] void run_child(int fd, const TriMesh& surface, const std::vector<Vec3d>& holes,
                            const std::vector<Vec3d>& seeds, const std::string& switches) {
  Header header{0, 0, 0, 0};
  try {
    tetgenio in, out;
    in.firstnumber = 0;
    in.numberofpoints = int(surface.positions_mm.size());
    in.pointlist = new REAL[size_t(in.numberofpoints) * 3];
    for (size_t i = 0; i < surface.positions_mm.size(); ++i) {
      in.pointlist[3 * i] = surface.positions_mm[i].x;
      in.pointlist[3 * i + 1] = surface.positions_mm[i].y;
      in.pointlist[3 * i + 2] = surface.positions_mm[i].z;
    }
    in.numberoffacets = int(surface.triangles.size());
    in.facetlist = new tetgenio::facet[surface.triangles.size()];
    for (size_t f = 0; f < surface.triangles.size(); ++f) {
      tetgenio::facet& facet = in.facetlist[f];
      tetgenio::init(&facet);
      facet.numberofpolygons = 1;
      facet.polygonlist = new tetgenio::polygon[1];
      tetgenio::init(&facet.polygonlist[0]);
      facet.polygonlist[0].numberofvertices = 3;
      facet.polygonlist[0].vertexlist = new int[3];
      for (int k = 0; k < 3; ++k) facet.polygonlist[0].vertexlist[k] = int(surface.triangles[f][size_t(k)]);
    }
    in.numberofholes = int(holes.size());
    if (!holes.empty()) in.holelist = new REAL[holes.size() * 3];
    for (size_t h = 0; h < holes.size(); ++h) {
      in.holelist[3 * h] = holes[h].x;
      in.holelist[3 * h + 1] = holes[h].y;
      in.holelist[3 * h + 2] = holes[h].z;
    }
    in.numberofregions = int(seeds.size());
    if (!seeds.empty()) in.regionlist = new REAL[seeds.size() * 5];
    for (size_t r = 0; r < seeds.size(); ++r) {
      REAL* region = in.regionlist + 5 * r;
      region[0] = seeds[r].x;
      region[1] = seeds[r].y;
      region[2] = seeds[r].z;
      region[3] = REAL(r);
      region[4] = -1;  // no volume bound of its own
    }
    tetgenbehavior behavior;
    std::vector<char> text(switches.begin(), switches.end());
    text.push_back('\0');
    if (!behavior.parse_commandline(text.data())) throw 10;
    // A volume bound given any other way than through -a is ignored unless fixedvolume is set.
    if (behavior.maxvolume > 0) behavior.fixedvolume = 1;
    tetrahedralize(&behavior, &in, &out);
    header.points = uint64_t(out.numberofpoints);
    header.tets = uint64_t(out.numberoftetrahedra);
    header.has_attributes = out.numberoftetrahedronattributes > 0 && out.tetrahedronattributelist != nullptr;
    if (out.numberofcorners != 4) throw 2;
    bool ok = write_all(fd, &header, sizeof header) &&
              write_all(fd, out.pointlist, sizeof(REAL) * 3 * header.points) &&
              write_all(fd, out.tetrahedronlist, sizeof(int) * 4 * header.tets);
    for (uint64_t t = 0; ok && header.has_attributes && t < header.tets; ++t)
      ok = write_all(fd, &out.tetrahedronattributelist[t * size_t(out.numberoftetrahedronattributes)], sizeof(REAL));
    ::_exit(ok ? 0 : 3);
  } catch (int code) {
    header.status = code;
  } catch (const std::bad_alloc&) {
    header.status = 1;
  } catch (...) {
    header.status = 2;
  }
  write_all(fd, &header, sizeof header);
  ::_exit(0);
}

double tet_volume(const Vec3d& a, const Vec3d& b, const Vec3d& c, const Vec3d& d) {
  return dot(b - a, cross(c - a, d - a)) / 6.0;
}

}  // namespace

std::string tetgen_switches(const TetOptions& o, bool regions) {
  std::string s = "pzQ";
  // TetGen 1.5 adds no point at all under -Y, so a quality or volume bound would be ignored.
  const bool refine = o.max_radius_edge_ratio != 0 || o.max_tet_volume_mm3 != 0;
  if (o.preserve_surface && !refine) s += "Y";
  if (o.max_radius_edge_ratio != 0) {
    if (!(o.max_radius_edge_ratio > 1.0) || !std::isfinite(o.max_radius_edge_ratio))
      throw InvalidInput("the radius-edge quality bound must be greater than 1 (TetGen), got " + number(o.max_radius_edge_ratio));
    s += "q" + number(o.max_radius_edge_ratio);
    if (o.min_dihedral_deg != 0) {
      if (!(o.min_dihedral_deg > 0 && o.min_dihedral_deg < 70))
        throw InvalidInput("the minimum dihedral angle must be between 0 and 70 degrees");
      s += "/" + number(o.min_dihedral_deg);
    }
  } else if (o.min_dihedral_deg != 0) {
    throw InvalidInput("a minimum dihedral angle needs a radius-edge quality bound too");
  }
  if (o.max_tet_volume_mm3 != 0) {
    if (!(o.max_tet_volume_mm3 > 0) || !std::isfinite(o.max_tet_volume_mm3))
      throw InvalidInput("the maximum tetrahedron volume must be positive (mm3)");
    s += "a" + number(o.max_tet_volume_mm3);
  }
  if (regions) s += "A";
  return s;
}

TetMesh tetrahedralize(const TriMesh& surface, const TetOptions& options, const std::vector<Vec3d>& region_seeds) {
  const std::string switches = tetgen_switches(options, !region_seeds.empty());
  if (surface.triangles.empty()) throw InvalidInput("the surface to tetrahedralize is empty");
  if (surface.positions_mm.size() > size_t(INT32_MAX) || surface.triangles.size() > size_t(INT32_MAX))
    throw ResourceLimit("the surface is too large for TetGen's 32-bit indices");
  // Cavities (components oriented inward) stay empty: a hole point just inside each.
  std::vector<Vec3d> holes;
  for (const MeshComponent& c : mesh_components(surface)) {
    if (c.signed_volume_mm3 >= 0) continue;
    const auto& t = surface.triangles[c.triangles.front()];
    const Vec3d &a = surface.positions_mm[t[0]], &b = surface.positions_mm[t[1]], &d = surface.positions_mm[t[2]];
    Vec3d n = cross(b - a, d - a);
    double shortest = std::min({norm(b - a), norm(d - b), norm(a - d)});
    // The face points out of the material, into the cavity.
    holes.push_back((a + b + d) / 3.0 + n / norm(n) * (0.01 * shortest));
  }

  Progress progress("tetrahedralize", 1);
  int fds[2];
  if (::pipe(fds) != 0) throw std::runtime_error("cannot create a pipe for TetGen");
  std::fflush(nullptr);
  const pid_t parent = ::getpid();
  // The child starts with the parent's address space mapped; it may add the budget to it.
  const uint64_t address_limit = options.max_memory_bytes ? mapped_bytes() + options.max_memory_bytes : 0;
  pid_t pid = ::fork();
  if (pid < 0) {
    ::close(fds[0]);
    ::close(fds[1]);
    throw ResourceLimit("cannot start a process for TetGen");
  }
  if (pid == 0) {
    ::close(fds[0]);
    prepare_child(parent, address_limit);
    run_child(fds[1], surface, holes, region_seeds, switches);
  }
  ::close(fds[1]);
  std::vector<char> data;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(options.time_limit_s);
  bool timed_out = false;
  char buffer[1 << 16];
  for (;;) {
    double left = std::chrono::duration<double>(deadline - std::chrono::steady_clock::now()).count();
    if (left <= 0) {
      timed_out = true;
      break;
    }
    pollfd p{fds[0], POLLIN, 0};
    int ready = ::poll(&p, 1, int(std::min(left, 1.0) * 1000) + 1);
    if (ready < 0 && errno == EINTR) continue;
    if (ready <= 0) continue;
    ssize_t n = ::read(fds[0], buffer, sizeof buffer);
    if (n <= 0) break;
    data.insert(data.end(), buffer, buffer + n);
  }
  ::close(fds[0]);
  if (timed_out) ::kill(pid, SIGKILL);
  int status = 0;
  ::waitpid(pid, &status, 0);
  if (timed_out)
    throw ResourceLimit("TetGen did not finish within " + number(options.time_limit_s) +
                        " s; decimate or clean the surface first, or relax the quality bound");
  if (WIFSIGNALED(status))
    throw InvalidInput("TetGen crashed on this surface (signal " + std::to_string(WTERMSIG(status)) + ")");
  if (data.size() < sizeof(Header)) throw InvalidInput("TetGen stopped without a result");
  Header header;
  std::memcpy(&header, data.data(), sizeof header);
  if (header.status == 1)
    throw ResourceLimit(options.max_memory_bytes
                            ? "TetGen ran out of its memory budget of " + number(double(options.max_memory_bytes) / 1e9) +
                                  " GB (--max-memory); relax the volume or quality bound"
                            : tetgen_error(1));
  if (header.status != 0) throw InvalidInput(tetgen_error(header.status) + " (switches " + switches + ")");
  const size_t expected = sizeof(Header) + sizeof(REAL) * 3 * header.points + sizeof(int) * 4 * header.tets +
                          (header.has_attributes ? sizeof(REAL) * header.tets : 0);
  if (data.size() != expected) throw InvalidInput("TetGen's result arrived incomplete");

  TetMesh mesh;
  const char* p = data.data() + sizeof(Header);
  mesh.nodes_mm.resize(header.points);
  for (uint64_t i = 0; i < header.points; ++i, p += 3 * sizeof(REAL)) {
    REAL xyz[3];
    std::memcpy(xyz, p, sizeof xyz);
    mesh.nodes_mm[i] = Vec3d{xyz[0], xyz[1], xyz[2]};
  }
  mesh.tets.resize(header.tets);
  for (uint64_t t = 0; t < header.tets; ++t, p += 4 * sizeof(int)) {
    int v[4];
    std::memcpy(v, p, sizeof v);
    for (int k = 0; k < 4; ++k) {
      if (v[k] < 0 || uint64_t(v[k]) >= header.points) throw InvalidInput("TetGen returned an index out of range");
      mesh.tets[t][size_t(k)] = uint32_t(v[k]);
    }
    auto& tet = mesh.tets[t];
    if (tet_volume(mesh.nodes_mm[tet[0]], mesh.nodes_mm[tet[1]], mesh.nodes_mm[tet[2]], mesh.nodes_mm[tet[3]]) < 0)
      std::swap(tet[2], tet[3]);
  }
  if (header.has_attributes) {
    mesh.regions.resize(header.tets);
    for (uint64_t t = 0; t < header.tets; ++t, p += sizeof(REAL)) {
      REAL a;
      std::memcpy(&a, p, sizeof a);
      mesh.regions[t] = int(std::lround(a));
    }
  }
  progress.advance();
  return mesh;
}

TetReport tet_report(const TetMesh& m) {
  TetReport r;
  r.nodes = m.nodes_mm.size();
  r.tets = m.tets.size();
  r.ratio_bins = {1.0, 1.2, 1.4, 2.0, 5.0};
  r.ratio_counts.assign(r.ratio_bins.size() + 1, 0);
  r.min_tet_volume_mm3 = HUGE_VAL;
  r.max_tet_volume_mm3 = -HUGE_VAL;
  r.min_dihedral_deg = 180;
  r.max_dihedral_deg = 0;
  long double volume = 0;
  for (const auto& t : m.tets) {
    const Vec3d p[4] = {m.nodes_mm[t[0]], m.nodes_mm[t[1]], m.nodes_mm[t[2]], m.nodes_mm[t[3]]};
    double v = tet_volume(p[0], p[1], p[2], p[3]);
    volume += v;
    if (v <= 0) ++r.inverted_tets;
    r.min_tet_volume_mm3 = std::min(r.min_tet_volume_mm3, v);
    r.max_tet_volume_mm3 = std::max(r.max_tet_volume_mm3, v);
    // Dihedral angle at edge (i, j): between the two faces through it.
    static const int kEdges[6][4] = {{0, 1, 2, 3}, {0, 2, 1, 3}, {0, 3, 1, 2}, {1, 2, 0, 3}, {1, 3, 0, 2}, {2, 3, 0, 1}};
    double shortest = HUGE_VAL;
    for (const auto& e : kEdges) {
      Vec3d axis = p[e[1]] - p[e[0]];
      shortest = std::min(shortest, norm(axis));
      Vec3d n1 = cross(axis, p[e[2]] - p[e[0]]), n2 = cross(axis, p[e[3]] - p[e[0]]);
      double c = dot(n1, n2) / (norm(n1) * norm(n2));
      double angle = std::acos(std::clamp(c, -1.0, 1.0)) * 180.0 / 3.14159265358979323846;
      r.min_dihedral_deg = std::min(r.min_dihedral_deg, angle);
      r.max_dihedral_deg = std::max(r.max_dihedral_deg, angle);
    }
    // Circumradius: |a|^2 (b x c) + |b|^2 (c x a) + |c|^2 (a x b) over 12 V, edges from p0.
    Vec3d a = p[1] - p[0], b = p[2] - p[0], c = p[3] - p[0];
    Vec3d numerator = cross(b, c) * dot(a, a) + cross(c, a) * dot(b, b) + cross(a, b) * dot(c, c);
    double ratio = v > 0 ? norm(numerator) / (12.0 * v) / shortest : HUGE_VAL;
    size_t bin = size_t(std::upper_bound(r.ratio_bins.begin(), r.ratio_bins.end(), ratio) - r.ratio_bins.begin());
    ++r.ratio_counts[bin];
  }
  r.volume_mm3 = double(volume);
  if (m.tets.empty()) r.min_tet_volume_mm3 = r.max_tet_volume_mm3 = 0;
  return r;
}

}  // namespace lacuna
