#include "solids/simplify.h"

#include <tbb/parallel_for.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_sort.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <numeric>
#include <functional>
#include <limits>
#include <memory>
#include <tuple>
#include <type_traits>
#include <unordered_map>
#include <utility>

#include "errors.h"
#include "solids/exact.h"
#include "solids/extract.h"
#include "solids/mesh_distance.h"
#include "util/progress.h"
#include "util/system.h"

namespace lacuna {
namespace {

// Seconds since it was made (for SimplifyStats' time breakdown).
class Stopwatch {
 public:
  double seconds() const { return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count(); }

 private:
  std::chrono::steady_clock::time_point start_ = std::chrono::steady_clock::now();
};

constexpr uint32_t kNone = UINT32_MAX;
constexpr int kBlockVoxels = 32;  // the blocks a volume's surface is simplified in
constexpr double kPi = 3.14159265358979323846;
constexpr double kDeviationMargin = 0.75;
// How far the quadric (the plain SUM of squared distances to every original plane merged into a
// vertex, so it bounds each distance by its square root) may go in a block, in units of the squared
// deviation. Within a block every original vertex is tracked to the end, so the quadric need not be
// the bound there; 1 would cap the sum at the deviation's square, which on a curved stretch stops a
// vertex that stands for many planes long before any of them is that far. Measured (sampled one-sided
// Hausdorff distances both ways, extracted <-> compact, with the deviation d): capsule walk of 1 000
// at voxel r/6 (d = 0.0167 mm): factor 1 0.0120 / 0.0124 mm, 217 542 triangles; 6: 0.0136 / 0.0147,
// 142 192; 9: 0.0158 / 0.0153, 129 462; 12: 0.0171 (beyond d), 121 430. lattice_block (d = 0.04 mm):
// 1: 0.0152 / 0.0165, 78 472; 6: 0.0276 / 0.0330, 68 890; 12: 0.0332 / 0.0354, 64 408. The pass
// across the blocks' faces keeps factor 1: the points its blocks tracked are not carried into it.
constexpr double kBlockQuadricFactor = 6;
// A triangle's shape: 4 sqrt(3) area over the sum of its squared edges, 1 when equilateral, 0 when
// flat; collapses may not push the worst triangle they touch below this (see RegionSimplifier::collapse).
constexpr double kMinQuality = 0.15;

// The square of that shape measure (no square root needed to compare it).
double quality2(const Vec3d& a, const Vec3d& b, const Vec3d& c) {
  const Vec3d ab = b - a, bc = c - b, ca = a - c;
  const double edges = dot(ab, ab) + dot(bc, bc) + dot(ca, ca);
  const Vec3d n = cross(ab, -ca);
  return edges > 0 ? 12 * dot(n, n) / (edges * edges) : 0;
}


// Sum of weighted squared distances to planes: Q(p) = p'Ap + 2b'p + c, with the total weight w.
struct Quadric {
  double a00 = 0, a01 = 0, a02 = 0, a11 = 0, a12 = 0, a22 = 0, b0 = 0, b1 = 0, b2 = 0, c = 0, w = 0;

  // The plane n.x + d = 0 (n of unit length) with weight `weight`.
  void add_plane(const Vec3d& n, double d, double weight) {
    a00 += weight * n.x * n.x;
    a01 += weight * n.x * n.y;
    a02 += weight * n.x * n.z;
    a11 += weight * n.y * n.y;
    a12 += weight * n.y * n.z;
    a22 += weight * n.z * n.z;
    b0 += weight * d * n.x;
    b1 += weight * d * n.y;
    b2 += weight * d * n.z;
    c += weight * d * d;
    w += weight;
  }
  Quadric& operator+=(const Quadric& o) {
    a00 += o.a00, a01 += o.a01, a02 += o.a02, a11 += o.a11, a12 += o.a12, a22 += o.a22;
    b0 += o.b0, b1 += o.b1, b2 += o.b2, c += o.c, w += o.w;
    return *this;
  }
  // Whether the planes are all one plane (their unit normals agree to about 0.1 degrees): the
  // squared norm of A equals the square of its trace only when A has rank one.
  bool flat() const {
    const double frobenius2 = a00 * a00 + a11 * a11 + a22 * a22 + 2 * (a01 * a01 + a02 * a02 + a12 * a12);
    return w > 0 && frobenius2 >= (1 - 1e-6) * w * w;
  }
  // Mean squared distance (mm^2) of p to the planes.
  double error(const Vec3d& p) const {
    const double q = p.x * (a00 * p.x + a01 * p.y + a02 * p.z) + p.y * (a01 * p.x + a11 * p.y + a12 * p.z) +
                     p.z * (a02 * p.x + a12 * p.y + a22 * p.z) + 2 * (b0 * p.x + b1 * p.y + b2 * p.z) + c;
    return std::max(0.0, q);
  }
  // The minimiser on the plane n.p = c (the positions that keep the enclosed volume), pulled
  // slightly towards m: p = p0 - M^-1 n (n.p0 - c) / (n.M^-1 n), with p0 the unconstrained
  // minimiser and M the regularised matrix. False when either is too badly conditioned.
  bool minimiser_on_plane(const Vec3d& m, const Vec3d& n, double c_plane, Vec3d& p) const {
    Vec3d p0, mn;
    if (!solve(m, n, p0, mn)) return false;
    const double denominator = dot(n, mn);
    if (!(std::fabs(denominator) > 1e-300)) return false;
    p = p0 - mn * ((dot(n, p0) - c_plane) / denominator);
    return is_finite(p);
  }
  // p = the regularised minimiser, mn = M^-1 n.
  bool solve(const Vec3d& m, const Vec3d& n, Vec3d& p, Vec3d& mn) const {
    if (!(w > 0)) return false;
    const double reg = 1e-3 * w;
    const double m00 = a00 + reg, m11 = a11 + reg, m22 = a22 + reg;
    const double c00 = m11 * m22 - a12 * a12, c01 = a02 * a12 - a01 * m22, c02 = a01 * a12 - a02 * m11;
    const double det = m00 * c00 + a01 * c01 + a02 * c02;
    if (!(std::fabs(det) > 1e-12 * w * w * w)) return false;
    const double c11 = m00 * m22 - a02 * a02, c12 = a01 * a02 - m00 * a12, c22 = m00 * m11 - a01 * a01;
    const double r0 = reg * m.x - b0, r1 = reg * m.y - b1, r2 = reg * m.z - b2;
    const double inv = 1.0 / det;
    p = Vec3d{(c00 * r0 + c01 * r1 + c02 * r2) * inv, (c01 * r0 + c11 * r1 + c12 * r2) * inv,
              (c02 * r0 + c12 * r1 + c22 * r2) * inv};
    mn = Vec3d{(c00 * n.x + c01 * n.y + c02 * n.z) * inv, (c01 * n.x + c11 * n.y + c12 * n.z) * inv,
               (c02 * n.x + c12 * n.y + c22 * n.z) * inv};
    return is_finite(p) && is_finite(mn);
  }
  // The unconstrained minimiser, pulled slightly towards `m` so flat and straight stretches have
  // one; false when the system is too badly conditioned.
  bool minimiser(const Vec3d& m, Vec3d& p) const {
    if (!(w > 0)) return false;
    const double reg = 1e-3 * w;
    const double m00 = a00 + reg, m11 = a11 + reg, m22 = a22 + reg;
    const double r0 = reg * m.x - b0, r1 = reg * m.y - b1, r2 = reg * m.z - b2;
    const double c00 = m11 * m22 - a12 * a12, c01 = a02 * a12 - a01 * m22, c02 = a01 * a12 - a02 * m11;
    const double det = m00 * c00 + a01 * c01 + a02 * c02;
    if (!(std::fabs(det) > 1e-12 * w * w * w)) return false;
    const double c11 = m00 * m22 - a02 * a02, c12 = a01 * a02 - m00 * a12, c22 = m00 * m11 - a01 * a01;
    p = Vec3d{(c00 * r0 + c01 * r1 + c02 * r2) / det, (c01 * r0 + c11 * r1 + c12 * r2) / det,
              (c02 * r0 + c12 * r1 + c22 * r2) / det};
    return is_finite(p);
  }
};

Quadric operator+(Quadric a, const Quadric& b) { return a += b; }

void add_triangle_plane(Quadric& q, const Vec3d& a, const Vec3d& b, const Vec3d& c) {
  const Vec3d n = cross(b - a, c - a);
  const double len = norm(n);
  if (!(len > 0)) return;
  const Vec3d unit = n / len;
  q.add_plane(unit, -dot(unit, a), 1.0);
}

// Half-edges of a region are numbered 4t + k (k < 3: from corner k to corner k + 1 of triangle t),
// so finding the triangle and the next corner takes shifts, not divisions.
constexpr uint32_t kNextCorner[4] = {1, 2, 0, 0};
constexpr uint32_t kPrevCorner[4] = {2, 0, 1, 0};
inline uint32_t next_he(uint32_t h) { return (h & ~3u) | kNextCorner[h & 3]; }
inline uint32_t prev_he(uint32_t h) { return (h & ~3u) | kPrevCorner[h & 3]; }
inline uint32_t tri_of(uint32_t h) { return h >> 2; }

// An axis-aligned region: the open box (lo, hi) holds the vertices that may move; [lo, hi) decides
// which region writes a triangle.
struct RegionBox {
  Vec3d lo, hi;
  bool strictly_inside(const Vec3d& p) const {
    return p.x > lo.x && p.x < hi.x && p.y > lo.y && p.y < hi.y && p.z > lo.z && p.z < hi.z;
  }
  bool in_closed(const Vec3d& p) const {
    return p.x >= lo.x && p.x <= hi.x && p.y >= lo.y && p.y <= hi.y && p.z >= lo.z && p.z <= hi.z;
  }
  bool in_half_open(const Vec3d& p) const {
    return p.x >= lo.x && p.x < hi.x && p.y >= lo.y && p.y < hi.y && p.z >= lo.z && p.z < hi.z;
  }
};

// A collapse waiting its turn: the edge (keep, drop) and the versions of both ends when it was
// queued (16 bits are plenty: a stale entry that slips through is only tried, and every test
// runs again then).
struct QueueEntry {
  uint32_t keep, drop;
  uint16_t keep_version, drop_version;
};

// Collapses by increasing deviation, in buckets of equal width in deviation (the square root of
// the quadric error): pushing and popping cost O(1), and within a bucket the last queued goes
// first, so the order is fixed by the input alone.
class CollapseQueue {
 public:
  static constexpr int kBuckets = 64;
  void clear() {
    for (auto& b : buckets_) b.clear();
    lowest_ = kBuckets;
  }
  // `fraction`: deviation over the tolerance, in [0, 1].
  void push(double fraction, const QueueEntry& e) {
    const int b = std::min(kBuckets - 1, int(fraction * kBuckets));
    buckets_[size_t(b)].push_back(e);
    lowest_ = std::min(lowest_, b);
  }
  bool pop(QueueEntry& e) {
    while (lowest_ < kBuckets && buckets_[size_t(lowest_)].empty()) ++lowest_;
    if (lowest_ == kBuckets) return false;
    e = buckets_[size_t(lowest_)].back();
    buckets_[size_t(lowest_)].pop_back();
    return true;
  }

