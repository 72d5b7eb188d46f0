#!/usr/bin/env bash
# Installs what is missing, builds (Release), runs every test; then builds
# again with AddressSanitizer + UndefinedBehaviorSanitizer and runs the
# tests there too. Exits non-zero on the first failure.
set -eu
cd "$(dirname "$0")/.."
./tools/install-deps.sh
jobs=$(nproc)
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build build -j"$jobs"
ctest --test-dir build --output-on-failure
cmake -S . -B build-asan -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCDL_SANITIZE=ON -DCDL_NATIVE=OFF >/dev/null
cmake --build build-asan -j"$jobs"
# Under the sanitizers: every unit test (readers, corpora, BSDFs, integrators
# on analytic scenes with 16x fewer samples and sqrt(16)-wider tolerances);
# the reference comparisons already ran above and only repeat the renders.
ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
  CDL_TEST_SCALE=16 ctest --test-dir build-asan -L unit --output-on-failure
