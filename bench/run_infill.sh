#!/usr/bin/env bash
# Fills a 60 mm imported hull with a lattice (bench/infill_60mm.json) and prints the report's
# times and peak memory, at the voxel sizes given (default 0.1 and 0.15 mm; a size whose estimate
# exceeds the budget is refused with exit 3 and the message says what would fit).
# Usage: bench/run_infill.sh [BUILD_DIR] [VOXEL_MM ...]    (MAX_MEMORY_GB, default 20)
set -euo pipefail
build="${1:-build}"
shift || true
sizes=("$@")
[ "${#sizes[@]}" -gt 0 ] || sizes=(0.1 0.15)
out="$(mktemp -d)"
for h in "${sizes[@]}"; do
  if "$build/lacuna" run bench/infill_60mm.json -o "$out/$h" --quiet --json --voxel-size "$h" \
      --max-memory "${MAX_MEMORY_GB:-20}" > "$out/report.out" 2> "$out/error.out"; then
    python3 -c "import json,sys; r=json.load(open(sys.argv[1])); o=r['outputs'][0]; print(json.dumps({'voxel_size_mm': r['voxel_size_mm'], 'total_seconds': r['total_seconds'], 'stage_seconds': r['stage_seconds'], 'peak_memory_bytes': r['peak_memory_bytes'], 'memory_estimate_bytes': r['memory_estimate_bytes'], 'triangles': o['triangles'], 'voxels': o['voxels'], 'relative_density': o.get('relative_density'), 'valid': o['checks']['valid']}))" "$out/report.out"
  else
    echo "voxel $h mm: exit $?: $(cat "$out/error.out")"
  fi
done
rm -rf "$out"
