#!/usr/bin/env bash
# Herzog et al. 2007, Figure 8.2: photon ray splatting with and without the
# visibility mask (§8.1, --visibility-mask), on McGuire's Cornell box:
#   direct light from 50000 photon rays (fractions 1/0/0, maxdepth 1),
#   indirect light from 200000 (fractions 0/1/0, --direct none),
#   global illumination from 250000 (fractions 0.2/0.8/0),
# each against a converged path-traced reference (maxdepth 1, maxdepth D minus
# maxdepth 1 with the same seed, maxdepth D). Errors: relMSE over the image and
# over the shadow boundaries (pixels within 2 of a factor-2 change of the direct
# reference's luminance), the mean ratio, and the time of each render.
# usage: bench/splat_fig82.sh [OUT] [RES] [PASSES] [REF_SPP]   (defaults out/splat_fig82 256x256 1 2048)
set -eu
here=$(cd "$(dirname "$0")/.." && pwd)
out=${1:-$here/out/splat_fig82}
res=${2:-256x256}
passes=${3:-1}
refspp=${4:-2048}
depth=8
candela=${CANDELA:-$here/build/candela}
mkdir -p "$out"
args=("$here/../shared/scenes/cornell-box-mcguire/CornellBox-Original.obj" --lookat 0,1,3.9,0,1,0,0,1,0
  --fov 39.3077 --res "$res")
for d in $depth 1; do
  [ -f "$out/path_d$d.exr" ] || "$candela" render "${args[@]}" --maxdepth $d -i path --spp "$refspp" --seed 3 -q \
    -o "$out/path_d$d.exr"
done
run() { # name maxdepth splat-options...
  local name=$1 d=$2
  shift 2
  for m in off on; do
    "$candela" render "${args[@]}" --maxdepth "$d" -i splat --progressive off --occlusion off -C 1 --spp "$passes" --visibility-mask $m "$@" \
      -o "$out/$name-$m.exr" >"$out/$name-$m.log"
  done
}
run direct 1 --photons 50000 --fractions 1,0,0
run indirect $depth --photons 200000 --fractions 0,1,0 --direct none
run global $depth --photons 250000 --fractions 0.2,0.8,0
/usr/bin/python3 - "$out" "$here/docs/splat-fig82.png" "$here/bench" <<'EOF'
import re, sys
import numpy as np
import OpenImageIO as oiio
out, png = sys.argv[1], sys.argv[2]
sys.path.insert(0, sys.argv[3])
from boundary import boundary_mask
load = lambda n: oiio.ImageBuf(f"{out}/{n}.exr").get_pixels(oiio.FLOAT)[:, :, :3].astype(np.float64)
full, direct = load(f"path_d8"), load("path_d1")
refs = {"direct": direct, "indirect": np.clip(full - direct, 0, None), "global": full}
lum = lambda x: x.mean(axis=2)
mask = boundary_mask(lum(direct), eps=1e-2)
seen_light = lum(direct) > 1.0  # the light itself: the reference and splat agree there, it swamps means
print(f"shadow-boundary mask: {int((mask & ~seen_light).sum())} pixels")
print("| light | mask | relMSE image | relMSE boundaries | mean ratio | time (s) |")
print("|---|---|---|---|---|---|")
rows = []
for name, ref in refs.items():
    r = lum(ref)
    valid = (r > 0.02 * r.mean()) & ~seen_light
    for m in ("off", "on"):
        t = lum(load(f"{name}-{m}"))
        e = (t - r) ** 2 / (r ** 2 + 1e-3 * r.mean() ** 2)
        secs = re.search(r"spp in ([0-9.]+) s", open(f"{out}/{name}-{m}.log").read()).group(1)
        print(f"| {name} | {m} | {e[valid].mean():.3g} | {e[valid & mask].mean():.3g} | "
              f"{t[valid].sum() / r[valid].sum():.3f} | {secs} |")
        rows.append((name, m, t, r))
# picture: per light, reference | off | on (tone-mapped), a row each
def tone(x, scale):
    return np.clip(x / scale, 0, 1) ** (1 / 2.2)
lines = []
for name in refs:
    r = lum(refs[name]); s = np.percentile(r, 99)
    ims = [tone(r, s)] + [tone(t, s) for (n, m, t, _) in rows if n == name]
    lines.append(np.concatenate(ims, axis=1))
img = np.concatenate(lines, axis=0)
img = np.repeat(img[:, :, None], 3, axis=2).astype(np.float32)
buf = oiio.ImageBuf(oiio.ImageSpec(img.shape[1], img.shape[0], 3, oiio.FLOAT))
buf.set_pixels(oiio.ROI(), img)
buf.write(png)
print(f"wrote {png} (rows: direct, indirect, global; columns: path, splat, splat with the mask)")
EOF
