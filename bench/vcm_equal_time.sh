#!/usr/bin/env bash
# Equal time for vcm (Georgiev et al. 2012) against bdpt, pm, sppm and its own
# merging half, with bench/compare (effective clock, 0.1 %-trimmed relMSE), on
# two generated scenes at 160x120, --maxdepth 16:
#  - doorajar: an interior lit indirectly through a door ajar, against the
#    32768-spp path reference of the tests (tests/data/doorajar_path_160.exr);
#  - caustic_ring: caustics from a metal ring and a glass sphere under a small
#    light, against OUT/caustic_ref.exr, made here when missing: vcm with
#    r_1 = 0.012, 4 light paths per pixel, 1536 passes, seed 99 (about 7
#    minutes on 2 cores), a different seed from the timed renders.
# usage: bench/vcm_equal_time.sh [OUT] [TIMES]   (defaults out/vcm_equal_time 4,16)
set -eu
here=$(cd "$(dirname "$0")/.." && pwd)
out=${1:-$here/out/vcm_equal_time}
times=${2:-4,16}
candela=${CANDELA:-$here/build/candela}
scenes=$here/scenes/generated
mkdir -p "$out"
configs=(--config "bdpt=-i bdpt" --config "pm=-i pm" --config "sppm=-i sppm" --config "vcm=-i vcm"
  --config "vcm-merge=-i vcm --vcm-mode merge" --config "vcm-k4=-i vcm --merge-paths 4")
ref=$out/caustic_ref.exr
# shellcheck disable=SC2046 # the .cam files hold options
[ -f "$ref" ] || "$candela" render "$scenes/caustic_ring.obj" $(cat "$scenes/caustic_ring.cam") --res 160x120 \
  --maxdepth 16 -i vcm --radius 0.012 --merge-paths 4 --seed 99 --spp 1536 -q -o "$ref"
for s in doorajar caustic_ring; do
  r=$ref
  [ "$s" = doorajar ] && r=$here/tests/data/doorajar_path_160.exr
  "$here/bench/compare" --candela "$candela" --scene "$scenes/$s.obj" --ref "$r" --res 160x120 \
    --render-args "$(cat "$scenes/$s.cam") --maxdepth 16" "${configs[@]}" --times "$times" --target 0.005 \
    --metric relmse_trimmed --clock effective --out "$out/$s"
done
