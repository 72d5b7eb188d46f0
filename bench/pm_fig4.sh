#!/usr/bin/env bash
# Reproduces Keller & Wald 2000, Figure 4, on scenes/generated/doorslit: the
# camera's room (right) is lit only through a 5 cm door slit from the room with
# the light (left). `candela photons` pictures of pass 0 seen from above, at
# equal stored photons:
#   a) the importons,
#   b) the standard photon map,
#   c) the importance-driven map with p bounded below by --importance-eps
#      (unbiased: photons with p < eps are stored with probability eps),
#   d) the importance-driven map with --importance-discard (photons with
#      p < eps dropped: biased),
# with the photon paths each needed, and a count of the photon dots per square
# metre of the plan: in the camera's room, in the light's room in the strip just
# behind the shared wall away from the door (x in [3.7, 4.0], z outside [1.0, 2.9]:
# importance bleeds 0.31 m through the 0.2 m wall from the camera's side, as the
# importon query radius is 5 % of the scene diagonal, 0.51 m), around the door
# and the slit (x in [3.3, 4.0], z in [1.0, 2.9]) and in the rest of the light's
# room (x < 3.3).
# usage: bench/pm_fig4.sh [OUT] [PHOTONS] [EPS_LIST]
#   PHOTONS   stored photons of every map (default 100000)
#   EPS_LIST  comma-separated --importance-eps values of c) and d) (default
#             0.01,0.1: the default and a ten times larger cutoff)
set -eu
here=$(cd "$(dirname "$0")/.." && pwd)
out=${1:-$here/out/pm_fig4}
n=${2:-100000}
epss=${3:-0.01,0.1}
candela=$here/build/candela
py=/usr/bin/python3
scene=$here/scenes/generated/doorslit.obj
cam=$(cat "$here/scenes/generated/doorslit.cam")
opts="$cam --res 160x120 --maxdepth 16 --photons $n"
mkdir -p "$out"
t0=$(date +%s)
: > "$out/log.txt"
shoot() { # name, extra options
  local name=$1
  shift
  local s e line
  s=$(date +%s.%N)
  # shellcheck disable=SC2086
  line=$("$candela" photons "$scene" $opts "$@" -o "$out/$name.png" | tr '\n' ' ')
  e=$(date +%s.%N)
  printf '%s\t%s\t%s\t%s\n' "$name" "$*" "$(echo "$e - $s" | bc)" "$line" >> "$out/log.txt"
}
shoot standard
for eps in ${epss//,/ }; do
  shoot "importance-eps$eps" --importance --importance-eps "$eps"
  shoot "importance-discard$eps" --importance --importance-eps "$eps" --importance-discard
done
t1=$(date +%s)

"$py" - "$out" "$n" "$((t1 - t0))" "$cam" "$epss" <<'EOF'
import sys, re, os
import numpy as np
import matplotlib
matplotlib.use('Agg')
import matplotlib.image as mpimg
out, n, secs, cam, epss = sys.argv[1:]
# plan geometry of doorslit: the bounds span x in [-0.2, 8.4] (outer walls 0.2 m),
# z in [-0.2, 4.2]; candela photons scales the larger extent to 800 pixels
x0, x1, z0, z1 = -0.2, 8.4, -0.2, 4.2
# strips of the light's room by distance from the shared wall (x = 4.0), away from the door
# (the first strip holds the wall's face itself, a line in the plan; the second
# ends 3 cm off the face)
strips = [(3.97, 4.005), (3.9, 3.97), (3.8, 3.9), (3.7, 3.8), (3.6, 3.7), (3.4, 3.6), (3.0, 3.4), (2.0, 3.0)]
rows = []
for line in open(os.path.join(out, 'log.txt')):
    name, args, t, text = line.rstrip('\n').split('\t')
    m = re.search(r'(\d+) photon paths .*?(\d+) global \+ (\d+) caustic photons stored of (\d+) hits, ([0-9.]+) MiB', text)
    imp = re.search(r'(\d+) importons from (\d+) paths, f = ([0-9.eE+-]+)', text)
    img = mpimg.imread(os.path.join(out, name + '.png'))[:, :, :3]
    h, w, _ = img.shape
    s = (w - 1) / (x1 - x0)
    # a photon dot adds red 0.5 (linear; 0.74 in the sRGB PNG); walls are grey 0.12 (0.38 sRGB)
    dots = img[:, :, 0] > 0.5
    col = lambda x: int((x - x0) * s)
    row = lambda z: int((z - z0) * s)
    def density(xa, xb, za=0.05, zb=3.95):  # dot pixels per m^2 of plan in [xa, xb] x [za, zb]
        d = dots[row(za):row(zb), col(xa):col(xb)]
        return d.sum(), (xb - xa) * (zb - za)
    def dens(*boxes):
        c = [density(*b) for b in boxes]
        return sum(x[0] for x in c) / sum(x[1] for x in c)
    rows.append(dict(name=name, args=args, t=float(t), paths=int(m.group(1)), stored=int(m.group(2)),
                     hits=int(m.group(4)), mib=float(m.group(5)),
                     behind=dens((3.7, 3.98, 0.05, 1.0), (3.7, 3.98, 2.9, 3.95)), door=dens((3.3, 3.98, 1.0, 2.9)),
                     rest=dens((0.05, 3.3)), cam=dens((4.22, 8.15)), imp=imp.groups() if imp else None,
                     profile=[dens((a, b, 0.05, 1.0), (a, b, 2.9, 3.95)) for a, b in strips]))
std = rows[0]
md = []
w = md.append
w('Scene `scenes/generated/doorslit.obj`, camera `%s`, `--res 160x120 --maxdepth 16 --photons %s`; '
  'pictures of pass 0 from above (`candela photons`), the light\'s room on the left (x < 4), the '
  'shared wall at x in [4.0, 4.2] with the slit, the camera\'s room on the right.\n' % (cam, n))
if rows[1]['imp']:
    ni, npaths, f = rows[1]['imp']
    w('Importons: %s from %s paths, f = %s (the picture: `pm-fig4-importons.png`).\n' % (ni, npaths, f))
w('| map | options | stored | photon paths | paths / standard | hits | MiB | time s | camera room | '
  'light room: behind the wall | light room: door and slit | light room: rest |')
w('|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|')
for r in rows:
    w('| %s | `%s` | %d | %d | %.1f | %d | %.2f | %.2f | %.0f | %.0f | %.0f | %.0f |' % (
        r['name'], r['args'] or '-', r['stored'], r['paths'], r['paths'] / std['paths'], r['hits'], r['mib'],
        r['t'], r['cam'], r['behind'], r['door'], r['rest']))
w('\nThe last four columns: dots per m² of the plan, a dot being a pixel of the 800-pixel-wide plan that holds at least one photon; they saturate where '
  'photons are dense, so they compare where photons are sparse. Total time %s s.\n' % secs)
w('Dots per m² in the light\'s room by distance from the shared wall (its face at x = 4.0; z outside [1.0, 2.9], '
  'away from the door and the slit). The importon query radius is 5 % of the scene diagonal, 0.51 m, so '
  'importons on the camera\'s side of the 0.2 m wall reach 0.31 m into the light\'s room. The face column is '
  'denser in every map because the wall face is a line in the plan; the last column compares it with the '
  'standard map:\n')
w('| map | wall face (0-3 cm) | ' + ' | '.join('%.2f-%.2f m' % (4.0 - b, 4.0 - a) for a, b in strips[1:]) +
  ' | face / (1-2 m), relative to standard |')
w('|---|' + '---:|' * (len(strips) + 1))
rel = lambda r: r['profile'][0] / r['profile'][-1] if r['profile'][-1] else float('inf')
for r in rows:
    w('| %s | ' % r['name'] + ' | '.join('%.0f' % v for v in r['profile']) + ' | %s |' % (
        '%.2f' % (rel(r) / rel(std)) if r['profile'][-1] else '- (none beyond)'))
open(os.path.join(out, 'results.md'), 'w').write('\n'.join(md) + '\n')
print('\n'.join(md))
EOF

e1=${epss%%,*}
cp "$out/importance-eps$e1.importons.png" "$here/docs/pm-fig4-importons.png"
cp "$out/standard.png" "$here/docs/pm-fig4-standard.png"
for eps in ${epss//,/ }; do
  cp "$out/importance-eps$eps.png" "$here/docs/pm-fig4-importance-eps$eps.png"
  cp "$out/importance-discard$eps.png" "$here/docs/pm-fig4-importance-discard$eps.png"
done
