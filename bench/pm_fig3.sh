#!/usr/bin/env bash
# Keller & Wald 2000, Figure 3: automatic caustics. The caustic error of pm
# against the ratio q (--caustic-ratio) at a fixed number of global photons.
#
# Scene: the McGuire CornellBox-Sphere (glass sphere Ni 2.5 on the right, mirror
# sphere on the left), seen from a close-up camera above the glass sphere so
# that its caustic fills a good part of the image.
#
#  1. Reference (cached in OUT/refs): light tracing alone (-i bdpt --mis light),
#     the estimator that converges fastest on L S+ D E caustics seen on a
#     diffuse floor, as two halves of REF_SPP/2 spp with seeds 1 and 2; their
#     mean is the reference and their difference estimates its own noise.
#     A "no caustics" image: the same scene with the glass sphere made black
#     Lambertian (path tracing, 512 spp), and a bdpt image that only fills
#     the non-floor pixels of the reference close-up PNG (light tracing
#     cannot see the specular spheres).
#  2. Caustic mask: pixels whose camera ray hits the floor (analytic ray cast
#     against the floor rectangle and the two spheres, whose centres and radii
#     come from the OBJ, with a 3 % margin on the radii) AND where the 3x3
#     blurred reference is more than 1.5 times the blurred no-caustics image
#     (i.e. at least a third of the light there came through the glass).
#  3. Sweep q in {1, 1/2, 1/5, 1/10, 1/20} with --caustic-select prefix and
#     random at --photons PHOTONS and SPP passes (each pass traces its own
#     maps); relMSE (candela diff's definition, mean over pixels and channels
#     of (t-r)^2/(r^2+0.01)) inside the mask, on the rest of the floor
#     (control) and mean ratio inside the mask; photon counts from the pm:
#     line.
#  4. OUT/table.md, OUT/results.csv, docs/pm-fig3-error.png and close-ups
#     docs/pm-fig3-q1.png, -q5.png, -q20.png (prefix), docs/pm-fig3-ref.png
#     and a strip of all four, docs/pm-fig3-closeups.png.
#
# usage: bench/pm_fig3.sh [OUT] [PHOTONS] [SPP] [REF_SPP] [SEEDS]
#   defaults: out/pm_fig3 50000 16 2048 2: about 9 minutes on 2 shared cores,
#   of which the cached reference takes 3.5 (delete OUT/refs to redo it);
#   PM_FIG3_SCENE and PM_FIG3_RES override the scene and the 160x120 size
#   (the camera and the mask's spheres/floor assume CornellBox-Sphere);
#   PM_FIG3_REUSE=1 keeps renders already in OUT/renders (tables and plots only).
set -eu
here=$(cd "$(dirname "$0")/.." && pwd)
out=${1:-$here/out/pm_fig3}
photons=${2:-50000}
spp=${3:-16}
refspp=${4:-2048}
seeds=${5:-2}
candela=$here/build/candela
py=/usr/bin/python3
scene=${PM_FIG3_SCENE:-$here/../shared/scenes/cornell-box-mcguire/CornellBox-Sphere.obj}
res=${PM_FIG3_RES:-160x120}
cam="--lookat 0.3,1.2,1.75,0.5,0,0.45,0,1,0 --fov 36"
docs=$here/docs
mkdir -p "$out/refs" "$out/renders"
out=$(cd "$out" && pwd)

# ---------------------------------------------------------------- helper
cat > "$out/fig3.py" <<'EOF'
"""pm_fig3 helper: PFM I/O, the caustic mask, masked errors, table, plot, close-ups."""
import csv, json, math, os, re, sys
import numpy as np


def read_pfm(p):
    with open(p, 'rb') as f:
        if f.readline().strip() != b'PF':
            raise SystemExit(f'{p}: not an RGB PFM')
        w, h = map(int, f.readline().split())
        s = float(f.readline())
        a = np.frombuffer(f.read(), dtype='<f4' if s < 0 else '>f4').reshape(h, w, 3)
    return a[::-1].astype(np.float64)  # PFM stores the bottom row first


