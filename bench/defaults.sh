#!/usr/bin/env bash
# What a user gets first: every method with its defaults on the default scene
# (the Cornell box of scenes/, 256x256, the README's camera), 16 passes each:
# seconds per pass, the total (issue 14's goal: under 10 s on 2 cores), the
# photon/preprocessing share the method reports, and the error against the
# independent reference.
# usage: bench/defaults.sh [BUILD_DIR] [SHARED_DIR] [SPP]   (prints Markdown)
set -eu
here=$(cd "$(dirname "$0")/.." && pwd)
build=${1:-$here/build}
shared=${2:-$here/../shared}
spp=${3:-16}
candela=$build/candela
scene=$here/scenes/cornell-box/CornellBox-Original.obj
ref=$shared/references/mcguire-cornell-original_path_256.exr
cam="--lookat 0,1,3.9,0,1,0,0,1,0 --fov 39.3077 --res 256x256"
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
echo "## Defaults on the default scene (Cornell box 256x256, $spp passes, $(nproc) threads)"
echo
echo "| method | s per pass | $spp passes (s) | relMSE | mean ratio |"
echo "|---|---|---|---|---|"
for m in path bdpt ir rigi pm gkde splat sppm vcm; do
  # shellcheck disable=SC2086
  line=$("$candela" render "$scene" $cam -i "$m" --spp "$spp" -q -o "$tmp/$m.exr")
  secs=$(echo "$line" | sed -n 's/.* spp in \([0-9.]*\) s.*/\1/p')
  d=$("$candela" diff "$tmp/$m.exr" "$ref")
  rel=$(echo "$d" | sed -n 's/.*relmse \([^ ]*\) .*/\1/p')
  ratio=$(echo "$d" | sed -n 's/.*mean_ratio \([^ ]*\) .*/\1/p')
  printf '| %s | %.3f | %.2f | %s | %s |\n' "$m" "$(echo "$secs / $spp" | bc -l)" "$secs" "$rel" "$ratio"
done
