#!/usr/bin/env bash
# --maxdepth counts the bounces of the whole path (1 = direct light only) in
# every method: at each depth each method's image mean must match path's at
# the same depth within TOL (ir: within its clamping bias, IRLOW below path
# and TOL above). rigi and pm once capped the eye and light subpaths
# separately: 1.23x path at --maxdepth 1.
# usage: maxdepth.sh CANDELA TOL IRLOW "DEPTHS" -- render args (scene, camera, light)...
set -u
candela=$1 tol=$2 irlow=$3 depths=$4
shift 5
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fail=0
ratio() { "$candela" diff "$1" "$2" | tr -s ' ' '\n' | awk 'p {print; exit} $0 == "mean_ratio" {p = 1}'; }
for md in $depths; do
  "$candela" render "$@" --maxdepth "$md" -i path --spp 1024 -q -o "$tmp/path.exr" >/dev/null || { echo "FAIL: path at --maxdepth $md"; exit 1; }
  for m in "bdpt --spp 128" "rigi --spp 8" "ir --spp 8" "pm --spp 16" "sppm --spp 32" "vcm --spp 64"; do
    i=${m%% *}
    # shellcheck disable=SC2086 # the method's options are split on purpose
    "$candela" render "$@" --maxdepth "$md" -i $m -q -o "$tmp/$i.exr" >/dev/null || { echo "FAIL: $i at --maxdepth $md exited $?"; fail=1; continue; }
    r=$(ratio "$tmp/$i.exr" "$tmp/path.exr")
    lo=$tol
    [ "$i" = ir ] && lo=$irlow
    if awk -v r="$r" -v lo="$lo" -v hi="$tol" 'BEGIN {exit !(r > 1 - lo && r < 1 + hi)}'; then
      echo "ok  : --maxdepth $md $i/path mean $r"
    else
      echo "FAIL: --maxdepth $md $i/path mean $r (limits 1 - $lo, 1 + $tol)"; fail=1
    fi
  done
done
exit $fail
