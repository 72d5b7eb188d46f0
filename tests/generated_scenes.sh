#!/usr/bin/env bash
# The generated test scenes: the committed files are exactly what
# scenes/generate.py writes, and each renders (1 spp) without a warning.
# usage: generated_scenes.sh REPO_DIR CANDELA
set -u
repo=$1 candela=$2
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fail=0
/usr/bin/python3 "$repo/scenes/generate.py" "$tmp" >/dev/null || { echo "FAIL: generate.py exited $?"; exit 1; }
for f in "$repo"/scenes/generated/*.obj; do
  n=$(basename "$f" .obj)
  for ext in obj mtl cam; do
    if ! cmp -s "$repo/scenes/generated/$n.$ext" "$tmp/$n.$ext"; then echo "FAIL: $n.$ext differs from what generate.py writes"; fail=1; fi
  done
  # shellcheck disable=SC2046
  err=$("$candela" render "$f" $(cat "$repo/scenes/generated/$n.cam") --res 32x24 --spp 1 -o "$tmp/$n.exr" 2>&1 >/dev/null)
  if [ $? -ne 0 ] || [ -n "$err" ]; then echo "FAIL: $n renders with: $err"; fail=1; else echo "ok  : $n generated identically and renders cleanly"; fi
done
exit $fail
