#!/usr/bin/env bash
# Equal time for splat (Herzog et al. 2007) against the photon map, path and
# bdpt, with bench/compare, on McGuire's Cornell box (256x256, against the
# pbrt reference) and Sponza (200x150, its light as a point light, against a
# 4096-spp path render made here as OUT/sponza_path_4096.exr: the same render
# as bench/splat_fig72.sh's path_d8.exr, which can be copied there to save
# the time). splat runs with
# its defaults (direct maps, no cache) and with the report's cache (SH maps,
# C 0.6, S 0.2, --cache 0.5) plus filtering; pm with its defaults (8 final
# gather rays, precomputed irradiance).
# usage: bench/splat_equal_time.sh [OUT] [TIMES]   (defaults out/splat_equal_time 2,4,8,16)
set -eu
here=$(cd "$(dirname "$0")/.." && pwd)
out=${1:-$here/out/splat_equal_time}
times=${2:-2,4,8,16}
candela=${CANDELA:-$here/build/candela}
shared=$here/../shared
mkdir -p "$out"
configs=(--config "path=-i path" --config "bdpt=-i bdpt" --config "pm=-i pm"
  --config "splat=-i splat" --config "splat-cache=-i splat --mode sh -C 0.6 -S 0.2 --cache 0.5 --filter 20000")
"$here/bench/compare" --candela "$candela" --scene "$shared/scenes/cornell-box-mcguire/CornellBox-Original.obj" \
  --ref "$shared/references/mcguire-cornell-original_path_256.exr" --res 256x256 \
  --render-args "--lookat 0,1,3.9,0,1,0,0,1,0 --fov 39.3077 --maxdepth 64" \
  "${configs[@]}" --times "$times" --target 0.002 --out "$out/cornell"
sponza=("$shared/scenes/sponza-dabrovic/obj-converted/sponza.obj"
  --lookat 14.4499,6.89415,-1.18547,13.4563,6.78438,-1.15861,-0.109708,0.993957,0.00374357 --fov 75
  --point-light 0,17,0,157,157,157 --maxdepth 8)
ref=$out/sponza_path_4096.exr
[ -f "$ref" ] || "$candela" render "${sponza[@]}" --res 200x150 -i path --spp 4096 --seed 3 -q -o "$ref"
"$here/bench/compare" --candela "$candela" --scene "${sponza[0]}" --ref "$ref" --res 200x150 \
  --render-args "${sponza[*]:1}" "${configs[@]}" --times "$times" --target 0.01 --out "$out/sponza"
