#!/usr/bin/env bash
# The constant-density capsule walk: N capsules of radius 0.5 mm along a persistent random walk of
# 0.5 mm steps in a cube of side 20 (N/1000)^(1/3) mm, voxel r/6, through the whole recipe to a
# checked binary STL (one process each, so the peak memory is the run's own), with the union's
# volume against Lacuna at 0.04 mm for N = 1 000 and 10 000.
# Usage: bench/run_capsules.sh [BUILD_DIR]   (default: build)
set -euo pipefail
build="${1:-build}"
out="$(mktemp -d)"
for n in 1000 10000 50000; do
  reference=()
  [ "$n" -le 10000 ] && reference=(--reference-voxel 0.04)
  "$build/bench/lacuna_capsules_bench" --count "$n" --full --only-recipe "${reference[@]}" --out "$out/$n"
done
rm -rf "$out"
