#!/usr/bin/env bash
# candela benchmark (issue: renderer core). All figures come from one run on
# one machine, as ratios where possible:
#  1. Mrays/s of `path` against Embree's raw incoherent throughput
#     (bench_rays: rtcIntersect1 + rtcOccluded1 from pre-generated rays) on the
#     Cornell box (256x256) and on Sponza with a point light;
#  2. time for `path` to reach the relative MSE that an independent-sampling
#     path tracer has at 1024 spp on the Cornell box (the established
#     renderers' setting), with the Sobol and the independent sampler.
# usage: bench/run.sh [BUILD_DIR] [SHARED_DIR]   (prints Markdown)
set -eu
here=$(cd "$(dirname "$0")/.." && pwd)
build=${1:-$here/build}
shared=${2:-$here/../shared}
candela=$build/candela
raw=$build/bench/bench_rays
cornell=$here/scenes/cornell-box/CornellBox-Original.obj
ref=$shared/references/mcguire-cornell-original_path_256.exr
sponza=$shared/scenes/sponza-dabrovic/obj-converted/sponza.obj
cam="--lookat 0,1,3.9,0,1,0,0,1,0 --fov 39.3077 --res 256x256 --maxdepth 64"
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

field() { tr -s ' ' '\n' | awk -v k="$1" 'p {print; exit} $0 == k {p = 1}'; }
mrays() { sed -n 's/.* \([0-9.]*\) Mrays\/s.*/\1/p'; }
best() { sort -g | tail -n 1; } # best of repeated runs: least disturbed

echo "## Throughput ($(nproc) threads, best of 3)"
echo
echo "| scene | path Mrays/s | raw Embree Mrays/s | ratio |"
echo "|---|---|---|---|"
run_pair() { # name scene raw-args -- render-args
  local name=$1 scene=$2 rawargs=$3; shift 4
  local p r
  p=$(for i in 1 2 3; do "$candela" render "$scene" "$@" -q -o "$tmp/t.exr" | mrays; done | best)
  r=$(for i in 1 2 3; do "$raw" "$scene" $rawargs | mrays; done | best)
  echo "| $name | $p | $r | $(awk -v a="$p" -v b="$r" 'BEGIN {printf "%.2f", a / b}') |"
}
run_pair "Cornell box 256x256, sobol" "$cornell" "" -- $cam --spp 32
run_pair "Cornell box 256x256, independent" "$cornell" "" -- $cam --spp 32 --sampler independent
if [ -f "$sponza" ]; then
  light="0,17,0,2000,2000,2000"
  run_pair "Sponza 512x512 + point light" "$sponza" "--point-light $light" -- \
    --point-light $light --lookat -10,4,0,10,6,0,0,1,0 --fov 60 --res 512x512 --spp 4 --maxdepth 8
fi

echo
echo "## Time to equal error on the Cornell box (256x256)"
echo
"$candela" render "$cornell" $cam --spp 1024 --sampler independent --seed 3 -q -o "$tmp/target.exr" > "$tmp/target.log"
target=$("$candela" diff "$tmp/target.exr" "$ref" | field relmse)
ttarget=$(sed -n 's/.* spp in \([0-9.]*\) s.*/\1/p' "$tmp/target.log")
echo "Target: relative MSE $target = independent sampling at 1024 spp (took $ttarget s here)."
echo
echo "| sampler | spp | time (s) | relative MSE |"
echo "|---|---|---|---|"
reached=""
for smp in sobol independent; do
  spp=64 pt="" pe=""
  while [ $spp -le 4096 ]; do
    out=$("$candela" render "$cornell" $cam --spp $spp --sampler $smp --seed 4 -q -o "$tmp/s.exr")
    t=$(echo "$out" | sed -n 's/.* spp in \([0-9.]*\) s.*/\1/p')
    e=$("$candela" diff "$tmp/s.exr" "$ref" | field relmse)
    echo "| $smp | $spp | $t | $e |"
    if awk -v e="$e" -v t="$target" 'BEGIN {exit !(e <= t)}'; then
      # log-log interpolation between the budgets that bracket the target
      est=$(awk -v t0="$pt" -v e0="$pe" -v t1="$t" -v e1="$e" -v g="$target" 'BEGIN {
        if (t0 == "") { printf "%.1f", t1; exit }
        f = (log(g) - log(e0)) / (log(e1) - log(e0)); printf "%.1f", exp(log(t0) + f * (log(t1) - log(t0))) }')
      reached="$reached$smp: ${est} s; "
      break
    fi
    pt=$t pe=$e
    spp=$((spp * 2))
  done
done
echo
echo "Time to the target (log-log interpolation): $reached"
echo "Established renderers on a 2-core machine, 1024 spp: Mitsuba 0.6 49 s, Cycles 58 s, pbrt-v3 114 s."
echo "Target from the issue: at most half the fastest, 24.5 s." 
