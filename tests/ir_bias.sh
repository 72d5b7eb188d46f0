#!/usr/bin/env bash
# Instant radiosity (ir) clamps G and so loses light where surfaces meet;
# rigi uses the same point lights but thresholds G and is unbiased.
# Asserts: ir's image mean is below the reference by more than 1 %, rigi's
# within 1 %. usage: ir_bias.sh CANDELA REF.exr SCENE render-args...
set -u
candela=$1 ref=$2
shift 2
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fail=0
for i in ir rigi; do
  "$candela" render "$@" -i $i --light-paths 256 --interleave 4 --spp 16 -q -o "$tmp/$i.exr" >/dev/null || exit 1
  r=$("$candela" diff "$tmp/$i.exr" "$ref" | tr -s ' ' '\n' | awk 'p {print; exit} $0 == "mean_ratio" {p = 1}')
  if [ $i = ir ]; then
    if awk -v r="$r" 'BEGIN {exit !(r < 0.99)}'; then echo "ok  : ir mean ratio $r (< 0.99: clamping bias)"; else echo "FAIL: ir mean ratio $r (expected < 0.99)"; fail=1; fi
  else
    if awk -v r="$r" 'BEGIN {exit !(r > 0.99 && r < 1.01)}'; then echo "ok  : rigi mean ratio $r (within 1 %)"; else echo "FAIL: rigi mean ratio $r"; fail=1; fi
  fi
done
exit $fail
