#!/usr/bin/env bash
# Bekaert et al. 2003, Figures 4 and 7, and gkde's bias maps.
#
# Figure 4 (bias of the approximate normalization, §3): the generated
# `grazing` scene (a blue light standing on a floor, tilted back, a box in
# front) rendered by path tracing (unbiased, REF_SPP spp) and by gkde with
# STEPS steps at the calibrated bandwidth and at a quarter of it (with 16x
# the steps); the bias maps are `candela diff --heatmap` against the path
# reference (relative error per pixel, 1e-4 blue to 1 red).
# Cornell bias map: gkde with 4 x STEPS steps against the pbrt reference of
# the McGuire box.
# Figure 7 (non-diffuse light to the viewer): the McGuire CornellBox-Glossy
# with 1, 4 and 16 eye paths per pixel at equal time (TIME s each) against a
# path reference: relMSE and images.
#
# Writes OUT/table.md and docs/gkde-fig4.png (reference | gkde | bias map |
# gkde at h/4 | its bias map), docs/gkde-bias-cornell.png and docs/gkde-fig7.png
# (reference | 1 | 4 | 16 eye paths).
# usage: bench/gkde_fig47.sh [OUT] [STEPS] [TIME] [REF_SPP]
#   defaults: out/gkde_fig47 16 20 8192 (about 15 minutes on 2 cores)
set -eu
here=$(cd "$(dirname "$0")/.." && pwd)
out=${1:-$here/out/gkde_fig47}
steps=${2:-16}
budget=${3:-20}
refspp=${4:-8192}
candela=${CANDELA:-$here/build/candela}
shared=$here/../shared
mkdir -p "$out"
key() { tr -s ' ' '\n' | awk -v k="$1" 'p {print; exit} $0 == k {p = 1}'; }

# Figure 4
# shellcheck disable=SC2207 # the camera file holds options
cam=($(cat "$here/scenes/generated/grazing.cam"))
g=("$here/scenes/generated/grazing.obj" "${cam[@]}" --res 320x240 --maxdepth 8)
[ -f "$out/grazing_ref.exr" ] || "$candela" render "${g[@]}" -i path --spp "$refspp" -q -o "$out/grazing_ref.exr"
"$candela" render "${g[@]}" -i gkde --progressive off --overlaps 5 --spp "$steps" -o "$out/grazing_gkde.exr" | tee "$out/grazing_gkde.log"
h=$(grep -o 'gkde: h [0-9.e-]*' "$out/grazing_gkde.log" | awk '{print $3}')
h4=$(awk -v h="$h" 'BEGIN {print h / 4}')
"$candela" render "${g[@]}" -i gkde --progressive off --overlaps 5 --bandwidth "$h4" --spp $((16 * steps)) -o "$out/grazing_gkde_h4.exr" |
  tee "$out/grazing_gkde_h4.log"
{
  echo "## Figure 4: grazing light (320x240, maxdepth 8, path reference $refspp spp)"
  echo
  echo "| render | mean ratio | relMSE | block_dev32 |"
  echo "|---|---|---|---|"
  for n in gkde gkde_h4; do
    d=$("$candela" diff "$out/grazing_$n.exr" "$out/grazing_ref.exr" --heatmap "$out/grazing_${n}_bias.png")
    label="gkde h $h, $steps steps"
    [ $n = gkde_h4 ] && label="gkde h $h4, $((16 * steps)) steps"
    echo "| $label | $(echo "$d" | key mean_ratio) | $(echo "$d" | key relmse) | $(echo "$d" | key block_dev32) |"
  done
} > "$out/table.md"

# Cornell bias map
# shellcheck disable=SC2054 # the commas are within --lookat
cb=("$shared/scenes/cornell-box-mcguire/CornellBox-Original.obj" --lookat 0,1,3.9,0,1,0,0,1,0 --fov 39.3077 --res 256x256)
"$candela" render "${cb[@]}" -i gkde --progressive off --overlaps 5 --spp $((4 * steps)) -q -o "$out/cornell_gkde.exr"
d=$("$candela" diff "$out/cornell_gkde.exr" "$shared/references/mcguire-cornell-original_path_256.exr" \
  --heatmap "$here/docs/gkde-bias-cornell.png")
{
  echo
  echo "Cornell box (McGuire, 256x256, $((4 * steps)) steps) against pbrt: mean $(echo "$d" | key mean_ratio)," \
    "relMSE $(echo "$d" | key relmse), block_dev32 $(echo "$d" | key block_dev32)"
  echo
  echo "## Figure 7: CornellBox-Glossy, equal time ($budget s), 160x160"
  echo
  echo "| eye paths per pixel | steps | relMSE | mean ratio |"
  echo "|---|---|---|---|"
} >> "$out/table.md"

# Figure 7
# shellcheck disable=SC2054
gl=("$shared/scenes/cornell-box-mcguire/CornellBox-Glossy.obj" --lookat 0,1,3.9,0,1,0,0,1,0 --fov 39.3077 --res 160x160)
[ -f "$out/glossy_ref.exr" ] || "$candela" render "${gl[@]}" -i path --spp "$refspp" -q -o "$out/glossy_ref.exr"
for e in 1 4 16; do
  "$candela" render "${gl[@]}" -i gkde --progressive off --overlaps 5 --eye-paths $e --time "$budget" -o "$out/glossy_e$e.exr" > "$out/glossy_e$e.log"
  d=$("$candela" diff "$out/glossy_e$e.exr" "$out/glossy_ref.exr")
  echo "| $e | $(grep -o '[0-9]* spp in' "$out/glossy_e$e.log" | awk '{print $1}') | $(echo "$d" | key relmse) |" \
    "$(echo "$d" | key mean_ratio) |" >> "$out/table.md"
done
cat "$out/table.md"

/usr/bin/python3 - "$out" "$here/docs" <<'EOF'
import sys
import numpy as np
import OpenImageIO as oiio

out, docs = sys.argv[1], sys.argv[2]
def srgb(n, gain=1.0):
    a = oiio.ImageBuf(n).get_pixels(oiio.FLOAT)[:, :, :3].astype(np.float64)
    v = np.clip(a * gain, 0, 1)
    return np.where(v <= 0.0031308, 12.92 * v, 1.055 * v ** (1 / 2.4) - 0.055)
def png(n):
    return oiio.ImageBuf(n).get_pixels(oiio.FLOAT)[:, :, :3].astype(np.float64)
def write(tiles, path):
    strip = np.concatenate(tiles, axis=1)
    buf = oiio.ImageBuf(oiio.ImageSpec(strip.shape[1], strip.shape[0], 3, oiio.UINT8))
    buf.set_pixels(oiio.ROI(0, strip.shape[1], 0, strip.shape[0]), (strip * 255 + 0.5).astype(np.uint8))
    buf.write(path)
write([srgb(f"{out}/grazing_ref.exr"), srgb(f"{out}/grazing_gkde.exr"), png(f"{out}/grazing_gkde_bias.png"),
       srgb(f"{out}/grazing_gkde_h4.exr"), png(f"{out}/grazing_gkde_h4_bias.png")], f"{docs}/gkde-fig4.png")
write([srgb(f"{out}/glossy_ref.exr")] + [srgb(f"{out}/glossy_e{e}.exr") for e in (1, 4, 16)],
      f"{docs}/gkde-fig7.png")
EOF
