#!/usr/bin/env bash
# Bekaert et al. 2003, Figure 6: a building floor with thousands of small
# lights, most hidden from any one point (scenes/generate.py building, not
# committed: generated into OUT). 1) gkde at RES with STEPS steps of 100000
# light paths: time, links per eye vertex and the cost split (the report:
# about 5 minutes on a 1.5 GHz Athlon, ~30 trial links per eye vertex for 10
# unoccluded, counting and linking about 10 %). 2) bench/compare at equal
# time against path, bdpt, rigi and pm at CMP_RES, budgets BUDGETS, against
# a path reference of REF_SPP spp.
# usage: bench/gkde_fig6.sh [OUT] [RES] [STEPS] [CMP_RES] [BUDGETS] [REF_SPP]
#   defaults: out/gkde_fig6 512x384 15 256x192 10,20,40 4096
set -eu
here=$(cd "$(dirname "$0")/.." && pwd)
out=${1:-$here/out/gkde_fig6}
res=${2:-512x384}
steps=${3:-15}
cres=${4:-256x192}
budgets=${5:-10,20,40}
refspp=${6:-4096}
candela=${CANDELA:-$here/build/candela}
mkdir -p "$out"
[ -f "$out/building.obj" ] || /usr/bin/python3 "$here/scenes/generate.py" "$out" building
cam=$(cat "$out/building.cam")
# shellcheck disable=SC2086 # the camera file holds options
"$candela" render "$out/building.obj" $cam --res "$res" -i gkde --progressive off --overlaps 5 --spp "$steps" -o "$out/gkde.exr" -o "$out/gkde.png" |
  tee "$out/gkde.log"
# shellcheck disable=SC2086
[ -f "$out/ref.exr" ] || "$candela" render "$out/building.obj" $cam --res "$cres" -i path --spp "$refspp" -q -o "$out/ref.exr"
"$here/bench/compare" --candela "$candela" --scene "$out/building.obj" --ref "$out/ref.exr" --res "$cres" \
  --render-args "$cam" --config "gkde=-i gkde" --config "path=-i path" --config "bdpt=-i bdpt" \
  --config "rigi=-i rigi" --config "pm=-i pm" --times "$budgets" --target auto --out "$out/compare" \
  --clock effective | tee "$out/compare.md"
