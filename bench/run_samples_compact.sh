#!/usr/bin/env bash
# Every sample run twice, plain (--simplify 0: the marching-tetrahedra surface) and compact (the
# recipe's default simplification): per surface file its size, triangles, and how long PrusaSlicer
# takes to load it (`prusa-slicer --info`, wall time), plus each run's total time. Prints a Markdown
# table. Usage: bench/run_samples_compact.sh [BUILD_DIR] [SAMPLE ...]   (default: build, every sample)
# COMPACT_ONLY=1 runs the compact surfaces only (the plain columns then read "-"): after a change to
# the simplifier, which leaves the plain surfaces as they were.
set -euo pipefail
build="${1:-build}"
shift || true
samples=("$@")
if [ "${#samples[@]}" -eq 0 ]; then
  for f in samples/*.json; do
    case "$f" in *.expected.json) continue ;; esac
    samples+=("$(basename "$f" .json)")
  done
fi
command -v prusa-slicer >/dev/null || { echo "prusa-slicer is not installed" >&2; exit 2; }
out="$(mktemp -d)"
trap 'rm -rf "$out"' EXIT
echo "| sample | file | plain triangles | plain size | plain load | plain run | compact triangles | compact size | compact load | compact run |"
echo "| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |"
modes=(plain compact)
[ "${COMPACT_ONLY:-0}" = 1 ] && modes=(compact)
for s in "${samples[@]}"; do
  for mode in "${modes[@]}"; do
    args=()
    [ "$mode" = plain ] && args=(--simplify 0)
    "$build/lacuna" run "samples/$s.json" -o "$out/$s-$mode" --quiet --json "${args[@]}" > "$out/$s-$mode.json"
  done
  /usr/bin/python3 - "$out" "$s" <<'EOF'
import json, os, subprocess, sys, time
out, s = sys.argv[1], sys.argv[2]
rows = {}
for mode in ("plain", "compact"):
    if not os.path.exists(f"{out}/{s}-{mode}.json"):
        continue
    report = json.load(open(f"{out}/{s}-{mode}.json"))
    for o in report["outputs"]:
        path = o["file"]
        if not path.endswith((".stl", ".3mf")):
            continue
        start = time.monotonic()
        subprocess.run(["prusa-slicer", "--info", path], check=True, capture_output=True)
        load = time.monotonic() - start
        rows.setdefault(os.path.basename(path), {})[mode] = (o["triangles"], os.path.getsize(path), load, report["total_seconds"])
for f, r in rows.items():
    c = r["compact"]
    if "plain" in r:
        p = r["plain"]
        plain = f"{p[0]:,} | {p[1] / 1e6:.1f} MB | {p[2]:.2f} s | {p[3]:.1f} s".replace(",", " ")
    else:
        plain = "- | - | - | -"
    print(f"| {s} | {f} | {plain} | {c[0]:,} | {c[1] / 1e6:.1f} MB | {c[2]:.2f} s | {c[3]:.1f} s |".replace(",", " "))
EOF
done
