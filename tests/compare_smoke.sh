#!/usr/bin/env bash
# Smoke test of the equal-time harness bench/compare: path tracing with the
# Sobol and the independent sampler on the shipped Cornell box at 0.5 s and
# 1 s (256x256). Checks what could go wrong in the harness: one CSV row per
# render, relative MSE falling with time (10 % tolerance for timing noise),
# both configs in the time-to-target table, a real PNG plot, and one-line
# failures for a bad config and a missing candela.
# usage: compare_smoke.sh REPO_DIR CANDELA SHARED_DIR
set -u
if [ $# -ne 3 ]; then echo "usage: compare_smoke.sh REPO_DIR CANDELA SHARED_DIR" >&2; exit 2; fi
repo=$1 candela=$2 shared=$3
compare=$repo/bench/compare
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fail=0
ok() { echo "ok  : $*"; }
bad() { echo "FAIL: $*"; fail=1; }

common=(--scene "$repo/scenes/cornell-box/CornellBox-Original.obj"
        --ref "$shared/references/mcguire-cornell-original_path_256.exr" --res 256x256
        --render-args "--lookat 0,1,3.9,0,1,0,0,1,0 --fov 39.3077 --maxdepth 64"
        --candela "$candela")
if "$compare" "${common[@]}" --config "sobol=-i path" \
     --config "independent=-i path --sampler independent" \
     --times 0.5,1 --target 0.01 --out "$tmp/out" >"$tmp/stdout" 2>"$tmp/stderr"; then
  ok "harness ran"
else
  bad "harness exited $?: $(tail -n 1 "$tmp/stderr")"; exit 1
fi

csv=$tmp/out/results.csv
rows=$(($(wc -l <"$csv") - 1))
[ "$rows" -eq 4 ] && ok "results.csv has 4 rows" || bad "results.csv has $rows rows, expected 4"

for cfg in sobol independent; do
  e05=$(awk -F, -v c=$cfg '$1 == c && $2 == 0.5 {print $6}' "$csv")
  e1=$(awk -F, -v c=$cfg '$1 == c && $2 == 1 {print $6}' "$csv")
  if [ -n "$e05" ] && [ -n "$e1" ] && awk -v a="$e05" -v b="$e1" 'BEGIN {exit !(b <= 1.1 * a && a > 0)}'; then
    ok "$cfg: relmse $e05 at 0.5 s, $e1 at 1 s (falls, 10 % tolerance)"
  else
    bad "$cfg: relmse '$e05' at 0.5 s, '$e1' at 1 s (must fall within 10 %)"
  fi
  if sed -n '/^### Time to reach/,$p' "$tmp/out/table.md" | grep -Eq "^\| $cfg \| ~?[0-9.e+-]+ \|"; then
    ok "$cfg in the time-to-target table"
  else
    bad "$cfg missing from the time-to-target table"
  fi
done
cmp -s "$tmp/stdout" "$tmp/out/table.md" && ok "stdout is table.md" || bad "stdout differs from table.md"

magic=$(head -c 8 "$tmp/out/plot.png" 2>/dev/null | od -An -tx1 | tr -d ' \n')
[ "$magic" = 89504e470d0a1a0a ] && ok "plot.png is a PNG" || bad "plot.png missing or not a PNG ($magic)"

# Failures must be one line and a non-zero exit, before anything is rendered.
check_failure() { # what -- args...
  local what=$1; shift 2
  if "$compare" "$@" >/dev/null 2>"$tmp/err"; then bad "$what: exit 0"; return; fi
  local n; n=$(wc -l <"$tmp/err")
  [ "$n" -eq 1 ] && ok "$what: one-line error: $(cat "$tmp/err")" || bad "$what: $n lines of error"
}
check_failure "bad config" -- "${common[@]}" --config "no-equals-sign" --times 1 --target 0.01 --out "$tmp/bad"
check_failure "missing candela" -- "${common[@]}" --candela "$tmp/nothing" --config "p=-i path" \
  --times 1 --target 0.01 --out "$tmp/bad"
exit $fail
