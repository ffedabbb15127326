// The fractal Voronoi recipe inputs: `voronoi_spheres` (spheres on the generators of a level: clusters,
// granular structures), `voronoi_tiles` (each colour's compact tile, with a clearance) and `voronoi_foam`
// (the walls between colours, thickened).
#pragma once

namespace lacuna {
namespace voronoi {

void register_recipe_inputs();

}  // namespace voronoi
}  // namespace lacuna
