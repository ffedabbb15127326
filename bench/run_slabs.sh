#!/usr/bin/env bash
# `lacuna slice` slab by slab and over MPI ranks, against the whole part in one process: wall time and
# peak memory (GNU time's maximum resident set) of each run, and whether the files are the same bytes.
#   1. the Menger sponge level 5 at 1/3^6 of its side (27 mm, voxel 1/27 mm), whole and 8 slabs;
#   2. the 60 mm egg infill (bench/infill_60mm.json) at 0.1 mm, whole and 8 slabs, and at 0.05 mm within
#      a 4 GB budget (slabs as high as the estimates allow) against the whole part (a 20 GB budget);
#   3. mpirun -np 2 with one thread per rank against one process with one thread (Menger, level 5).
# Usage: bench/run_slabs.sh [BUILD_DIR] [STEPS]   (default: build, steps 123; step 3 needs mpirun and an
#        MPI build)
set -euo pipefail
build="$(cd "${1:-build}" && pwd)"
steps="${2:-123}"
lacuna="$build/lacuna"
out="$(mktemp -d)"
trap 'rm -rf "$out"' EXIT
python3 - "$out/menger5.json" <<'PY'
import json, sys
h = 27 / 729
json.dump({"lacuna_recipe": 1, "name": "menger5", "voxel_size_mm": h,
           "inputs": {"sponge": {"type": "cifs", "level": 5,
                                 "system": {"library": "menger_sponge", "scale": 27, "translate_mm": [h / 2] * 3}}},
           "outputs": [{"of": "sponge", "file": "menger5.stl"}]}, open(sys.argv[1], "w"))
PY
cp bench/infill_60mm.json "$out/" && sed -i 's#"../samples/#"'"$PWD"'/samples/#' "$out/infill_60mm.json"

# run NAME ARGS...: one timed slice; prints seconds, peak memory, slabs.
run() {
  local name="$1"; shift
  if ! /usr/bin/time -f "%e %M" -o "$out/$name.time" "$@" --quiet --json > "$out/$name.json" 2> "$out/$name.err"; then
    echo "{\"run\": \"$name\", \"failed\": $(python3 -c 'import json,sys; print(json.dumps(open(sys.argv[1]).read().strip()))' "$out/$name.err")}"
    return 0
  fi
  python3 - "$out/$name.json" "$out/$name.time" "$name" <<'PY'
import json, sys
r = json.load(open(sys.argv[1]))
seconds, kb = open(sys.argv[2]).read().split()[-2:]
print(json.dumps({"run": sys.argv[3], "seconds": float(seconds), "peak_memory_gb": round(int(kb) / 1e6, 3),
                  "slabs": r["slabs"], "slab_mm": r["slab_mm"], "halo_mm": r["halo_mm"], "layers": r["layer_count"],
                  "estimate_gb": round(r["memory_estimate_bytes"] / 1e9, 3)}))
PY
}
same() { cmp -s "$out/$1" "$out/$2" && echo "{\"same_bytes\": [\"$1\", \"$2\"]}" || echo "{\"DIFFERENT\": [\"$1\", \"$2\"]}"; }

if [[ "$steps" == *1* ]]; then
run menger-whole "$lacuna" slice "$out/menger5.json" -o "$out/m-whole.zip"
run menger-8 "$lacuna" slice "$out/menger5.json" -o "$out/m-8.zip" --slab-mm 3.4
same m-whole.zip m-8.zip
fi
if [[ "$steps" == *2* ]]; then
run egg01-whole "$lacuna" slice "$out/infill_60mm.json" -o "$out/e-whole.zip"
run egg01-8 "$lacuna" slice "$out/infill_60mm.json" -o "$out/e-8.zip" --slab-mm 4.6
same e-whole.zip e-8.zip
run egg005-4gb "$lacuna" slice "$out/infill_60mm.json" -o "$out/e-005.zip" --voxel-size 0.05 --max-memory 4
run egg005-whole "$lacuna" slice "$out/infill_60mm.json" -o "$out/e-005-whole.zip" --voxel-size 0.05 --max-memory 20
same e-005.zip e-005-whole.zip
fi
if [[ "$steps" == *3* ]] && command -v mpirun >/dev/null && "$lacuna" --version | grep -q MPI; then
  root=(); [ "$(id -u)" -eq 0 ] && root=(--allow-run-as-root)
  run menger-1-thread "$lacuna" slice "$out/menger5.json" -o "$out/m-1.zip" --threads 1
  run menger-np2 mpirun -np 2 --oversubscribe "${root[@]}" "$lacuna" slice "$out/menger5.json" -o "$out/m-np2.zip" --threads 1
  same m-1.zip m-np2.zip
fi
