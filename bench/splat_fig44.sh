#!/usr/bin/env bash
# Herzog et al. 2007, Figure 4.4: the bandwidth each photon ray gets from
# its path density (eq. 4.8-4.9), seen per pixel (`--aov bandwidth`: the
# kernel-weighted mean bandwidth of the rays that splatted the pixel, for
# rays ending at depth 2, at depth 3 and at any depth), on McGuire's box
# with a mirror and a glass sphere: rays through the glass (caustics) get
# narrow kernels, rays of more bounces wide ones. False colour, red the
# smallest and blue the largest bandwidth (log scale, as the report).
# usage: bench/splat_fig44.sh [OUT] [RES] [PHOTONS]  (defaults out/splat_fig44 320 200000)
set -eu
here=$(cd "$(dirname "$0")/.." && pwd)
out=${1:-$here/out/splat_fig44}
res=${2:-320}
photons=${3:-200000}
candela=${CANDELA:-$here/build/candela}
mkdir -p "$out"
"$candela" render "$here/../shared/scenes/cornell-box-mcguire/CornellBox-Sphere.obj" --lookat 0,1,3.9,0,1,0,0,1,0 \
  --fov 39.3077 --res "${res}x$res" -i splat --progressive off --occlusion off -C 1 --photons "$photons" --spp 1 --aov bandwidth -o "$out/bw.exr"
/usr/bin/python3 - "$out/bw.exr" "$here/docs/splat-fig44.png" <<'PY'
import sys
import numpy as np
import OpenImageIO as oiio
import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt
p = oiio.ImageBuf(sys.argv[1]).get_pixels(oiio.FLOAT).astype(np.float64)
img = np.clip(p[:, :, :3] / (1.0 + p[:, :, :3]), 0, 1) ** (1 / 2.2)
bw = p[:, :, 3:6]
vals = bw[bw > 0]
lo, hi = np.percentile(vals, 2), np.percentile(vals, 98)
fig, ax = plt.subplots(1, 4, figsize=(16, 4.4))
ax[0].imshow(img)
ax[0].set_title("splat, 1 pass")
for i, name in enumerate(["rays of depth 2", "rays of depth 3", "all rays"]):
    b = np.where(bw[:, :, i] > 0, np.log(np.clip(bw[:, :, i], lo, hi)), np.nan)
    im = ax[i + 1].imshow(b, cmap="jet_r", vmin=np.log(lo), vmax=np.log(hi))
    ax[i + 1].set_title(f"bandwidth, {name}")
for a in ax:
    a.axis("off")
cb = fig.colorbar(im, ax=ax[1:], fraction=0.02)
ticks = np.geomspace(lo, hi, 5)
cb.set_ticks(np.log(ticks))
cb.set_ticklabels([f"{t:.3g}" for t in ticks])
fig.savefig(sys.argv[2], dpi=80, bbox_inches="tight")
print(f"bandwidth (scene units): 2nd-98th percentile {lo:.3g} .. {hi:.3g}; medians by depth 2, 3, all: "
      + ", ".join(f"{np.median(bw[:, :, i][bw[:, :, i] > 0]):.3g}" for i in range(3)))
PY