def write_pfm(p, a):
    h, w, _ = a.shape
    with open(p, 'wb') as f:
        f.write(b'PF\n%d %d\n-1.0\n' % (w, h))
        f.write(np.ascontiguousarray(a[::-1], dtype='<f4').tobytes())


def rel_terms(t, r):
    return ((t - r) ** 2 / (r ** 2 + 0.01)).mean(axis=2)


def blur3(a):
    p = np.pad(a, ((1, 1), (1, 1), (0, 0)), mode='edge')
    h, w = a.shape[:2]
    return sum(p[i:i + h, j:j + w] for i in range(3) for j in range(3)) / 9.0


def spheres_from_obj(path):
    """Centre and radius of every material group named *Sphere* (bounding box)."""
    V, groups, cur = [], {}, None
    for line in open(path):
        t = line.split()
        if not t:
            continue
        if t[0] == 'v':
            V.append([float(x) for x in t[1:4]])
        elif t[0] == 'usemtl':
            cur = t[1]
        elif t[0] == 'f' and cur and 'sphere' in cur.lower():
            for x in t[1:]:
                i = int(x.split('/')[0])
                groups.setdefault(cur, []).append(V[i - 1 if i > 0 else len(V) + i])
    out = []
    for g, pts in groups.items():
        a = np.array(pts)
        lo, hi = a.min(0), a.max(0)
        out.append(((lo + hi) / 2, (hi - lo).max() / 2))
    return out


def floor_pixels(cam, w, h, spheres, floor=(-1.0, 1.0, -1.04, 0.99), margin=1.03):
    """Pixels whose centre ray hits the floor (y = 0) inside the box before any sphere.
    Same camera model as candela (src/scene/camera.h)."""
    v = [float(x) for x in re.search(r'--lookat (\S+)', cam).group(1).split(',')]
    fov = float(re.search(r'--fov (\S+)', cam).group(1))
    e, t, up = np.array(v[0:3]), np.array(v[3:6]), np.array(v[6:9])
    f = (t - e) / np.linalg.norm(t - e)
    r = np.cross(f, up); r /= np.linalg.norm(r)
    u = np.cross(r, f)
    th = math.tan(math.radians(fov) / 2)
    x = (np.arange(w) + 0.5)[None, :]
    y = (np.arange(h) + 0.5)[:, None]
    sx = (2 * x / w - 1) * th * w / h
    sy = (1 - 2 * y / h) * th
    d = f + r * sx[..., None] + u * sy[..., None]
    d /= np.linalg.norm(d, axis=2, keepdims=True)
    dy = np.where(np.abs(d[..., 1]) > 1e-9, d[..., 1], -1e-9)
    tf = -e[1] / dy
    p = e + d * tf[..., None]
    ok = (tf > 0) & (p[..., 0] > floor[0]) & (p[..., 0] < floor[1]) & (p[..., 2] > floor[2]) & (p[..., 2] < floor[3])
    for c, rad in spheres:
        oc = e - c
        b = (d * oc).sum(2)
        disc = b * b - (oc @ oc - (rad * margin) ** 2)
        ok &= ~((disc > 0) & (-b - np.sqrt(np.maximum(disc, 0)) < tf))
    return ok


def srgb(a, exposure=0.0):
    a = np.clip(a * 2.0 ** exposure, 0, 1)
    return np.where(a <= 0.0031308, 12.92 * a, 1.055 * a ** (1 / 2.4) - 0.055)