 private:
  std::array<std::vector<QueueEntry>, kBuckets> buckets_;
  int lowest_ = kBuckets;
};

// What one block of the first pass leaves: its vertices (local numbering), the grid-edge key of
// those on the block's faces, the quadrics of the vertices that moved freely, the volume still
// owed near each vertex, and its triangles.
// Where a vertex of a block surface comes in the whole surface's numbering (number_block_vertices):
// an interior vertex by its block (first) and its place there, then every vertex on a block face
// by its grid edge's key.
using VertexOrder = std::pair<uint64_t, uint64_t>;
// Where a triangle of a block surface comes in the whole surface: its block, then its place there.
using TriangleOrder = std::pair<uint64_t, uint64_t>;
constexpr uint64_t kOnBlockFace = uint64_t(1) << 63;

struct BlockResult {
  int64_t origin_voxels[3] = {0, 0, 0};
  std::vector<Vec3d> positions;
  std::vector<uint64_t> keys;
  std::vector<Quadric> quadrics;     // of the vertices with has_quadric, in their order
  std::vector<uint8_t> has_quadric;
  std::vector<double> debt6;
  std::vector<std::array<uint32_t, 3>> triangles;
};

// Constructs an element given no arguments as nothing: the element is left as the allocation left
// it, so a large array's pages are first touched (and cleared by the kernel) where its elements are
// written, in parallel, not by the vector's constructor on one thread. Others as std::allocator.
template <class T>
struct UnsetAllocator : std::allocator<T> {
  template <class U>
  struct rebind {
    using other = UnsetAllocator<U>;
  };
  UnsetAllocator() = default;
  template <class U>
  UnsetAllocator(const UnsetAllocator<U>&) noexcept {}
  template <class U>
  void construct(U*) noexcept {
    static_assert(std::is_trivially_copyable_v<U> && std::is_trivially_destructible_v<U>, "plain values only");
  }
  template <class U, class... Args>
  void construct(U* p, Args&&... args) {
    ::new (static_cast<void*>(p)) U(std::forward<Args>(args)...);
  }
};

// The vertices of a global mesh between passes. debt6: six times the volume the surface owes
// near the vertex (what the cubes' merge lost there and no collapse has given back yet); each
// collapse that may places its vertex to pay its two ends' debts.
struct Vertices {
  std::vector<Vec3d> positions;
  // Read only where has_quadric is set (written first): left unset by Vertices(n).
  std::vector<Quadric, UnsetAllocator<Quadric>> quadrics;
  std::vector<uint8_t> has_quadric;
  std::vector<double> debt6;
  // When not empty: the order a region numbers its vertices in (by these keys, otherwise by index).
  std::vector<VertexOrder> order;
  explicit Vertices(size_t n) : positions(n), quadrics(n), has_quadric(n, 0), debt6(n, 0.0) {}
};

// A whole surface's triangles: resized unset, then filled in parallel.
using TriangleList = std::vector<std::array<uint32_t, 3>, UnsetAllocator<std::array<uint32_t, 3>>>;

// An open-addressing table (linear probing) from 64-bit keys to 32-bit values, sized to be at most
// half full with the entries it is reset for; slot() finds a key's slot, or the empty one where it
// would go.
class SlotTable {
 public:
  static constexpr uint64_t kEmpty = UINT64_MAX;
  void reset(size_t entries) {
    size_t capacity = 16;
    while (capacity < 2 * entries) capacity *= 2;
    keys_.assign(capacity, kEmpty);
    values_.resize(capacity);
    mask_ = capacity - 1;
  }
  size_t slot(uint64_t key) const {
    size_t i = size_t((key * 0x9e3779b97f4a7c15ull) >> 32) & mask_;
    while (keys_[i] != kEmpty && keys_[i] != key) i = (i + 1) & mask_;
    return i;
  }
  uint64_t& key(size_t slot) { return keys_[slot]; }
  uint32_t& value(size_t slot) { return values_[slot]; }

 private:
  std::vector<uint64_t> keys_;
  std::vector<uint32_t> values_;
  size_t mask_ = 0;
};

// One region's piece of the mesh and the collapses in it. Everything is local: vertices and
// triangles are renumbered, and only the region's own unlocked vertices are written back.
//
// Two ways to guard: `guarded` tests every collapse against every triangle near it (a grid of
// the region, updated as triangles change); otherwise a collapse is tested against the triangles
// that share its vertices, and verify() then tests the pairs of nearby triangles of the result
// that share none with exact predicates. A region whose result fails verify() is simplified
// again, guarded, from its input, so nothing untested leaves it either way; the second way is several times faster and
// almost never has to redo a region.
class RegionSimplifier {
 public:
  explicit RegionSimplifier(const SimplifyOptions& options) {
    // Every collapse keeps the quadric error of the new vertex (a plain sum of squared distances to
    // the original planes merged into it) within its bound (kBlockQuadricFactor) and every original
    // vertex the region removed or moved within the deviation of the new fan. Drift over many
    // collapses, the points the pass across the blocks does not track and the chords between
    // vertices add a little: at three quarters of the deviation the measured one-sided Hausdorff
    // distances stay within it (see the simplify tests and the capsule benchmark).
    max_deviation_ = kDeviationMargin * options.max_deviation_mm;
    deviation_limit2_ = squared_limit(max_deviation_);
    tolerance2_ = max_deviation_ * max_deviation_;
    quadric_tolerance2_ = tolerance2_;
    cos_normal_ = std::cos(options.max_normal_change_deg * kPi / 180.0);
  }

  // Loads the given triangles of a global mesh; quadrics of vertices that carry one are taken,
  // the others summed from their local triangles.
  void load_global(const RegionBox& box, const std::array<uint32_t, 3>* global_tris,
                   const std::vector<uint32_t>& tri_ids, const Vertices& vertices) {
    box_ = box;
    const size_t nt = tri_ids.size();
    // Each global vertex once, numbered in the order the region numbers them: by index, or as the
    // whole surface numbers them, so the region does what it does there. A table of the region's
    // own size (global id -> slot) finds them; the corners hold their slots until the numbers are
    // known.
    table_.reset(3 * nt);
    global_vertex_.clear();
    tri_.resize(nt);
    for (size_t i = 0; i < nt; ++i)
      for (int k = 0; k < 3; ++k) {
        const uint32_t g = global_tris[tri_ids[i]][size_t(k)];
        const size_t slot = table_.slot(g);
        if (table_.key(slot) == SlotTable::kEmpty) {
          table_.key(slot) = g;
          global_vertex_.push_back(g);
        }
        tri_[i][size_t(k)] = uint32_t(slot);
      }
    if (vertices.order.empty()) {
      std::sort(global_vertex_.begin(), global_vertex_.end());
    } else {
      const std::vector<VertexOrder>& order = vertices.order;
      std::sort(global_vertex_.begin(), global_vertex_.end(), [&](uint32_t a, uint32_t b) { return order[a] < order[b]; });
    }
    const size_t nv = global_vertex_.size();
    for (size_t v = 0; v < nv; ++v) table_.value(table_.slot(global_vertex_[v])) = uint32_t(v);
    for (auto& t : tri_)
      for (uint32_t& corner : t) corner = table_.value(corner);
    pos_.resize(nv);
    quadric_.assign(nv, Quadric());
    own_quadric_.assign(nv, 0);
    debt_.resize(nv);
    for (size_t v = 0; v < nv; ++v) {
      const uint32_t g = global_vertex_[v];
      pos_[v] = vertices.positions[g];
      debt_[v] = vertices.debt6[g];
      if (vertices.has_quadric[g]) {  // moved in the first pass: its quadric carries the planes merged into it
        quadric_[v] = vertices.quadrics[g];
        own_quadric_[v] = 1;
      }
    }
    debt_start_ = debt_;
    init();
    quadric_tolerance2_ = tolerance2_;
  }

  // Loads one block of the extracted surface.
  void load_block(const SurfaceBlock& block) {
    box_ = RegionBox{block.box_mm.min, block.box_mm.max};
    global_vertex_.clear();
    tri_ = block.triangles;
    pos_ = block.positions_mm;
    quadric_.assign(pos_.size(), Quadric());
    own_quadric_.assign(pos_.size(), 0);
    debt_ = block.volume_debt6;
    debt_.resize(pos_.size(), 0.0);
    debt_start_ = debt_;
    init();
    quadric_tolerance2_ = kBlockQuadricFactor * tolerance2_;
  }

  void run(bool guarded) {
    guarded_ = guarded;
    if (guarded_) build_grid();
    queue_.clear();
    for (uint32_t h = 0; h < opp_.size(); ++h) {
      const uint32_t g = opp_[h];
      if (g == kNone || g < h) continue;
      consider(from(h), to(h));
    }
    QueueEntry e;
    while (queue_.pop(e)) {
      if (!vertex_alive_[e.keep] || !vertex_alive_[e.drop] || uint16_t(version_[e.keep]) != e.keep_version ||
          uint16_t(version_[e.drop]) != e.drop_version)
        continue;
      if (!collapse(e.keep, e.drop)) continue;
      ++collapses_;
      for (uint32_t w : keep_ring_after_) consider(e.keep, w);
    }
  }

  // Whether no two live triangles meet other than in the vertices or edge they share, given that
  // the loaded triangles did not (the block of a valid surface, or a region of one) and that
  // every collapse tested its changed triangles against all triangles sharing a vertex with them:
  // every pair with a changed triangle whose boxes overlap and that shares no vertex is tested
  // exactly. (A pair that shares a vertex now either shared it when the later of its two changed,
  // and that collapse tested it, or both hold the collapse's kept vertex and were tested with each
  // other; a graph fan's pair stays apart as long as neither changes.) The boxes go into a grid
  // of fixed cells, filled by counting.
  bool verify() {
    const size_t nt = tri_.size();
    size_grid(kVerifyTrianglesPerCell);
    verify_boxes_.resize(nt);
    verify_start_.assign(size_t(cells_) * cells_ * cells_ + 1, 0);
    for (int pass = 0; pass < 2; ++pass) {
      for (uint32_t t = 0; t < nt; ++t) {
        if (!tri_alive_[t]) continue;
        if (pass == 0) verify_boxes_[t] = entry_of(t);
        for_cells(box_of(verify_boxes_[t]), [&](size_t c) {
          if (pass == 0) ++verify_start_[c + 1];
          else verify_entries_[verify_cursor_[c]++] = t;
        });
      }
      if (pass == 0) {
        for (size_t c = 0; c + 1 < verify_start_.size(); ++c) verify_start_[c + 1] += verify_start_[c];
        verify_entries_.resize(verify_start_.back());
        verify_cursor_.assign(verify_start_.begin(), verify_start_.end() - 1);
      }
    }
    stamp_.assign(nt, 0);
    stamp_now_ = 0;
    for (uint32_t t = 0; t < nt; ++t) {
      if (!tri_alive_[t] || !tri_changed_[t]) continue;
      const auto& ids = tri_[t];
      const std::array<Vec3d, 3> tp{pos_[ids[0]], pos_[ids[1]], pos_[ids[2]]};
      const Box3 tb = box_of(verify_boxes_[t]);
      next_stamp();
      bool crossed = false;
      for_cells(tb, [&](size_t c) {
        for (uint32_t i = verify_start_[c]; i < verify_start_[c + 1] && !crossed; ++i) {
          const uint32_t u = verify_entries_[i];
          // A pair of changed triangles is tested from the lower one.
          if (u == t || (tri_changed_[u] && u < t) || stamp_[u] == stamp_now_ || !overlaps(verify_boxes_[u], tb))
            continue;
          stamp_[u] = stamp_now_;
          const auto& uids = tri_[u];
          if (shares_vertex(ids, uids)) continue;  // tested by the collapse that last changed either
          crossed = exact::faces_intersect(tp, ids, {pos_[uids[0]], pos_[uids[1]], pos_[uids[2]]}, uids);
        }
      });
      if (crossed) return false;
    }
    return true;
  }

