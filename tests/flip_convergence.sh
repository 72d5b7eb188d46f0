#!/usr/bin/env bash
# FLIP of Cornell-box path renders against the independent reference falls
# as the samples grow (4, 16, 64 spp), is 0 for the reference against
# itself, and --flip-map writes a PNG of the image's size.
# usage: flip_convergence.sh CANDELA REF.exr -- render args...
set -u
candela=$1 ref=$2
shift 3
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fail=0
check() { if awk "BEGIN {exit !($1)}"; then echo "ok  : $2"; else echo "FAIL: $2"; fail=1; fi; }
key() { tr -s ' ' '\n' | awk -v k="$1" 'p {print; exit} $0 == k {p = 1}'; }
prev=1
for n in 4 16 64; do
  "$candela" render "$@" --spp $n --seed 7 -q -o "$tmp/$n.exr" >/dev/null || { echo "FAIL: render exited $?"; exit 1; }
  f=$("$candela" diff "$tmp/$n.exr" "$ref" | key flip_hdr)
  check "$f < 0.8 * $prev" "HDR-FLIP at $n spp: $f (previous $prev)"
  prev=$f
done
self=$("$candela" diff "$ref" "$ref" --flip-map "$tmp/map.png" | key flip_hdr)
check "$self == 0" "HDR-FLIP of the reference against itself: $self"
"$candela" diff "$tmp/map.png" "$tmp/map.png" | grep -q "flip_ldr 0.000000" || { echo "FAIL: the map's PNG"; fail=1; }
exit $fail
