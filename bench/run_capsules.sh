#!/usr/bin/env bash
# Runs the capsule benchmark for N = 1 000, 10 000 and 50 000 (one process each, so peak memory is
# per run). Usage: bench/run_capsules.sh [BUILD_DIR]   (default: build)
set -euo pipefail
build="${1:-build}"
out="$(mktemp -d)"
for n in 1000 10000 50000; do
  soup=--soup
  [ "$n" -gt 10000 ] && soup=""   # the soup path takes minutes there
  "$build/bench/lacuna_capsules_bench" --count "$n" $soup --full --out "$out/$n"
done
rm -rf "$out"
