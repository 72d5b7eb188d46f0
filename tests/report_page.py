#!/usr/bin/python3
"""The comparison page of bench/compare --html (issue 30) in headless Chromium.

Renders the Cornell box at 64x64 with path, bdpt and pm at three short
budgets, opens the page with a self-test hash (index.html#selftest=...) that
switches the method with the number key, the budget by clicking the plot
point and the exposure with its slider (the code paths of the UI), and reads
back a pixel of the viewer canvas; then it presses every other key once and
wheels, drags and clicks an inset and a thumbnail. Checks: no script or console errors, the
page ready in under a second (performance.now() at the end of its start-up),
and the canvas pixel equals the sRGB tonemap of value x 2^exposure computed
here from that method's EXR, within 2/255, at a pixel where the other images
differ from it by more (so the check can tell the images apart). The same for
the page bench/report.py makes from the renders directory.
usage: report_page.py REPO_DIR CANDELA SHARED_DIR  (CHROMIUM=path overrides the browser)
"""

import json
import html
import math
import os
import re
import shutil
import subprocess
import sys
import tempfile

TOL = 2  # of 255: half-float storage and rounding
LOAD_LIMIT_MS = 1000.0
failures = []


def ok(msg):
    print(f"ok  : {msg}")


def bad(msg):
    print(f"FAIL: {msg}")
    failures.append(msg)


def srgb8(v):
    v = 12.92 * v if v <= 0.0031308 else 1.055 * v ** (1 / 2.4) - 0.055
    return 0 if v <= 0 else 255 if v >= 1 else int(math.floor(v * 255 + 0.5))


def run_page(chromium, index, spec, tmp):
    """Opens index.html#selftest=spec; returns (result dict or None, console lines)."""
    url = "file://" + os.path.abspath(index) + "#selftest=" + spec
    cmd = [chromium, "--headless", "--no-sandbox", "--disable-gpu", "--enable-logging=stderr", "--v=0",
           f"--user-data-dir={tmp}/chromium-profile", "--dump-dom", url]
    p = subprocess.run(cmd, capture_output=True, text=True, timeout=90)
    console = [l for l in p.stderr.splitlines() if ":CONSOLE" in l]
    m = re.search(r'<pre id="selftest-result"[^>]*>(.*?)</pre>', p.stdout, re.S)
    if not m or not m.group(1).strip():
        return None, console + [f"chromium exit {p.returncode}, no self-test result in the DOM"]
    return json.loads(html.unescape(m.group(1))), console


def pick_pixel(cdl, images, method_file, exposure):
    """A pixel where the chosen image is mid-grey after tonemapping and every
    other image differs there by more than TOL in some channel."""
    import numpy as np
    scale = 2.0 ** exposure
    chosen = images[method_file]
    best, best_score = None, None
    h, w = chosen.shape[:2]
    for y in range(2, h - 2):
        for x in range(2, w - 2):
            v = [srgb8(float(c) * scale) for c in chosen[y, x]]
            if min(v) < 20 or max(v) > 235:
                continue
            others_differ = all(
                max(abs(srgb8(float(c) * scale) - a) for c, a in zip(img[y, x], v)) > TOL
                for f, img in images.items() if f != method_file)
            if not others_differ:
                continue
            sep = min(max(abs(srgb8(float(c) * scale) - a) for c, a in zip(img[y, x], v))
                      for f, img in images.items() if f != method_file)
            score = (sep, -abs(float(np.mean(v)) - 128))  # the most distinctive, then mid-grey
            if best_score is None or score > best_score:
                best, best_score = (x, y), score
    return best