  // Writes the moved vertices' positions and quadrics back (unlocked ones only: no other region
  // touches them), appends the triangles this region owns and the changes of the vertices' debts
  // (a locked vertex may take debts in several regions: the caller adds them up in order).
  void store_global(Vertices& vertices, std::vector<std::array<uint32_t, 3>>& out_tris,
                    std::vector<std::pair<uint32_t, double>>& debt_changes) const {
    for (size_t v = 0; v < pos_.size(); ++v) {
      const uint32_t g = global_vertex_[v];
      if (debt_[v] != debt_start_[v]) debt_changes.push_back({g, debt_[v] - debt_start_[v]});
      if (!moved_[v]) continue;
      vertices.positions[g] = pos_[v];
      vertices.quadrics[g] = quadric_[v];
      vertices.has_quadric[g] = 1;
    }
    for (size_t i = 0; i < tri_.size(); ++i) {
      if (!tri_alive_[i]) continue;
      const auto& t = tri_[i];
      const Vec3d centroid = (pos_[t[0]] + pos_[t[1]] + pos_[t[2]]) / 3.0;
      if (!box_.in_half_open(centroid)) continue;
      out_tris.push_back({global_vertex_[t[0]], global_vertex_[t[1]], global_vertex_[t[2]]});
    }
  }

  // The block's surviving vertices (in their local order), keys and triangles.
  void store_block(const SurfaceBlock& block, BlockResult& out) const {
    out = BlockResult();
    std::vector<uint32_t> index(pos_.size(), kNone);
    size_t live = 0, used = 0, moved = 0;
    for (size_t i = 0; i < tri_.size(); ++i)
      if (tri_alive_[i]) {
        ++live;
        for (uint32_t v : tri_[i]) index[v] = 0;
      }
    for (size_t v = 0; v < pos_.size(); ++v)
      if (index[v] == 0) {
        ++used;
        moved += moved_[v];
      }
    out.positions.reserve(used);
    out.keys.reserve(used);
    out.quadrics.reserve(moved);
    out.has_quadric.reserve(used);
    out.debt6.reserve(used);
    out.triangles.reserve(live);
    for (size_t v = 0; v < pos_.size(); ++v) {
      if (index[v] == kNone) continue;
      index[v] = uint32_t(out.positions.size());
      out.positions.push_back(pos_[v]);
      out.keys.push_back(block.keys[v]);
      if (moved_[v]) out.quadrics.push_back(quadric_[v]);
      out.has_quadric.push_back(moved_[v]);
      out.debt6.push_back(debt_[v]);
    }
    for (size_t i = 0; i < tri_.size(); ++i)
      if (tri_alive_[i]) out.triangles.push_back({index[tri_[i][0]], index[tri_[i][1]], index[tri_[i][2]]});
  }

  // Whether the quadric may go beyond the deviation's square (a block), and the plain bound.
  bool bold() const { return quadric_tolerance2_ > tolerance2_; }
  void keep_quadric_within_deviation() { quadric_tolerance2_ = tolerance2_; }

  uint64_t collapses() const { return collapses_; }
  uint64_t rejected_by_intersection() const { return rejected_intersection_; }

 private:
  static constexpr uint8_t kUnknownAxis = 0xff;  // graph_axis_: 2 * axis + (sign < 0), or unknown
  static constexpr int kMaxCells = 32;           // grid cells per axis of a region
  // verify()'s grid: about eight live triangles per cell (the walk of 10 000 capsules: verification
  // 1.6 thread seconds with two, 1.3 with eight or sixteen).
  static constexpr double kVerifyTrianglesPerCell = 8;
  struct Entry {
    float lo[3], hi[3];
    uint32_t tri, version;
  };

  uint32_t from(uint32_t h) const { return tri_[h >> 2][h & 3]; }
  uint32_t to(uint32_t h) const { return tri_[h >> 2][kNextCorner[h & 3]]; }

  // Topology, locks and quadrics of the loaded triangles.
  void init() {
    const size_t nt = tri_.size(), nv = pos_.size();
    tri_alive_.assign(nt, 1);
    tri_changed_.assign(nt, 0);
    quality2_.resize(nt);
    for (size_t i = 0; i < nt; ++i) quality2_[i] = quality2(pos_[tri_[i][0]], pos_[tri_[i][1]], pos_[tri_[i][2]]);
    vertex_alive_.assign(nv, 1);
    version_.assign(nv, 0);
    degree_.assign(nv, 0);
    corner_.assign(nv, kNone);
    graph_axis_.assign(nv, kUnknownAxis);
    touch_stamp_.assign(nv, 0);
    touch_state_.assign(nv, kUnknownAxis);
    touch_checked_.assign(nv, 0);
    touch_now_ = 0;
    moved_.assign(nv, 0);
    shifted_.assign(nv, 0);
    tracked_.clear();
    tri_points_.assign(nt, kNone);
    for (size_t i = 0; i < nt; ++i)
      for (int k = 0; k < 3; ++k) {
        const uint32_t v = tri_[i][size_t(k)];
        ++degree_[v];
        if (corner_[v] == kNone) corner_[v] = uint32_t(4 * i + size_t(k));
      }
    pair_half_edges();
    compute_locks();
    for (size_t i = 0; i < nt; ++i) {
      Quadric q;
      add_triangle_plane(q, pos_[tri_[i][0]], pos_[tri_[i][1]], pos_[tri_[i][2]]);
      for (uint32_t v : tri_[i])
        if (!own_quadric_[v]) quadric_[v] += q;
    }
    collapses_ = rejected_intersection_ = 0;
  }

  // Pairs each half-edge a -> b with the one half-edge b -> a, when the edge has exactly those
  // two: every half-edge goes into an open-addressing table keyed by (a, b), a repeated key marks
  // its slot as ambiguous, and each half-edge then looks up (b, a).
  void pair_half_edges() {
    const size_t nt = tri_.size();
    opp_.assign(4 * nt, kNone);
    table_.reset(3 * nt);
    for (uint32_t t = 0; t < nt; ++t)
      for (uint32_t k = 0; k < 3; ++k) {
        const uint32_t h = 4 * t + k, a = from(h), b = to(h);
        if (a == b) continue;
        const uint64_t key = (uint64_t(a) << 32) | b;
        const size_t i = table_.slot(key);
        if (table_.key(i) == key) {
          table_.value(i) = kNone;  // two half-edges a -> b: the edge is not manifold
        } else {
          table_.key(i) = key;
          table_.value(i) = h;
        }
      }
    for (uint32_t t = 0; t < nt; ++t)
      for (uint32_t k = 0; k < 3; ++k) {
        const uint32_t h = 4 * t + k, a = from(h), b = to(h);
        if (a == b) continue;
        const size_t own = table_.slot((uint64_t(a) << 32) | b), back = table_.slot((uint64_t(b) << 32) | a);
        if (table_.value(own) == kNone || table_.key(back) == SlotTable::kEmpty || table_.value(back) == kNone) continue;
        opp_[h] = table_.value(back);
      }
  }

  // A vertex may move only when it lies strictly inside the open box, every triangle around it
  // lies in the closed box, and its triangles form one closed fan. Then every triangle a
  // collapse changes stays in the closed box with a vertex strictly inside, so it can meet
  // triangles of other regions only in edges and vertices that exist already.
  void compute_locks() {
    const size_t nv = pos_.size();
    locked_.assign(nv, 0);
    for (size_t v = 0; v < nv; ++v)
      if (!box_.strictly_inside(pos_[v])) locked_[v] = 1;
    for (const auto& t : tri_) {
      if (box_.in_closed(pos_[t[0]]) && box_.in_closed(pos_[t[1]]) && box_.in_closed(pos_[t[2]])) continue;
      locked_[t[0]] = locked_[t[1]] = locked_[t[2]] = 1;
    }
    open_fan_.assign(nv, 0);
    for (size_t v = 0; v < nv; ++v)
      if (!walk_fan(uint32_t(v), nullptr, nullptr)) open_fan_[v] = locked_[v] = 1;
  }

  // Walks the fan of v (corners at v, and the vertex each leads to); false when it is not one
  // closed fan of degree_[v] faces.
  bool walk_fan(uint32_t v, std::vector<uint32_t>* ring, std::vector<uint32_t>* corners) const {
    const uint32_t start = corner_[v];
    if (start == kNone) return false;
    uint32_t c = start, steps = 0;
    do {
      if (ring) ring->push_back(to(c));
      if (corners) corners->push_back(c);
      const uint32_t across = opp_[prev_he(c)];
      if (across == kNone) return false;
      c = across;
      if (++steps > degree_[v]) return false;
    } while (c != start);
    return steps == degree_[v];
  }

  static Box3 tri_box(const std::array<Vec3d, 3>& p) {
    Box3 b;
    b.min = {std::min({p[0].x, p[1].x, p[2].x}), std::min({p[0].y, p[1].y, p[2].y}), std::min({p[0].z, p[1].z, p[2].z})};
    b.max = {std::max({p[0].x, p[1].x, p[2].x}), std::max({p[0].y, p[1].y, p[2].y}), std::max({p[0].z, p[1].z, p[2].z})};
    return b;
  }
  static bool shares_vertex(const std::array<uint32_t, 3>& x, const std::array<uint32_t, 3>& y) {
    for (uint32_t v : x)
      if (v == y[0] || v == y[1] || v == y[2]) return true;
    return false;
  }
  static bool overlaps(const Entry& e, const Box3& b) {
    return !(e.lo[0] > b.max.x || e.hi[0] < b.min.x || e.lo[1] > b.max.y || e.hi[1] < b.min.y || e.lo[2] > b.max.z ||
             e.hi[2] < b.min.z);
  }

  void next_stamp() {
    if (++stamp_now_ == 0) {
      std::fill(stamp_.begin(), stamp_.end(), 0);
      stamp_now_ = 1;
    }
  }

  // A grid over the region's box holding every live triangle (triangles reaching outside it go
  // to the border cells).
  void build_grid() {
    size_grid();
    grid_.resize(size_t(cells_ * cells_ * cells_));
    for (auto& list : grid_) list.clear();
    grid_version_.assign(tri_.size(), 0);
    stamp_.assign(tri_.size(), 0);
    stamp_now_ = 0;
    for (uint32_t t = 0; t < tri_.size(); ++t)
      if (tri_alive_[t]) insert(t);
  }

  // The cells of the grids over the region's box (build_grid's, verify's): about `per_cell` live
  // triangles per cell of a surface through the box, so cells ~ live^(1/2) per axis.
  void size_grid(double per_cell = 2.0) {
    size_t live = 0;
    for (uint8_t alive : tri_alive_) live += alive;
    cells_ = int(std::clamp(std::sqrt(double(live) / per_cell), 4.0, double(kMaxCells)));
    const Vec3d size = box_.hi - box_.lo;
    for (int k = 0; k < 3; ++k) inv_cell_[k] = cells_ / size[k];
  }

  // t's box rounded outwards to float.
  Entry entry_of(uint32_t t) const {
    const auto& v = tri_[t];
    const Box3 b = tri_box({pos_[v[0]], pos_[v[1]], pos_[v[2]]});
    Entry e;
    for (int k = 0; k < 3; ++k) {
      e.lo[k] = std::nextafter(float(b.min[k]), -HUGE_VALF);
      e.hi[k] = std::nextafter(float(b.max[k]), HUGE_VALF);
    }
    e.tri = t;
    e.version = 0;
    return e;
  }

  static Box3 box_of(const Entry& e) { return {{e.lo[0], e.lo[1], e.lo[2]}, {e.hi[0], e.hi[1], e.hi[2]}}; }

  int cell_coord(double v, int k) const {
    const double c = std::floor((v - box_.lo[k]) * inv_cell_[k]);
    return int(std::clamp(c, 0.0, double(cells_ - 1)));
  }

  template <class Visit>
  void for_cells(const Box3& b, Visit&& visit) const {
    const int x0 = cell_coord(b.min.x, 0), x1 = cell_coord(b.max.x, 0), y0 = cell_coord(b.min.y, 1),
              y1 = cell_coord(b.max.y, 1), z0 = cell_coord(b.min.z, 2), z1 = cell_coord(b.max.z, 2);
    for (int x = x0; x <= x1; ++x)
      for (int y = y0; y <= y1; ++y)
        for (int z = z0; z <= z1; ++z) visit(size_t((x * cells_ + y) * cells_ + z));
  }

