#!/usr/bin/env bash
# Herzog et al. 2007, Figures 6.2 and 6.8: splat's radiance cache (--cache,
# SH maps, C 0.6, S 0.2 as the report's cache rows) on McGuire's Cornell box,
# one frame of PHOTONS photon rays, against the pbrt reference:
#   Figure 6.2: the report's weight (eq. 6.7) against Ward's (--cache-weight
#     ward), with the same records;
#   Figure 6.8: record spacing from the splats' irradiance gradient (eq.
#     6.9-6.12, the default) against the geometric spacing (harmonic mean
#     distance alone, --cache-spacing geometric): record positions, counts,
#     the gradient magnitude, and the error at shadow boundaries (pixels
#     within 2 of a factor-2 change of the reference's luminance).
# usage: bench/splat_fig62_68.sh [OUT] [PHOTONS] [EPS]   (defaults out/splat_fig62_68 500000 0.5)
set -eu
here=$(cd "$(dirname "$0")/.." && pwd)
out=${1:-$here/out/splat_fig62_68}
photons=${2:-500000}
eps=${3:-0.5}
candela=${CANDELA:-$here/build/candela}
ref=$here/../shared/references/mcguire-cornell-original_path_256.exr
mkdir -p "$out"
args=("$here/../shared/scenes/cornell-box-mcguire/CornellBox-Original.obj" --lookat 0,1,3.9,0,1,0,0,1,0
  --fov 39.3077 --res 256x256 -i splat --progressive off --occlusion off -C 1 --mode sh -C 0.6 -S 0.2 --photons "$photons" --spp 1)
"$candela" render "${args[@]}" -o "$out/nocache.exr" >"$out/nocache.log"
for sp in gradient geometric; do
  for w in report ward; do
    "$candela" render "${args[@]}" --cache "$eps" --cache-spacing $sp --cache-weight $w --aov records \
      -o "$out/$sp-$w.exr" >"$out/$sp-$w.log"
  done
done
/usr/bin/python3 - "$out" "$ref" "$here/docs" "$here/bench" <<'EOF'
import re, sys
import numpy as np
import OpenImageIO as oiio
out, ref_path, docs = sys.argv[1:4]
sys.path.insert(0, sys.argv[4])
from boundary import boundary_mask
def load(path, layer=""):
    b = oiio.ImageBuf(path)
    names = list(b.spec().channelnames)
    px = b.get_pixels(oiio.FLOAT)
    idx = [names.index(f"{layer}{c}") for c in "RGB"]
    return px[:, :, idx].astype(np.float64)
lum = lambda x: x.mean(axis=2)
ref = lum(load(ref_path))
light = ref > 1.0  # the light seen: left out
mask = boundary_mask(ref, eps=1e-2)
valid = (ref > 0.02 * ref.mean()) & ~light
err = lambda t: (t - ref) ** 2 / (ref ** 2 + 1e-3 * ref.mean() ** 2)
print(f"shadow-boundary mask: {int((mask & valid).sum())} pixels")
print("| spacing | weight | records | relMSE image | relMSE boundaries | mean ratio | T_cache (s) | total (s) |")
print("|---|---|---|---|---|---|---|---|")
imgs = {}
for name in ("nocache", "gradient-report", "gradient-ward", "geometric-report", "geometric-ward"):
    t = lum(load(f"{out}/{name}.exr"))
    imgs[name] = t
    log = open(f"{out}/{name}.log").read()
    rec = re.search(r"cache: ([0-9.]+) records", log)
    tc = re.search(r"T_cache ([0-9.]+)", log).group(1)
    secs = re.search(r"spp in ([0-9.]+) s", log).group(1)
    sp, _, w = name.partition("-")
    e = err(t)
    print(f"| {sp} | {w or '-'} | {rec.group(1) if rec else '-'} | {e[valid].mean():.3g} | "
          f"{e[valid & mask].mean():.3g} | {t[valid].sum() / ref[valid].sum():.3f} | {tc} | {secs} |")
def save(img, path):
    img = np.clip(img, 0, 1).astype(np.float32)
    if img.ndim == 2:
        img = np.repeat(img[:, :, None], 3, axis=2)
    b = oiio.ImageBuf(oiio.ImageSpec(img.shape[1], img.shape[0], 3, oiio.FLOAT))
    b.set_pixels(oiio.ROI(), img)
    b.write(path)
tone = lambda x: np.clip(x / np.percentile(ref, 99), 0, 1) ** (1 / 2.2)
def heat(t):  # relative error, blue < 5 %, green 15 %, red >= 30 %
    r = np.clip(np.abs(t - ref) / np.maximum(ref, 1e-3 * ref.mean()), 0, 0.3)
    c = np.zeros(r.shape + (3,))
    c[..., 2] = np.clip(1 - r / 0.15, 0, 1)
    c[..., 1] = np.clip(1 - np.abs(r - 0.15) / 0.15, 0, 1)
    c[..., 0] = np.clip((r - 0.15) / 0.15, 0, 1)
    c[light] = 0
    return c
g = lambda x: np.repeat(tone(x)[:, :, None], 3, axis=2)
# Figure 6.2: report's weight | Ward's (top), their relative errors (bottom)
fig62 = np.concatenate([np.concatenate([g(imgs["gradient-report"]), g(imgs["gradient-ward"])], 1),
                        np.concatenate([heat(imgs["gradient-report"]), heat(imgs["gradient-ward"])], 1)], 0)
save(fig62, f"{docs}/splat-fig62.png")
# Figure 6.8: records (red dots) over the image, geometric | gradient spacing, and |grad E|
panels = []
for sp in ("geometric", "gradient"):
    rec = load(f"{out}/{sp}-report.exr", "records.")
    base = 0.5 * g(imgs[f"{sp}-report"])
    base[rec[:, :, 0] > 0] = (1, 0, 0)
    panels.append(base)
grad = load(f"{out}/gradient-report.exr", "records.")[:, :, 2]
gm = np.clip(grad / np.percentile(grad[grad > 0], 99), 0, 1) if (grad > 0).any() else grad
panels.append(np.repeat(gm[:, :, None], 3, axis=2))
save(np.concatenate(panels, 1), f"{docs}/splat-fig68.png")
print(f"wrote {docs}/splat-fig62.png (report | Ward; images, relative errors) and {docs}/splat-fig68.png "
      "(records with geometric | gradient spacing, gradient magnitude)")
EOF
