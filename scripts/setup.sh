#!/usr/bin/env bash
# Installs whatever Lacuna needs that is missing (Debian 12 packages), builds it, and then either
# runs a recipe or the whole test suite.
#
#   scripts/setup.sh                      install and build
#   scripts/setup.sh --run RECIPE [ARGS]  ... then `lacuna run RECIPE ARGS`
#   scripts/setup.sh --test               ... with the test clients (PrusaSlicer, admesh, Gmsh, CalculiX, Draco's
#                                         reference decoder, pytest, meshio, Chromium, PIL) and clang (scripts/fuzz.sh),
#                                         warnings as errors, then the whole test suite through CTest
#
# The Python module is built for Debian's /usr/bin/python3 (where python3-numpy lives), whatever
# python3 comes first on PATH; PYTHONPATH=build/python imports it from the build tree.
set -euo pipefail
cd "$(dirname "$0")/.."

mode=build
recipe=""
run_args=()
case "${1:-}" in
  --run) mode=run; recipe="${2:?usage: scripts/setup.sh --run RECIPE [lacuna run options]}"; shift 2; run_args=("$@") ;;
  --test) mode=test ;;
  "") ;;
  *) echo "usage: scripts/setup.sh [--run RECIPE [options] | --test]" >&2; exit 2 ;;
esac

packages=(build-essential cmake ninja-build ccache pkg-config
          libopenvdb-dev libboost-iostreams-dev libcgal-dev libgmp-dev libmpfr-dev libtet1.5-dev
          libdraco-dev lib3mf-dev libzip-dev zlib1g-dev libeigen3-dev libtbb-dev
          nlohmann-json3-dev libcli11-dev libgtest-dev
          python3-dev pybind11-dev python3-numpy
          libopenmpi-dev openmpi-bin)  # optional for building: `lacuna slice` over MPI ranks
if [ "$mode" = test ]; then
  # Real downstream clients the tests run the outputs through.
  packages+=(prusa-slicer admesh gmsh calculix-ccx draco python3-pytest python3-meshio clang libclang-rt-14-dev
             chromium python3-pil)
fi

# report.html's viewer is bundled from npm packages at build time: Node.js and npm from Debian,
# unless a node and npm are on PATH already.
command -v node >/dev/null && command -v npm >/dev/null || packages+=(nodejs npm)

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ "${#missing[@]}" -gt 0 ]; then
  echo "setup: installing ${missing[*]}" >&2
  sudo=""
  [ "$(id -u)" -ne 0 ] && sudo=sudo
  export DEBIAN_FRONTEND=noninteractive
  $sudo apt-get update -q
  $sudo apt-get install -y -q --no-install-recommends "${missing[@]}"
fi

# three.js and esbuild (and playwright-core for the browser tests), as pinned by the lock file.
if [ ! -f export/viewer/node_modules/.package-lock.json ] ||
   ! cmp -s export/viewer/package-lock.json export/viewer/node_modules/.lacuna-lock; then
  echo "setup: installing export/viewer's npm packages" >&2
  (cd export/viewer && npm ci --no-audit --no-fund --loglevel=error && cp package-lock.json node_modules/.lacuna-lock)
fi

build_dir=build
werror=OFF
[ "$mode" = test ] && werror=ON
cmake -S . -B "$build_dir" -G Ninja -DCMAKE_BUILD_TYPE=Release -DLACUNA_WERROR="$werror" \
      -DPython_EXECUTABLE=/usr/bin/python3 >/dev/null
# Two parallel compile jobs of the OpenVDB/CGAL translation units need about 5 GB.
cmake --build "$build_dir" -j "$(nproc)"

case "$mode" in
  run) exec "$build_dir/lacuna" run "$recipe" "${run_args[@]}" ;;
  test) cd "$build_dir" && exec ctest --output-on-failure -j "$(nproc)" ;;
esac