  // Lists t, with its box rounded outwards to float, in the cells its box meets; entries of an
  // earlier version of t go stale: a query skips them, and a list drops them whenever its size
  // reaches a power of two, so lists stay within twice their live size.
  void insert(uint32_t t) {
    const auto& v = tri_[t];
    const Box3 b = tri_box({pos_[v[0]], pos_[v[1]], pos_[v[2]]});
    Entry e = entry_of(t);
    e.version = ++grid_version_[t];
    for_cells(b, [&](size_t c) {
      std::vector<Entry>& list = grid_[c];
      if (list.size() >= 64 && (list.size() & (list.size() - 1)) == 0)
        list.erase(std::remove_if(list.begin(), list.end(),
                                  [&](const Entry& x) { return !tri_alive_[x.tri] || x.version != grid_version_[x.tri]; }),
                   list.end());
      list.push_back(e);
    });
  }

  // The position the collapse of (keep, drop) would use before the volume is taken into account:
  // keep's own when it is locked, else the quadric's minimiser (the midpoint when it has none).
  Vec3d first_target(uint32_t keep, uint32_t drop, const Quadric& q) const {
    if (locked_[keep]) return pos_[keep];
    const Vec3d mid = (pos_[keep] + pos_[drop]) * 0.5;
    Vec3d target;
    if (!q.minimiser(mid, target)) target = mid;
    return target;
  }

  // Queues the collapse of edge (x, y) if the quadric error at its best position is within the
  // tolerance (the position that keeps the volume is worked out when the collapse is tried).
  void consider(uint32_t x, uint32_t y) {
    if (locked_[x] && locked_[y]) return;
    uint32_t keep = x, drop = y;
    if (locked_[x] == 0 && locked_[y] == 0 && y < x) std::swap(keep, drop);  // deterministic choice
    if (locked_[y]) std::swap(keep, drop);
    // A collapse into a vertex whose fan is not closed (on the region's border) is never taken, and
    // its fan stays open: collapses neither remove a border edge nor pair one.
    if (open_fan_[keep]) return;
    const Quadric q = quadric_[keep] + quadric_[drop];
    const double error = q.error(first_target(keep, drop, q));
    if (error > quadric_tolerance2_) return;
    queue_.push(std::sqrt(error / quadric_tolerance2_), {keep, drop, uint16_t(version_[keep]), uint16_t(version_[drop])});
  }

  Vec3d at(uint32_t v, uint32_t keep, const Vec3d& target) const { return v == keep ? target : pos_[v]; }

  // Whether the fan around p, given as corners (centre, next, previous) after `rename` and with
  // positions from `position`, projects one-to-one onto the coordinate plane orthogonal to axis
  // k with orientation sign s: then 2k + (s < 0), else kUnknownAxis. The projected faces must all
  // turn the same way and wind exactly once around p (exact orientations; the winding counts the
  // steps from below the line through p along the first projected axis to on or above it).
  template <class Rename, class Position>
  uint8_t graph_state(const Vec3d& p, const std::vector<uint32_t>& corners, Rename&& rename, Position&& position,
                      uint8_t preferred = kUnknownAxis) const {
    if (preferred != kUnknownAxis) {
      const int k = preferred / 2, i = (k + 1) % 3, j = (k + 2) % 3, sign = (preferred & 1) ? -1 : 1;
      int crossings = 0;
      bool ok = true;
      for (uint32_t c : corners) {
        const Vec3d a = position(rename(to(c))), b = position(rename(from(prev_he(c))));
        if (exact::orient2d(p[i], p[j], a[i], a[j], b[i], b[j]) != sign) {
          ok = false;
          break;
        }
        const bool a_low = a[j] < p[j], b_low = b[j] < p[j];
        if (sign > 0 ? (a_low && !b_low) : (!a_low && b_low)) ++crossings;
      }
      if (ok && crossings == 1) return preferred;
    }
    Vec3d normal;
    for (uint32_t c : corners) {
      const Vec3d a = position(rename(to(c))), b = position(rename(from(prev_he(c))));
      normal += cross(a - p, b - p);
    }
    const int k = dominant_axis(normal);
    const int i = (k + 1) % 3, j = (k + 2) % 3;
    const int sign = normal[k] > 0 ? 1 : -1;
    int crossings = 0;
    for (uint32_t c : corners) {
      const Vec3d a = position(rename(to(c))), b = position(rename(from(prev_he(c))));
      if (exact::orient2d(p[i], p[j], a[i], a[j], b[i], b[j]) != sign) return kUnknownAxis;
      const bool a_low = a[j] < p[j], b_low = b[j] < p[j];
      if (sign > 0 ? (a_low && !b_low) : (!a_low && b_low)) ++crossings;
    }
    return crossings == 1 ? uint8_t(2 * k + (sign < 0)) : kUnknownAxis;
  }

  // Whether triangle (v, a, b), counter-clockwise around v, projects with v's cached orientation.
  static bool keeps_graph(uint8_t state, const Vec3d& v, const Vec3d& a, const Vec3d& b) {
    const int k = state / 2, i = (k + 1) % 3, j = (k + 2) % 3, sign = (state & 1) ? -1 : 1;
    return exact::orient2d(v[i], v[j], a[i], a[j], b[i], b[j]) == sign;
  }

  // Whether p lies within the deviation of triangle abc (its box first).
  bool within_deviation(const Vec3d& p, const Vec3d& a, const Vec3d& b, const Vec3d& c) const {
    const double d = max_deviation_;
    for (int k = 0; k < 3; ++k)
      if (p[k] < std::min({a[k], b[k], c[k]}) - d || p[k] > std::max({a[k], b[k], c[k]}) + d) return false;
    return point_triangle_distance2(p, a, b, c) <= deviation_limit2_;
  }

