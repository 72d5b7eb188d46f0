#!/usr/bin/env bash
# gkde is consistent: its bias comes from the approximate normalization of
# eq. 6 over footprints of radius ~h (§3) and must shrink with h. Renders
# bandwidth H with N steps and H/2 with 4N (about the same noise: a quarter
# of the footprint area each), and asserts that the smaller h lowers the
# bias measured on 32x32 blocks (RMS of block-mean ratios minus 1) by at
# least a quarter, brings the image mean closer to the reference and lowers
# the relative MSE.
# usage: gkde_bias.sh CANDELA REF.exr H N -- render args...
set -u
candela=$1 ref=$2 h=$3 n=$4
shift 5
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
key() { tr -s ' ' '\n' | awk -v k="$1" 'p {print; exit} $0 == k {p = 1}'; }
h2=$(awk -v h="$h" 'BEGIN {print h / 2}')
"$candela" render "$@" -i gkde --bandwidth "$h" --spp "$n" --seed 3 -q -o "$tmp/a.exr" >/dev/null || { echo "FAIL: render exited $?"; exit 1; }
"$candela" render "$@" -i gkde --bandwidth "$h2" --spp $((4 * n)) --seed 4 -q -o "$tmp/b.exr" >/dev/null || { echo "FAIL: render exited $?"; exit 1; }
da=$("$candela" diff "$tmp/a.exr" "$ref")
db=$("$candela" diff "$tmp/b.exr" "$ref")
ba=$(echo "$da" | key block_dev32) bb=$(echo "$db" | key block_dev32)
ma=$(echo "$da" | key mean_ratio) mb=$(echo "$db" | key mean_ratio)
ea=$(echo "$da" | key relmse) eb=$(echo "$db" | key relmse)
echo "h $h, $n steps: mean $ma, block_dev32 $ba, relmse $ea"
echo "h $h2, $((4 * n)) steps: mean $mb, block_dev32 $bb, relmse $eb"
fail=0
check() { # what condition(awk) a b
  if awk -v a="$3" -v b="$4" "BEGIN {exit !($2)}"; then echo "ok  : $1 ($3 -> $4)"; else echo "FAIL: $1 ($3 -> $4)"; fail=1; fi
}
check "block bias falls by a quarter or more" "b < 0.75 * a" "$ba" "$bb"
check "mean closer to the reference" "(b > 1 ? b - 1 : 1 - b) < (a > 1 ? a - 1 : 1 - a)" "$ma" "$mb"
check "relative MSE falls" "b < a" "$ea" "$eb"
exit $fail
