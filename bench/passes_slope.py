#!/usr/bin/python3
"""relMSE against passes on the Cornell box (McGuire's, 256x256, maxdepth 64):
snapshots of one progressive render after 4, 16, 64 and 256 passes (seed 1)
against ../shared/references/mcguire-cornell-original_path_256.exr, with the
slope of log relMSE per log passes between snapshots (-1: Monte Carlo's 1/N;
progressive photon mapping at alpha = 2/3 reaches -2/3).

  CANDELA_LIBRARY=build/libcandela.so PYTHONPATH=python \\
    /usr/bin/python3 bench/passes_slope.py METHOD [CANDELA ARGS...]
"""
import os
import sys

import numpy as np

import candela

HERE = os.path.dirname(os.path.abspath(__file__))
SHARED = os.path.join(HERE, "..", "..", "shared")


def relmse(t, r):
    return float(np.mean((t - r) ** 2 / (r ** 2 + 0.01)))


def block(t, r, bs=8):
    h, w = r.shape[:2]
    a = t.reshape(h // bs, bs, w // bs, bs, 3).sum(axis=(1, 3, 4))
    b = r.reshape(h // bs, bs, w // bs, bs, 3).sum(axis=(1, 3, 4))
    return float(np.median(a / b))


def main():
    if len(sys.argv) < 2:
        sys.exit(__doc__)
    method = sys.argv[1]
    ref = candela.read(os.path.join(SHARED, "references", "mcguire-cornell-original_path_256.exr"))
    scene = candela.Scene(os.path.join(SHARED, "scenes", "cornell-box-mcguire", "CornellBox-Original.obj"), quiet=True)
    args = ["--lookat", "0,1,3.9,0,1,0,0,1,0", "--fov", "39.3077", "--maxdepth", "64", "-i", method] + sys.argv[2:]
    prev = None
    with candela.Renderer(scene, args=args, res=(256, 256), seed=1, quiet=True) as r:
        for k in (4, 16, 64, 256):
            r.render_passes(k - r.passes)
            img = r.image()
            e = relmse(img, ref)
            slope = "  slope %.2f" % (np.log(e / prev) / np.log(4)) if prev else ""
            print("%s %4d passes %6.1f s  relMSE %.3e  block median %.4f  mean %.4f%s"
                  % (method, k, r.stats()["seconds"], e, block(img, ref), img.mean() / ref.mean(), slope))
            prev = e


if __name__ == "__main__":
    main()
