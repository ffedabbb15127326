#!/usr/bin/env bash
# Every sample run with a Draco output added beside each single-object surface output (same object,
# default quantization: a tenth of the voxel): per file the triangles, the binary STL's size, the .drc
# size and their ratio, the quantization bits and the bound on vertex moves, from report.json. Prints a
# Markdown table and the smallest ratio. Usage: bench/run_samples_draco.sh [BUILD_DIR] [SAMPLE ...]
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
out="$(mktemp -d)"
trap 'rm -rf "$out"' EXIT
echo "| sample | file | triangles | binary STL | .drc | ratio | bits | refinements | max move (mm) | voxel (mm) |"
echo "| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |"
for s in "${samples[@]}"; do
  /usr/bin/python3 - "samples/$s.json" "$out/$s.json" <<'PY'
import json, os, sys
source, target = sys.argv[1], sys.argv[2]
recipe = json.load(open(source))
# Relative paths in the recipe (meshes, systems) stay relative to the samples folder.
recipe.setdefault("name", os.path.splitext(os.path.basename(source))[0])
names = {o["file"].lower() for o in recipe["outputs"]}
added = []
for o in recipe["outputs"]:
    stem, ext = os.path.splitext(o["file"])
    if ext.lower() in (".stl", ".3mf") and isinstance(o["of"], str) and (stem + ".drc").lower() not in names:
        added.append({"of": o["of"], "file": stem + ".drc"})
        names.add((stem + ".drc").lower())
recipe["outputs"] += added
json.dump(recipe, open(target, "w"))
PY
  cp "$out/$s.json" "samples/.draco-bench-$s.json"
  "$build/lacuna" run "samples/.draco-bench-$s.json" -o "$out/$s" --quiet --json > "$out/$s-report.json" || {
    rm -f "samples/.draco-bench-$s.json"; echo "| $s | failed | | | | | | | | |"; continue; }
  rm -f "samples/.draco-bench-$s.json"
  /usr/bin/python3 - "$out/$s-report.json" "$s" <<'PY'
import json, os, sys
report = json.load(open(sys.argv[1]))
for o in report["outputs"]:
    d = o.get("draco")
    if not d:
        continue
    print(f"| {sys.argv[2]} | {os.path.basename(o['file'])} | {o['triangles']:,} | {d['binary_stl_bytes']/1e6:.2f} MB | "
          f"{d['file_bytes']/1e6:.3f} MB | {d['compression_vs_binary_stl']:.1f} | {d['quantization_bits']} | {d['refinements']} | "
          f"{d['max_move_mm']:.5f} | {report['voxel_size_mm']:g} |".replace(",", " "))
PY
done | tee "$out/table.md"
/usr/bin/python3 - "$out/table.md" <<'PY'
import sys
ratios = [float(line.split("|")[6]) for line in open(sys.argv[1]) if line.count("|") > 9 and "failed" not in line]
if ratios:
    print(f"\nsmallest ratio {min(ratios):.1f}, median {sorted(ratios)[len(ratios)//2]:.1f} over {len(ratios)} files")
PY
