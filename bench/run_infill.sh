#!/usr/bin/env bash
# Fills a 60 mm imported hull with a lattice at 0.1 mm voxels (bench/infill_60mm.json) and prints
# the report's times and peak memory. Usage: bench/run_infill.sh [BUILD_DIR]
set -euo pipefail
build="${1:-build}"
out="$(mktemp -d)"
"$build/lacuna" run bench/infill_60mm.json -o "$out" --quiet --json > "$out/report.out"
python3 -c "import json,sys; r=json.load(open(sys.argv[1])); o=r['outputs'][0]; print(json.dumps({'total_seconds': r['total_seconds'], 'stage_seconds': r['stage_seconds'], 'peak_memory_bytes': r['peak_memory_bytes'], 'triangles': o['triangles'], 'voxels': o['voxels'], 'relative_density': o.get('relative_density'), 'valid': o['checks']['valid']}))" "$out/report.out"
rm -rf "$out"
