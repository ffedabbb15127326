// The `voronoi_spheres` recipe input: spheres centred on the generators of a fractal Voronoi level
// (clusters, granular structures).
#pragma once

namespace lacuna {
namespace voronoi {

void register_recipe_inputs();

}  // namespace voronoi
}  // namespace lacuna
