#!/usr/bin/env bash
# Lights at infinity in every method that takes them: the environment-lit
# scene (scenes/generated/envlit.pbrt: EXR sky + sun over a floor, a wall and
# a box, 128x96) against path at 2048 passes, each method at 64 passes.
# usage: bench/envlit.sh [BUILD_DIR]   (prints Markdown)
set -eu
here=$(cd "$(dirname "$0")/.." && pwd)
candela=${1:-$here/build}/candela
scene=$here/scenes/generated/envlit.pbrt
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
key() { sed -n "s/.*$1 \([^ ]*\) .*/\1/p"; }
"$candela" render "$scene" -i path --spp 2048 -q -o "$tmp/ref.exr" >/dev/null
echo "## Lights at infinity: envlit.pbrt, 64 passes against path at 2048"
echo
echo "| method | options | mean ratio | relMSE | seconds |"
echo "|---|---|---|---|---|"
while IFS='|' read -r m opts; do
  # shellcheck disable=SC2086
  line=$("$candela" render "$scene" -i "$m" $opts --spp 64 -q -o "$tmp/x.exr")
  d=$("$candela" diff "$tmp/x.exr" "$tmp/ref.exr")
  printf '| %s | %s | %s | %s | %s |\n' "$m" "${opts:--}" "$(echo "$d" | key mean_ratio)" \
    "$(echo "$d" | key relmse)" "$(echo "$line" | sed -n 's/.* spp in \([0-9.]*\) s.*/\1/p')"
done <<'EOT'
path|
bdpt|
bdpt|--mis balance
bdpt|--mis stratified
bdpt|--mis light
bdpt|--light-paths 256 --interleave 4
pm|
rigi|
ir|
gkde|
splat|
vcm|
vcm|--vcm-mode merge
EOT
