#!/usr/bin/env bash
# Herzog et al. 2007, Figure 7.1 and Table 7.1: rendering time (one pass)
# against the number of photon rays at 500x500 and against the resolution
# at 500000 photon rays, for splat's three radiance maps and the photon map
# seen directly (pm --gather 0 --direct photons, K nearest), with the
# memory each reports; then Table 7.1's time split for the Cornell box.
# Scene: the McGuire Cornell box (the report's "classic Cornell Box"),
# fractions 0.3/0.7/0, C = 1, S = 0.4, R = 0.2 as in Table 7.1.
# usage: bench/splat_fig71.sh [OUT] [PHOTONS] [RESOLUTIONS] [K]
#   defaults: out/splat_fig71 5000,20000,80000,320000,1280000 100,250,500,750,1000 800
set -eu
here=$(cd "$(dirname "$0")/.." && pwd)
out=${1:-$here/out/splat_fig71}
photons=${2:-5000,20000,80000,320000,1280000}
resolutions=${3:-100,250,500,750,1000}
k=${4:-800}
candela=${CANDELA:-$here/build/candela}
scene="$here/../shared/scenes/cornell-box-mcguire/CornellBox-Original.obj"
cam="--lookat 0,1,3.9,0,1,0,0,1,0 --fov 39.3077"
mkdir -p "$out"
csv="$out/fig71.csv"
echo "sweep,method,photons,res,seconds,mib,t_ray,t_light,t_build,t_solve,t_brdf" >"$csv"
run() { # sweep method photons res
  local m=$1 p=$2 r=$3 args log
  case $m in
    pm) args="-i pm --progressive off --visibility gather --knn 50 --knn $k --gather 0 --direct photons" ;;
    *) args="-i splat --progressive off --occlusion off -C 1 --mode $m --fractions 0.3,0.7,0 -C 1 -S 0.4 -R 0.2" ;;
  esac
  log="$out/$m-$p-$r.log"
  # shellcheck disable=SC2086 # options
  "$candela" render "$scene" $cam --res "${r}x$r" $args --photons "$p" --spp 1 -o "$out/$m-$p-$r.exr" >"$log" 2>&1
  /usr/bin/python3 - "$log" "$sweep,$m,$p,$r" >>"$csv" <<'EOF'
import re, sys
t = open(sys.argv[1]).read()
secs = re.search(r"spp in ([0-9.]+) s", t).group(1)
mib = re.search(r"(?:memory|maps) ([0-9.]+) MiB", t)
split = re.search(r"T_ray ([0-9.]+), T_light ([0-9.]+), T_build ([0-9.]+), T_solve ([0-9.]+), (?:T_cache [0-9.]+, )?T_brdf ([0-9.]+)", t)
parts = list(split.groups()) if split else [""] * 5
print(",".join([sys.argv[2], secs, mib.group(1) if mib else ""] + parts))
EOF
}
for sweep in photons res; do
  if [ $sweep = photons ]; then list=$photons; else list=$resolutions; fi
  for v in ${list//,/ }; do
    for m in direct histogram sh pm; do
      if [ $sweep = photons ]; then run "$m" "$v" 500; else run "$m" 500000 "$v"; fi
      tail -1 "$csv"
    done
  done
done
/usr/bin/python3 - "$csv" "$out/fig71.png" <<'EOF'
import csv, sys
import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt
rows = list(csv.DictReader(open(sys.argv[1])))
fig, ax = plt.subplots(1, 3, figsize=(15, 4.5))
names = {"direct": "splat direct", "histogram": "splat histogram", "sh": "splat SH", "pm": "pm k-NN"}
for m in names:
    ph = [r for r in rows if r["sweep"] == "photons" and r["method"] == m]
    rs = [r for r in rows if r["sweep"] == "res" and r["method"] == m]
    ax[0].plot([int(r["photons"]) for r in ph], [float(r["seconds"]) for r in ph], "o-", label=names[m])
    ax[1].plot([int(r["res"]) for r in rs], [float(r["seconds"]) for r in rs], "o-", label=names[m])
    ax[2].plot([int(r["res"]) for r in rs], [float(r["mib"] or 0) for r in rs], "o-", label=names[m])
ax[0].set_xscale("log"); ax[0].set_yscale("log")
ax[0].set_xlabel("photon rays (500x500)"); ax[0].set_ylabel("seconds, 2 cores")
ax[1].set_xlabel("image side (500000 photon rays)"); ax[1].set_ylabel("seconds, 2 cores")
ax[2].set_xlabel("image side (500000 photon rays)"); ax[2].set_ylabel("MiB reported")
for a in ax:
    a.grid(True, alpha=0.3); a.legend()
fig.suptitle("Figure 7.1 (Herzog et al. 2007): Cornell box, one pass")
fig.tight_layout()
fig.savefig(sys.argv[2], dpi=90)
EOF
echo "wrote $csv and $out/fig71.png"
