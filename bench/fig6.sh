#!/usr/bin/env bash
# Reproduces Kollig & Keller's Figure 6 with bench/compare on the generated
# office and conference interiors and on the Cornell box: references by path
# tracing (cached in OUT/refs), then every configuration of bench/fig6.cfg at
# each time budget. usage: bench/fig6.sh [OUT] [BUDGETS] [REF_SPP]
set -eu
here=$(cd "$(dirname "$0")/.." && pwd)
out=${1:-$here/out/fig6}
budgets=${2:-1,2,4}
refspp=${3:-2048}
candela=$here/build/candela
mkdir -p "$out/refs"
gen=$here/scenes/generated
for scene in office conference cornell; do
  if [ $scene = cornell ]; then
    file=$here/scenes/cornell-box/CornellBox-Original.obj
    cam="--lookat 0,1,3.9,0,1,0,0,1,0 --fov 39.3077"
  else
    file=$gen/$scene.obj
    cam=$(cat "$gen/$scene.cam")
  fi
  res=160x120
  ref=$out/refs/$scene.exr
  # shellcheck disable=SC2086
  [ -f "$ref" ] || "$candela" render "$file" $cam --res $res --spp "$refspp" --maxdepth 16 -q -o "$ref" >&2
  "$here/bench/compare" --scene "$file" --ref "$ref" --res $res --render-args "$cam --maxdepth 16" \
    --configs "$here/bench/fig6.cfg" --times "$budgets" --target auto --out "$out/$scene" --clock effective \
    > "$out/$scene.md"
  echo "## $scene" && cat "$out/$scene.md"
done
