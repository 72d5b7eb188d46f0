#!/usr/bin/env bash
# Reproduces Keller & Wald 2000 (importance sampling techniques for the photon
# map), Figures 1 and 2, on scenes/generated/rooms10x10 (10 x 10 rooms, one
# light each, the camera in room (4, 4)):
#  1. `candela photons` pictures of pass 0's photons seen from above: the
#     standard map, the importons and the importance-driven map at equal stored
#     photons (PICS counts; the report had 6e5 and 6e6), and the camera's view
#     of one map of each (one pass, --gather 0: the map visualised directly);
#  2. the error of the camera's view (relMSE against a path-traced reference)
#     for a sweep of --photons with and without --importance, with the global
#     map visualised directly (--gather 0) and with final gathering
#     (--gather 16); from it the relMSE ratio at equal stored photons and the
#     memory ratio at equal error (docs/pm-fig12.md, docs/pm-fig2-error.png);
#  3. a one-pass probe (two seeds) that splits the error of a single map into
#     its systematic part and its noise.
#
# The error runs use a copy of the scene translated by (-18.9, 0, -18.9) so that
# the camera's room sits at the origin: at the original coordinates (|x|, |z|
# about 20 m) the shadow rays of light sampling end inside the light (see
# docs/pm-fig12.md), which blackens the direct light on the table tops in pm
# and removes the light-sampling part of it in path. The geometry is otherwise
# the same; the photon pictures use the original file.
#
# usage: bench/pm_fig12.sh [OUT] [STD_COUNTS] [IMP_COUNTS] [PASSES] [REF_SPP]
#   STD_COUNTS, IMP_COUNTS  comma-separated --photons values
#   PASSES                  --spp of the pm runs (each pass traces fresh photons)
#   REF_SPP                 spp of the reference (two halves, seeds 1 and 2;
#                           cached in OUT/ref, about 4 minutes on 2 cores)
# environment: PICS (picture counts, default 100000,1000000; "" for none),
#   GATHERS (default "0 16"), IMP_ARGS (extra options of the importance runs,
#   e.g. "--importance-eps 0.001"), PM_ARGS (extra options of every pm run,
#   e.g. "--knn 400"), PROBE (one-pass probe counts, default 25000,100000),
#   DOCS=0 to leave docs/ alone (the default set only writes docs/ when
#   IMP_ARGS and PM_ARGS are empty).
# A run whose .diff exists in OUT/runs (a picture whose .txt exists in OUT/pics)
# is not repeated.
set -eu
here=$(cd "$(dirname "$0")/.." && pwd)
out=${1:-$here/out/pm_fig12}
stdn=${2:-25000,50000,100000,200000,400000,800000,1600000,3200000,6400000}
impn=${3:-25000,50000,100000,200000}
passes=${4:-4}
refspp=${5:-8192}
pics=${PICS-100000,1000000}
gathers=${GATHERS:-0 16}
impargs=${IMP_ARGS:-}
pmargs=${PM_ARGS:-}
probe=${PROBE-25000,100000}
docs=${DOCS:-1}
[ -z "$impargs$pmargs" ] || docs=0
slug() { echo "$1" | tr -c 'A-Za-z0-9.\n' '_' | sed 's/__*/_/g; s/_$//'; }
stag=$(slug "std$pmargs")
itag=$(slug "imp$pmargs$impargs")
candela=$here/build/candela
py=/usr/bin/python3 # Debian's, with numpy and matplotlib
gen=$here/scenes/generated
res=160x120
depth=16
# direct light: 32 shadow rays spread over the lights of nearby primary photons
# (L_con), one to the rest: unbiased and nearly noise-free here, where 99 of the
# 100 lights are occluded (--direct power with one ray leaves relMSE ~18 per pass)
direct="--direct lcon --shadow-rays 32 --knn 100 --precompute 4" # the defaults of the first run spelled out
mkdir -p "$out/pics" "$out/ref" "$out/runs" "$out/scene"
t_start=$(date +%s)

