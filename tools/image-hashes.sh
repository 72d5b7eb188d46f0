#!/usr/bin/env bash
# Renders every case of tools/image-hashes.cases (a method and its options,
# Cornell box, 48x48, 2 spp, 2 threads) and prints an MD5 of each image's
# pixels (not the file: EXR metadata holds the render time). Run it before
# and after a change that must not change images, and diff the two:
#   tools/image-hashes.sh build/candela > before.txt; ...; diff before.txt after.txt
set -eu
candela=${1:-build/candela}
here=$(cd "$(dirname "$0")" && pwd)
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
i=0
while read -r line; do
  [ -z "$line" ] && continue
  i=$((i + 1))
  # shellcheck disable=SC2086
  "$candela" render "$here/../scenes/cornell-box/CornellBox-Original.obj" --lookat 0,1,3.9,0,1,0,0,1,0 --fov 39.3 \
    --res 48x48 --spp 2 --threads 2 -q -i $line -o "$tmp/c$i.exr" > /dev/null
  printf '%s\t' "$line"
  /usr/bin/python3 - "$tmp/c$i.exr" <<'PY'
import hashlib, sys, OpenImageIO as oiio
inp = oiio.ImageInput.open(sys.argv[1]); h = hashlib.md5(); sub = 0
while inp.seek_subimage(sub, 0):
    h.update(inp.read_image(0, 0, 0, -1, "float").tobytes()); sub += 1
print(h.hexdigest())
PY
done < "$here/image-hashes.cases"
