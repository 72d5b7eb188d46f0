#!/usr/bin/env bash
# --direct none leaves direct light out: at --maxdepth 1 (no indirect light)
# pm and splat then see only the emitters the camera sees, the same image
# whatever the method (identical pixels), and less than with direct light.
# usage: direct_none.sh CANDELA -- render args...
set -u
candela=$1
shift 2
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fail=0
"$candela" render "$@" --maxdepth 1 -i pm --gather 0 --direct none --spp 1 -q -o "$tmp/pm.exr" >/dev/null || exit 1
"$candela" render "$@" --maxdepth 1 -i splat --direct none --spp 1 -q -o "$tmp/splat.exr" >/dev/null || exit 1
"$candela" render "$@" --maxdepth 1 -i pm --gather 0 --spp 1 -q -o "$tmp/full.exr" >/dev/null || exit 1
rmse=$("$candela" diff "$tmp/pm.exr" "$tmp/splat.exr" | awk '{print $2}')
if [ "$rmse" = "0" ]; then echo "ok  : pm and splat without direct light at maxdepth 1: identical (emitters only)"; else echo "FAIL: they differ (rmse $rmse)"; fail=1; fi
ratio=$("$candela" diff "$tmp/pm.exr" "$tmp/full.exr" | tr -s ' ' '\n' | awk 'p {print; exit} $0 == "mean_ratio" {p = 1}')
if awk -v r="$ratio" 'BEGIN {exit !(r < 0.9)}'; then echo "ok  : and darker than with direct light (mean ratio $ratio)"; else echo "FAIL: mean ratio $ratio (direct light not left out?)"; fail=1; fi
exit $fail
