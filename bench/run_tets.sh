#!/usr/bin/env bash
# TetGen on the checked Menger level-3 solid (1.18 M surface triangles, surface preserved) and on a
# lattice surface decimated to about 100 000 triangles. Usage: bench/run_tets.sh [BUILD_DIR]
set -euo pipefail
build="${1:-build}"
out="$(mktemp -d)"
"$build/lacuna" run samples/menger_sponge.json -o "$out/menger" --quiet
"$build/bench/lacuna_tet_bench" --mesh "$out/menger/menger_sponge.stl"
"$build/lacuna" run samples/lattice_block.json -o "$out/lattice" --quiet
"$build/bench/lacuna_tet_bench" --mesh "$out/lattice/lattice_block.stl" --decimate 0.0008
rm -rf "$out"
