#!/usr/bin/env bash
# Consistency of a biased progressive method (splat) against an independent
# reference: the image mean within TOL at N and 4N passes, the relative MSE
# falling (at 4N at most 0.7 of that at N) and the bias measured on 32x32
# blocks (block_dev32) falling too, as the kernels shrink with the passes.
# usage: splat_reference.sh CANDELA REF.exr N TOL -- render args...
set -u
candela=$1 ref=$2 n=$3 tol=$4
shift 5
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fail=0
metric() { # image key
  "$candela" diff "$1" "$ref" | tr -s ' ' '\n' | awk -v k="$2" 'p {print; exit} $0 == k {p = 1}'
}
"$candela" render "$@" --spp "$n" -q -o "$tmp/n.exr" >/dev/null || { echo "FAIL: render exited $?"; exit 1; }
"$candela" render "$@" --spp $((4 * n)) -q -o "$tmp/4n.exr" >/dev/null || { echo "FAIL: render exited $?"; exit 1; }
for f in n 4n; do
  r=$(metric "$tmp/$f.exr" mean_ratio)
  if awk -v r="$r" -v t="$tol" 'BEGIN {exit !(r > 1 - t && r < 1 + t)}'; then
    echo "ok  : mean ratio at $f = $r (within $tol)"
  else
    echo "FAIL: mean ratio at $f = $r (limit 1 +- $tol)"; fail=1
  fi
done
for k in relmse block_dev32; do
  a=$(metric "$tmp/n.exr" $k) b=$(metric "$tmp/4n.exr" $k)
  lim=1; [ $k = relmse ] && lim=0.7
  if awk -v a="$a" -v b="$b" -v l="$lim" 'BEGIN {exit !(b < l * a)}'; then
    echo "ok  : $k $a at N=$n, $b at 4N (falls below $lim x)"
  else
    echo "FAIL: $k $a at N=$n, $b at 4N (must fall below $lim x)"; fail=1
  fi
done
exit $fail
