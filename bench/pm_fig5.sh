#!/usr/bin/env bash
# Keller & Wald 2000, Figure 5: direct light with many lights, with and without
# the photon map's L_con (lights whose primary photons lie within
# --lcon-radius of the shading point), at equal time, on the building floor
# with 149 ceiling panels (298 emitting triangles), direct light only
# (--maxdepth 1).
#
#  0. The scene is scenes/generated/floor_many_lights.obj translated by
#     (-17.5, 0, -2.5) (camera likewise), so that the camera's office is near
#     the origin. This worked around a shadow-ray bug that the results below
#     were measured with: before commit 975253e, candela's light-sampling
#     shadow rays (src/transport/light_select.c, src/integrators/path.c)
#     found the light itself from surfaces within about 2.4 m of a light when
#     |x| ~ 20 m (the desk tops went black in pm and half dark in path).
#     975253e fixed it, and the translation stays so that the runs remain
#     comparable. OUT/orig.md renders the untranslated scene against the same
#     reference as a regression check: it agrees since 975253e.
#  1. Reference (cached in OUT/refs): -i path --maxdepth 1, two halves of
#     REF_SPP/2 spp (seeds 1, 2); their mean is the reference, their
#     difference estimates its own noise.
#  2. bench/compare with bench/pm_fig5.cfg at BUDGETS (--clock effective,
#     --target auto; Sobol sampler, candela's default): OUT/main, and the
#     same methods with --sampler independent (plain Monte Carlo): OUT/indep.
#     OUT/*/summary.md adds |L_con|, the seconds per pass, trimmed relMSE,
#     mean ratio, relMSE relative to the first config and the slope of log
#     relMSE over log time (-1 for Monte Carlo convergence).
#  3. Sweeps at one budget SWEEP_BUDGET: shadow rays S (power and lcon),
#     --photons and --lcon-radius (lcon and lcon-biased): OUT/sweep/summary.md.
#  4. Figure 5 images at EQUAL_TIME seconds each: docs/pm-fig5-power.png
#     (a: without), docs/pm-fig5-lcon.png (b: unbiased with L_con),
#     docs/pm-fig5-lcon-biased.png (c: biased with L_con),
#     docs/pm-fig5-lcon-r025.png (b with a too small radius, 0.25 m:
#     overmodulation), docs/pm-fig5-ref.png and docs/pm-fig5-strip.png; the
#     harness plots as docs/pm-fig5-plot.png and docs/pm-fig5-plot-indep.png.
#
# usage: bench/pm_fig5.sh [OUT] [BUDGETS] [REF_SPP] [SWEEP_BUDGET] [EQUAL_TIME] [SEEDS]
#   defaults: out/pm_fig5 1,2,4,8,16 16384 4 8 1. About 8.5 minutes on an idle
#   2-core machine once the reference is cached, plus about 2 for the reference
#   (longer when the machine is shared).
#   PM_FIG5_INDEP_BUDGETS (default 1,2,4,8): budgets of the --sampler independent runs.
#   PM_FIG5_SKIP_SWEEP=1 skips step 3, PM_FIG5_SKIP_MAIN=1 step 2;
#   PM_FIG5_REUSE=1 keeps the harness results already in OUT/{main,indep,sweep}
#   (statistics, calibration, summaries, long runs and images are redone);
#   PM_FIG5_LONG_SPP (default 512; 0 skips) sets the fixed-spp convergence runs
#   of lcon and lcon-biased (LONG_SPP/4 and LONG_SPP spp: OUT/long.md).
set -eu
here=$(cd "$(dirname "$0")/.." && pwd)
out=${1:-$here/out/pm_fig5}
budgets=${2:-1,2,4,8,16}
refspp=${3:-16384}
sweep_budget=${4:-4}
equal=${5:-8}
seeds=${6:-1}
long_spp=${PM_FIG5_LONG_SPP:-512}
indep_budgets=${PM_FIG5_INDEP_BUDGETS:-1,2,4,8}
candela=$here/build/candela
py=/usr/bin/python3
res=160x120
docs=$here/docs
mkdir -p "$out/refs" "$out/scene" "$out/images"
out=$(cd "$out" && pwd)
orig=$here/scenes/generated/floor_many_lights.obj
scene=$out/scene/floor_many_lights_centered.obj
# the generated camera --lookat 15.3,1.7,0.3,19.5,0.8,3.3,0,1,0 --fov 60, translated
cam="--lookat -2.2,1.7,-2.2,2,0.8,0.8,0,1,0 --fov 60"
origcam=$(cat "${orig%.obj}.cam")