def cmd_mask(out, scene, cam, w, h):
    ra, rb = read_pfm(f'{out}/refs/ref_a.pfm'), read_pfm(f'{out}/refs/ref_b.pfm')
    ref = (ra + rb) / 2
    write_pfm(f'{out}/refs/ref.pfm', ref)
    nocau = read_pfm(f'{out}/refs/nocaustics.pfm')
    fl = floor_pixels(cam, w, h, spheres_from_obj(scene))
    lum = lambda a: a.mean(axis=2)
    mask = fl & (lum(blur3(ref)) > 1.5 * lum(blur3(nocau)))
    rest = fl & ~mask
    # the focused core: the brightest 10 % of the mask (blurred reference)
    lb = lum(blur3(ref))
    core = mask & (lb >= np.percentile(lb[mask], 90))
    np.save(f'{out}/refs/core.npy', core)
    np.save(f'{out}/refs/mask.npy', mask)
    np.save(f'{out}/refs/rest.npy', rest)
    # noise of the reference itself: Var(ref) = Var(half)/2 and E[relmse(a, b)] = 2 Var(half)
    # (relative terms), so relmse of the mean against the truth is about relmse(a, b) / 4
    tm = rel_terms(ra, rb)
    info = {'mask_pixels': int(mask.sum()), 'floor_pixels': int(fl.sum()), 'core_pixels': int(core.sum()),
            'ref_noise_mask': float(tm[mask].mean() / 4), 'ref_noise_rest': float(tm[rest].mean() / 4),
            'ref_noise_core': float(tm[core].mean() / 4),
            'ref_mean_mask': float(ref[mask].mean()), 'nocaustics_mean_mask': float(nocau[mask].mean())}
    json.dump(info, open(f'{out}/refs/mask.json', 'w'), indent=1)
    import matplotlib
    matplotlib.use('Agg')
    import matplotlib.pyplot as plt
    vis = srgb(ref) * 0.5
    vis[mask] = vis[mask] * 0.5 + np.array([1.0, 0.3, 0.0]) * 0.5
    plt.imsave(f'{out}/refs/mask.png', np.clip(vis, 0, 1))
    print(json.dumps(info))


def parse_log(path):
    s = open(path).read()
    m = re.search(r'(\d+) spp in ([\d.]+) s', s)
    g = re.search(r'per pass (\d+) photon paths traced \((\d+) for the global map\), (\d+) global \+ (\d+) caustic', s)
    t = re.search(r'photon tracing ([\d.]+) s over (\d+) passes', s)
    c = re.search(r'CPU ([\d.]+) ([\d.]+)', s)
    return {'cpu_seconds': float(c.group(1)) + float(c.group(2)),'spp': int(m.group(1)), 'seconds': float(m.group(2)), 'paths': int(g.group(1)),
            'paths_global': int(g.group(2)), 'global': int(g.group(3)), 'caustic': int(g.group(4)),
            'photon_seconds': float(t.group(1))}


