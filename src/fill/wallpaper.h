// Periodic fractal patterns (../shared/spec/random-fractal-fill.md): a random fractal fill of one fundamental
// region of a wallpaper group, kept free of overlaps with every image of every motif under the group, then
// replicated over whole cells. Cell coordinates (u, v) stand for the point u a + v b of the lattice.
#pragma once

#include <string>
#include <vector>

#include "fill/fill.h"
#include "geometry.h"

namespace lacuna {
namespace fill {

enum class Group { p1, p2, pm, pg, cm, pmm, pmg, pgg, cmm, p4, p4m, p4g, p3, p3m1, p31m, p6, p6m };

// "p4m" -> Group::p4m. Throws InvalidInput for an unknown name, listing the 17.
Group group_from_name(const std::string& name);
std::string group_name(Group group);

// The lattice of translations, in millimetres. Each group constrains it:
// p1, p2: any two independent vectors; pm, pg, pmm, pmg, pgg: rectangular (a perpendicular to b);
// cm, cmm: rhombic (|a| = |b|, the mirrors along a + b); p4, p4m, p4g: square;
// p3, p3m1, p31m, p6, p6m: hexagonal (|a| = |b| at 60 or 120 degrees).
struct Lattice {
  Vec2d a{1, 0};
  Vec2d b{0, 1};
};

// x -> linear x + translation.
struct Affine2 {
  double linear[2][2] = {{1, 0}, {0, 1}};
  Vec2d translation;
};

Vec2d apply(const Affine2& map, const Vec2d& p);

// The lattice the group's cell coordinates refer to: the given one, except that a hexagonal b at 60 degrees
// from a becomes b - a (120 degrees). Throws InvalidInput naming the group and what is wrong (checked to 1e-9
// relative): degenerate or non-finite vectors, unequal lengths, a wrong angle.
Lattice group_lattice(Group group, const Lattice& lattice);

// The group's operations modulo the lattice, in cell coordinates (the International Tables' coordinates
// for the primitive cell; for cm and cmm the rhombic cell, whose mirror swaps u and v). The first is the
// identity; there are as many as the point group's order (1 .. 12).
std::vector<Affine2> cell_operations(Group group);
// The same in millimetres: linear part B L B^-1 and translation B t, with B = [a b] of group_lattice().
// Throws as group_lattice().
std::vector<Affine2> world_operations(Group group, const Lattice& lattice);

// A fundamental region, a counter-clockwise polygon in cell coordinates of area 1 / (number of operations):
// its images under the operations and the lattice tile the plane. Its mirror-line edges lie on mirrors.
std::vector<Vec2d> fundamental_region(Group group);
// The same in millimetres. Throws as group_lattice().
std::vector<Vec2d> fundamental_region_mm(Group group, const Lattice& lattice);

// The image of a placement under an isometry (a reflection flips `mirrored`).
Placement2 transform(const Affine2& isometry, const Placement2& placement);

// What to do with a motif that would overlap its own images (one that a mirror line or rotation centre cuts):
enum class BoundaryPolicy {
  kAllow,   // keep it, overlapping its images across the mirror lines and around the rotation centres that cut it
  kReject,  // try another position
  kSnap,    // a motif cut by a rotation centre is centred on it, one cut by a mirror line is moved
            // perpendicularly onto it, turned to align its mirrors (if it has the symmetry, else rejected);
            // its area is then stabilizer_order times the law's, the part inside the fundamental region
};

struct WallpaperFill {
  Group group = Group::p1;
  Lattice lattice;        // group_lattice() of the one given
  Motif2 motif;
  BoundaryPolicy policy = BoundaryPolicy::kReject;
  FillResult2 fundamental;  // the motifs whose centres lie in the fundamental region, in placement order
};

// Fills the fundamental region (area A) with motif i of area A / (zeta(c, N) (N + i)^c) (times its
// stabilizer order when snapped), at the first of max_trials uniform random positions in it where the motif
// keeps gap_mm from every image of the motifs placed before and from its own images (except the ones the
// policy allows). min_area_mm2 and the stop reasons are as in fill_region(); boundary_gap_mm is not used (the
// pattern has no boundary). Throws as fill_region() and group_lattice().
WallpaperFill fill_wallpaper(Group group, const Lattice& lattice, const Motif2& motif, const FillOptions& options = {},
                             BoundaryPolicy policy = BoundaryPolicy::kReject);

// Every image of every motif whose centre lies in the parallelogram {u a + v b : 0 <= u < cells_u,
// 0 <= v < cells_v}; images that coincide (a snapped motif and its stabilizer) appear once. Throws
// InvalidInput unless both counts are >= 1, ResourceLimit past 100 000 000 placements.
// `orbits`, when given, receives for each placement the index of the fundamental region's motif it is an
// image of.
std::vector<Placement2> replicate(const WallpaperFill& fill, int cells_u, int cells_v,
                                  std::vector<uint32_t>* orbits = nullptr);

// How the motifs of a pattern are coloured; every image of a motif takes its motif's colour, so the
// colouring keeps the pattern's symmetry.
enum class Coloring {
  kSize,    // by size class: class k holds the areas in (A_0 / 2^(k+1), A_0 / 2^k], A_0 the first motif's
  kOrbit,   // by orbit under the group: motif i (and all its images) takes colour i mod the palette's size
  kRandom,  // each motif a colour drawn uniformly from the palette (seeded)
};
// "size", "orbit" or "random"; throws InvalidInput otherwise.
Coloring coloring_from_name(const std::string& name);
// The palette index (0 .. palette_size - 1) of each motif of the fundamental region, in placement order.
// Throws InvalidInput unless palette_size >= 1.
std::vector<int> motif_colors(const FillResult2& fill, Coloring by, int palette_size, uint64_t seed);
// The same as palette entries: motif i takes palette[motif_colors(...)[i]]. Throws as motif_colors().
std::vector<std::string> motif_palette_colors(const FillResult2& fill, Coloring by, const std::vector<std::string>& palette,
                                              uint64_t seed);
// "#rrggbb,#rrggbb,..." (1 to 64 colours, hexadecimal digits either case) as lower-case "#rrggbb"
// strings; throws InvalidInput naming the entry that is not one.
std::vector<std::string> parse_palette(const std::string& text);
// Eight colours that tell apart in print and on screen (ColorBrewer's Dark2).
std::vector<std::string> default_palette();

// The pattern replicated over cells x cells unit cells as an SVG picture (y up), the fundamental region
// outlined in red: motifs black, or each in the colour `fills` gives its orbit (one "#rrggbb" per motif of
// the fundamental region). Throws as replicate(), and InvalidInput when `fills` is given with another size.
std::string wallpaper_svg(const WallpaperFill& pattern, int cells, const std::vector<std::string>& fills = {});

}  // namespace fill
}  // namespace lacuna