# ---------------------------------------------------------------- scene
if [ ! -f "$scene" ]; then
  cp "${orig%.obj}.mtl" "$out/scene/"
  "$py" - "$orig" "$scene" <<'EOF'
import sys
with open(sys.argv[1]) as f, open(sys.argv[2], 'w') as g:
    for line in f:
        if line.startswith('v '):
            x, y, z = map(float, line.split()[1:4])
            line = f'v {x - 17.5:.6g} {y:.6g} {z - 2.5:.6g}\n'
        g.write(line)
EOF
fi

# ---------------------------------------------------------------- reference
refs=$out/refs
for half in a b; do
  seed=1; [ $half = b ] && seed=2
  if [ ! -f "$refs/ref_$half.exr" ]; then
    echo "reference half $half: path --maxdepth 1, $((refspp / 2)) spp" >&2
    # shellcheck disable=SC2086
    "$candela" render "$scene" $cam --res $res -i path --maxdepth 1 --spp $((refspp / 2)) --seed $seed -q \
      -o "$refs/ref_$half.exr" -o "$refs/ref_$half.pfm" >&2
  fi
done
"$py" - "$refs" <<'EOF'
import sys
import numpy as np
def read(p):
    with open(p, 'rb') as f:
        f.readline(); w, h = map(int, f.readline().split()); s = float(f.readline())
        return np.frombuffer(f.read(), dtype='<f4' if s < 0 else '>f4').reshape(h, w, 3)[::-1].astype(np.float64)
d = sys.argv[1]
a, b = read(f'{d}/ref_a.pfm'), read(f'{d}/ref_b.pfm')
ref = (a + b) / 2
h, w, _ = ref.shape
with open(f'{d}/ref.pfm', 'wb') as f:
    f.write(b'PF\n%d %d\n-1.0\n' % (w, h))
    f.write(np.ascontiguousarray(ref[::-1], dtype='<f4').tobytes())
noise = ((a - b) ** 2 / (ref ** 2 + 0.01)).mean() / 4
open(f'{d}/noise.txt', 'w').write(f'{noise:.3e}\n')
print(f'reference noise (relMSE of the reference itself, from its halves): {noise:.3e}', file=sys.stderr)
EOF
# the harness reads EXR or PFM; the mean of the halves is written as PFM
ref=$refs/ref.pfm
noise=$(cat "$refs/noise.txt")
echo "reference noise: $noise" >&2

cfg=$here/bench/pm_fig5.cfg
render_args="$cam --maxdepth 1"
P="-i pm --gather 0"

# ---------------------------------------------------------------- |L_con| and photon cost per config
# an 8 spp render: mean |L_con| ('-' without L_con), photon tracing seconds per pass and all seconds per pass
: > "$out/lcon_sizes.txt"
add_sizes() { # NAME=ARGS lines on stdin
  while IFS='=' read -r name args; do
    # shellcheck disable=SC2086
    "$candela" render "$scene" $render_args --res $res --spp 8 $args -o "$out/images/stats.pfm" < /dev/null |
      "$py" -c '
import re, sys
s = sys.stdin.read()
l = re.search(r"\|L_con\| ([\d.]+)", s)
t = re.search(r"photon tracing ([\d.]+) s over (\d+) passes", s)
m = re.search(r"(\d+) spp in ([\d.]+) s", s)
print(sys.argv[1], l.group(1) if l else "-", f"{float(t.group(1)) / int(t.group(2)):.4f}" if t else "0",
      f"{float(m.group(2)) / int(m.group(1)):.4f}")' "$name" >> "$out/lcon_sizes.txt"
  done
}

