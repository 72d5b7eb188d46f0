#!/usr/bin/env bash
# Herzog et al. 2007, Table 7.1's final-gathering rows (RS-FG against PM-FG,
# the report: 3825 s against 5108 s with 600 gather rays): photon ray
# splatting to the gather rays' hits (splat --gather N) against the photon map
# read at the gather rays' hits (pm --gather N, with its precomputed irradiance
# and without it, the classic k-NN estimate at every hit), the same gather rays
# and photons, on a generated conference room of about 250k triangles (diffuse,
# lit indirectly: scenes/generate.py conference_fg), one pass each, indirect
# light alone (--direct none: the light sampled at the camera's points is the
# same in both and its noise on the ceiling next to the luminaires would hide
# the comparison); time split and relMSE against a converged path render of
# indirect light (maxdepth 8 minus maxdepth 1 with the same seed).
# usage: bench/splat_fg.sh [OUT] [RES] [GATHER] [PHOTONS] [REF_SPP]
#   defaults: out/splat_fg 320x240 64 200000 2048
set -eu
here=$(cd "$(dirname "$0")/.." && pwd)
out=${1:-$here/out/splat_fg}
res=${2:-320x240}
gather=${3:-64}
photons=${4:-200000}
refspp=${5:-2048}
candela=${CANDELA:-$here/build/candela}
mkdir -p "$out"
[ -f "$out/conference_fg.obj" ] || /usr/bin/python3 "$here/scenes/generate.py" "$out" conference_fg >/dev/null
# shellcheck disable=SC2207 # the camera file holds options
args=("$out/conference_fg.obj" $(cat "$out/conference_fg.cam") --res "$res" --maxdepth 8)
for d in 8 1; do
  [ -f "$out/path_d$d.exr" ] || "$candela" render "${args[@]}" --maxdepth $d -i path --spp "$refspp" --seed 3 -q \
    -o "$out/path_d$d.exr"
done
"$candela" render "${args[@]}" -i splat --progressive off --occlusion off -C 1 --direct none --gather "$gather" --photons "$photons" -C 0.6 -S 0.2 -R 0.4 \
  --spp 1 -o "$out/rs-fg.exr" >"$out/rs-fg.log"
"$candela" render "${args[@]}" -i pm --progressive off --visibility gather --knn 50 --direct none --gather "$gather" --photons "$photons" --spp 1 \
  -o "$out/pm-fg.exr" >"$out/pm-fg.log"
"$candela" render "${args[@]}" -i pm --progressive off --visibility gather --knn 50 --direct none --gather "$gather" --photons "$photons" --precompute 0 --spp 1 \
  -o "$out/pm-fg-knn.exr" >"$out/pm-fg-knn.log"
/usr/bin/python3 - "$out" <<'PY'
import re, sys
import numpy as np
import OpenImageIO as oiio
out = sys.argv[1]
load = lambda n: oiio.ImageBuf(f"{out}/{n}.exr").get_pixels(oiio.FLOAT)[:, :, :3].astype(np.float64).mean(axis=2)
ref = np.clip(load("path_d8") - load("path_d1"), 0, None)
print("| method | time (s) | split | MiB | relMSE | median relative error | mean ratio |")
print("|---|---|---|---|---|---|---|")
for m in ("rs-fg", "pm-fg", "pm-fg-knn"):
    log = open(f"{out}/{m}.log").read()
    secs = re.search(r"spp in ([0-9.]+) s", log).group(1)
    split = re.search(r"T_ray.*T_brdf [0-9.]+", log) or re.search(r"photon tracing [0-9.]+ s", log)
    mib = re.search(r"([0-9.]+) MiB", log)
    t = load(m)
    e = (t - ref) ** 2 / (ref ** 2 + 0.01 * ref.mean() ** 2)
    rel = np.abs(t - ref) / np.maximum(ref, 0.05 * ref.mean())
    print(f"| {m} | {secs} | {split.group(0) if split else ''} | {mib.group(1) if mib else ''} | {e.mean():.4g} | "
          f"{np.median(rel):.3f} | {t.sum() / ref.sum():.4f} |")
PY
