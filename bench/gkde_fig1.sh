#!/usr/bin/env bash
# Bekaert et al. 2003, Figure 1: direct light only (--maxdepth 1), gkde
# against the photon map seen directly (pm --gather 0) at equal time, in the
# two-room scene (scenes/generated/tworoom: a 5 cm wall with an open doorway,
# the light in the far room, the camera in the dark one). The dark side of
# the wall must stay black apart from the light patch the doorway lets
# through; its sharp edges are the shadow boundaries.
#
#  1. Reference: path tracing at maxdepth 1, REF_SPP spp (cached in OUT).
#  2. gkde, pm --gather 0 --direct photons (the photon map seen directly,
#     its primary photons the direct light: Jensen's estimate, which leaks) and
#     the same with --visibility all (photons hidden from the query point left
#     out), at TIME seconds each.
#  3. Masks from the reference: "boundary" = pixels within 2 pixels of a
#     change of log luminance by more than a factor 3 (the light patch's and
#     the doorway's edges); "dark" = pixels whose 5x5 neighbourhood is below
#     1 % of the mean of lit pixels (where only a leak can put light).
#     relMSE (candela diff's definition) over the image, the boundary mask and
#     the dark mask, the light that lands in the dark mask relative to the
#     reference image mean, and the image mean ratio.
#  4. OUT/table.md and docs/gkde-fig1.png (reference, gkde, pm, pm with
#     visibility; exposure +2 stops).
#
# usage: bench/gkde_fig1.sh [OUT] [TIME] [REF_SPP]   (defaults out/gkde_fig1 10 4096)
set -eu
here=$(cd "$(dirname "$0")/.." && pwd)
out=${1:-$here/out/gkde_fig1}
budget=${2:-10}
refspp=${3:-4096}
candela=${CANDELA:-$here/build/candela}
py=/usr/bin/python3
scene=$here/scenes/generated/tworoom.obj
# shellcheck disable=SC2207 # the camera file holds options
cam=($(cat "$here/scenes/generated/tworoom.cam"))
args=("$scene" "${cam[@]}" --res 320x240 --maxdepth 1)
mkdir -p "$out"
[ -f "$out/ref.exr" ] || "$candela" render "${args[@]}" -i path --spp "$refspp" -q -o "$out/ref.exr"
"$candela" render "${args[@]}" -i gkde --progressive off --overlaps 5 --time "$budget" -o "$out/gkde.exr" | tee "$out/gkde.log"
"$candela" render "${args[@]}" -i pm --progressive off --visibility gather --knn 50 --photons 100000 --gather 0 --direct photons --time "$budget" -o "$out/pm.exr" | tee "$out/pm.log"
"$candela" render "${args[@]}" -i pm --progressive off --visibility gather --knn 50 --photons 100000 --gather 0 --direct photons --visibility all --time "$budget" -o "$out/pm_vis.exr" |
  tee "$out/pm_vis.log"
"$py" - "$out" "$here/docs/gkde-fig1.png" <<'EOF'
import sys
import numpy as np
import OpenImageIO as oiio

out, fig = sys.argv[1], sys.argv[2]
def load(n):
    return oiio.ImageBuf(f"{out}/{n}.exr").get_pixels(oiio.FLOAT)[:, :, :3].astype(np.float64)
ref = load("ref")
lum = ref.mean(axis=2)
lit = lum[lum > 0].mean()
ll = np.log(lum + 1e-3 * lit)
edge = np.zeros_like(lum, dtype=bool)
for dy, dx in ((0, 1), (1, 0)):
    d = np.abs(ll[dy:, dx:] - ll[:ll.shape[0] - dy, :ll.shape[1] - dx]) > np.log(3.0)
    edge[dy:, dx:] |= d
    edge[:ll.shape[0] - dy, :ll.shape[1] - dx] |= d
def grow(m, r):
    g = m.copy()
    for dy in range(-r, r + 1):
        for dx in range(-r, r + 1):
            g |= np.roll(np.roll(m, dy, 0), dx, 1)
    return g
boundary = grow(edge, 2)
dark = ~grow(lum > 0.01 * lit, 2)
rows = []
imgs = [("path reference", ref)]
for name, label in (("gkde", "gkde"), ("pm", "pm (photon map seen directly)"), ("pm_vis", "pm, hidden photons left out")):
    t = load(name)
    e = (t - ref) ** 2 / (ref ** 2 + 0.01)
    spp = open(f"{out}/{name}.log").read().split(" spp in")[0].split()[-1]
    rows.append((label, spp, e.mean(), e[boundary].mean(), e[dark].mean(),
                 t.mean(axis=2)[dark].sum() / lum.sum(), t.mean() / ref.mean()))
    imgs.append((label, t))
with open(f"{out}/table.md", "w") as f:
    f.write("| method | steps | relMSE image | relMSE boundary (%d px) | relMSE dark (%d px) "
            "| light in dark / image | mean ratio |\n|---|---|---|---|---|---|---|\n"
            % (boundary.sum(), dark.sum()))
    for r in rows:
        f.write("| %s | %s | %.3g | %.3g | %.3g | %.3g | %.4f |\n" % r)
print(open(f"{out}/table.md").read())
# the strip: each image with +2 stops, sRGB, labelled by order
tiles = []
for label, t in imgs:
    v = np.clip(t * 4.0, 0, 1)
    v = np.where(v <= 0.0031308, 12.92 * v, 1.055 * v ** (1 / 2.4) - 0.055)
    tiles.append(v)
strip = np.concatenate([np.concatenate(tiles[:2], axis=1), np.concatenate(tiles[2:], axis=1)], axis=0)
buf = oiio.ImageBuf(oiio.ImageSpec(strip.shape[1], strip.shape[0], 3, oiio.UINT8))
buf.set_pixels(oiio.ROI(0, strip.shape[1], 0, strip.shape[0]), (strip * 255 + 0.5).astype(np.uint8))
buf.write(fig)
EOF