# the scene copy with the camera's room at the origin
scene=$out/scene/rooms10x10_c.obj
if [ ! -f "$scene" ]; then
  cp "$gen/rooms10x10.mtl" "$out/scene/"
  "$py" - "$gen/rooms10x10.obj" "$scene" <<'EOF'
import sys
with open(sys.argv[1]) as f, open(sys.argv[2], 'w') as o:
    for line in f:
        if line.startswith('v '):
            x, y, z = map(float, line.split()[1:4])
            line = 'v %.6g %.6g %.6g\n' % (x - 18.9, y, z - 18.9)
        o.write(line)
EOF
fi
cam="--lookat -1.7,1.6,-1.7,1.3,1.1,1.4,0,1,0 --fov 60" # rooms10x10.cam moved likewise

# pm run: name, pm options...; writes OUT/runs/NAME.{pfm,png,log,diff}
pm() {
  local b=$out/runs/$1
  shift
  [ -f "$b.diff" ] && return 0
  # shellcheck disable=SC2086
  "$candela" render "$scene" $cam --res $res --maxdepth $depth -i pm --progressive off --visibility gather --knn 50 $direct $pmargs "$@" \
    -o "$b.pfm" -o "$b.png" > "$b.log" 2>&1
  "$candela" diff "$b.pfm" "$ref" > "$b.diff"
}

# 1. reference: path tracing in two halves (their difference gives its noise)
half=$((refspp / 2))
ref=$out/ref/c_${res}_$refspp.pfm
for seed in 1 2; do
  f=$out/ref/c_${res}_${half}_s$seed.pfm
  # shellcheck disable=SC2086
  [ -f "$f" ] || "$candela" render "$scene" $cam --res $res --spp $half --maxdepth $depth -i path --seed $seed -q -o "$f" >&2
done
"$py" - "$out/ref/c_${res}_${half}_s1.pfm" "$out/ref/c_${res}_${half}_s2.pfm" "$ref" <<'EOF'
import sys, numpy as np
def read(p):
    with open(p, 'rb') as f:
        f.readline(); w, h = map(int, f.readline().split()); s = float(f.readline())
        return np.fromfile(f, dtype='<f4' if s < 0 else '>f4').reshape(h, w, 3).astype(np.float64)
a, b = read(sys.argv[1]), read(sys.argv[2])
h, w, _ = a.shape
with open(sys.argv[3], 'wb') as f:
    f.write(b'PF\n%d %d\n-1.0\n' % (w, h)); ((a + b) / 2).astype('<f4').tofile(f)
EOF
"$candela" diff "$out/ref/c_${res}_${half}_s1.pfm" "$out/ref/c_${res}_${half}_s2.pfm" > "$out/ref/c_${res}_$refspp.halves.txt"

