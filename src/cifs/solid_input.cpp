#include "cifs/solid_input.h"

#include <cmath>
#include <memory>
#include <set>
#include <string>

#include "cifs/library.h"
#include "cifs/tessellate.h"
#include "errors.h"

namespace lacuna {
namespace cifs {
namespace {

// Every piece is streamed through the rasterizer (about 25 us each with its edges): 20 million take
// minutes; more would run for hours with nothing to show.
constexpr uint64_t kMaxPieces = 20'000'000;

Vec3d column(const Eigen::Matrix3Xd& v, Eigen::Index i) { return Vec3d{v(0, i), v(1, i), v(2, i)}; }

// Edges (pairs of vertex indices) of a primitive with `m` vertices: segments and polygons along
// their outline, polyhedra along their faces, each edge once.
std::vector<std::pair<int, int>> primitive_edges(const State& s) {
  std::set<std::pair<int, int>> edges;
  const int m = int(s.vertices.cols());
  auto loop = [&](const std::vector<int>& face) {
    for (size_t i = 0; i < face.size(); ++i) {
      int a = face[i], b = face[(i + 1) % face.size()];
      edges.insert({std::min(a, b), std::max(a, b)});
    }
  };
  if (primitive_dimension(s.primitive) == 3) {
    for (const auto& face : primitive_faces(s)) loop(face);
  } else if (primitive_dimension(s.primitive) == 1) {
    edges.insert({0, m - 1});
  } else {
    std::vector<int> outline;
    for (int i = 0; i < m; ++i) outline.push_back(i);
    loop(s.faces.empty() ? outline : s.faces.front());
  }
  return {edges.begin(), edges.end()};
}

// The largest piece (diagonal of its vertices' box, mm) of each level from 0 up to `level`, as far
// as the levels stay small (at most kMeasuredPieces pieces); levels beyond are not listed.
constexpr uint64_t kMeasuredPieces = 100'000;

std::vector<double> largest_pieces(const Cifs& c, int level) {
  std::vector<double> largest;
  for (int l = 0; l <= level && count_pieces(c.automaton, l) <= kMeasuredPieces; ++l) {
    double d = 0;
    for_each_piece(c, l, [&](const Piece& piece) {
      Box3 box;
      for (Eigen::Index i = 0; i < piece.vertices->cols(); ++i) box.expand(column(*piece.vertices, i));
      d = std::max(d, norm(box.size()));
    });
    largest.push_back(d);
  }
  return largest;
}

// Refuses a level whose pieces are all under an eighth of a voxel when the level before already
// was: every further level moves the surface by less than that and only multiplies the work (the
// Sierpinski triangle at level 14 is 4.8 million pieces of a thousandth of a millimetre). Levels
// too large to list are extrapolated with the slowest shrinking seen in the last three levels.
void refuse_subvoxel_levels(const Cifs& c, int level, double voxel_mm) {
  if (!(voxel_mm > 0) || level < 2) return;
  const std::vector<double> d = largest_pieces(c, level);
  if (d.size() < 2 || !(d.back() > 0)) return;
  double shrink = 0;
  for (size_t l = d.size() - 1; l >= 1 && l + 3 >= d.size(); --l) {
    if (!(d[l - 1] > 0)) return;
    shrink = std::max(shrink, d[l] / d[l - 1]);
  }
  if (!(shrink < 1)) return;
  auto largest_at = [&](int l) {
    return size_t(l) < d.size() ? d[size_t(l)] : d.back() * std::pow(shrink, double(l - int(d.size()) + 1));
  };
  const double small = voxel_mm / 8;
  int first = 0;  // the first level under an eighth of a voxel
  while (first < level && !(largest_at(first) < small)) ++first;
  if (!(largest_at(first) < small) || level <= first) return;
  const bool measured = size_t(level) < d.size();
  throw InvalidInput("level " + std::to_string(level) + " makes pieces of at most " + (measured ? "" : "about ") +
                     message_number(largest_at(level)) + " mm, under an eighth of the voxel (" +
                     message_number(voxel_mm) + " mm): the levels past " + std::to_string(first) +
                     " change no voxel and only multiply the work; use \"level\" " + std::to_string(first) +
                     " or less, or a smaller voxel_size_mm");
}

}  // namespace

Cifs fit_to_box(const Cifs& cifs_in, const Box3& target) {
  Cifs c = cifs_in;
  complete_primitives(c.automaton);
  // The pieces of a few levels bound the attractor closely (they contain it).
  Box3 source;
  const int level = int(std::min<uint64_t>(3, count_pieces(c.automaton, 3) > 100000 ? 1 : 3));
  for_each_piece(c, level, [&](const Piece& piece) {
    for (Eigen::Index i = 0; i < piece.vertices->cols(); ++i) source.expand(column(*piece.vertices, i));
  });
  double scale = HUGE_VAL;
  for (int k = 0; k < 3; ++k)
    if (source.size()[k] > 1e-12 * norm(source.size())) scale = std::min(scale, target.size()[k] / source.size()[k]);
  if (!std::isfinite(scale) || !(scale > 0)) throw InvalidInput("cannot fit an attractor without extent to a box");
  const Vec3d shift = (target.min + target.max) * 0.5 - (source.min + source.max) * 0.5 * scale;
  for (Eigen::Index i = 0; i < c.control_points.cols(); ++i) {
    const double w = c.rational ? c.control_points(3, i) : 1.0;
    c.control_points.block<3, 1>(0, i) = c.control_points.block<3, 1>(0, i) * scale + Eigen::Vector3d(shift.x, shift.y, shift.z) * w;
  }
  return c;
}

GeometrySet attractor_geometry(const Cifs& cifs_in, int level, const SolidOptions& options) {
  auto c = std::make_shared<Cifs>(cifs_in);
  complete_primitives(c->automaton);
  const uint64_t pieces = count_pieces(c->automaton, level);
  if (pieces > kMaxPieces)
    throw ResourceLimit("level " + std::to_string(level) + " has " + std::to_string(pieces) + " pieces, more than " +
                        std::to_string(kMaxPieces) + "; use a lower level");
  refuse_subvoxel_levels(*c, level, options.voxel_size_mm);
  int dimension = -1;
  for (const State& s : c->automaton.states) {
    int d = primitive_dimension(s.primitive);
    if (dimension >= 0 && d != dimension && options.as != SolidOptions::As::kEdges)
      throw InvalidInput("the system mixes primitives of different dimensions; use \"as\": \"edges\"");
    dimension = std::max(dimension, d);
  }
  SolidOptions::As as = options.as;
  if (as == SolidOptions::As::kDefault)
    as = dimension == 1 ? SolidOptions::As::kTubes : dimension == 2 ? SolidOptions::As::kShell : SolidOptions::As::kCells;
  if (as == SolidOptions::As::kTubes && dimension != 1) throw InvalidInput("\"tubes\" needs a curve system; use \"edges\"");
  if (as == SolidOptions::As::kShell && dimension != 2) throw InvalidInput("\"shell\" needs a surface system");
  if (as == SolidOptions::As::kCells && dimension != 3) throw InvalidInput("\"cells\" needs a volume system");
  if ((as == SolidOptions::As::kTubes || as == SolidOptions::As::kEdges) && !(options.radius_mm > 0))
    throw InvalidInput("tubes need a positive \"radius_mm\"");
  if (as == SolidOptions::As::kShell && !(options.thickness_mm > 0))
    throw InvalidInput("a shell needs a positive \"thickness_mm\"");
  const size_t batch = std::max<size_t>(options.batch_pieces, 1);

  GeometryStream stream;
  switch (as) {
    case SolidOptions::As::kCells:
      stream.emit = [c, level, batch](const std::function<void(const GeometrySet&)>& sink) {
        tessellate_cells(*c, level, batch, [&](const ConvexCells& cells) {
          GeometrySet set;
          set.cells.push_back(cells);
          sink(set);
        });
      };
      break;
    case SolidOptions::As::kTubes: {
      // Consecutive pieces share their end points, so a curve split between batches stays whole.
      const double radius = options.radius_mm;
      stream.emit = [c, level, batch, radius](const std::function<void(const GeometrySet&)>& sink) {
        GeometrySet set;
        size_t count = 0;
        for (auto& line : tessellate_curves(*c, level)) {
          for (size_t i = 0; i < line.size(); i += batch) {
            size_t end = std::min(line.size(), i + batch + 1);
            set.tubes.tubes.push_back(Tube{std::vector<Vec3d>(line.begin() + long(i), line.begin() + long(end)), {radius}});
            count += end - i;
            if (count >= batch) {
              sink(set);
              set = GeometrySet();
              count = 0;
            }
          }
        }
        if (!set.tubes.tubes.empty()) sink(set);
      };
      break;
    }
    case SolidOptions::As::kShell:
    case SolidOptions::As::kEdges: {
      const bool shell = as == SolidOptions::As::kShell;
      const double size = shell ? options.thickness_mm : options.radius_mm;
      auto edges = std::make_shared<std::vector<std::vector<std::pair<int, int>>>>();
      for (const State& s : c->automaton.states) edges->push_back(primitive_edges(s));
      stream.emit = [c, level, batch, shell, size, edges](const std::function<void(const GeometrySet&)>& sink) {
        GeometrySet set;
        size_t count = 0;
        for_each_piece(*c, level, [&](const Piece& piece) {
          const Eigen::Matrix3Xd& v = *piece.vertices;
          if (shell) {
            ThickSurface& s = set.surfaces.empty() ? set.surfaces.emplace_back(ThickSurface{TriMesh{}, size})
                                                   : set.surfaces.back();
            uint32_t base = uint32_t(s.surface.positions_mm.size());
            for (Eigen::Index i = 0; i < v.cols(); ++i) s.surface.positions_mm.push_back(column(v, i));
            for (uint32_t i = 1; i + 1 < uint32_t(v.cols()); ++i) s.surface.triangles.push_back({base, base + i, base + i + 1});
          } else {
            for (const auto& [a, b] : (*edges)[size_t(piece.state)])
              set.tubes.tubes.push_back(Tube{{column(v, a), column(v, b)}, {size}});
          }
          if (++count >= batch) {
            sink(set);
            set = GeometrySet();
            count = 0;
          }
        });
        if (count > 0) sink(set);
      };
      break;
    }
    case SolidOptions::As::kDefault:
      break;
  }
  GeometrySet out;
  out.streams.push_back(std::move(stream));
  return out;
}

}  // namespace cifs
}  // namespace lacuna