def check_page(label, chromium, index, cdl, exr_dir, ref_path, method, budget, exposure, tmp, ids_expected):
    names = {f: cdl.read(os.path.join(exr_dir, f)) for f in os.listdir(exr_dir) if f.endswith(".exr")}
    target = f"{method}_{budget:g}s_seed1.exr"
    if target not in names:
        bad(f"{label}: {target} not kept in {exr_dir}")
        return
    names["reference.exr"] = cdl.read(ref_path)
    xy = pick_pixel(cdl, names, target, exposure)
    if xy is None:
        bad(f"{label}: no pixel of {target} that the other images do not share (test setup)")
        return
    x, y = xy
    spec = f"method:{method},budget:{budget:g},exposure:{exposure:g},x:{x},y:{y}"
    res, console = run_page(chromium, index, spec, tmp)
    if res is None:
        bad(f"{label}: {'; '.join(console)}")
        return
    if res.get("error"):
        bad(f"{label}: self-test failed in the page: {res['error']} {res.get('errors')}")
        return
    errs = res.get("errors", []) + console
    if not res.get("keys_exercised"):
        bad(f"{label}: the self-test did not exercise the other controls")
    if errs:
        bad(f"{label}: script/console errors: {errs}")
    else:
        ok(f"{label}: no script or console errors")
    ready = res.get("ready_ms", 1e9)
    msg = (f"{label}: page ready {ready:.0f} ms after navigation start (scripts loaded "
           f"{res.get('scripts_loaded_ms', 0):.0f} ms, data decoded {res.get('decoded_ms', 0):.0f} ms)")
    ok(msg) if ready < LOAD_LIMIT_MS else bad(msg + f", limit {LOAD_LIMIT_MS:.0f} ms")
    if sorted(res.get("images", [])) == sorted(ids_expected):
        ok(f"{label}: the page holds the reference and the {len(ids_expected) - 1} renders")
    else:
        bad(f"{label}: images {res.get('images')}, expected {ids_expected}")
    want_id = f"{method}_{budget:g}"
    if res.get("shown") == want_id and abs(res.get("exposure", 99) - exposure) < 1e-9:
        ok(f"{label}: after {', '.join(res.get('steps', []))}: shows {want_id} at exposure {exposure:g}")
    else:
        bad(f"{label}: shows {res.get('shown')} at exposure {res.get('exposure')}, "
            f"expected {want_id} at {exposure:g} (steps {res.get('steps')})")
    value = names[target][y, x]
    expect = [srgb8(float(c) * 2.0 ** exposure) for c in value]
    got = res.get("canvas", [])
    diff = max(abs(a - b) for a, b in zip(got, expect)) if len(got) == 3 else 999
    others = min(max(abs(srgb8(float(c) * 2.0 ** exposure) - g) for c, g in zip(img[y, x], got))
                 for f, img in names.items() if f != target) if len(got) == 3 else 0
    msg = (f"{label}: canvas pixel ({x}, {y}) = {got}, tonemap of the EXR value "
           f"{[round(float(c), 5) for c in value]} x 2^{exposure:g} = {expect} (off by {diff}/255; "
           f"the nearest other image is {others}/255 away)")
    ok(msg) if diff <= TOL and others > TOL else bad(msg + f", tolerance {TOL}/255")


