#!/usr/bin/env bash
# Random fractal fills at scale (program build/bench/lacuna_fill_bench): 100 000 circles in p6m,
# 50 000 spheres in the egg hull scaled to 60 mm (placements per second, stop reasons, peak memory),
# and the box-counting dimension of 20 000 circles (c = 1.3) against 2/c.
# Usage: bench/run_fill.sh [BUILD_DIR]
set -euo pipefail
build="${1:-build}"
"$build/bench/lacuna_fill_bench" --circles 100000 --spheres 0
"$build/bench/lacuna_fill_bench" --circles 0 --spheres 50000
"$build/bench/lacuna_fill_bench" --circles 0 --spheres 0 --dimension-circles 20000
