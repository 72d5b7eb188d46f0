#!/usr/bin/env bash
# Renders a scene at N and 4N samples per pixel and checks it against an
# independent reference image: the image mean must agree within TOL and the
# relative MSE must fall like 1/N (ratio at most 0.35; 0.25 is ideal, the
# reference's own noise raises it a little). Anything else is bias.
# With ROBUST=1 (scenes with rare, very bright fireflies) the mean is the
# median of 16x16 block-mean ratios and the error the relative MSE without
# the largest 0.1 % of per-pixel terms (see ../shared/references/README.md).
# usage: [ROBUST=1] reference.sh CANDELA REF.exr N TOL -- render args...
set -u
candela=$1 ref=$2 n=$3 tol=$4
shift 5
mean_key=mean_ratio err_key=relmse
if [ "${ROBUST:-0}" = 1 ]; then mean_key=block_median_ratio err_key=relmse_trimmed; fi
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fail=0

render() { # spp seed out
  "$candela" render "$@" -q >/dev/null || { echo "FAIL: render exited $?"; exit 1; }
}
metric() { # image key
  "$candela" diff "$1" "$ref" | tr -s ' ' '\n' | awk -v k="$2" 'p {print; exit} $0 == k {p = 1}'
}

render "$@" --spp "$n" --seed 11 -o "$tmp/n.exr"
render "$@" --spp $((4 * n)) --seed 12 -o "$tmp/4n.exr"
e1=$(metric "$tmp/n.exr" $err_key)
e4=$(metric "$tmp/4n.exr" $err_key)
for f in n 4n; do
  r=$(metric "$tmp/$f.exr" $mean_key)
  if awk -v r="$r" -v t="$tol" 'BEGIN {exit !(r > 1 - t && r < 1 + t)}'; then
    echo "ok  : $mean_key at $f = $r (within $tol)"
  else
    echo "FAIL: $mean_key at $f = $r (limit 1 +- $tol)"; fail=1
  fi
done
ratio=$(awk -v a="$e4" -v b="$e1" 'BEGIN {printf "%.4f", a / b}')
if awk -v r="$ratio" 'BEGIN {exit !(r <= 0.35)}'; then
  echo "ok  : $err_key $e1 at N=$n, $e4 at 4N: ratio $ratio (<= 0.35)"
else
  echo "FAIL: $err_key $e1 at N=$n, $e4 at 4N: ratio $ratio (limit 0.35)"; fail=1
fi
exit $fail