def main(argv):
    if len(argv) != 3:
        print("usage: report_page.py REPO_DIR CANDELA SHARED_DIR", file=sys.stderr)
        return 2
    repo, candela, shared = argv
    chromium = os.environ.get("CHROMIUM") or shutil.which("chromium") or "/usr/bin/chromium"
    if not (os.path.isfile(chromium) and os.access(chromium, os.X_OK)):
        print("FAIL: chromium is not installed (Debian package chromium: run tools/install-deps.sh); "
              "the page cannot be checked")
        return 1
    os.environ["CANDELA_LIBRARY"] = os.path.join(os.path.dirname(os.path.abspath(candela)), "libcandela.so")
    sys.path.insert(0, os.path.join(repo, "python"))
    import candela as cdl
    tmp = tempfile.mkdtemp(prefix="report_page.")
    try:
        out = os.path.join(tmp, "out")
        ref = os.path.join(shared, "references", "mcguire-cornell-original_path_256.exr")
        budgets = (0.2, 0.4, 0.8)
        methods = ("path", "bdpt", "pm")
        cmd = [os.path.join(repo, "bench", "compare"),
               "--scene", os.path.join(shared, "scenes", "cornell-box-mcguire", "CornellBox-Original.obj"),
               "--ref", os.path.join(tmp, "ref64.exr"), "--res", "64x64",
               "--render-args", "--lookat 0,1,3.9,0,1,0,0,1,0 --fov 39.3077",
               "--times", ",".join(f"{b:g}" for b in budgets), "--target", "auto",
               "--candela", candela, "--html", "--inset", "20,40,36,56", "--inset", "4,4,60,20", "--out", out]
        for m in methods:
            cmd += ["--config", f"{m}=-i {m}"]
        # The 256x256 reference box-filtered to 64x64 (4x4 pixel means).
        r = cdl.read(ref)
        cdl.write(os.path.join(tmp, "ref64.exr"), r.reshape(64, 4, 64, 4, 3).mean(axis=(1, 3)))
        p = subprocess.run(cmd, capture_output=True, text=True, timeout=300)
        if p.returncode != 0:
            bad(f"bench/compare --html exited {p.returncode}: {p.stderr.strip().splitlines()[-1:]}")
            return 1
        ok("bench/compare --html ran")
        index = os.path.join(out, "index.html")
        renders = os.path.join(out, "renders")
        kept = sorted(f for f in os.listdir(renders) if f.endswith(".exr"))
        want = sorted([f"{m}_{b:g}s_seed1.exr" for m in methods for b in budgets] + ["reference.exr"])
        ok("renders/ keeps the 9 seed-1 EXRs and the reference") if kept == want else bad(f"renders/ holds {kept}")
        with open(os.path.join(out, "results.csv"), encoding="utf-8") as f:
            header = f.readline().strip().split(",")
        has_flip = getattr(cdl, "flip", None) is not None
        if ("flip" in header) == has_flip:
            ok(f"results.csv {'has' if has_flip else 'has no'} flip column, as candela.flip is "
               f"{'present' if has_flip else 'absent'}")
        else:
            bad(f"results.csv header {header} with candela.flip {'present' if has_flip else 'absent'}")
        ids = ["reference"] + [f"{m}_{b:g}" for m in methods for b in budgets]
        check_page("compare page", chromium, index, cdl, renders, os.path.join(tmp, "ref64.exr"),
                   "bdpt", 0.4, 1.5, tmp, ids)

        out2 = os.path.join(tmp, "dirpage")
        p = subprocess.run([os.path.join(repo, "bench", "report.py"), renders, "--ref",
                            os.path.join(renders, "reference.exr"), "--out", out2, "--candela", candela,
                            "--inset", "20,40,36,56"], capture_output=True, text=True, timeout=120)
        if p.returncode != 0:
            bad(f"bench/report.py exited {p.returncode}: {p.stderr.strip().splitlines()[-1:]}")
        else:
            ok("bench/report.py on the renders directory ran")
            # the first image with a pixel no other image shares: a method
            # that converges fast enough matches the reference everywhere
            # within TOL at its longest budget (path did at 0.8 s once
            # it traced 0.71 of raw Embree's rays per second)
            names = {f: cdl.read(os.path.join(renders, f)) for f in os.listdir(renders) if f.endswith(".exr")}
            pick = next(((m, b) for b in sorted(budgets, reverse=True) for m in methods
                         if f"{m}_{b:g}s_seed1.exr" in names and
                         pick_pixel(cdl, names, f"{m}_{b:g}s_seed1.exr", -1.0) is not None), ("path", 0.8))
            check_page("directory page", chromium, os.path.join(out2, "index.html"), cdl, renders,
                       os.path.join(renders, "reference.exr"), pick[0], pick[1], -1.0, tmp, ids)
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    print(f"{len(failures)} failure(s)" if failures else "all checks passed")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
