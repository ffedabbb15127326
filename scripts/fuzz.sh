#!/usr/bin/env bash
# The libFuzzer targets (tests/fuzz/: recipe parser, CIFS systems, STL/OBJ/PLY/3MF readers, Draco files), built with
# Debian's clang in build-fuzz/ and run for SECONDS each (default 20), then every file of the
# regression corpus tests/fuzz_corpus/ once. A crash leaves its input as build-fuzz/tests/fuzz/<target>-crash-*:
# copy it into tests/fuzz_corpus/<target>/ with the fix. The same build then runs the unit tests of what it
# compiles (generators, recipes, mesh readers and writers, mesh checks; label sanitize) under AddressSanitizer
# and UndefinedBehaviorSanitizer.
#
#   scripts/fuzz.sh [SECONDS]
set -euo pipefail
cd "$(dirname "$0")/.."
seconds="${1:-20}"
CXX=clang++ CC=clang cmake -S . -B build-fuzz -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DLACUNA_FUZZ=ON \
    -DLACUNA_BUILD_TESTS=OFF -DLACUNA_BUILD_BENCH=OFF -DLACUNA_BUILD_PYTHON=OFF -DLACUNA_FUZZ_SECONDS="$seconds" \
    -DPython_EXECUTABLE=/usr/bin/python3 >/dev/null
cmake --build build-fuzz -j "$(nproc)" --target recipe_fuzz cifs_system_fuzz mesh_fuzz draco_fuzz lacuna_sanitized_tests
cd build-fuzz && exec ctest --output-on-failure -j "$(nproc)" -L 'fuzz|sanitize'