  bool collapse(uint32_t keep, uint32_t drop) {
    drop_corners_.clear();
    drop_ring_.clear();
    if (!walk_fan(drop, &drop_ring_, &drop_corners_)) return false;
    uint32_t h = kNone;
    for (uint32_t c : drop_corners_)
      if (to(c) == keep) h = c;
    if (h == kNone) return false;
    const uint32_t g = opp_[h];
    if (g == kNone) return false;
    const uint32_t t1 = tri_of(h), t2 = tri_of(g);
    const uint32_t a = to(next_he(h)), b = to(next_he(g));
    keep_corners_.clear();
    keep_ring_.clear();
    if (!walk_fan(keep, &keep_ring_, &keep_corners_)) return false;
    // Link condition: keep and drop have exactly a and b as common neighbours.
    int common = 0;
    for (uint32_t x : drop_ring_)
      if (std::find(keep_ring_.begin(), keep_ring_.end(), x) != keep_ring_.end()) {
        if (x != a && x != b) return false;
        ++common;
      }
    if (common != 2 || a == b) return false;
    if (degree_[a] < 4 || degree_[b] < 4 || degree_[keep] + degree_[drop] < 7) return false;

    // The new fan of keep: both fans without t1 and t2, drop renamed.
    new_fan_.clear();
    for (uint32_t c : keep_corners_)
      if (tri_of(c) != t1 && tri_of(c) != t2) new_fan_.push_back(c);
    for (uint32_t c : drop_corners_)
      if (tri_of(c) != t1 && tri_of(c) != t2) new_fan_.push_back(c);
    auto rename = [&](uint32_t x) { return x == drop ? keep : x; };

    // A free vertex goes where the quadric is least among the positions that give the enclosed
    // volume its due (the volume before plus the two ends' debts; the new fan's volume is linear
    // in its position), unless that costs more than the tolerance; then to the plain minimiser.
    const Quadric q = quadric_[keep] + quadric_[drop];
    const Vec3d mid = (pos_[keep] + pos_[drop]) * 0.5;
    Vec3d n;
    double old6 = 0;
    for (uint32_t c : keep_corners_)
      old6 += dot(pos_[keep] - mid, cross(pos_[to(c)] - mid, pos_[from(prev_he(c))] - mid));
    for (uint32_t c : drop_corners_)
      if (tri_of(c) != t1 && tri_of(c) != t2)
        old6 += dot(pos_[drop] - mid, cross(pos_[to(c)] - mid, pos_[from(prev_he(c))] - mid));
    for (uint32_t c : new_fan_) n += cross(pos_[to(c)] - mid, pos_[from(prev_he(c))] - mid);
    // On a flat stretch the volume can only be given back by leaving its plane: the debt waits for
    // a curved one (a flat face stays flat, to the bit, for node sets and slicers).
    const double owed6 = debt_[keep] + debt_[drop];
    const double paid6 = q.flat() ? 0.0 : owed6;
    enum class Shape { kFine, kMisshapen, kRefused };
    Vec3d target;
    bool keep_moves = false;
    // The triangles that change at `placement`: drop's (renamed), and keep's when keep moves. None
    // may turn further than the normal bound, nor be worse shaped than the worst it replaces unless
    // it stays above kMinQuality: exact tests keep even a needle valid, but slicers, viewers and
    // meshers recompute its normal in float and trip on it.
    auto shape_at = [&](Placement placement) {
      target = first_target(keep, drop, q);
      if (!locked_[keep] && placement != Placement::kBest) {
        target = placement == Placement::kAtKeep ? pos_[keep] : pos_[drop];  // float already, as every position
        if (!box_.strictly_inside(target) || q.error(target) > quadric_tolerance2_) return Shape::kRefused;
      } else if (!locked_[keep]) {
        Vec3d volume_target;
        if (q.minimiser_on_plane(mid, n, old6 + paid6 + dot(n, mid), volume_target) &&
            q.error(round_to_output(volume_target)) <= quadric_tolerance2_)
          target = volume_target;
        target = round_to_output(target);
        if (!box_.strictly_inside(target) || q.error(target) > quadric_tolerance2_) return Shape::kRefused;
      } else if (!box_.strictly_inside(target)) {
        return Shape::kRefused;
      }
      keep_moves = target != pos_[keep];
      double old_quality2 = std::min(quality2_[t1], quality2_[t2]);
      double new_quality2 = HUGE_VAL;
      changed_.clear();
      changed_quality2_.clear();
      changed_ids_.clear();
      changed_pos_.clear();
      changed_box_.clear();
      for (uint32_t c : new_fan_) {
        const uint32_t t = tri_of(c);
        const auto& old = tri_[t];
        const bool of_drop = old[0] == drop || old[1] == drop || old[2] == drop;
        if (!of_drop && !keep_moves) continue;
        const std::array<uint32_t, 3> ids{rename(old[0]), rename(old[1]), rename(old[2])};
        const std::array<Vec3d, 3> p{at(ids[0], keep, target), at(ids[1], keep, target), at(ids[2], keep, target)};
        if (exact::collinear(p[0], p[1], p[2])) return Shape::kRefused;
        const Vec3d n_old = cross(pos_[old[1]] - pos_[old[0]], pos_[old[2]] - pos_[old[0]]);
        const Vec3d n_new = cross(p[1] - p[0], p[2] - p[0]);
        if (dot(n_old, n_new) <= cos_normal_ * norm(n_old) * norm(n_new)) return Shape::kMisshapen;
        old_quality2 = std::min(old_quality2, quality2_[t]);
        changed_quality2_.push_back(quality2(p[0], p[1], p[2]));
        new_quality2 = std::min(new_quality2, changed_quality2_.back());
        changed_.push_back(t);
        changed_ids_.push_back(ids);
        changed_pos_.push_back(p);
        changed_box_.push_back(tri_box(p));
      }
      return new_quality2 < std::min(kMinQuality * kMinQuality, old_quality2) ? Shape::kMisshapen : Shape::kFine;
    };
    // Misshapen at the best position, a free vertex is tried where keep is, then where drop is: on a
    // cylinder the quadric's minimiser sits mid-edge, which thins the triangles across the axis,
    // while an end keeps the ring's spacing (lattice_block: 68 890 -> 48 528 triangles).
    Shape shape = Shape::kRefused;
    for (Placement placement : {Placement::kBest, Placement::kAtKeep, Placement::kAtDrop}) {
      shape = shape_at(placement);
      if (shape != Shape::kMisshapen || locked_[keep]) break;
    }
    if (shape != Shape::kFine) return false;

    // Pairs sharing a vertex whose fan is a graph over a coordinate plane meet only in what they
    // share. keep's new fan is checked whole; a neighbour whose fan was a graph stays one when
    // its changed triangles keep the orientation: its changed stretch (two triangles) spans the
    // same angle as before, since both spans lie below a full turn and agree modulo one.
    const uint8_t keep_state = graph_state(target, new_fan_, rename, [&](uint32_t x) { return at(x, keep, target); },
                                           graph_axis_[keep] != kUnknownAxis ? graph_axis_[keep] : graph_axis_[drop]);
    touched_.clear();
    if (++touch_now_ == 0) {
      std::fill(touch_stamp_.begin(), touch_stamp_.end(), 0);
      touch_now_ = 1;
    }
    for (size_t i = 0; i < changed_.size(); ++i)
      for (int k = 0; k < 3; ++k) {
        const uint32_t w = changed_ids_[i][size_t(k)];
        if (w == keep) continue;
        if (touch_stamp_[w] != touch_now_) {
          touch_stamp_[w] = touch_now_;
          touched_.push_back(w);
          touch_state_[w] = graph_axis_[w];
          if (touch_state_[w] == kUnknownAxis) {
            // Not known: the whole fan as it will be (without t1 and t2).
            fan_scratch_.clear();
            if (walk_fan(w, nullptr, &fan_scratch_)) {
              fan_scratch_.erase(std::remove_if(fan_scratch_.begin(), fan_scratch_.end(),
                                                [&](uint32_t c) { return tri_of(c) == t1 || tri_of(c) == t2; }),
                                 fan_scratch_.end());
              touch_state_[w] = graph_state(pos_[w], fan_scratch_, rename, [&](uint32_t x) { return at(x, keep, target); });
            }
            touch_checked_[w] = 1;  // the whole fan was checked: no triangle to test on its own
            continue;
          }
          touch_checked_[w] = 0;
        }
        if (touch_checked_[w] || touch_state_[w] == kUnknownAxis) continue;
        if (!keeps_graph(touch_state_[w], changed_pos_[i][size_t(k)], changed_pos_[i][size_t((k + 1) % 3)],
                         changed_pos_[i][size_t((k + 2) % 3)]))
          touch_state_[w] = kUnknownAxis;
      }
    auto verified = [&](uint32_t x) {
      if (x == keep) return keep_state != kUnknownAxis;
      return (touch_stamp_[x] == touch_now_ ? touch_state_[x] : graph_axis_[x]) != kUnknownAxis;
    };
    auto shares_verified = [&](const std::array<uint32_t, 3>& x, const std::array<uint32_t, 3>& y) {
      for (uint32_t v : x)
        if ((v == y[0] || v == y[1] || v == y[2]) && verified(v)) return true;
      return false;
    };
    auto meets = [&](size_t i, const std::array<uint32_t, 3>& ids) {
      return !shares_verified(changed_ids_[i], ids) &&
             exact::faces_intersect(changed_pos_[i], changed_ids_[i], {pos_[ids[0]], pos_[ids[1]], pos_[ids[2]]}, ids);
    };
    // The changed triangles all hold keep: one graph fan covers every pair of them.
    for (size_t i = 0; i < changed_.size() && keep_state == kUnknownAxis; ++i)
      for (size_t j = i + 1; j < changed_.size(); ++j) {
        if (shares_verified(changed_ids_[i], changed_ids_[j])) continue;
        if (exact::faces_intersect(changed_pos_[i], changed_ids_[i], changed_pos_[j], changed_ids_[j])) {
          ++rejected_intersection_;
          return false;
        }
      }
    // The deviation tests last: they cost the most, and the cheaper tests above refuse most
    // of the collapses that fail.
    // Every original vertex the region has removed or moved stays within the deviation of the
    // surface: each is kept with a triangle it lies that near (a list per triangle), and the points
    // of the triangles a collapse removes or changes must each find a triangle of the new fan (its
    // own triangle's new shape first). Plane distances alone miss a spike folded into its base, and
    // many small moves could carry the surface away from a point no single collapse moved far.
    {
      // A triangle of the new fan within the deviation of the point (its id), or kNone.
      auto near_new_fan = [&](const Vec3d& point) {
        for (uint32_t c : new_fan_)
          if (within_deviation(point, target, at(rename(to(c)), keep, target), at(rename(from(prev_he(c))), keep, target)))
            return tri_of(c);
        return kNone;
      };
      // A vertex still at its extracted place (a locked vertex of the pass across the blocks that a
      // block moved is not: the block tracked its points).
      auto original = [&](uint32_t v) { return !shifted_[v] && !own_quadric_[v]; };
      pending_.clear();
      if (original(drop)) pending_.push_back({pos_[drop], kNone, kNone});
      if (keep_moves && original(keep)) pending_.push_back({pos_[keep], kNone, kNone});
      for (uint32_t t : {t1, t2})
        for (uint32_t id = tri_points_[t]; id != kNone; id = tracked_[id].next)
          pending_.push_back({tracked_[id].at, id, kNone});
      for (size_t i = 0; i < changed_.size(); ++i) {
        const auto& p = changed_pos_[i];
        for (uint32_t id = tri_points_[changed_[i]]; id != kNone; id = tracked_[id].next)
          pending_.push_back(
              {tracked_[id].at, id, within_deviation(tracked_[id].at, p[0], p[1], p[2]) ? changed_[i] : kNone});
      }
      for (PendingPoint& point : pending_)
        if (point.tri == kNone && (point.tri = near_new_fan(point.at)) == kNone) return false;
    }

    // The new triangles stay near the old surface: each centroid, and the midpoint of every edge
    // from the new vertex, within the deviation of the old fans (vertex tests alone let a
    // triangle bridge a concave crease or a sliver).
    // The sample's own triangle as it was is tried first: it is usually the one near.
    auto near_old_surface = [&](const Vec3d& sample, uint32_t first) {
      const auto& f = tri_[first];
      if (within_deviation(sample, pos_[f[0]], pos_[f[1]], pos_[f[2]])) return true;
      for (const std::vector<uint32_t>* fan : {&keep_corners_, &drop_corners_})
        for (uint32_t c : *fan) {
          const auto& t = tri_[tri_of(c)];
          if (within_deviation(sample, pos_[t[0]], pos_[t[1]], pos_[t[2]])) return true;
        }
      return false;
    };
    // A changed triangle is its old self with one corner (drop, or keep) moved to the target, so
    // its centroid is within a third of that move of the old one, and the midpoint of its edge
    // from the target within half of it: no search when that is within the deviation.
    const double moved_drop = norm(target - pos_[drop]), moved_keep = norm(target - pos_[keep]);
    for (size_t i = 0; i < changed_.size(); ++i) {
      const auto& old = tri_[changed_[i]];
      const bool of_drop = old[0] == drop || old[1] == drop || old[2] == drop;
      if ((of_drop ? moved_drop : moved_keep) <= 3 * max_deviation_) continue;
      if (!near_old_surface((changed_pos_[i][0] + changed_pos_[i][1] + changed_pos_[i][2]) / 3.0, changed_[i]))
        return false;
    }
    for (uint32_t c : new_fan_) {
      if ((from(c) == drop ? moved_drop : moved_keep) <= 2 * max_deviation_) continue;
      if (!near_old_surface((target + pos_[rename(to(c))]) * 0.5, tri_of(c))) return false;
    }

    next_stamp_for_collapse(t1, t2);
    bool hit = false;
    if (guarded_) {
      // Every live triangle whose box meets a changed one.
      Box3 all = changed_box_.empty() ? Box3() : changed_box_[0];
      for (const Box3& cb : changed_box_) {
        all.min = {std::min(all.min.x, cb.min.x), std::min(all.min.y, cb.min.y), std::min(all.min.z, cb.min.z)};
        all.max = {std::max(all.max.x, cb.max.x), std::max(all.max.y, cb.max.y), std::max(all.max.z, cb.max.z)};
      }
      if (!changed_.empty())
        for_cells(all, [&](size_t cell) {
          if (hit) return;
          auto& list = grid_[cell];
          for (const Entry& en : list) {
            const uint32_t u = en.tri;
            if (!overlaps(en, all) || !tri_alive_[u] || en.version != grid_version_[u] || stamp_[u] == stamp_now_)
              continue;
            stamp_[u] = stamp_now_;
            for (size_t i = 0; i < changed_.size() && !hit; ++i)
              if (overlaps(en, changed_box_[i]) && meets(i, tri_[u])) hit = true;
            if (hit) return;
          }
        });
    } else {
      // The unchanged triangles around every vertex of a changed one that is not covered by a
      // graph fan; pairs sharing no vertex are left to verify().
      for (size_t i = 0; i < changed_.size() && !hit; ++i)
        for (uint32_t x : changed_ids_[i]) {
          if (verified(x)) continue;
          fan_scratch_.clear();
          if (x == keep) {
            walk_fan(keep, nullptr, &fan_scratch_);
            walk_fan(drop, nullptr, &fan_scratch_);
          } else {
            walk_fan(x, nullptr, &fan_scratch_);
          }
          for (uint32_t c : fan_scratch_) {
            const uint32_t u = tri_of(c);
            if (stamp_[u] == stamp_now_) continue;  // t1, t2 or a changed one
            if (meets(i, tri_[u])) {
              hit = true;
              break;
            }
          }
          if (hit) break;
        }
    }
    if (hit) {
      ++rejected_intersection_;
      return false;
    }

    // Commit: t1 and t2 go, their outer edges are glued, drop's corners become keep's.
    const uint32_t h1 = next_he(h), h2 = next_he(h1), g1 = next_he(g), g2 = next_he(g1);
    const uint32_t o1 = opp_[h1], o2 = opp_[h2], o3 = opp_[g1], o4 = opp_[g2];
    if (o1 == kNone || o2 == kNone || o3 == kNone || o4 == kNone) return false;
    opp_[o1] = o2;
    opp_[o2] = o1;
    opp_[o3] = o4;
    opp_[o4] = o3;
    for (uint32_t x : {h, h1, h2, g, g1, g2}) opp_[x] = kNone;
    for (uint32_t c : drop_corners_) tri_[tri_of(c)][c & 3] = keep;
    tri_alive_[t1] = tri_alive_[t2] = 0;
    for (size_t i = 0; i < changed_.size(); ++i) {
      tri_changed_[changed_[i]] = 1;
      quality2_[changed_[i]] = changed_quality2_[i];
    }
    vertex_alive_[drop] = 0;
    corner_[drop] = kNone;
    corner_[keep] = o2;  // now keep -> a
    corner_[a] = o1;     // a -> keep
    corner_[b] = o3;     // b -> keep
    degree_[keep] = degree_[keep] + degree_[drop] - 4;
    degree_[a] -= 1;
    degree_[b] -= 1;
    pos_[keep] = target;
    quadric_[keep] += quadric_[drop];
    debt_[keep] = owed6 - (dot(target - mid, n) - old6);
    debt_[drop] = 0;
    moved_[keep] = 1;
    if (keep_moves) shifted_[keep] = 1;
    // The tracked points of the removed and changed triangles go to the triangles they were found
    // near (in the order found: the lists, and so the output, do not depend on threads).
    tri_points_[t1] = tri_points_[t2] = kNone;
    for (uint32_t t : changed_) tri_points_[t] = kNone;
    for (const PendingPoint& point : pending_) {
      uint32_t id = point.id;
      if (id == kNone) {
        id = uint32_t(tracked_.size());
        tracked_.push_back({point.at, kNone});
      }
      tracked_[id].next = tri_points_[point.tri];
      tri_points_[point.tri] = id;
    }
    ++version_[keep];
    ++version_[drop];
    graph_axis_[keep] = keep_state;
    for (uint32_t w : touched_) graph_axis_[w] = touch_state_[w];
    if (guarded_)
      for (uint32_t t : changed_) insert(t);
    keep_ring_after_.clear();
    for (uint32_t c : new_fan_) keep_ring_after_.push_back(rename(to(c)));
    return true;
  }

