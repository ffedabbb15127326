#!/usr/bin/env bash
# The AddressSanitizer + UndefinedBehaviorSanitizer build (-DLACUNA_SANITIZE=ON) in build-asan/, and the
# test suite under it without the sample runs and the Python module (they take most of the time and
# memory there). Not part of .ci/run: on 2 cores the build alone takes longer than CI's budget allows;
# CI runs the unit tests of the generators, readers and checks sanitized in the fuzzing build instead.
#
#   scripts/sanitize.sh            build, then the fast tests
#   scripts/sanitize.sh -R Cli     ... only the tests matching a CTest regular expression
set -euo pipefail
cd "$(dirname "$0")/.."
cmake -S . -B build-asan -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DLACUNA_SANITIZE=ON -DLACUNA_BUILD_BENCH=OFF \
      -DLACUNA_BUILD_PYTHON=OFF -DPython_EXECUTABLE=/usr/bin/python3 >/dev/null
cmake --build build-asan -j "$(nproc)" --target lacuna lacuna_tests
cd build-asan
export ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=halt_on_error=1:print_stacktrace=1
exec ctest --output-on-failure -j "$(nproc)" -E '^Samples/' "$@"
