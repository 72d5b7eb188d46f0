#!/usr/bin/env bash
# pm against Mitsuba 0.6's photon mapper on the McGuire Cornell box
# (issue #5): Mitsuba takes 7.1 s on 2 cores for 250k photons with final
# gathering at 256x256. We cannot run Mitsuba here, so its error is stood in
# for by candela's plain Jensen photon mapper with Mitsuba's settings
# (250k global photons, 120-photon lookups, 16 direct-light samples, 16 final
# gathering rays, 4 samples per pixel, each with its own photon map, which
# only makes the target stricter); then bench/compare measures how long each
# configuration of bench/pm_speed.cfg needs to reach that error.
# usage: bench/pm_speed.sh [OUT] [BUDGETS]
set -eu
here=$(cd "$(dirname "$0")/.." && pwd)
out=${1:-$here/out/pm_speed}
budgets=${2:-1,2,4,8}
candela=$here/build/candela
scene=$here/../shared/scenes/cornell-box-mcguire/CornellBox-Original.obj
ref=$here/../shared/references/mcguire-cornell-original_path_256.exr
cam="--lookat 0,1,3.9,0,1,0,0,1,0 --fov 39.3077"
mkdir -p "$out"
# shellcheck disable=SC2086
"$candela" render "$scene" $cam --res 256x256 -i pm --photons 250000 --knn 120 --precompute 0 \
  --gather 16 --shadow-rays 16 --spp 4 -o "$out/mitsuba-settings.exr" > "$out/mitsuba-settings.log"
target=$("$candela" diff "$out/mitsuba-settings.exr" "$ref" | sed -n 's/.*relmse \([0-9.e+-]*\).*/\1/p')
echo "target relMSE (Mitsuba's settings in candela): $target"
grep -E 'spp in|pm:' "$out/mitsuba-settings.log"
"$here/bench/compare" --scene "$scene" --ref "$ref" --res 256x256 --render-args "$cam" \
  --configs "$here/bench/pm_speed.cfg" --times "$budgets" --target "$target" --out "$out/runs" \
  --clock effective | tee "$out/table.md"
