#!/usr/bin/env bash
# Menger sponge levels 4 and 5 at 1/3^6 of the side (rasterization of the streamed cells), and the
# whole recipe to a checked STL at 1/3^5 (level 4) where mesh and checks fit in memory.
# Usage: bench/run_menger.sh [BUILD_DIR]   (default: build)
set -euo pipefail
build="${1:-build}"
out="$(mktemp -d)"
"$build/bench/lacuna_menger_bench" --level 4 --divisions 729 --full-divisions 243 --out "$out/4"
"$build/bench/lacuna_menger_bench" --level 5 --divisions 729
rm -rf "$out"
