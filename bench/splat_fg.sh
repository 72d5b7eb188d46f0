#!/usr/bin/env bash
# Herzog et al. 2007, Table 7.1's final-gathering rows (RS-FG against PM-FG,
# the report: 3825 s against 5108 s with 600 gather rays): photon ray
# splatting to the gather rays' hits (splat --gather N) against the photon map
# read at the gather rays' hits (pm --gather N, with its precomputed irradiance
# and without it, the classic k-NN estimate at every hit), the same gather rays
# and photons, on a generated conference room of about 250k triangles (diffuse,
# lit indirectly: scenes/generate.py conference_fg), one pass each; time split
# and relMSE against a converged path render.
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
ref=$out/path_$refspp.exr
[ -f "$ref" ] || "$candela" render "${args[@]}" -i path --spp "$refspp" --seed 3 -q -o "$ref"
"$candela" render "${args[@]}" -i splat --gather "$gather" --photons "$photons" -C 0.6 -S 0.2 -R 0.4 --spp 1 \
  -o "$out/rs-fg.exr" >"$out/rs-fg.log"
"$candela" render "${args[@]}" -i pm --gather "$gather" --photons "$photons" --spp 1 -o "$out/pm-fg.exr" \
  >"$out/pm-fg.log"
"$candela" render "${args[@]}" -i pm --gather "$gather" --photons "$photons" --precompute 0 --spp 1 \
  -o "$out/pm-fg-knn.exr" >"$out/pm-fg-knn.log"
echo "| method | time (s) | split | MiB | relMSE | mean ratio |"
echo "|---|---|---|---|---|---|"
for m in rs-fg pm-fg pm-fg-knn; do
  log=$out/$m.log
  secs=$(sed -n 's/.* spp in \([0-9.]*\) s.*/\1/p' "$log")
  split=$(grep -o 'T_ray.*T_brdf [0-9.]*' "$log" || grep -o 'photon tracing [0-9.]* s[^;]*' "$log" || true)
  mib=$(grep -o '[0-9.]* MiB' "$log" | head -1)
  d=$("$candela" diff "$out/$m.exr" "$ref")
  key() { echo "$d" | tr -s ' ' '\n' | awk -v k="$1" 'p {print; exit} $0 == k {p = 1}'; }
  echo "| $m | $secs | $split | $mib | $(key relmse) | $(key mean_ratio) |"
done