# 2. photon pictures (original scene and camera, the resolution of the runs:
#    the importons are traced through the image, so it sets f) and one-pass
#    views of the camera with the map visualised directly
ocam=$(cat "$gen/rooms10x10.cam")
for n in ${pics//,/ }; do
  for m in std imp; do
    name=${stag}_$n extra=""
    [ $m = imp ] && name=${itag}_$n && extra="--importance $impargs"
    if [ ! -f "$out/pics/$name.txt" ]; then
      t0=$(date +%s.%N)
      # shellcheck disable=SC2086
      line=$("$candela" photons "$gen/rooms10x10.obj" $ocam --res $res --maxdepth $depth --photons "$n" $pmargs $extra \
        -o "$out/pics/$name.png")
      t1=$(date +%s.%N)
      printf '%s %.2f s: %s\n' "$name" "$(echo "$t1 - $t0" | bc)" "$(echo "$line" | tr '\n' ' ')" > "$out/pics/$name.txt"
    fi
    # shellcheck disable=SC2086
    pm "view_$name" --gather 0 --photons "$n" --spp 1 $extra
  done
done

# 3. the sweeps
for g in $gathers; do
  for n in ${stdn//,/ }; do pm "g${g}_p${passes}_${stag}_$n" --gather "$g" --photons "$n" --spp "$passes"; done
  # shellcheck disable=SC2086
  for n in ${impn//,/ }; do pm "g${g}_p${passes}_${itag}_$n" --gather "$g" --photons "$n" --spp "$passes" --importance $impargs; done
done
# 4. one pass, seeds 1 and 2: error of a single map and its noise
for n in ${probe//,/ }; do
  for seed in 1 2; do
    pm "probe_${stag}_${n}_s$seed" --gather 0 --photons "$n" --spp 1 --seed $seed
    # shellcheck disable=SC2086
    pm "probe_${itag}_${n}_s$seed" --gather 0 --photons "$n" --spp 1 --seed $seed --importance $impargs
  done
done
t_end=$(date +%s)

# 5. tables, ratios and the plot
docsdir=$here/docs
[ "$docs" = 1 ] || docsdir=$out
"$py" - "$out" "$passes" "$stag" "$itag" "$refspp" "$res" "$gathers" "$stdn" "$impn" "$pics" "$probe" \
  "$docsdir" "$((t_end - t_start))" "$impargs" "$pmargs" <<'EOF'
import sys, re, os, math
import numpy as np
import matplotlib
matplotlib.use('Agg')
import matplotlib.pyplot as plt
out, P, stag, itag, refspp, res, gathers, stdn, impn, pics, probe, docs, secs, impargs, pmargs = sys.argv[1:]
gathers = gathers.split()
lst = lambda s: [x for x in s.split(',') if x]

def read(p):
    with open(p, 'rb') as f:
        f.readline(); w, h = map(int, f.readline().split()); s = float(f.readline())
        return np.fromfile(f, dtype='<f4' if s < 0 else '>f4').reshape(h, w, 3).astype(np.float64)

def run(name):
    b = '%s/runs/%s' % (out, name)
    if not os.path.exists(b + '.diff'):
        return None
    log, diff = open(b + '.log').read(), open(b + '.diff').read()
    m = re.search(r'per pass (\d+) photon paths.*?(\d+) global \+ (\d+) caustic.*?maps ([0-9.]+) MiB', log)
    t = re.search(r'spp in ([0-9.]+) s', log)
    tp = re.search(r'photon tracing ([0-9.]+) s', log)
    rel = re.search(r'relmse ([-+0-9.eE]+)', diff)
    mr = re.search(r'mean_ratio ([-+0-9.eE]+)', diff)
    if not (m and t and rel):
        return None
    return dict(paths=int(m.group(1)), stored=int(m.group(2)), mib=float(m.group(4)),
                time=float(t.group(1)), tphot=float(tp.group(1)) if tp else float('nan'),
                relmse=float(rel.group(1)), mean_ratio=float(mr.group(1)), pfm=b + '.pfm')

def interp_x(curve, y):
    """x where the log-log polyline [(x, y)] (sorted by x) first reaches y."""
    for (x0, y0), (x1, y1) in zip(curve, curve[1:]):
        if (y0 - y) * (y1 - y) <= 0 and y0 != y1:
            f = (math.log(y) - math.log(y0)) / (math.log(y1) - math.log(y0))
            return math.exp(math.log(x0) + f * (math.log(x1) - math.log(x0)))
    return None

md = []
w = md.append
halves = open('%s/ref/c_%s_%s.halves.txt' % (out, res, refspp)).read()
hrel = float(re.search(r'relmse ([-+0-9.eE]+)', halves).group(1))
w('Reference: `path`, %s, `--maxdepth 16`, %s spp as two halves (seeds 1 and 2); the relMSE between the '
  'halves is %.4g, so the reference carries about %.2g of relMSE itself (a quarter of that), which every '
  'pm value below includes.\n' % (res, refspp, hrel, hrel / 4))
w('pm runs: `-i pm --progressive off --visibility gather --knn 50 --res %s --maxdepth 16 --direct lcon --shadow-rays 32 %s--spp %s` (each pass traces a '
  'fresh map of --photons photons; the passes average), importance runs add `%s`. "maps MiB" is '
  'the peak of the maps in the `pm:` line: global map, the copy of its primary photons for L_con and, with '
  'final gathering, the precomputed irradiance (the same share of the global map in both methods).\n'
  % (res, pmargs + ' ' if pmargs else '', P, ('--importance ' + impargs).strip()))
fig, axes = plt.subplots(1, 2, figsize=(12, 4.8))
summary = []
for g in gathers:
    std = [(int(n), r) for n in lst(stdn) for r in [run('g%s_p%s_%s_%s' % (g, P, stag, n))] if r]
    imp = [(int(n), r) for n in lst(impn) for r in [run('g%s_p%s_%s_%s' % (g, P, itag, n))] if r]
    if not std or not imp:
        continue
    mode = 'global map visualised directly (`--gather 0`)' if g == '0' else 'final gathering (`--gather %s`)' % g
    w('\n### %s, %s passes\n' % (mode, P))
    w('| method | --photons | stored | photon paths / pass | maps MiB | photon tracing s (all passes) | total s | relMSE | mean ratio |')
    w('|---|---:|---:|---:|---:|---:|---:|---:|---:|')
    for label, rs in (('standard', std), ('importance', imp)):
        for n, r in rs:
            w('| %s | %d | %d | %d | %.2f | %.2f | %.2f | %.4g | %.3f |' % (
                label, n, r['stored'], r['paths'], r['mib'], r['tphot'], r['time'], r['relmse'], r['mean_ratio']))
    sn = dict(std)
    w('\nAt equal stored photons:\n')
    w('| --photons | relMSE standard | relMSE importance | ratio std / imp | photon paths imp / std |')
    w('|---:|---:|---:|---:|---:|')
    eq = []
    for n, r in imp:
        if n in sn:
            s = sn[n]
            eq.append((n, s['relmse'] / r['relmse']))
            w('| %d | %.4g | %.4g | %.2f | %.1f |' % (n, s['relmse'], r['relmse'], s['relmse'] / r['relmse'],
                                                   r['paths'] / s['paths']))
    curve = sorted((r['mib'], r['relmse']) for n, r in std)
    lo, hi = min(c[1] for c in curve), max(c[1] for c in curve)
    w('\nAt equal error (the memory of the standard map at the importance map\'s relMSE, interpolated log-log '
      'between the sweep points):\n')
    w('| importance --photons | relMSE | importance MiB | standard MiB at that relMSE | memory ratio |')
    w('|---:|---:|---:|---:|---:|')
    ratios = []
    for n, r in imp:
        m = interp_x(curve, r['relmse'])
        if m is not None:
            ratios.append('%.1f (%dk)' % (m / r['mib'], n // 1000))
            w('| %d | %.4g | %.2f | %.2f | %.1f |' % (n, r['relmse'], r['mib'], m, m / r['mib']))
        elif r['relmse'] < lo:
            ratios.append('>%.1f (%dk, not reached)' % (curve[-1][0] / r['mib'], n // 1000))
            w('| %d | %.4g | %.2f | > %.2f (the standard sweep ends at relMSE %.4g) | > %.1f |' % (
                n, r['relmse'], r['mib'], curve[-1][0], lo, curve[-1][0] / r['mib']))
        else:
            w('| %d | %.4g | %.2f | above the standard sweep (max %.4g) | - |' % (n, r['relmse'], r['mib'], hi))
    summary.append('- gather %s, %s passes: relMSE standard / importance at equal stored photons: %s; '
                   'memory ratio at equal error: %s' % (
                       g, P, ', '.join('%.2f (%dk)' % (v, n // 1000) for n, v in eq), ', '.join(ratios)))
    sty = '-' if g == '0' else '--'
    for ax, key, xl in ((axes[0], 'stored', 'stored photons (per pass)'), (axes[1], 'mib', 'photon maps, MiB (peak)')):
        ax.loglog([r[key] for n, r in std], [r['relmse'] for n, r in std], 'o' + sty, color='tab:blue',
                  label='standard, --gather %s' % g)
        ax.loglog([r[key] for n, r in imp], [r['relmse'] for n, r in imp], 's' + sty, color='tab:red',
                  label='importance, --gather %s' % g)
        ax.set_xlabel(xl)
        ax.set_ylabel('relMSE of the camera view')
        ax.grid(True, which='both', alpha=0.3)
for ax in axes:
    ax.axhline(hrel / 4, color='grey', lw=0.8, ls=':')
    ax.legend(fontsize=8)
fig.suptitle('rooms10x10, camera in room (4, 4): error vs stored photons and vs memory\n'
             '(%s passes per image; dotted: the reference\'s own noise)%s' % (P, ('  ' + impargs + ' ' + pmargs).rstrip()))
fig.tight_layout()
plotname = 'pm-fig2-error.png' if docs.endswith('docs') else 'pm-fig2-error-%s.png' % itag
fig.savefig(os.path.join(docs, plotname), dpi=90)

# one-pass probe
rows = []
for n in lst(probe):
    for label, tg in (('standard', stag), ('importance', itag)):
        a, b = run('probe_%s_%s_s1' % (tg, n)), run('probe_%s_%s_s2' % (tg, n))
        if not (a and b):
            continue
        x, y = read(a['pfm']), read(b['pfm'])
        noise = float(np.mean((x - y) ** 2 / (((x + y) / 2) ** 2 + 0.01))) / 2  # per-image variance
        e = (a['relmse'] + b['relmse']) / 2
        rows.append('| %s | %s | %.4g, %.4g | %.4g | %.4g |' % (label, n, a['relmse'], b['relmse'], noise,
                                                              e - noise - hrel / 4))
if rows:
    w('\n### One map (one pass, `--gather 0`, seeds 1 and 2)\n')
    w('Noise: half the relMSE between the two seeds\' images (the variance of one image); systematic part: '
      'the mean relMSE minus that noise and the reference\'s own noise.\n')
    w('| method | --photons | relMSE (seed 1, seed 2) | noise | systematic part |')
    w('|---|---:|---:|---:|---:|')
    md.extend(rows)
views = [(int(n), t, r) for n in lst(pics) for t in ('standard', 'importance')
         for r in [run('view_%s_%s' % (stag if t == 'standard' else itag, n))] if r]
if views:
    w('\n### The views of Figure 2 (one pass, `--gather 0`)\n')
    w('| method | --photons | photon paths | maps MiB | time s | relMSE |')
    w('|---|---:|---:|---:|---:|---:|')
    for n, t, r in views:
        w('| %s | %d | %d | %.2f | %.2f | %.4g |' % (t, n, r['paths'], r['mib'], r['time'], r['relmse']))
w('\nSummary:\n')
md.extend(summary)
w('\nRun time %s s (not counting cached runs). Plot: `%s`.' % (secs, plotname))
open(os.path.join(out, 'results_%s_p%s.md' % (itag, P)), 'w').write('\n'.join(md) + '\n')
print('\n'.join(md))
EOF

# 6. pictures into docs/
if [ "$docs" = 1 ] && [ -n "$pics" ]; then
  p1=${pics%%,*}
  cp "$out/pics/${stag}_$p1.png" "$here/docs/pm-fig1-standard.png"
  cp "$out/pics/${itag}_$p1.importons.png" "$here/docs/pm-fig1-importons.png"
  cp "$out/pics/${itag}_$p1.png" "$here/docs/pm-fig1-importance.png"
  for n in ${pics//,/ }; do
    cp "$out/pics/${stag}_$n.png" "$here/docs/pm-fig2-photons-standard-$n.png"
    cp "$out/pics/${itag}_$n.png" "$here/docs/pm-fig2-photons-importance-$n.png"
    cp "$out/runs/view_${stag}_$n.png" "$here/docs/pm-fig2-view-standard-$n.png"
    cp "$out/runs/view_${itag}_$n.png" "$here/docs/pm-fig2-view-importance-$n.png"
  done
fi
for n in ${pics//,/ }; do cat "$out/pics/${stag}_$n.txt" "$out/pics/${itag}_$n.txt"; done
