#!/usr/bin/env bash
# `lacuna render` on meshes of about 1.1 and 4.5 million triangles (balls of radius 5 and 10 mm at
# 0.05 mm voxels, not simplified), one view and four views, wall time of the whole command (reading
# the STL included).
# Usage: bench/run_render.sh [BUILD_DIR]
set -euo pipefail
build="${1:-build}"
out="$(mktemp -d)"
trap 'rm -rf "$out"' EXIT
for radius in 5 10; do
cat > "$out/ball.json" <<JSON
{"voxel_size_mm": 0.05, "simplify_mm": 0, "inputs": {"ball": {"type": "sphere", "radius_mm": $radius}},
 "outputs": [{"of": "ball", "file": "ball.stl"}]}
JSON
rm -rf "$out/ball"
"$build/lacuna" run "$out/ball.json" -o "$out/ball" --quiet
for views in iso iso,front,top,side; do
  start=$(date +%s.%N)
  "$build/lacuna" render "$out/ball/ball.stl" -o "$out/ball.png" --views "$views" --json > "$out/render.json"
  end=$(date +%s.%N)
  /usr/bin/python3 -c "import json,sys; r=json.load(open('$out/render.json')); print(f'{r[\"triangles\"]} triangles, views $views, {r[\"width\"]}x{r[\"height\"]}: {$end-$start:.2f} s')"
done
done
