#!/usr/bin/env bash
# The superimposed Sierpinski curves S_(1,7) (87 376 segments) on a torus as tubes of radius 0.15 mm
# at 0.03 mm voxels:
#  1. their exact fill rate in the square for the tubes' width on a torus of scale 20 mm;
#  2. mapping and rasterization on that torus (major radius 30 mm, minor 20 mm), bench program;
#  3. the whole recipe to a checked 3MF (bench/torus_sierpinski.json: a torus of scale 5 mm; the
#     mesh of the 20 mm torus would have about 500 M triangles). The budget's estimate counts every
#     tube's band as if none overlapped (here they overlap about 3 times), so it runs with a budget
#     of 32 GB (MAX_MEMORY_GB) and reports the peak it actually reached.
# Usage: bench/run_curves.sh [BUILD_DIR]
set -euo pipefail
build="${1:-build}"
out="$(mktemp -d)"
trap 'rm -rf "$out"' EXIT
# Tube diameter 0.3 mm over the torus's minor circumference 2 pi 20 mm, as a width in the square (side 2).
"$build/lacuna" curve fill-rate --kind sierpinski --orders 1..7 --width 0.004775 --json
"$build/bench/lacuna_curves_bench" --first-order 1 --last-order 7 --scale 20 --radius 0.15 --voxel 0.03
"$build/lacuna" run bench/torus_sierpinski.json -o "$out/run" --quiet --json --max-memory "${MAX_MEMORY_GB:-32}" > "$out/report.json"
python3 -c "import json,sys; r=json.load(open(sys.argv[1])); o=r['outputs'][0]; print(json.dumps({'total_seconds': r['total_seconds'], 'stage_seconds': r['stage_seconds'], 'peak_memory_bytes': r['peak_memory_bytes'], 'memory_estimate_bytes': r['memory_estimate_bytes'], 'voxels': o['voxels'], 'triangles': o['triangles'], 'components': o['components'], 'genus': o['genus'], 'valid': o['checks']['valid']}))" "$out/report.json"
