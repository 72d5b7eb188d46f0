#!/usr/bin/env bash
# A Mitsuba 0.6 room lit through a window by <emitter type="sunsky"> alone
# (tests/data/sunsky_room.xml): path and bdpt agree in the mean within 3 %
# (measured 1.0018 at 512 / 128 spp), and the image is lit (a sun patch on
# the floor far brighter than the room's mean; the scene had no light before
# the daylight emitters).
#   sunsky_room.sh CANDELA SCENE
set -u
candela=$1 scene=$2
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
"$candela" render "$scene" -i path --spp 256 -q -o "$tmp/path.exr" >/dev/null 2>&1 || exit 1
"$candela" render "$scene" -i bdpt --spp 64 -q -o "$tmp/bdpt.exr" >/dev/null 2>&1 || exit 1
d=$("$candela" diff "$tmp/bdpt.exr" "$tmp/path.exr")
ratio=$(echo "$d" | sed -n 's/.*mean_ratio \([^ ]*\) .*/\1/p')
mean=$(echo "$d" | sed -n 's/.*ref \([^)]*\)).*/\1/p')
fail=0
check() { if awk "BEGIN {exit !($1)}"; then echo "ok  : $2"; else echo "FAIL: $2"; fail=1; fi; }
check "$ratio > 0.97 && $ratio < 1.03" "bdpt 64 spp / path 256 spp: mean $ratio (within 3 %)"
check "$mean > 0.005" "the room is lit: mean radiance $mean"
exit $fail
