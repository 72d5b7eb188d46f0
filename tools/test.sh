#!/usr/bin/env bash
# Installs what is missing, builds (Release), runs every test (the Python
# package's included); then builds again with AddressSanitizer +
# UndefinedBehaviorSanitizer and runs the unit tests there too; then fuzzes
# each reader for 30 s. Exits non-zero on the first failure.
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
# Fuzzing over the public API (clang + libFuzzer, ASan + UBSan): every
# regression input of fuzz/regressions, then 30 s per reader (OBJ/MTL, pbrt,
# PLY, images, options) from seeds drawn from the tests' inputs.
cmake -S . -B build-fuzz -DCMAKE_C_COMPILER=clang -DCMAKE_CXX_COMPILER=clang++ -DCDL_FUZZ=ON -DBUILD_TESTING=OFF \
  -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCDL_NATIVE=OFF >/dev/null
cmake --build build-fuzz -j"$jobs" --target fuzz
tests/fuzz.sh build-fuzz "$PWD" 30
