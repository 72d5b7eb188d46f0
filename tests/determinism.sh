#!/usr/bin/env bash
# The same seed gives a bit-identical image with 1 and 2 threads; another
# seed gives a different one (so the comparison can fail).
# usage: determinism.sh CANDELA SCENE -- render args...
set -u
candela=$1 scene=$2
shift 3
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fail=0
for t in 1 2; do
  "$candela" render "$scene" "$@" --seed 5 --threads $t -q -o "$tmp/t$t.exr" -o "$tmp/t$t.pfm" >/dev/null || exit 1
done
"$candela" render "$scene" "$@" --seed 6 --threads 2 -q -o "$tmp/s6.pfm" >/dev/null || exit 1
if cmp -s "$tmp/t1.pfm" "$tmp/t2.pfm"; then echo "ok  : 1 and 2 threads give identical pixels (PFM)"; else echo "FAIL: 1 and 2 threads differ"; fail=1; fi
rmse=$("$candela" diff "$tmp/t1.exr" "$tmp/t2.exr" | awk '{print $2}')
if [ "$rmse" = "0" ]; then echo "ok  : EXR pixels identical (rmse $rmse)"; else echo "FAIL: EXR rmse $rmse"; fail=1; fi
if cmp -s "$tmp/t1.pfm" "$tmp/s6.pfm"; then echo "FAIL: seeds 5 and 6 give the same image"; fail=1; else echo "ok  : another seed gives another image"; fi
exit $fail
