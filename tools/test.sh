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
ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
  ctest --test-dir build-asan --output-on-failure
