#!/usr/bin/env bash
# Long fuzzing campaigns over the public API (libFuzzer, clang, ASan+UBSan):
#   bench/fuzz.sh [SECONDS per target, default 600] [TARGET...]
# Targets: obj pbrt ply image options (default all, two at a time). Builds
# build-fuzz/ if needed; corpora grow in fuzz/corpus/TARGET across runs. A
# crash stops with its input in fuzz/corpus/TARGET-artifacts/: minimize it
# (build-fuzz/fuzz/fuzz_TARGET -minimize_crash=1 FILE), fix the bug and add
# the file to fuzz/regressions/TARGET/, which every test run replays.
set -eu
cd "$(dirname "$0")/.."
secs=${1:-600}
shift || true
cmake -S . -B build-fuzz -DCMAKE_C_COMPILER=clang -DCMAKE_CXX_COMPILER=clang++ -DCDL_FUZZ=ON -DBUILD_TESTING=OFF \
  -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCDL_NATIVE=OFF >/dev/null
cmake --build build-fuzz -j"$(nproc)" --target fuzz >/dev/null
exec tests/fuzz.sh build-fuzz "$PWD" "$secs" "$PWD/fuzz/corpus" "$@"
