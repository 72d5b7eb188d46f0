#!/usr/bin/env bash
# An option that should improve an image at the same samples (splat's
# --filter, its radiance cache, its visibility mask): the variant's relative
# MSE against REF at most FACTOR times the base render's, and its mean
# within TOL of REF's. Optionally REGION (X0,Y0,X1,Y1) measures a part.
# usage: variant_better.sh CANDELA REF FACTOR TOL REGION|- -- base args... -- variant args...
set -u
candela=$1 ref=$2 factor=$3 tol=$4 region=$5
shift 6
base=()
while [ $# -gt 0 ] && [ "$1" != "--" ]; do base+=("$1"); shift; done
shift
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
reg=()
[ "$region" != - ] && reg=(--region "$region")
metric() { # image key
  "$candela" diff "$1" "$ref" "${reg[@]}" | tr -s ' ' '\n' | awk -v k="$2" 'p {print; exit} $0 == k {p = 1}'
}
"$candela" render "${base[@]}" -q -o "$tmp/base.exr" >/dev/null || { echo "FAIL: base render exited $?"; exit 1; }
"$candela" render "${base[@]}" "$@" -q -o "$tmp/var.exr" >/dev/null || { echo "FAIL: variant render exited $?"; exit 1; }
a=$(metric "$tmp/base.exr" relmse) b=$(metric "$tmp/var.exr" relmse) m=$(metric "$tmp/var.exr" mean_ratio)
fail=0
if awk -v a="$a" -v b="$b" -v f="$factor" 'BEGIN {exit !(b < f * a)}'; then
  echo "ok  : relMSE $a without, $b with '$*' (below $factor x)"
else
  echo "FAIL: relMSE $a without, $b with '$*' (must fall below $factor x)"; fail=1
fi
if awk -v r="$m" -v t="$tol" 'BEGIN {exit !(r > 1 - t && r < 1 + t)}'; then
  echo "ok  : mean ratio with it $m (within $tol)"
else
  echo "FAIL: mean ratio with it $m (limit 1 +- $tol)"; fail=1
fi
exit $fail