def cmd_table(out, docs, runs):
    """runs: lines 'select q_label q seed stem'."""
    ref = read_pfm(f'{out}/refs/ref.pfm')
    mask, rest = np.load(f'{out}/refs/mask.npy'), np.load(f'{out}/refs/rest.npy')
    core = np.load(f'{out}/refs/core.npy')
    info = json.load(open(f'{out}/refs/mask.json'))
    rows, imgs = [], {}
    for line in open(runs):
        sel, ql, q, seed, stem = line.split()
        img = read_pfm(stem + '.pfm')
        imgs[(sel, float(q), int(seed))] = img
        t = rel_terms(img, ref)
        r = parse_log(stem + '.log')
        r.update(select=sel, q_label=ql, q=float(q), seed=int(seed), stem=stem,
                 relmse_caustic=float(t[mask].mean()), relmse_core=float(t[core].mean()),
                 relmse_rest=float(t[rest].mean()), ratio_caustic=float(img[mask].mean() / ref[mask].mean()),
                 ratio_core=float(img[core].mean() / ref[core].mean()))
        rows.append(r)
    keys = ['select', 'q_label', 'q', 'seed', 'spp', 'seconds', 'cpu_seconds', 'photon_seconds', 'paths',
            'paths_global', 'global', 'caustic', 'relmse_caustic', 'relmse_core', 'relmse_rest', 'ratio_caustic',
            'ratio_core']
    with open(f'{out}/results.csv', 'w', newline='') as f:
        wr = csv.DictWriter(f, keys)
        wr.writeheader()
        for r in rows:
            wr.writerow({k: r[k] for k in keys})
    agg = {}
    for r in rows:
        agg.setdefault((r['select'], r['q']), []).append(r)
    sels = [s for s in ('prefix', 'random') if any(k[0] == s for k in agg)]
    qs = sorted({k[1] for k in agg}, reverse=True)
    mean = lambda rs, k: sum(x[k] for x in rs) / len(rs)
    nseeds = max(len(v) for v in agg.values())

    def split(s, q, region):
        """Noise part of the relMSE (per run) from the spread between seeds, in the terms of the
        reference: sum over pairs of (a-b)^2 / (2 (r^2+0.01)), averaged; None with one seed."""
        ims = [imgs[(s, q, x['seed'])] for x in agg[(s, q)]]
        if len(ims) < 2:
            return None
        m = sum(ims) / len(ims)
        var = sum(((a - m) ** 2 / (ref ** 2 + 0.01)).mean(axis=2) for a in ims) / (len(ims) - 1)
        return float(var[region].mean())

    lines = [f"Caustic mask: {info['mask_pixels']} pixels of {info['floor_pixels']} floor pixels; core (brightest "
             f"10 % of the mask): {info['core_pixels']} pixels. Reference noise (relMSE of the reference itself, "
             f"from its two halves): {info['ref_noise_mask']:.1e} in the mask, {info['ref_noise_core']:.1e} in "
             f"the core, {info['ref_noise_rest']:.1e} on the rest of the floor. Counts per pass; errors and times "
             f"are means over {nseeds} seed(s); cpu s = user + sys CPU seconds of the render process (2 threads; "
             f"wall time varies with the machine's other load). noise = the part of the mask relMSE from the "
             f"spread between seeds (sample variance), bias^2 = relMSE - noise - reference noise.", '',
             '| select | q | paths | global paths | global photons | caustic photons | caustic / path | '
             'wall s | cpu s | photon s (wall) | relMSE mask | noise | bias^2 | relMSE core | relMSE rest of floor | '
             'mean ratio mask | mean ratio core |',
             '|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|']
    for s in sels:
        for q in qs:
            rs = agg.get((s, q))
            if not rs:
                continue
            nz = split(s, q, mask)
            e = mean(rs, 'relmse_caustic')
            nzs = f'{nz:.4f}' if nz is not None else '-'
            bs = f"{e - nz - info['ref_noise_mask']:.4f}" if nz is not None else '-'
            lines.append(f"| {s} | {rs[0]['q_label']} | {mean(rs, 'paths'):.0f} | {mean(rs, 'paths_global'):.0f} | "
                         f"{mean(rs, 'global'):.0f} | {mean(rs, 'caustic'):.0f} | "
                         f"{mean(rs, 'caustic') / mean(rs, 'paths'):.3f} | {mean(rs, 'seconds'):.2f} | "
                         f"{mean(rs, 'cpu_seconds'):.1f} | {mean(rs, 'photon_seconds'):.2f} | {e:.4f} | {nzs} | {bs} | "
                         f"{mean(rs, 'relmse_core'):.4f} | {mean(rs, 'relmse_rest'):.4f} | "
                         f"{mean(rs, 'ratio_caustic'):.3f} | {mean(rs, 'ratio_core'):.3f} |")
    open(f'{out}/table.md', 'w').write('\n'.join(lines) + '\n')
    print('\n'.join(lines))

    import matplotlib
    matplotlib.use('Agg')
    import matplotlib.pyplot as plt
    fig, (a1, a2) = plt.subplots(1, 2, figsize=(10.5, 4.3), dpi=110)
    style = {'prefix': dict(marker='o', ls='-', ms=7), 'random': dict(marker='s', ls='--', ms=5, mfc='none')}
    for s in sels:
        qq = [q for q in qs if (s, q) in agg]
        x = [1 / q for q in qq]
        a1.plot(x, [mean(agg[(s, q)], 'relmse_caustic') for q in qq], color='C0', label=f'{s}: caustic mask', **style[s])
        a1.plot(x, [mean(agg[(s, q)], 'relmse_core') for q in qq], color='C3', label=f'{s}: caustic core', **style[s])
        a1.plot(x, [mean(agg[(s, q)], 'relmse_rest') for q in qq], color='C2', label=f'{s}: rest of the floor',
                **style[s])
        a2.plot(x, [mean(agg[(s, q)], 'caustic') for q in qq], color='C1', label=f'{s}: caustic photons', **style[s])
        a2.plot(x, [mean(agg[(s, q)], 'global') for q in qq], color='C4', label=f'{s}: global photons', **style[s])
        a2.plot(x, [mean(agg[(s, q)], 'paths') for q in qq], color='C7', label=f'{s}: paths traced', **style[s])
    a1.axhline(info['ref_noise_mask'], color='grey', lw=0.8, ls=':', label='reference noise (mask)')
    for a in (a1, a2):
        a.set_xscale('log')
        a.set_yscale('log')
        a.set_xticks([1 / q for q in qs])
        a.set_xticklabels(['1' if q == 1 else f'1/{round(1 / q)}' for q in qs])
        a.minorticks_off()
        a.yaxis.set_major_locator(matplotlib.ticker.LogLocator(subs=(1, 2, 5)))
        a.yaxis.set_major_formatter(matplotlib.ticker.FuncFormatter(lambda v, _: f'{v:g}'))
        a.set_xlabel('q (--caustic-ratio)')
        a.grid(True, which='major', alpha=0.3)
        a.legend(fontsize=7)
    spp = rows[0]['spp']
    a1.set_ylabel('relative MSE')
    a1.set_title(f"pm error vs q, {rows[0]['global']} global photons, {spp} spp", fontsize=9)
    a2.set_ylabel('per pass')
    a2.set_title('photon map sizes and paths', fontsize=9)
    fig.tight_layout()
    fig.savefig(f'{docs}/pm-fig3-error.png')

    # close-ups: the mask's bounding box (3x) and a tight zoom on the core (6x)
    ys, xs = np.nonzero(mask)
    y0, y1 = max(0, ys.min() - 6), min(mask.shape[0], ys.max() + 7)
    x0, x1 = max(0, xs.min() - 6), min(mask.shape[1], xs.max() + 7)
    cy, cx = [int(v.mean()) for v in np.nonzero(core)]
    zy0, zx0 = max(0, cy - 12), max(0, cx - 20)
    zy1, zx1 = min(mask.shape[0], zy0 + 24), min(mask.shape[1], zx0 + 40)
    up = lambda a, k: np.repeat(np.repeat(a, k, axis=0), k, axis=1)
    wide = lambda a: up(srgb(a[y0:y1, x0:x1]), 3)
    zoom = lambda a: up(srgb(a[zy0:zy1, zx0:zx1]), 6)
    fill = read_pfm(f'{out}/refs/fill_bdpt.pfm')
    fl = floor_pixels(os.environ['CAM'], ref.shape[1], ref.shape[0], spheres_from_obj(os.environ['SCENE']))
    refvis = np.where(fl[..., None], ref, fill)
    panels = [('ref', 'reference (floor: light tracing; rest: bdpt)', refvis)]
    for ql, tag in (('1', 'q1'), ('1/5', 'q5'), ('1/20', 'q20')):
        r = [x for x in rows if x['select'] == 'prefix' and x['q_label'] == ql and x['seed'] == 1]
        if r:
            panels.append((tag, f"q = {ql} (seed 1): {r[0]['caustic']} caustic photons/pass\nrelMSE mask "
                                f"{r[0]['relmse_caustic']:.4f}, core {r[0]['relmse_core']:.3f}",
                           imgs[('prefix', r[0]['q'], 1)]))
    for tag, _, img in panels:
        plt.imsave(f'{docs}/pm-fig3-{tag}.png', np.clip(wide(img), 0, 1))
    n = len(panels)
    fig, ax = plt.subplots(2, n, figsize=(3.3 * n, 5.6), dpi=110,
                           gridspec_kw={'height_ratios': [(y1 - y0) / (x1 - x0), 24 / 40]})
    for i, (tag, title, img) in enumerate(panels):
        ax[0, i].imshow(np.clip(wide(img), 0, 1), interpolation='nearest')
        ax[0, i].add_patch(plt.Rectangle(((zx0 - x0) * 3 - 0.5, (zy0 - y0) * 3 - 0.5), (zx1 - zx0) * 3,
                                         (zy1 - zy0) * 3, fill=False, ec='yellow', lw=0.8))
        ax[0, i].set_title(title, fontsize=7)
        ax[1, i].imshow(np.clip(zoom(img), 0, 1), interpolation='nearest')
        for a in ax[:, i]:
            a.axis('off')
    fig.suptitle(f"pm caustic at fixed {rows[0]['global']} global photons, {spp} spp (prefix selection); "
                 "bottom: the yellow box enlarged", fontsize=8)
    fig.tight_layout()
    fig.savefig(f'{docs}/pm-fig3-closeups.png')


