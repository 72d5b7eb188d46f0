#!/usr/bin/env bash
# One method against a converged path-traced reference (for the occluded
# interiors: tests/data/make_interior_refs.sh): the image mean within IMGTOL
# and the mean over REGION (X0,Y0,X1,Y1 pixels: the room without the light)
# within ROOMTOL. Light leaking through a wall, a wrong depth limit or a
# biased density estimate shows there first. LO (optional, default the
# tolerance) widens the lower limits for a method biased dark by design (ir).
# INFO (optional) is a second set of options rendered and reported only.
# usage: [LO=l] [INFO="opts"] interior.sh CANDELA REF.exr REGION IMGTOL ROOMTOL "METHOD OPTS" -- render args
set -u
candela=$1 ref=$2 region=$3 imgtol=$4 roomtol=$5 method=$6
shift 7
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
key() { tr -s ' ' '\n' | awk -v k="$1" 'p {print; exit} $0 == k {p = 1}'; }
fail=0
check() { # what value tol lo
  if awk -v r="$2" -v t="$3" -v l="$4" 'BEGIN {exit !(r > 1 - l && r < 1 + t)}'; then
    echo "ok  : $1 $2 (limits 1 - $4, 1 + $3)"
  else
    echo "FAIL: $1 $2 (limits 1 - $4, 1 + $3)"; fail=1
  fi
}
run() { # "method opts" out render-args...
  local o=$1 out=$2 t0
  shift 2
  t0=$(date +%s.%N)
  # shellcheck disable=SC2086 # the method's options are split on purpose
  "$candela" render "$@" -i $o -q -o "$out" >/dev/null || return 1
  echo "      -i $o: $(awk -v a="$t0" -v b="$(date +%s.%N)" 'BEGIN {printf "%.1f", b - a}') s"
}
run "$method" "$tmp/m.exr" "$@" || { echo "FAIL: -i $method exited $?"; exit 1; }
img=$("$candela" diff "$tmp/m.exr" "$ref" | key mean_ratio)
room=$("$candela" diff "$tmp/m.exr" "$ref" --region "$region" | key mean_ratio)
check "-i $method: image mean / path" "$img" "$imgtol" "${LO:-$imgtol}"
check "-i $method: region ($region) mean / path" "$room" "$roomtol" "${LO:-$roomtol}"
if [ -n "${INFO:-}" ]; then
  run "$INFO" "$tmp/i.exr" "$@" || { echo "FAIL: -i $INFO exited $?"; exit 1; }
  echo "info: -i $INFO: image mean / path $("$candela" diff "$tmp/i.exr" "$ref" | key mean_ratio)," \
       "region $("$candela" diff "$tmp/i.exr" "$ref" --region "$region" | key mean_ratio) (reported, not checked)"
fi
exit $fail