# single-thread CPU seconds per pass (a 1 s render with --threads 1 under /usr/bin/time, scene
# load excluded): a time axis that other load hardly disturbs (no OpenMP spin-waiting in it)
: > "$out/costs.txt"
calibrate() { # NAME=ARGS lines on stdin
  while IFS='=' read -r name args; do
    # shellcheck disable=SC2086
    /usr/bin/time -f 'CPU %U %S' -o "$out/images/cal.time" "$candela" render "$scene" $render_args --res $res \
      --threads 1 --time 1 -q $args -o "$out/images/cal.pfm" < /dev/null > "$out/images/cal.log"
    "$py" -c '
import re, sys
s = open(sys.argv[2]).read()
c = re.search(r"CPU ([\d.]+) ([\d.]+)", open(sys.argv[3]).read())
m = re.search(r"(\d+) spp in ([\d.]+) s \(load ([\d.]+) s\)", s)
print(sys.argv[1], f"{(float(c.group(1)) + float(c.group(2)) - float(m.group(3))) / int(m.group(1)):.5f}")' \
      "$name" "$out/images/cal.log" "$out/images/cal.time" >> "$out/costs.txt"
  done
}

# table of a harness run: relmse, trimmed, mean ratio, spp, seconds per pass, |L_con|
summarize() { # RESULTS.CSV NOISE SIZES
  "$py" - "$@" <<'EOF'
import csv, math, sys
rows = list(csv.DictReader(open(sys.argv[1])))
noise = float(sys.argv[2])
sizes = {l.split()[0]: l.split()[1:] for l in open(sys.argv[3]) if l.strip()}
costs = {l.split()[0]: float(l.split()[1]) for l in open(sys.argv[4]) if l.strip()} if len(sys.argv) > 4 else {}
cfgs = list(dict.fromkeys(r['config'] for r in rows))
budgets = sorted({float(r['budget']) for r in rows})
def mean(rs, k):
    return sum(float(r[k]) for r in rs) / len(rs)
print('| config | mean L_con | photon s / pass (8 spp test) | budget s | effective s | spp | s per pass (eff.) | '
      'relMSE | relMSE trimmed | mean ratio | relMSE / relMSE of ' + cfgs[0] + ' | CPU model s | '
      'relMSE x CPU model s |')
print('|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|')
base = {}
for c in cfgs:
    for b in budgets:
        rs = [r for r in rows if r['config'] == c and float(r['budget']) == b]
        e = mean(rs, 'relmse')
        if c == cfgs[0]:
            base[b] = e
        spp = mean(rs, 'spp')
        sz = sizes.get(c, ['-', '-', '-'])
        print(f"| {c} | {sz[0]} | {sz[1]} | {b:g} | {mean(rs, 'effective_seconds'):.1f} | {spp:.0f} | "
              f"{mean(rs, 'effective_seconds') / spp:.4f} | {e:.2e} | {mean(rs, 'relmse_trimmed'):.2e} | "
              f"{mean(rs, 'mean_ratio'):.4f} | {e / base[b]:.2f} | "
              + (f"{spp * costs[c] / 2:.2f} | {e * spp * costs[c] / 2:.2e} |" if c in costs else "- | - |"))
if len(budgets) > 1:
    print()
    print('| config | slope of log relMSE over log effective seconds | the same after subtracting the '
          f'reference noise ({noise:.1e}) |')
    print('|---|---:|---:|')
    for c in cfgs:
        pts = []
        for b in budgets:
            rs = [r for r in rows if r['config'] == c and float(r['budget']) == b]
            pts.append((mean(rs, 'effective_seconds'), mean(rs, 'relmse')))
        def slope(ys):
            xs = [math.log(p[0]) for p in pts]
            ys = [math.log(y) for y in ys]
            mx, my = sum(xs) / len(xs), sum(ys) / len(ys)
            return sum((x - mx) * (y - my) for x, y in zip(xs, ys)) / sum((x - mx) ** 2 for x in xs)
        corr = [p[1] - noise for p in pts]
        s2 = f'{slope(corr):.2f}' if all(v > 0 for v in corr) else '-'
        print(f'| {c} | {slope([p[1] for p in pts]):.2f} | {s2} |')
# appended to summarize(): a load-independent time axis
quiet_obs = {}
for c in cfgs:
    rs = [r for r in rows if r['config'] == c and float(r['cpu_share']) >= 0.95 and int(r['spp']) > 0]
    if rs:
        per = sorted(float(r['seconds']) / int(r['spp']) for r in rs)
        quiet_obs[c] = per[len(per) // 2]
models = [('Quiet-machine cost model: seconds per pass = median over the renders that got >= 95 % of their '
           'CPUs (configs without such renders are left out); time = spp x that (the error at a given spp does '
           'not depend on the load: common random numbers).', quiet_obs),
          ('CPU cost model: seconds per pass = single-thread CPU seconds per pass (a 1 s --threads 1 '
           'calibration render) / 2 threads; time = spp x that.', {c: costs[c] / 2 for c in cfgs if c in costs})]
for title, quiet in models:
    if not quiet:
        continue
    print()
    print(title)
    print()
    print('| config | s per pass | ' + ' | '.join(f'{b:g} s budget: model s, relMSE' for b in budgets) + ' |')
    print('|---|---:|' + '---|' * len(budgets))
    for c in cfgs:
        if c not in quiet:
            print(f'| {c} | - |' + ' - |' * len(budgets))
            continue
        cells = []
        for b in budgets:
            rs = [r for r in rows if r['config'] == c and float(r['budget']) == b]
            cells.append(f"{mean(rs, 'spp') * quiet[c]:.1f}, {mean(rs, 'relmse'):.2e}")
        print(f'| {c} | {quiet[c]:.4f} | ' + ' | '.join(cells) + ' |')
    if len(budgets) > 1 and cfgs[0] in quiet:
        # relMSE of each config at the model times of the first config's points, log-log interpolated
        def curve(c):
            pts = []
            for b in budgets:
                rs = [r for r in rows if r['config'] == c and float(r['budget']) == b]
                pts.append((mean(rs, 'spp') * quiet[c], mean(rs, 'relmse')))
            return sorted(pts)
        def at(pts, t):
            if pts[-1][0] < t <= pts[-1][0] * 1.05:  # a hair past the last point: its error (pessimistic)
                return pts[-1][1]
            for (t0, e0), (t1, e1) in zip(pts, pts[1:]):
                if t0 <= t <= t1 and t1 > t0:
                    w = (math.log(t) - math.log(t0)) / (math.log(t1) - math.log(t0))
                    return math.exp((1 - w) * math.log(e0) + w * math.log(e1))
            return None
        ts = sorted({round(p[0], 2) for c in cfgs if c in quiet for p in curve(c)})
        grid = [2 ** k for k in range(-2, 8) if any(curve(c)[0][0] <= 2 ** k <= curve(c)[-1][0] * 1.05 for c in quiet)]
        print()
        print('relMSE at equal model time (log-log interpolation between measured points; - outside the measured range):')
        print()
        print('| config | ' + ' | '.join(f'{t:g} s' for t in grid) + ' |')
        print('|---|' + '---|' * len(grid))
        for c in cfgs:
            if c not in quiet:
                continue
            vals = [at(curve(c), t) for t in grid]
            print(f'| {c} | ' + ' | '.join(f'{v:.2e}' if v else '-' for v in vals) + ' |')
        b0 = [at(curve(cfgs[0]), t) for t in grid]
        for c in cfgs[1:]:
            if c not in quiet:
                continue
            vals = [at(curve(c), t) for t in grid]
            print(f'| {cfgs[0]} / {c} | ' + ' | '.join(f'{x / v:.2f}' if x and v else '-' for x, v in zip(b0, vals)) + ' |')
EOF
}

# ---------------------------------------------------------------- main comparison (Sobol sampler, the default)
if [ -z "${PM_FIG5_SKIP_MAIN:-}" ]; then
  grep -v '^ *#' "$cfg" | grep '=' > "$out/main_configs.txt"
  add_sizes < "$out/main_configs.txt"
  calibrate < "$out/main_configs.txt"
  if [ -z "${PM_FIG5_REUSE:-}" ] || [ ! -f "$out/main/results.csv" ]; then
    "$here/bench/compare" --scene "$scene" --ref "$ref" --res $res --render-args "$render_args" \
      --configs "$cfg" --times "$budgets" --seeds "$seeds" --target auto --clock effective --out "$out/main" > /dev/null
  fi
  summarize "$out/main/results.csv" "$noise" "$out/lcon_sizes.txt" "$out/costs.txt" > "$out/main/summary.md"
  # the same with independent random numbers (plain Monte Carlo, the setting of the paper)
  mc=(
    "power-indep=$P --direct power --shadow-rays 16 --photons 1000 --sampler independent"
    "lcon-indep=$P --direct lcon --shadow-rays 16 --photons 20000 --sampler independent"
    "lcon-biased-indep=$P --direct lcon-biased --shadow-rays 16 --photons 20000 --sampler independent"
  )
  for c in "${mc[@]}"; do echo "$c"; done > "$out/indep_configs.txt"
  add_sizes < "$out/indep_configs.txt"
  calibrate < "$out/indep_configs.txt"
  args=()
  for c in "${mc[@]}"; do args+=(--config "$c"); done
  if [ -z "${PM_FIG5_REUSE:-}" ] || [ ! -f "$out/indep/results.csv" ]; then
    "$here/bench/compare" --scene "$scene" --ref "$ref" --res $res --render-args "$render_args" \
      "${args[@]}" --times "$indep_budgets" --seeds "$seeds" --target auto --clock effective --out "$out/indep" > /dev/null
  fi
  summarize "$out/indep/results.csv" "$noise" "$out/lcon_sizes.txt" "$out/costs.txt" > "$out/indep/summary.md"
fi

# ---------------------------------------------------------------- sweeps (one budget: see docs/pm-fig5.md on
# bench/compare's extrapolation overflow with several budgets and an error that hardly falls)
if [ -z "${PM_FIG5_SKIP_SWEEP:-}" ]; then
  sweep=(
    "power-S1=$P --direct power --shadow-rays 1 --photons 1000"
    "power-S4=$P --direct power --shadow-rays 4 --photons 1000"
    "power-S16=$P --direct power --shadow-rays 16 --photons 1000"
    "lcon-S4=$P --direct lcon --shadow-rays 4 --photons 20000"
    "lcon-S16=$P --direct lcon --shadow-rays 16 --photons 20000"
    "lcon-S32=$P --direct lcon --shadow-rays 32 --photons 20000"
    "lcon-S64=$P --direct lcon --shadow-rays 64 --photons 20000"
    "lcon-N5k=$P --direct lcon --shadow-rays 16 --photons 5000"
    "lcon-N10k=$P --direct lcon --shadow-rays 16 --photons 10000"
    "lcon-N40k=$P --direct lcon --shadow-rays 16 --photons 40000"
    "lcon-N80k=$P --direct lcon --shadow-rays 16 --photons 80000"
    "lcon-R0.25=$P --direct lcon --shadow-rays 16 --photons 20000 --lcon-radius 0.25"
    "lcon-R0.5=$P --direct lcon --shadow-rays 16 --photons 20000 --lcon-radius 0.5"
    "lcon-R1=$P --direct lcon --shadow-rays 16 --photons 20000 --lcon-radius 1"
    "lcon-R4=$P --direct lcon --shadow-rays 16 --photons 20000 --lcon-radius 4"
    "lcon-biased-R0.5=$P --direct lcon-biased --shadow-rays 16 --photons 20000 --lcon-radius 0.5"
    "lcon-biased-R1=$P --direct lcon-biased --shadow-rays 16 --photons 20000 --lcon-radius 1"
    "lcon-biased-R2.24=$P --direct lcon-biased --shadow-rays 16 --photons 20000"
  )
  for c in "${sweep[@]}"; do echo "$c"; done > "$out/sweep_configs.txt"
  add_sizes < "$out/sweep_configs.txt"
  calibrate < "$out/sweep_configs.txt"
  args=()
  for c in "${sweep[@]}"; do args+=(--config "$c"); done
  if [ -z "${PM_FIG5_REUSE:-}" ] || [ ! -f "$out/sweep/results.csv" ]; then
    "$here/bench/compare" --scene "$scene" --ref "$ref" --res $res --render-args "$render_args" \
      "${args[@]}" --times "$sweep_budget" --seeds "$seeds" --target auto --clock effective --out "$out/sweep" > /dev/null
  fi
  summarize "$out/sweep/results.csv" "$noise" "$out/lcon_sizes.txt" "$out/costs.txt" > "$out/sweep/summary.md"
fi

# ---------------------------------------------------------------- convergence at LONG_SPP (load-independent)
if [ "$long_spp" -gt 0 ]; then
  longmd=$out/long.md
  {
    echo "lcon and lcon-biased (S = 16, 20000 photons, radius 2.24 m, Sobol) at fixed spp against the reference:"
    echo
    echo "| config | spp | seconds | relMSE | relMSE trimmed | mean ratio |"
    echo "|---|---:|---:|---:|---:|---:|"
  } > "$longmd"
  for c in "lcon=$P --direct lcon --shadow-rays 16 --photons 20000" \
           "lcon-biased=$P --direct lcon-biased --shadow-rays 16 --photons 20000"; do
    n=${c%%=*}
    for spp in $((long_spp / 4)) "$long_spp"; do
      # shellcheck disable=SC2086
      log=$("$candela" render "$scene" $render_args --res $res --spp "$spp" -q ${c#*=} -o "$out/images/long_$n.pfm")
      d=$("$candela" diff "$out/images/long_$n.pfm" "$ref")
      echo "| $n | $spp | $(echo "$log" | sed -n 's/.* spp in \([0-9.]*\) s.*/\1/p') |" \
        "$(echo "$d" | sed -n 's/.*relmse \([^ ]*\) .*/\1/p') | $(echo "$d" | sed -n 's/.*relmse_trimmed \([^ ]*\) .*/\1/p') |" \
        "$(echo "$d" | sed -n 's/.*mean_ratio \([^ ]*\) .*/\1/p') |" >> "$longmd"
    done
  done
fi

# ---------------------------------------------------------------- the untranslated scene (shadow-ray bug)
origmd=$out/orig.md
{
  echo "Untranslated scenes/generated/floor_many_lights.obj against the reference of the translated copy"
  echo "(the same image up to rounding), $equal s each:"
  echo
  echo '```'
} > "$origmd"
for c in "path=-i path" "lcon=$P --direct lcon --shadow-rays 16 --photons 20000"; do
  # shellcheck disable=SC2086
  "$candela" render "$orig" $origcam --maxdepth 1 --res $res --time "$equal" -q ${c#*=} \
    -o "$out/images/orig_${c%%=*}.pfm" > /dev/null
  echo "${c%%=*} (untranslated): $("$candela" diff "$out/images/orig_${c%%=*}.pfm" "$ref")" >> "$origmd"
done
# shellcheck disable=SC2086
"$candela" render "$scene" $render_args --res $res --time "$equal" -q $P --direct lcon --shadow-rays 16 \
  --photons 20000 -o "$out/images/centered_lcon.pfm" > /dev/null
echo "lcon (translated):   $("$candela" diff "$out/images/centered_lcon.pfm" "$ref")" >> "$origmd"
echo '```' >> "$origmd"

# ---------------------------------------------------------------- Figure 5 images at equal time
for c in "power=$P --direct power --shadow-rays 4 --photons 1000" \
         "lcon=$P --direct lcon --shadow-rays 16 --photons 20000" \
         "lcon-biased=$P --direct lcon-biased --shadow-rays 16 --photons 20000" \
         "lcon-r025=$P --direct lcon --shadow-rays 16 --photons 20000 --lcon-radius 0.25"; do
  n=${c%%=*}
  # shellcheck disable=SC2086
  /usr/bin/time -f 'CPU %U %S' -a -o "$out/images/$n.log" "$candela" render "$scene" $render_args --res $res \
    --time "$equal" ${c#*=} -o "$out/images/$n.pfm" > "$out/images/$n.log"
  "$candela" diff "$out/images/$n.pfm" "$ref" >> "$out/images/$n.log"
done
"$py" - "$out" "$docs" "$equal" <<'EOF'
import re, sys
import numpy as np
import matplotlib
matplotlib.use('Agg')
import matplotlib.pyplot as plt
out, docs, equal = sys.argv[1:4]
def read(p):
    with open(p, 'rb') as f:
        f.readline(); w, h = map(int, f.readline().split()); s = float(f.readline())
        return np.frombuffer(f.read(), dtype='<f4' if s < 0 else '>f4').reshape(h, w, 3)[::-1].astype(np.float64)
def srgb(a):
    a = np.clip(a, 0, 1)
    return np.where(a <= 0.0031308, 12.92 * a, 1.055 * a ** (1 / 2.4) - 0.055)
up = lambda a: np.repeat(np.repeat(a, 2, axis=0), 2, axis=1)
panels = [('power', 'a) without L_con (power, S = 4)'), ('lcon', 'b) unbiased with L_con (S = 16 + 1)'),
          ('lcon-biased', 'c) biased with L_con (S = 16)'), ('lcon-r025', "b') unbiased, radius 0.25 m"),
          ('ref', 'reference (path)')]
fig, ax = plt.subplots(1, len(panels), figsize=(3.4 * len(panels), 3.0), dpi=110)
for a, (n, title) in zip(ax, panels):
    if n == 'ref':
        img = read(f'{out}/refs/ref.pfm')
        sub = 'path --maxdepth 1, both halves'
    else:
        img = read(f'{out}/images/{n}.pfm')
        log = open(f'{out}/images/{n}.log').read()
        m = re.search(r'(\d+) spp in ([\d.]+) s', log)
        c = re.search(r'CPU ([\d.]+) ([\d.]+)', log)
        e = re.search(r'relmse ([\d.e+-]+)', log)
        r = re.search(r'mean_ratio ([\d.e+-]+)', log)
        sub = (f'{m.group(1)} spp in {float(m.group(2)):.1f} s ({float(c.group(1)) + float(c.group(2)):.1f} cpu s)\n'
               f'relMSE {float(e.group(1)):.4f}, mean ratio {float(r.group(1)):.3f}')
    plt.imsave(f'{docs}/pm-fig5-{n}.png', up(srgb(img)))
    a.imshow(srgb(img), interpolation='nearest')
    a.set_title(f'{title}\n{sub}', fontsize=7)
    a.axis('off')
fig.suptitle(f'direct light on the many-lights floor, {equal} s wall clock each (Sobol sampler)', fontsize=8)
fig.tight_layout(rect=(0, 0, 1, 0.92))
fig.savefig(f'{docs}/pm-fig5-strip.png')
EOF
cp "$out/main/plot.png" "$docs/pm-fig5-plot.png" 2>/dev/null || true
cp "$out/indep/plot.png" "$docs/pm-fig5-plot-indep.png" 2>/dev/null || true

# ---------------------------------------------------------------- summary
echo "## reference noise: $noise"
for part in main indep; do
  if [ -f "$out/$part/table.md" ]; then
    echo "## $part"; cat "$out/$part/table.md"; echo; cat "$out/$part/summary.md"; echo
  fi
done
[ -f "$out/sweep/summary.md" ] && { echo "## sweep at $sweep_budget s"; cat "$out/sweep/summary.md"; echo; }
[ -f "$out/long.md" ] && { echo "## long runs"; cat "$out/long.md"; echo; }
echo "## untranslated scene"; cat "$origmd"
