#!/usr/bin/env bash
# cmake --install into a temporary prefix, then build the C example against
# the installed files twice, with pkg-config and with find_package(candela),
# and run both on the Cornell box.
#   install.sh BUILD_DIR SOURCE_DIR SCENE
set -eu
build=$1 src=$(cd "$2" && pwd) scene=$3
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
cmake --install "$build" --prefix "$tmp/prefix" >/dev/null
for f in include/candela/candela.h lib/libcandela.so lib/libcandela.a lib/pkgconfig/candela.pc \
         lib/cmake/candela/candelaConfig.cmake bin/candela; do
  [ -e "$tmp/prefix/$f" ] || { echo "FAIL: $f not installed"; exit 1; }
done
export PKG_CONFIG_PATH=$tmp/prefix/lib/pkgconfig
cc -std=c11 -Wall -Wextra -o "$tmp/ex_pc" "$src/examples/render_cornell.c" $(pkg-config --cflags --libs candela) \
  -Wl,-rpath,"$tmp/prefix/lib"
mkdir "$tmp/proj"
cat > "$tmp/proj/CMakeLists.txt" <<EOT
cmake_minimum_required(VERSION 3.16)
project(uses_candela C)
find_package(candela 0.2 REQUIRED)
add_executable(ex_cmake $src/examples/render_cornell.c)
target_link_libraries(ex_cmake PRIVATE candela::candela)
EOT
cmake -S "$tmp/proj" -B "$tmp/proj/build" -DCMAKE_PREFIX_PATH="$tmp/prefix" >/dev/null
cmake --build "$tmp/proj/build" >/dev/null
for ex in "$tmp/ex_pc" "$tmp/proj/build/ex_cmake"; do
  "$ex" "$scene" "$tmp/out.exr" 2>/dev/null | grep -q "path: 16 passes" || { echo "FAIL: $ex"; exit 1; }
done
PYTHONPATH=$tmp/prefix/lib/python3/dist-packages /usr/bin/python3 -c \
  "import candela; assert candela.version().startswith('0.2'); assert 'pm' in candela.integrators()" ||
  { echo "FAIL: the installed Python package"; exit 1; }
"$tmp/prefix/bin/candela" --version | grep -q "candela 0.2" || { echo "FAIL: installed candela"; exit 1; }
echo "ok: installed, built with pkg-config and with find_package(candela), rendered; Python package imports"