  // Stamps t1, t2 and the changed triangles, so the searches skip them.
  void next_stamp_for_collapse(uint32_t t1, uint32_t t2) {
    if (stamp_.size() != tri_.size()) stamp_.assign(tri_.size(), 0);
    next_stamp();
    stamp_[t1] = stamp_[t2] = stamp_now_;
    for (uint32_t t : changed_) stamp_[t] = stamp_now_;
  }

  double tolerance2_ = 0, quadric_tolerance2_ = 0, max_deviation_ = 0, cos_normal_ = 0;
  double deviation_limit2_ = 0;  // squared_limit(max_deviation_): squared distances decide as distances
  bool guarded_ = false;
  // Where a collapse puts a free vertex: the best position (see collapse), or where keep or drop is.
  enum class Placement { kBest, kAtKeep, kAtDrop };
  RegionBox box_;
  std::vector<uint32_t> global_vertex_;
  std::vector<std::array<uint32_t, 3>> tri_;
  std::vector<Vec3d> pos_;
  std::vector<Quadric> quadric_;
  std::vector<double> debt_, debt_start_;
  std::vector<double> quality2_, changed_quality2_;  // quality2 of every triangle, and of the changed ones as they would be
  std::vector<uint8_t> own_quadric_, tri_alive_, tri_changed_, vertex_alive_, locked_, open_fan_, graph_axis_;
  std::vector<Entry> verify_boxes_;
  std::vector<uint32_t> verify_start_, verify_cursor_, verify_entries_;
  std::vector<uint32_t> version_, degree_, corner_, opp_;
  SlotTable table_;  // load_global's (global id -> local number) and pair_half_edges' (a -> b half-edge)
  CollapseQueue queue_;
  double inv_cell_[3] = {1, 1, 1};
  int cells_ = kMaxCells;
  std::vector<std::vector<Entry>> grid_;
  std::vector<uint32_t> grid_version_, stamp_;
  uint32_t stamp_now_ = 0;
  std::vector<uint32_t> drop_corners_, drop_ring_, keep_corners_, keep_ring_, keep_ring_after_, new_fan_, changed_,
      touched_, fan_scratch_;
  std::vector<uint8_t> moved_, shifted_;  // moved: by a collapse here; shifted: off its original place
  // The tracked original vertices: a position and the next point of the same triangle's list.
  struct TrackedPoint {
    Vec3d at;
    uint32_t next;
  };
  std::vector<TrackedPoint> tracked_;
  std::vector<uint32_t> tri_points_;  // per triangle, the first of its tracked points (kNone: none)
  struct PendingPoint {
    Vec3d at;
    uint32_t id, tri;  // id: in tracked_, kNone for a point newly tracked; tri: the triangle it goes to
  };
  std::vector<PendingPoint> pending_;
  std::vector<uint32_t> touch_stamp_;
  std::vector<uint8_t> touch_state_, touch_checked_;
  uint32_t touch_now_ = 0;
  std::vector<Box3> changed_box_;
  std::vector<std::array<uint32_t, 3>> changed_ids_;
  std::vector<std::array<Vec3d, 3>> changed_pos_;
  uint64_t collapses_ = 0, rejected_intersection_ = 0;
};

// Adds what one region (or block) counted and timed to the totals.
void add_region_stats(SimplifyStats& total, const SimplifyStats& region) {
  total.collapses += region.collapses;
  total.rejected_by_intersection += region.rejected_by_intersection;
  total.regions_redone += region.regions_redone;
  total.regions_guarded += region.regions_guarded;
  total.run_thread_seconds += region.run_thread_seconds;
  total.verify_thread_seconds += region.verify_thread_seconds;
  total.redo_thread_seconds += region.redo_thread_seconds;
}

// Simplifies one region the fast way and verifies the result; redoes it guarded when the
// verification finds a crossing. `load` (re)loads the region's input.
template <class Load>
void simplify_region(RegionSimplifier& simplifier, Load&& load, SimplifyStats& stats) {
  const Stopwatch first;
  load();
  simplifier.run(false);
  stats.run_thread_seconds += first.seconds();
  const Stopwatch verifying;
  const bool verified = simplifier.verify();
  stats.verify_thread_seconds += verifying.seconds();
  if (!verified) {
    const Stopwatch redo;
    ++stats.regions_redone;
    // A block's bolder quadric bound meets the walls across a thin part more often; its region is
    // tried again the fast way within the plain bound (as the pass across the blocks runs), and
    // only then, if that fails too, guarded.
    const bool bold = simplifier.bold();
    auto run_within_deviation = [&](bool guarded) {
      load();
      simplifier.keep_quadric_within_deviation();
      simplifier.run(guarded);
    };
    if (bold) run_within_deviation(false);
    if (!bold || !simplifier.verify()) {
      ++stats.regions_guarded;
      run_within_deviation(true);
    }
    stats.redo_thread_seconds += redo.seconds();
  }
  stats.collapses += simplifier.collapses();
  stats.rejected_by_intersection += simplifier.rejected_by_intersection();
}

// The grid of regions a pass simplifies. Either from an origin (a mesh's own box), or the same
// planes for every surface of a grid: at (m + 1/2) sides for every integer m, so that regions of a
// block surface hold the meeting points of eight blocks in their middles wherever the surface
// starts (a surface streamed slab by slab meets the same regions as the whole). Keys order the
// regions x-major, or z-major (slab by slab, bottom to top).
struct Lattice {
  static constexpr double kShift = 1048576.5;  // 2^20 + 1/2: the planes' indices from 0
  Vec3d origin;
  double side = 1;
  bool canonical = false;
  bool z_major = false;
  double boundary(int k, int64_t i) const { return canonical ? (double(i) - kShift) * side : origin[k] + double(i) * side; }
  int64_t index_of(int k, double v) const {
    return std::max<int64_t>(0, int64_t(std::floor(canonical ? v / side + kShift : (v - origin[k]) / side)));
  }
  uint64_t pack(int64_t i, int64_t j, int64_t k) const {
    return z_major ? (uint64_t(k) << 42) | (uint64_t(j) << 21) | uint64_t(i)
                   : (uint64_t(i) << 42) | (uint64_t(j) << 21) | uint64_t(k);
  }
  void unpack(uint64_t key, int64_t& i, int64_t& j, int64_t& k) const {
    const int64_t a = int64_t(key >> 42), b = int64_t((key >> 21) & 0x1fffff), c = int64_t(key & 0x1fffff);
    i = z_major ? c : a;
    j = b;
    k = z_major ? a : c;
  }
};

// Which regions a pass simplifies and how it reads the triangles' order.
struct PassScope {
  // When given: the order the whole surface has its triangles in (a region loads them in it).
  const std::vector<TriangleOrder>* order = nullptr;
  // Only the regions whose z index lies in (z_after, z_until].
  int64_t z_after = -1, z_until = std::numeric_limits<int64_t>::max();
  bool apply_debt = true;  // add the regions' debt changes to the vertices (a later pass reads them)
};

// One pass over a global mesh: the regions of the lattice are simplified independently; a
// triangle belongs to every region whose open box its box meets, and to the region holding its
// centroid (which is the one that writes it). The regions' triangles, in key order, replace
// `triangles`, or, when `out` is given, are appended to it and `triangles` stays as it was.
template <class Triangles>
void simplify_pass(Vertices& vertices, Triangles& triangles, const Lattice& lattice, const SimplifyOptions& options,
                   SimplifyStats& stats, const PassScope& scope = {}, Triangles* out_triangles = nullptr) {
  const std::vector<Vec3d>& positions = vertices.positions;
  auto boundary = [&](int k, int64_t i) { return lattice.boundary(k, i); };
  auto index_of = [&](int k, double v) { return lattice.index_of(k, v); };
  const size_t nt = triangles.size();
  // (region, triangle) pairs, made per block of triangles and concatenated in order.
  const size_t blocks = std::max<size_t>(1, std::min<size_t>(64, nt / 65536 + 1));
  std::vector<std::vector<std::pair<uint64_t, uint32_t>>> parts(blocks);
  tbb::parallel_for(size_t(0), blocks, [&](size_t block) {
    auto& out = parts[block];
    for (size_t t = nt * block / blocks; t < nt * (block + 1) / blocks; ++t) {
      const auto& tri = triangles[t];
      const Vec3d &p0 = positions[tri[0]], &p1 = positions[tri[1]], &p2 = positions[tri[2]];
      const Box3 b{{std::min({p0.x, p1.x, p2.x}), std::min({p0.y, p1.y, p2.y}), std::min({p0.z, p1.z, p2.z})},
                   {std::max({p0.x, p1.x, p2.x}), std::max({p0.y, p1.y, p2.y}), std::max({p0.z, p1.z, p2.z})}};
      const Vec3d centroid = (p0 + p1 + p2) / 3.0;
      int64_t own[3], lo[3], hi[3];
      for (int k = 0; k < 3; ++k) {
        own[k] = index_of(k, centroid[k]);
        // The half-open rule by the exact boundary values.
        while (own[k] > 0 && centroid[k] < boundary(k, own[k])) --own[k];
        while (centroid[k] >= boundary(k, own[k] + 1)) ++own[k];
        lo[k] = std::max<int64_t>(0, index_of(k, b.min[k]) - 1);
        hi[k] = index_of(k, b.max[k]) + 1;
      }
      lo[2] = std::max(lo[2], scope.z_after + 1);
      hi[2] = std::min(hi[2], scope.z_until);
      bool own_listed = false;
      for (int64_t i = lo[0]; i <= hi[0]; ++i) {
        if (!(b.min.x < boundary(0, i + 1) && b.max.x > boundary(0, i))) continue;
        for (int64_t j = lo[1]; j <= hi[1]; ++j) {
          if (!(b.min.y < boundary(1, j + 1) && b.max.y > boundary(1, j))) continue;
          for (int64_t k = lo[2]; k <= hi[2]; ++k) {
            if (!(b.min.z < boundary(2, k + 1) && b.max.z > boundary(2, k))) continue;
            out.push_back({lattice.pack(i, j, k), uint32_t(t)});
            own_listed = own_listed || (i == own[0] && j == own[1] && k == own[2]);
          }
        }
      }
      if (!own_listed && own[2] > scope.z_after && own[2] <= scope.z_until)
        out.push_back({lattice.pack(own[0], own[1], own[2]), uint32_t(t)});
    }
  });
  std::vector<std::pair<uint64_t, uint32_t>> members;
  {
    size_t total = 0;
    for (const auto& p : parts) total += p.size();
    members.reserve(total);
    for (auto& p : parts) {
      members.insert(members.end(), p.begin(), p.end());
      std::vector<std::pair<uint64_t, uint32_t>>().swap(p);
    }
  }
  if (scope.order) {
    const std::vector<TriangleOrder>& order = *scope.order;
    tbb::parallel_sort(members.begin(), members.end(), [&](const auto& a, const auto& b) {
      return a.first != b.first ? a.first < b.first : order[a.second] < order[b.second];
    });
  } else {
    tbb::parallel_sort(members.begin(), members.end());
  }
  std::vector<size_t> region_start;
  for (size_t i = 0; i < members.size(); ++i)
    if (i == 0 || members[i].first != members[i - 1].first) region_start.push_back(i);
  region_start.push_back(members.size());
  const size_t regions = region_start.size() - 1;

  std::vector<std::vector<std::array<uint32_t, 3>>> out(regions);
  std::vector<std::vector<std::pair<uint32_t, double>>> debt_changes(regions);
  std::vector<SimplifyStats> region_stats(regions);
  Progress progress("simplify", regions);
  tbb::enumerable_thread_specific<RegionSimplifier> simplifiers(options);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, regions, 1), [&](const tbb::blocked_range<size_t>& range) {
    RegionSimplifier& simplifier = simplifiers.local();
    std::vector<uint32_t> ids;
    for (size_t r = range.begin(); r != range.end(); ++r) {
      ids.clear();
      for (size_t i = region_start[r]; i < region_start[r + 1]; ++i) ids.push_back(members[i].second);
      int64_t ri, rj, rk;
      lattice.unpack(members[region_start[r]].first, ri, rj, rk);
      const RegionBox box{{boundary(0, ri), boundary(1, rj), boundary(2, rk)},
                          {boundary(0, ri + 1), boundary(1, rj + 1), boundary(2, rk + 1)}};
      simplify_region(simplifier, [&] { simplifier.load_global(box, triangles.data(), ids, vertices); }, region_stats[r]);
      simplifier.store_global(vertices, out[r], debt_changes[r]);
      progress.advance();
    }
  });
  Triangles replaced;
  Triangles& result = out_triangles ? *out_triangles : replaced;
  std::vector<size_t> at(regions + 1, result.size());
  for (size_t r = 0; r < regions; ++r) at[r + 1] = at[r] + out[r].size();
  result.resize(at[regions]);
  tbb::parallel_for(size_t(0), regions, [&](size_t r) {
    std::copy(out[r].begin(), out[r].end(), result.begin() + std::ptrdiff_t(at[r]));
    std::vector<std::array<uint32_t, 3>>().swap(out[r]);
  });
  for (size_t r = 0; r < regions; ++r) {
    if (scope.apply_debt)
      for (const auto& [v, change] : debt_changes[r]) vertices.debt6[v] += change;
    add_region_stats(stats, region_stats[r]);
    ++stats.regions;
  }
  if (!out_triangles) triangles.swap(replaced);
}

