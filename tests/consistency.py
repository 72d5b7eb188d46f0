#!/usr/bin/python3
"""Issue 25's tests: the density-estimation methods converge to the right image.

  bias SCENE REF METHOD N [OPTIONS]
      one render of METHOD at its defaults (OPTIONS added) on an interior of
      scenes/generated, snapshots after N and 4N passes (seed 1, 160x120,
      maxdepth 16): against the path reference REF, the median over 8x8-pixel
      blocks of the block ratio must move towards 1 (or already be within 1 %
      of it) and the relative MSE must fall.
  sealed SCENE METHOD [OPTIONS]
      a few passes of METHOD on a sealed-room scene (the camera in the room
      no light path can enter): every pixel exactly 0.

Run through ctest (tests/CMakeLists.txt), with PYTHONPATH at python/ and
CANDELA_LIBRARY at the build's libcandela.so.
"""
import os
import sys

import numpy as np

import candela

GEN = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "scenes", "generated")


def scene_args(name):
    with open(os.path.join(GEN, name + ".cam")) as f:
        return f.read().split()


def block_ratio(test, ref, bs=8):
    h, w = ref.shape[:2]
    hb, wb = h // bs * bs, w // bs * bs
    t = test[:hb, :wb].reshape(hb // bs, bs, wb // bs, bs, 3).sum(axis=(1, 3, 4))
    r = ref[:hb, :wb].reshape(hb // bs, bs, wb // bs, bs, 3).sum(axis=(1, 3, 4))
    ok = r / (bs * bs * 3) >= 1e-6
    return float(np.median(t[ok] / r[ok]))


def relmse(test, ref):
    return float(np.mean((test - ref) ** 2 / (ref ** 2 + 0.01)))


def bias(name, refpath, method, n, extra):
    ref = candela.read(refpath)
    scene = candela.Scene(os.path.join(GEN, name + ".obj"), quiet=True)
    out = []
    with candela.Renderer(scene, args=scene_args(name) + ["-i", method] + extra, res=(160, 120), maxdepth=16,
                          seed=1, quiet=True) as r:
        for k in (n, 4 * n):
            r.render_passes(k - r.passes)
            img = r.image()
            out.append((block_ratio(img, ref), relmse(img, ref), r.stats()["seconds"]))
    (b1, e1, t1), (b4, e4, t4) = out
    print("%s -i %s %s: %d passes block %.4f relMSE %.4g (%.1f s); %d passes block %.4f relMSE %.4g (%.1f s)"
          % (name, method, " ".join(extra), n, b1, e1, t1, 4 * n, b4, e4, t4))
    ok = True
    if not (abs(1 - b4) < abs(1 - b1) or abs(1 - b4) < 0.01):
        print("FAIL: the block-median bias did not shrink from %d to %d passes" % (n, 4 * n))
        ok = False
    if not e4 < e1:
        print("FAIL: relMSE did not fall from %d to %d passes" % (n, 4 * n))
        ok = False
    return ok


def sealed(name, method, extra):
    scene = candela.Scene(os.path.join(GEN, name + ".obj"), quiet=True)
    with candela.Renderer(scene, args=scene_args(name) + ["-i", method] + extra, res=(80, 60), maxdepth=16,
                          seed=1, quiet=True) as r:
        r.render_passes(2)
        img = r.image()
    lit = int((img > 0).any(axis=2).sum())
    print("%s -i %s %s: largest pixel %.3g, %d pixels lit" % (name, method, " ".join(extra), img.max(), lit))
    if lit:
        print("FAIL: light in the sealed room")
    return lit == 0


def main():
    a = sys.argv[1:]
    if len(a) >= 4 and a[0] == "bias":
        ok = bias(a[1], a[2], a[3], int(a[4]), a[5:])
    elif len(a) >= 3 and a[0] == "sealed":
        ok = sealed(a[1], a[2], a[3:])
    else:
        sys.exit(__doc__)
    sys.exit(0 if ok else 1)


if __name__ == "__main__":
    main()
