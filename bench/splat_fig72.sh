#!/usr/bin/env bash
# Herzog et al. 2007, Figure 7.2: indirect light in a real interior (Sponza,
# standing in for Sibenik; its Mitsuba light as a point light), photon ray
# splatting (SH maps) against the photon map seen directly with K nearest
# photons (K chosen for a similar radius), both with the same number of
# photons and one eye sample per pixel, and (the report's (d)) splat with
# radiance caching and image-space filtering (--cache 0.5 --filter 20000, the
# cache rows' smaller C and S), against a converged path-traced
# reference of indirect light: path at maxdepth D minus path at maxdepth 1
# with the same seed (the direct light cancels sample by sample).
# Relative error maps (blue < 5 %, green 15 %, red >= 30 %, as the report)
# and the errors over the whole image and over a mask of boundaries (pixels
# within 2 of a factor-2 change of the full reference's luminance: edges of
# columns, arches, small objects), where boundary bias shows.
# SCENE=cornell runs the same check on McGuire's Cornell box instead (its
# light is seen: those pixels are left out), PASSES the passes of splat and
# pm (1). The README's box figures: SCENE=cornell PASSES=8 ... 128x128
# 200000 50 512.
# usage: [SCENE=sponza|cornell] [PASSES=n] bench/splat_fig72.sh [OUT] [RES] [PHOTONS] [K] [REF_SPP]
#   defaults: out/splat_fig72 400x300 500000 500 1024
set -eu
here=$(cd "$(dirname "$0")/.." && pwd)
out=${1:-$here/out/splat_fig72}
res=${2:-400x300}
photons=${3:-500000}
k=${4:-500}
refspp=${5:-1024}
depth=8
candela=${CANDELA:-$here/build/candela}
mkdir -p "$out"
passes=${PASSES:-1}
if [ "${SCENE:-sponza}" = cornell ]; then
  args=("$here/../shared/scenes/cornell-box-mcguire/CornellBox-Original.obj" --lookat 0,1,3.9,0,1,0,0,1,0
    --fov 39.3077 --res "$res" --maxdepth $depth)
  splat_opts=()
  cache_opts=(--mode sh -C 0.6 -S 0.2 --cache 0.5 --filter 20000)
  png=$out/fig72.png
else
  args=("$here/../shared/scenes/sponza-dabrovic/obj-converted/sponza.obj"
    --lookat 14.4499,6.89415,-1.18547,13.4563,6.78438,-1.15861,-0.109708,0.993957,0.00374357 --fov 75
    --point-light 0,17,0,157,157,157 --res "$res" --maxdepth $depth)
  splat_opts=(--mode sh --fractions 0,1,0 -C 0.9 -S 0.3 -R 0.2)
  cache_opts=(--mode sh --fractions 0,1,0 -C 0.5 -S 0.2 -R 0.2 --cache 0.5 --filter 20000)
  png=$here/docs/splat-fig72.png
fi
for d in $depth 1; do
  [ -f "$out/path_d$d.exr" ] || "$candela" render "${args[@]}" --maxdepth $d -i path --spp "$refspp" --seed 3 -q \
    -o "$out/path_d$d.exr"
done
"$candela" render "${args[@]}" -i splat --progressive off --occlusion off -C 1 --direct none "${splat_opts[@]}" --photons "$photons" --spp "$passes" \
  -o "$out/splat.exr" | tee "$out/splat.log"
"$candela" render "${args[@]}" -i splat --progressive off --occlusion off -C 1 --direct none "${cache_opts[@]}" --photons "$photons" --spp "$passes" \
  -o "$out/cache.exr" | tee "$out/cache.log"
"$candela" render "${args[@]}" -i pm --progressive off --visibility gather --knn 50 --direct none --gather 0 --knn "$k" --photons "$photons" --spp "$passes" \
  -o "$out/pm.exr" | tee "$out/pm.log"
/usr/bin/python3 - "$out" "$png" "${SCENE:-sponza}" "$here/bench" <<'EOF'
import sys
import numpy as np
import OpenImageIO as oiio
out, png, scene = sys.argv[1], sys.argv[2], sys.argv[3]
sys.path.insert(0, sys.argv[4])
from boundary import boundary_mask
def load(n):
    return oiio.ImageBuf(f"{out}/{n}.exr").get_pixels(oiio.FLOAT)[:, :, :3].astype(np.float64)
full, direct = load("path_d8"), load("path_d1")
ref = np.clip(full - direct, 0, None)
lum = lambda x: x.mean(axis=2)
mask = boundary_mask(lum(full), eps=1e-3)
r = lum(ref)
floor = 0.05 * r.mean()
# emitters the camera sees (the box's light): the methods keep them, the reference does not
seen_light = lum(direct) > 1.0 if scene == "cornell" else np.zeros(r.shape, bool)
valid = (r > floor) & ~seen_light
rows, panels = [], [("path, indirect light", ref, None)]
for name, label in (("splat", "splat (SH)"), ("cache", "splat (SH), cache + filter"), ("pm", "pm, K nearest")):
    t = load(name)
    rel = np.abs(lum(t) - r) / np.maximum(r, floor)
    e = (lum(t) - r) ** 2 / (r ** 2 + 0.01)
    rows.append((label, e[~seen_light].mean(), e[mask & ~seen_light].mean(), np.median(rel[valid]), np.median(rel[valid & mask]),
                 (rel[valid & mask] > 0.3).mean(), lum(t)[~seen_light].mean() / r[~seen_light].mean()))
    panels.append((label, t, rel))
with open(f"{out}/table.md", "w") as f:
    f.write(f"| method | relMSE image | relMSE boundary mask ({int(mask.sum())} px) | median rel. error | "
            "median rel. error in mask | mask pixels >= 30 % off | mean ratio |\n|---|---|---|---|---|---|---|\n")
    for row in rows:
        f.write("| %s | %.3g | %.3g | %.3f | %.3f | %.3f | %.4f |\n" % row)
print(open(f"{out}/table.md").read())
def tone(x):
    s = 1.0 / np.percentile(lum(ref), 99)
    return np.clip(x * s, 0, 1) ** (1 / 2.2)
def colour(rel):  # blue < 5 %, green 15 %, red >= 30 %
    t = np.clip(rel, 0, 0.3)
    c = np.zeros(rel.shape + (3,))
    a = t <= 0.15
    f = np.where(a, (t - 0.05).clip(0) / 0.10, (t - 0.15) / 0.15)
    c[..., 0] = np.where(a, 0, f)
    c[..., 1] = np.where(a, f, 1 - f)
    c[..., 2] = np.where(a, 1 - f, 0)
    return c
h, w = ref.shape[:2]
top = np.concatenate([tone(p[1]) for p in panels], axis=1)
bot = np.concatenate([np.stack([mask] * 3, axis=2).astype(float) * 0.8] + [colour(p[2]) for p in panels[1:]], axis=1)
img = np.concatenate([top, bot], axis=0)
buf = oiio.ImageBuf(oiio.ImageSpec(img.shape[1], img.shape[0], 3, oiio.UINT8))
buf.set_pixels(oiio.ROI(0, img.shape[1], 0, img.shape[0]), (img * 255 + 0.5).astype(np.uint8))
buf.write(png)
print("wrote", png)
EOF
