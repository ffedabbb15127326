#!/usr/bin/env bash
# A 3D fractal Voronoi foam (program build/bench/lacuna_voronoi_bench): m = 4, d = 2, levels 4 and 5
# (16 384 and 131 072 points) in a 40 mm period: rules, points, cells and walls, the foam's level set and
# mesh, peak memory; level 4 also computes the walls from every generator's own cell for comparison.
# Usage: bench/run_voronoi.sh [BUILD_DIR]
set -euo pipefail
build="${1:-build}"
"$build/bench/lacuna_voronoi_bench" --level 4 --reference
"$build/bench/lacuna_voronoi_bench" --level 5
