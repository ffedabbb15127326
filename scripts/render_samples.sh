#!/usr/bin/env bash
# The README's pictures: one sample of each family rendered with `lacuna render` (iso view, 480 x 360)
# into samples/pictures/NAME.png. Run after a change that alters how the samples look.
#   scripts/render_samples.sh [BUILD_DIR]
set -euo pipefail
cd "$(dirname "$0")/.."
build="${1:-build}"
mkdir -p samples/pictures
# Parts whose structure is inside a skin are shown cut at half their height (the rabbit at 0.3, through its body).
for entry in menger_sponge takagi_nurbs_shell lacunar_hexagon_plate lacunar_cell hilbert_sphere sierpinski_torus \
             voronoi_foam:0.5 porous_egg:0.5 lacunar_panel egg_infill:0.5 lattice_block lacunar_hexahedron:0.5 \
             lacunar_egg:0.5 bunny lacunar_bunny:0.3; do
  s="${entry%%:*}"
  args=()
  [ "$entry" != "$s" ] && args=(--section "${entry#*:}")
  "$build/lacuna" render "samples/$s.json" -o "samples/pictures/$s.png" --size 480x360 --title "$s" --quiet "${args[@]}"
  echo "samples/pictures/$s.png"
done