// The vertices the triangles use, renumbered in their order, and the triangles.
template <class Triangles>
TriMesh compact(const std::vector<Vec3d>& positions, const Triangles& triangles) {
  TriMesh out;
  std::vector<uint32_t> index(positions.size(), kNone);
  for (const auto& t : triangles)
    for (uint32_t v : t) index[v] = 0;
  for (size_t v = 0; v < positions.size(); ++v)
    if (index[v] == 0) {
      index[v] = uint32_t(out.positions_mm.size());
      out.positions_mm.push_back(positions[v]);
    }
  out.triangles.reserve(triangles.size());
  for (const auto& t : triangles) out.triangles.push_back({index[t[0]], index[t[1]], index[t[2]]});
  return out;
}

void check_options(const SimplifyOptions& options) {
  if (!(options.max_deviation_mm > 0) || !std::isfinite(options.max_deviation_mm))
    throw InvalidInput("simplification needs a positive maximum deviation in mm");
  if (!(options.max_normal_change_deg > 0 && options.max_normal_change_deg <= 180))
    throw InvalidInput("simplification needs a maximum normal change between 0 and 180 degrees");
}

}  // namespace

TriMesh simplify_mesh(const TriMesh& mesh, const SimplifyOptions& options, SimplifyStats* stats_out) {
  check_options(options);
  SimplifyStats stats;
  stats.input_triangles = mesh.triangles.size();
  Vertices vertices(mesh.positions_mm.size());
  std::vector<Vec3d>& positions = vertices.positions;
  for (size_t v = 0; v < positions.size(); ++v) positions[v] = round_to_output(mesh.positions_mm[v]);
  std::vector<std::array<uint32_t, 3>> triangles = mesh.triangles;
  Box3 box;
  double area = 0;
  for (const auto& t : triangles) {
    for (uint32_t v : t) box.expand(positions[v]);
    area += 0.5 * norm(cross(positions[t[1]] - positions[t[0]], positions[t[2]] - positions[t[0]]));
  }
  if (triangles.empty() || box.empty()) {
    stats.output_triangles = mesh.triangles.size();
    if (stats_out) *stats_out = stats;
    return mesh;
  }
  // About 20 000 triangles per region: a region of side s holds about s^2 of surface.
  double side = options.region_mm;
  if (!(side > 0)) {
    const double extent = std::max({box.size().x, box.size().y, box.size().z});
    side = std::clamp(std::sqrt(20000.0 * area / double(triangles.size())), extent / 64, std::max(extent / 2, 1e-9));
    if (!(side > 0)) side = 1;
  }
  Lattice lattice;
  lattice.origin = box.min - Vec3d{side, side, side} * 1.25;
  lattice.side = side;
  simplify_pass(vertices, triangles, lattice, options, stats);
  lattice.origin = lattice.origin - Vec3d{side, side, side} * 0.5;
  simplify_pass(vertices, triangles, lattice, options, stats);
  TriMesh out = compact(positions, triangles);
  stats.output_triangles = out.triangles.size();
  if (stats_out) *stats_out = stats;
  return out;
}

namespace {

// Extracts the blocks `which` of the extractor (its indices, in increasing order) and simplifies
// each within its own box: results[i] for which[i]. Adds their figures to `stats`.
std::vector<BlockResult> simplified_blocks(const BlockExtractor& extractor, const std::vector<size_t>& which,
                                           const SimplifyOptions& options, SimplifyStats& stats) {
  const size_t blocks = which.size();
  std::vector<BlockResult> results(blocks);
  std::vector<SimplifyStats> block_stats(blocks);
  {
    Progress progress("mesh", blocks);
    tbb::enumerable_thread_specific<RegionSimplifier> simplifiers(options);
    tbb::enumerable_thread_specific<SurfaceBlock> surface_blocks;
    tbb::parallel_for(tbb::blocked_range<size_t>(0, blocks, 1), [&](const tbb::blocked_range<size_t>& range) {
      RegionSimplifier& simplifier = simplifiers.local();
      SurfaceBlock& block = surface_blocks.local();
      for (size_t i = range.begin(); i != range.end(); ++i) {
        const Stopwatch extracting;
        extractor.extract(which[i], block);
        block_stats[i].extract_thread_seconds = extracting.seconds();
        block_stats[i].input_triangles = block.piece_triangles;
        block_stats[i].merged_triangles = block.triangles.size();
        if (!block.triangles.empty()) {
          simplify_region(simplifier, [&] { simplifier.load_block(block); }, block_stats[i]);
          simplifier.store_block(block, results[i]);
        }
        for (int k = 0; k < 3; ++k) results[i].origin_voxels[k] = block.origin_voxels[k];
        progress.advance();
      }
    });
  }
  for (size_t i = 0; i < blocks; ++i) {
    stats.input_triangles += block_stats[i].input_triangles;
    stats.merged_triangles += block_stats[i].merged_triangles;
    stats.extract_thread_seconds += block_stats[i].extract_thread_seconds;
    add_region_stats(stats, block_stats[i]);
    stats.regions += results[i].triangles.empty() ? 0 : 1;
  }
  return results;
}

// The regions of a block surface: one block wide, centred on the blocks' meeting points.
Lattice block_lattice(double voxel_size_mm) {
  Lattice lattice;
  lattice.side = kBlockVoxels * voxel_size_mm;
  lattice.canonical = true;
  lattice.z_major = true;
  return lattice;
}

// The regions' indices hold 21 bits: a surface within 2^19 blocks of the origin.
void check_lattice_reach(const Box3& box, double voxel_size_mm) {
  const double reach = double(1 << 19) * kBlockVoxels * voxel_size_mm;
  for (int k = 0; k < 3; ++k)
    if (!(box.min[k] > -reach && box.max[k] < reach))
      throw ResourceLimit("the surface reaches beyond " + std::to_string(1 << 19) +
                          " blocks of 32 voxels from the origin; move the part nearer the origin");
}

}  // namespace

TriMesh extract_simplified_surface(const Volume& volume, const SimplifyOptions& options, SimplifyStats* stats_out) {
  check_options(options);
  SimplifyStats stats;
  ExtractOptions extract;
  extract.merge_deviation_mm = options.merge_fraction * options.max_deviation_mm;
  const BlockExtractor extractor(volume, kBlockVoxels, extract);
  const size_t blocks = extractor.block_count();
  std::vector<size_t> all(blocks);
  std::iota(all.begin(), all.end(), size_t(0));
  const Stopwatch blocks_time;
  std::vector<BlockResult> results = simplified_blocks(extractor, all, options, stats);
  stats.blocks_seconds = blocks_time.seconds();
  const Stopwatch assemble_time;
  std::vector<const std::vector<uint64_t>*> keys(blocks);
  for (size_t i = 0; i < blocks; ++i) keys[i] = &results[i].keys;
  std::vector<std::vector<uint32_t>> global;
  const uint64_t total = number_block_vertices(keys, global);
  Vertices vertices(total);
  std::vector<Vec3d>& positions = vertices.positions;
  // A vertex on a block face owes what every block that has it owes: added up in block order.
  for (size_t i = 0; i < blocks; ++i)
    for (size_t v = 0; v < results[i].positions.size(); ++v)
      if (results[i].keys[v] != kInteriorVertex) vertices.debt6[global[i][v]] += results[i].debt6[v];
  std::vector<size_t> first_triangle(blocks + 1, 0);
  for (size_t i = 0; i < blocks; ++i) first_triangle[i + 1] = first_triangle[i] + results[i].triangles.size();
  TriangleList triangles(first_triangle[blocks]);
  tbb::parallel_for(size_t(0), blocks, [&](size_t i) {
    BlockResult& r = results[i];
    const std::vector<uint32_t>& g = global[i];
    size_t next_quadric = 0;
    for (size_t v = 0; v < r.positions.size(); ++v) {
      positions[g[v]] = r.positions[v];  // a shared vertex is the same float triple from every block
      if (r.keys[v] == kInteriorVertex) {
        if (r.has_quadric[v]) vertices.quadrics[g[v]] = r.quadrics[next_quadric];
        vertices.has_quadric[g[v]] = r.has_quadric[v];
        vertices.debt6[g[v]] = r.debt6[v];
      }
      next_quadric += r.has_quadric[v];
    }
    for (size_t t = 0; t < r.triangles.size(); ++t) {
      const auto& tri = r.triangles[t];
      triangles[first_triangle[i] + t] = {g[tri[0]], g[tri[1]], g[tri[2]]};
    }
    r = BlockResult();
    std::vector<uint32_t>().swap(global[i]);
  });
  // The blocks' results are copied out and freed: their pages go back before the pass takes more.
  release_free_memory();
  // Across the block faces: regions of the same size, shifted by half a block, so each holds a
  // meeting point of eight blocks in its middle.
  stats.assemble_seconds = assemble_time.seconds();
  if (!triangles.empty()) {
    const Stopwatch pass_time;
    Box3 box;
    for (const Vec3d& p : positions) box.expand(p);
    check_lattice_reach(box, volume.voxel_size_mm());
    simplify_pass(vertices, triangles, block_lattice(volume.voxel_size_mm()), options, stats);
    stats.pass_seconds = pass_time.seconds();
  }
  // The quadrics and debts are done with: freed before the compact copy is made (a fifth of the
  // surface's peak memory on the lacunar egg benchmark).
  decltype(vertices.quadrics)().swap(vertices.quadrics);
  std::vector<uint8_t>().swap(vertices.has_quadric);
  std::vector<double>().swap(vertices.debt6);
  TriMesh out = compact(positions, triangles);
  stats.output_triangles = out.triangles.size();
  if (stats_out) *stats_out = stats;
  return out;
}


