#!/usr/bin/python3
"""Two methods on the Cornell box, their error against the reference after
every pass, plotted against render time (the README's Python example).

    PYTHONPATH=python examples/error_vs_time.py [OUT.png]
"""
import sys

import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

import candela  # noqa: E402

scene = candela.Scene("scenes/cornell-box/CornellBox-Original.obj")
ref = candela.read("../shared/references/mcguire-cornell-original_path_256.exr")
camera = dict(res=(256, 256), lookat=(0, 1, 3.9, 0, 1, 0, 0, 1, 0), fov=39.3077)

for method, opts in (("path", {}), ("pm", {"photons": 50000})):
    times, errors = [], []
    with candela.Renderer(scene, integrator=method, **camera, **opts) as r:
        while r.stats().get("seconds", 0.0) < 4.0:  # 4 s each
            r.render_passes(1)
            times.append(r.stats()["seconds"])
            errors.append(candela.diff(r.image(), ref)["relmse"])
    plt.loglog(times, errors, marker=".", label=method)
    print(f"{method}: {len(times)} passes, relMSE {errors[-1]:.2e} after {times[-1]:.1f} s")

plt.xlabel("render time (s)")
plt.ylabel("relMSE against the reference")
plt.legend()
plt.savefig(sys.argv[1] if len(sys.argv) > 1 else "error_vs_time.png", dpi=100)