if __name__ == '__main__':
    if sys.argv[1] == 'mask':
        cmd_mask(sys.argv[2], sys.argv[3], sys.argv[4], int(sys.argv[5]), int(sys.argv[6]))
    else:
        cmd_table(sys.argv[2], sys.argv[3], sys.argv[4])
EOF

w=${res%x*}
h=${res#*x}
# ---------------------------------------------------------------- references
refs=$out/refs
if [ ! -f "$refs/ref_a.pfm" ] || [ ! -f "$refs/ref_b.pfm" ]; then
  echo "reference: light tracing, 2 x $((refspp / 2)) spp at $res" >&2
  for half in a b; do
    seed=1; [ $half = b ] && seed=2
    # shellcheck disable=SC2086
    "$candela" render "$scene" $cam --res "$res" -i bdpt --mis light --spp $((refspp / 2)) --seed $seed -q \
      -o "$refs/ref_$half.pfm" -o "$refs/ref_$half.exr" >&2
  done
fi
if [ ! -f "$refs/nocaustics.pfm" ]; then
  # the glass sphere as black Lambertian: the same scene without caustics
  sed 's/^mtllib .*/mtllib nocaustics.mtl/' "$scene" > "$refs/nocaustics.obj"
  "$py" - "${scene%.obj}.mtl" "$refs/nocaustics.mtl" <<'EOF'
import sys
src = open(sys.argv[1]).read()
a = src.index('newmtl rightSphere')
b = src.index('newmtl', a + 6)
open(sys.argv[2], 'w').write(src[:a] + 'newmtl rightSphere\n    Kd 0 0 0\n    illum 2\n\n' + src[b:])
EOF
  # shellcheck disable=SC2086
  "$candela" render "$refs/nocaustics.obj" $cam --res "$res" -i path --spp 512 -q -o "$refs/nocaustics.pfm" >&2
fi
if [ ! -f "$refs/fill_bdpt.pfm" ]; then
  # shellcheck disable=SC2086
  "$candela" render "$scene" $cam --res "$res" -i bdpt --spp 64 -q -o "$refs/fill_bdpt.pfm" >&2
fi
"$py" "$out/fig3.py" mask "$out" "$scene" "$cam" "$w" "$h" >&2

# ---------------------------------------------------------------- sweep
runs=$out/runs.txt
: > "$runs"
for seed in $(seq 1 "$seeds"); do
  for sel in prefix random; do
    for ql in 1 1/2 1/5 1/10 1/20; do
      q=$("$py" -c "print(eval('$ql'))")
      [ "$sel" = random ] && [ "$ql" = 1 ] && continue # q = 1: both selections are the same run
      stem=$out/renders/${sel}_q$(echo "$ql" | tr -d /)_s$seed
      if [ -n "${PM_FIG3_REUSE:-}" ] && [ -f "$stem.pfm" ] && grep -q '^CPU' "$stem.log" 2>/dev/null; then
        echo "$sel $ql $q $seed $stem" >> "$runs"
        [ "$ql" = 1 ] && echo "random $ql $q $seed $stem" >> "$runs"
        continue
      fi
      echo "pm --caustic-select $sel --caustic-ratio $ql --photons $photons --spp $spp --seed $seed" >&2
      # shellcheck disable=SC2086
      /usr/bin/time -f 'CPU %U %S' -a -o "$stem.log" "$candela" render "$scene" $cam --res "$res" -i pm --progressive off --visibility gather --knn 50 \
        --knn 100 --gather 16 --shadow-rays 1 --photons "$photons" --caustic-ratio "$q" --caustic-select "$sel" --spp "$spp" --seed "$seed" \
        -o "$stem.pfm" -o "$stem.png" > "$stem.log" 2>&1
      echo "$sel $ql $q $seed $stem" >> "$runs"
      if [ "$ql" = 1 ]; then # q = 1 is also the random row
        echo "random $ql $q $seed $stem" >> "$runs"
      fi
    done
  done
done
CAM="$cam" SCENE="$scene" "$py" "$out/fig3.py" table "$out" "$docs" "$runs"