// The stream keeps a window of the surface: the simplified blocks of the slabs added so far whose
// triangles a region not simplified yet still meets, with what the whole surface's pass would know
// of their vertices (positions, quadrics, debts, their place in its numbering). A region runs once
// every block it meets is in and every vertex it loads has its debt summed from all its blocks:
// after a slab ending at z1, the regions whose top lies 1.5 blocks below z1 (their triangles come
// from blocks ending at z1 - 1 block at most, whose vertices lie below z1). Regions run as they do
// in one pass (none reads what another wrote: a triangle two regions meet has its vertices locked
// in both), so their triangles are the whole pass's, emitted in its order.
struct StreamedSurface::Impl {
  SimplifyOptions options;
  double h = 0;
  Lattice lattice;
  std::function<void(const EmittedTriangles&)> emit;
  Vertices window{0};
  std::vector<uint64_t> numbers;  // per window vertex: its number in the stream
  std::vector<std::array<uint32_t, 3>> triangles;
  std::vector<TriangleOrder> triangle_order;
  std::unordered_map<uint64_t, uint32_t> on_face;  // grid edge key -> window vertex
  // Face vertices whose blocks are not all in: (block, debt) per block so far.
  std::unordered_map<uint64_t, std::vector<std::pair<uint64_t, double>>> unsettled;
  int64_t regions_done = -1;                  // regions with z index up to this have run
  int64_t lead_in_until = kUnbounded;         // a part's first slab starts here or below
  int64_t z_end = std::numeric_limits<int64_t>::min();  // the voxels added so far end here
  uint64_t next_number = 0;
  SimplifyStats stats;
  bool finished = false;

  static uint64_t block_key(const int64_t o[3]) {
    uint64_t key = 0;
    for (int k = 0; k < 3; ++k) {
      const int64_t b = o[k] / kBlockVoxels + (int64_t(1) << 19);
      if (o[k] % kBlockVoxels != 0 || b < 0 || b >= (int64_t(1) << 20))
        throw ResourceLimit("the surface reaches beyond " + std::to_string(1 << 19) +
                            " blocks of 32 voxels from the origin; move the part nearer the origin");
      key = (key << 20) | uint64_t(b);
    }
    return key;  // x-major, as the blocks come in the whole surface
  }

  uint32_t new_vertex(const Vec3d& p, const VertexOrder& order) {
    window.positions.push_back(p);
    window.quadrics.push_back(Quadric());
    window.has_quadric.push_back(0);
    window.debt6.push_back(0.0);
    window.order.push_back(order);
    numbers.push_back(next_number++);
    return uint32_t(window.positions.size() - 1);
  }

  void add_blocks(std::vector<BlockResult>& results) {
    for (BlockResult& r : results) {
      if (r.triangles.empty()) continue;
      const uint64_t bk = block_key(r.origin_voxels);
      std::vector<uint32_t> local(r.positions.size());
      size_t next_quadric = 0;
      for (size_t v = 0; v < r.positions.size(); ++v) {
        const size_t quadric = next_quadric;
        next_quadric += r.has_quadric[v];
        if (r.keys[v] == kInteriorVertex) {
          const uint32_t w = local[v] = new_vertex(r.positions[v], {bk, v});
          if (r.has_quadric[v]) window.quadrics[w] = r.quadrics[quadric];
          window.has_quadric[w] = r.has_quadric[v];
          window.debt6[w] = r.debt6[v];
        } else {
          auto [it, inserted] = on_face.try_emplace(r.keys[v], 0u);
          if (inserted) it->second = new_vertex(r.positions[v], {kOnBlockFace, r.keys[v]});
          local[v] = it->second;
          unsettled[r.keys[v]].push_back({bk, r.debt6[v]});
        }
      }
      for (size_t t = 0; t < r.triangles.size(); ++t) {
        const auto& tri = r.triangles[t];
        triangles.push_back({local[tri[0]], local[tri[1]], local[tri[2]]});
        triangle_order.push_back({bk, t});
      }
      r = BlockResult();
    }
  }

  // The face vertices below z_mm have every block in: their debts summed in the blocks' order.
  void settle(double z_mm) {
    for (auto it = unsettled.begin(); it != unsettled.end();) {
      const uint32_t w = on_face.at(it->first);
      if (!(window.positions[w].z < z_mm)) {
        ++it;
        continue;
      }
      std::sort(it->second.begin(), it->second.end());
      double debt = 0;
      for (const auto& [block, share] : it->second) debt += share;
      window.debt6[w] = debt;
      it = unsettled.erase(it);
    }
  }

  // Runs the regions up to z index `until`, emits their triangles and keeps what later regions meet.
  void run_regions(int64_t until) {
    if (until <= regions_done) {  // a part's lead-in: keep only what the part's regions meet
      keep_after(regions_done);
      return;
    }
    std::vector<std::array<uint32_t, 3>> out;
    if (!triangles.empty()) {
      PassScope scope;
      scope.order = &triangle_order;
      scope.z_after = regions_done;
      scope.z_until = until;
      scope.apply_debt = false;  // the stream's pass is the last: nothing reads the debts after it
      // Within the lattice's reach: every vertex lies in its block, whose origin block_key() bounded.
      simplify_pass(window, triangles, lattice, options, stats, scope, &out);
    }
    regions_done = until;
    if (!out.empty()) {
      EmittedTriangles batch;
      batch.corners.reserve(out.size());
      batch.numbers.reserve(out.size());
      for (const auto& t : out) {
        batch.corners.push_back({window.positions[t[0]], window.positions[t[1]], window.positions[t[2]]});
        batch.numbers.push_back({numbers[t[0]], numbers[t[1]], numbers[t[2]]});
      }
      stats.output_triangles += out.size();
      emit(batch);
    }
    keep_after(until);
  }

  // Keeps the triangles a region after `until` meets (its open box, or its half-open box holding
  // the centroid), and their vertices.
  void keep_after(int64_t until) {
    const double top = lattice.boundary(2, until + 1);
    size_t kept = 0;
    for (size_t t = 0; t < triangles.size(); ++t) {
      const auto& tri = triangles[t];
      const Vec3d &p0 = window.positions[tri[0]], &p1 = window.positions[tri[1]], &p2 = window.positions[tri[2]];
      const double centroid_z = (p0.z + p1.z + p2.z) / 3.0;
      if (std::max({p0.z, p1.z, p2.z}) > top || centroid_z >= top) {
        triangles[kept] = triangles[t];
        triangle_order[kept] = triangle_order[t];
        ++kept;
      }
    }
    triangles.resize(kept);
    triangle_order.resize(kept);
    // The vertices they use, renumbered in window order.
    std::vector<uint32_t> index(window.positions.size(), kNone);
    for (const auto& t : triangles)
      for (uint32_t v : t) index[v] = 0;
    uint32_t n = 0;
    for (size_t v = 0; v < index.size(); ++v) {
      if (index[v] == kNone) continue;
      index[v] = n;
      window.positions[n] = window.positions[v];
      window.quadrics[n] = window.quadrics[v];
      window.has_quadric[n] = window.has_quadric[v];
      window.debt6[n] = window.debt6[v];
      window.order[n] = window.order[v];
      numbers[n] = numbers[v];
      ++n;
    }
    window.positions.resize(n);
    window.quadrics.resize(n);
    window.has_quadric.resize(n);
    window.debt6.resize(n);
    window.order.resize(n);
    numbers.resize(n);
    for (auto& t : triangles)
      for (uint32_t& v : t) v = index[v];
    for (auto it = on_face.begin(); it != on_face.end();) {
      if (index[it->second] == kNone) {
        unsettled.erase(it->first);
        it = on_face.erase(it);
      } else {
        it->second = index[it->second];
        ++it;
      }
    }
  }
};

StreamedSurface::StreamedSurface(const SimplifyOptions& options, double voxel_size_mm,
                                 std::function<void(const EmittedTriangles&)> emit)
    : impl_(std::make_unique<Impl>()) {
  check_options(options);
  if (!(voxel_size_mm > 0)) throw InvalidInput("a streamed surface needs a positive voxel size");
  impl_->options = options;
  impl_->h = voxel_size_mm;
  impl_->lattice = block_lattice(voxel_size_mm);
  impl_->emit = std::move(emit);
}

StreamedSurface::~StreamedSurface() = default;

void StreamedSurface::add(const Volume& volume, int64_t z0_voxels, int64_t z1_voxels) {
  Impl& m = *impl_;
  if (m.finished) throw InternalError("StreamedSurface::add after finish");
  if (z1_voxels <= z0_voxels || (z0_voxels != m.z_end && m.z_end != std::numeric_limits<int64_t>::min()) ||
      (z1_voxels != kUnbounded && z1_voxels % kBlockVoxels != 0) ||
      (z0_voxels != kUnbounded && z0_voxels != -kUnbounded && z0_voxels % kBlockVoxels != 0))
    throw InternalError("StreamedSurface::add: slabs must follow each other on whole blocks of 32 voxels");
  if (!volume.empty() && std::fabs(volume.voxel_size_mm() - m.h) > 1e-12 * m.h)
    throw InternalError("StreamedSurface::add: a slab of another voxel size");
  if (m.z_end == std::numeric_limits<int64_t>::min() && m.lead_in_until != kUnbounded &&
      !(z0_voxels <= m.lead_in_until))
    throw InternalError("StreamedSurface::add: a part's first slab must start three blocks below its cut");
  m.z_end = z1_voxels;
  if (!volume.empty()) {
    ExtractOptions extract;
    extract.merge_deviation_mm = m.options.merge_fraction * m.options.max_deviation_mm;
    const BlockExtractor extractor(volume, kBlockVoxels, extract);
    std::vector<size_t> which;
    for (size_t i = 0; i < extractor.block_count(); ++i) {
      const int64_t z = extractor.block_origin(i)[2];
      if (z >= z0_voxels && z < z1_voxels) which.push_back(i);
    }
    std::vector<BlockResult> results = simplified_blocks(extractor, which, m.options, m.stats);
    m.add_blocks(results);
  }
  if (z1_voxels == kUnbounded) return;
  // Every vertex half a block below the cut has all its blocks in (the regions run next read none
  // above z1 - 1 block); a vertex on the cut plane lies far above that, whatever float rounding does.
  const double z1_mm = double(z1_voxels) * m.h;
  m.settle(z1_mm - 0.5 * m.lattice.side);
  // The regions whose top lies 1.5 blocks below z1: (k + 1 - kShift) side <= z1 - 1.5 side.
  const int64_t c = z1_voxels / kBlockVoxels;
  m.run_regions(c + (int64_t(1) << 20) - 2);
}

void StreamedSurface::finish() {
  Impl& m = *impl_;
  if (m.finished) return;
  m.settle(std::numeric_limits<double>::infinity());
  m.run_regions((int64_t(1) << 21) - 1);
  m.finished = true;
}

void StreamedSurface::begin_after(int64_t cut_voxels) {
  Impl& m = *impl_;
  if (m.z_end != std::numeric_limits<int64_t>::min() || m.finished || cut_voxels % kBlockVoxels != 0)
    throw InternalError("StreamedSurface::begin_after: before the first slab, at a whole block");
  m.regions_done = cut_voxels / kBlockVoxels + (int64_t(1) << 20) - 2;  // as add() runs them after that cut
  m.lead_in_until = cut_voxels - 3 * kBlockVoxels;
}

std::vector<StreamedSurface::WindowVertex> StreamedSurface::window_vertices() const {
  const Impl& m = *impl_;
  std::vector<WindowVertex> out(m.numbers.size());
  for (size_t v = 0; v < out.size(); ++v) out[v] = {m.numbers[v], {m.window.order[v].first, m.window.order[v].second}};
  return out;
}

const SimplifyStats& StreamedSurface::stats() const { return impl_->stats; }
uint64_t StreamedSurface::numbers_given() const { return impl_->next_number; }

}  // namespace lacuna
