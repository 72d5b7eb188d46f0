#!/usr/bin/python3
"""Interactive comparison page for a set of renders against a reference (issue 30).

Writes OUT/index.html and OUT/assets/: open index.html in a browser (it works
from a file:// URL, with no network). The float data of every image is
embedded in .js files (base64 of half floats, loaded by <script src>: Chromium
forbids fetch() and canvas readback of file:// images), so the page tonemaps
the HDR data itself (value x 2^exposure, sRGB, clamped) and computes the
per-pixel relMSE maps from it; FLIP maps, when candela.flip exists, are
embedded as PNG data. bench/compare --html makes the same page from its runs.

usage: bench/report.py DIR --ref REF.exr --out OUTDIR [--inset X0,Y0,X1,Y1]...

Images in DIR (*.exr; the reference itself is skipped if it lies there):
  METHOD_BUDGET.exr        e.g. path_0.5s.exr, bdpt_2.exr: METHOD at a time
                           budget of BUDGET seconds (the trailing 's' is
                           optional); an optional _seedN before .exr is
                           allowed and only the lowest seed of a
                           METHOD_BUDGET is shown
  any other name           a method of its own, without budget
With budgets, the error plots put the budget on the time axis (DIR holds no
measured times); without, the page has no plot. Values beyond the half-float
range (65504) are clamped in the page's copy of the data; the metrics are
computed from the EXRs at full precision.

Controls (also listed on the page): 1-9 choose the method (1 = reference),
left/right the previous/next method, up/down the budget, space swaps the shown
image A with the comparison image B (shift+key or shift+click chooses B), s
toggles the split view, d side by side, i/m/f image / relMSE map / FLIP map,
[ and ] change the exposure by half a stop, wheel or +/- zoom (integer
factors, nearest neighbour), drag pans, z fits the view.
"""

import argparse
import base64
import json
import math
import os
import re
import shutil
import sys

PROG = "report"
HERE = os.path.dirname(os.path.abspath(__file__))
TEMPLATES = os.path.join(HERE, "report")
DEFAULT_CANDELA = os.path.normpath(os.path.join(HERE, "..", "build", "candela"))
HALF_MAX = 65504.0
NAME_RE = re.compile(r"^(?P<method>.+?)_(?P<budget>[0-9]+(?:\.[0-9]*)?(?:e[-+]?[0-9]+)?)s?"
                     r"(?:_seed(?P<seed>[0-9]+))?$")
INSET_RE = re.compile(r"^\s*(\d+)\s*,\s*(\d+)\s*,\s*(\d+)\s*,\s*(\d+)\s*$")
NO_FLIP_NOTE = ("FLIP is not available: this build of the candela Python package has no "
                "candela.flip, so the FLIP column, plot and maps are left out.")


class ReportError(Exception):
    """A user-facing failure: one line, exit status 1."""


def parse_inset(text, width, height):
    """'X0,Y0,X1,Y1' in pixels, X1 and Y1 exclusive, inside the image."""
    m = INSET_RE.match(text)
    if not m:
        raise ReportError(f"--inset: expected X0,Y0,X1,Y1 (pixels), got '{text}'")
    x0, y0, x1, y1 = (int(v) for v in m.groups())
    if not (x0 < x1 <= width and y0 < y1 <= height):
        raise ReportError(f"--inset: {text} is not a non-empty region inside the "
                          f"{width}x{height} image (X1, Y1 exclusive)")
    return [x0, y0, x1, y1]


def load_candela(candela_exe):
    """The Python package over the libcandela.so next to the candela executable."""
    lib = os.path.join(os.path.dirname(os.path.abspath(candela_exe)), "libcandela.so")
    if not os.path.isfile(lib):
        raise ReportError(f"no libcandela.so next to {candela_exe} (see --candela)")
    os.environ.setdefault("CANDELA_LIBRARY", lib)
    sys.path.insert(0, os.path.join(HERE, "..", "python"))
    import candela  # noqa: E402 (needs CANDELA_LIBRARY)
    return candela


def flip_function(cdl):
    """candela.flip when this build has it (issue 30 part 1), else None."""
    return getattr(cdl, "flip", None)


def measure_flip(cdl, image, ref, map_png=None):
    """Mean HDR-FLIP of image against ref; with map_png, also writes the
    coloured map there (a PNG at exposure 0). None without candela.flip."""
    flip = flip_function(cdl)
    if flip is None:
        return None
    if map_png is None:
        return float(flip(image, ref, hdr=True))
    mean, fmap = flip(image, ref, hdr=True, map=True)
    write_atomic_via(map_png, lambda tmp: cdl.write(tmp, fmap, exposure=0.0))
    return float(mean)


def write_atomic_via(path, writer):
    """Calls writer(tmp) and renames tmp to path, so readers never see half a file."""
    root, ext = os.path.splitext(path)
    tmp = f"{root}.tmp{os.getpid()}{ext}"
    try:
        writer(tmp)
        os.replace(tmp, path)
    finally:
        if os.path.exists(tmp):
            os.remove(tmp)


def write_text(path, text):
    def w(tmp):
        with open(tmp, "w", encoding="utf-8") as f:
            f.write(text)
    write_atomic_via(path, w)


def half_base64(image):
    """The image as base64 of little-endian half floats, clamped to the half range."""
    import numpy as np
    a = np.nan_to_num(np.asarray(image, dtype=np.float32), nan=0.0,
                      posinf=HALF_MAX, neginf=-HALF_MAX)
    a = np.clip(a, -HALF_MAX, HALF_MAX).astype("<f2")
    return base64.b64encode(a.tobytes()).decode("ascii")


def png_data_url(path):
    with open(path, "rb") as f:
        return "data:image/png;base64," + base64.b64encode(f.read()).decode("ascii")


def js_assign(var, key, value):
    return f"{var}[{json.dumps(key)}] = {json.dumps(value, separators=(',', ':'))};\n"


def write_page(out, ref_image, entries, title, insets=(), flip_available=False, notes=(),
               time_label="budget (s)"):
    """Writes out/index.html and out/assets/.

    entries: dicts with method, budget (seconds or None), image (H x W x 3
    float array), and optionally time (the plot's x), spp, seconds, relmse,
    flip, flip_png (path of the coloured FLIP map). Methods keep their first
    appearance order; the reference comes first."""
    h, w = ref_image.shape[:2]
    for e in entries:
        if e["image"].shape[:2] != (h, w):
            raise ReportError(f"{e['method']}: image is {e['image'].shape[1]}x{e['image'].shape[0]}, "
                              f"the reference {w}x{h}")
    assets = os.path.join(out, "assets")
    data_dir = os.path.join(assets, "data")
    os.makedirs(data_dir, exist_ok=True)
    methods = []
    for e in entries:
        if e["method"] not in methods:
            methods.append(e["method"])
    order = sorted(entries, key=lambda e: (methods.index(e["method"]),
                                           e["budget"] if e["budget"] is not None else -1))
    images = [dict(id="reference", label="reference", method="reference", budget=None)]
    raws = [dict(rgb=half_base64(ref_image))]
    for e in order:
        b = e["budget"]
        ident = e["method"] if b is None else f"{e['method']}_{b:g}"
        label = e["method"] if b is None else f"{e['method']} {b:g} s"
        item = dict(id=ident, label=label, method=e["method"], budget=b)
        for k in ("time", "spp", "seconds", "relmse", "flip"):
            v = e.get(k)
            item[k] = v if v is None or not isinstance(v, float) or math.isfinite(v) else None
        images.append(item)
        raw = dict(rgb=half_base64(e["image"]))
        if e.get("flip_png") and os.path.isfile(e["flip_png"]):
            raw["flip"] = png_data_url(e["flip_png"])
        raws.append(raw)
    ids = [im["id"] for im in images]
    dup = sorted({i for i in ids if ids.count(i) > 1})
    if dup:
        raise ReportError(f"two images named '{dup[0]}' (method and budget)")
    scripts = []
    for k, raw in enumerate(raws):
        name = f"data/{k}.js"
        images[k]["src"] = name
        write_text(os.path.join(assets, name), js_assign("CDL_RAW", k, raw))
        scripts.append(name)
    page = dict(title=title, width=w, height=h, methods=["reference"] + methods,
                budgets=sorted({e["budget"] for e in entries if e["budget"] is not None}),
                images=images, insets=[list(r) for r in insets], flip=bool(flip_available),
                flipNote="" if flip_available else NO_FLIP_NOTE, notes=list(notes),
                timeLabel=time_label)
    write_text(os.path.join(assets, "page.js"),
               "window.CDL_RAW = {};\nwindow.CDL_PAGE = "
               + json.dumps(page, indent=1) + ";\n")
    for name in ("report.js", "report.css"):
        shutil.copyfile(os.path.join(TEMPLATES, name), os.path.join(assets, name + ".tmp"))
        os.replace(os.path.join(assets, name + ".tmp"), os.path.join(assets, name))
    with open(os.path.join(TEMPLATES, "index.html"), encoding="utf-8") as f:
        html = f.read()
    tags = "\n".join(f'<script src="assets/{s}"></script>' for s in scripts)
    html = html.replace("{{TITLE}}", escape_html(title)).replace("{{DATA_SCRIPTS}}", tags)
    write_text(os.path.join(out, "index.html"), html)
    return os.path.join(out, "index.html")


def escape_html(text):
    return (text.replace("&", "&amp;").replace("<", "&lt;").replace(">", "&gt;")
            .replace('"', "&quot;"))


def scan_dir(path, ref_path):
    """(method, budget or None, seed, file) for every EXR in path but the reference."""
    if not os.path.isdir(path):
        raise ReportError(f"{path}: not a directory")
    ref_real = os.path.realpath(ref_path)
    found = {}
    for name in sorted(os.listdir(path)):
        full = os.path.join(path, name)
        if not name.lower().endswith(".exr") or os.path.realpath(full) == ref_real:
            continue
        stem = name[:-4]
        m = NAME_RE.match(stem)
        if m:
            method, budget, seed = m["method"], float(m["budget"]), int(m["seed"] or 0)
            if not (budget > 0 and math.isfinite(budget)):
                method, budget, seed = stem, None, 0
        else:
            method, budget, seed = stem, None, 0
        key = (method, budget)
        if key not in found or seed < found[key][2]:
            found[key] = (method, budget, seed, full)
    if not found:
        raise ReportError(f"{path}: no .exr images besides the reference")
    return list(found.values())


def parse_args(argv):
    p = argparse.ArgumentParser(prog="bench/report.py", description=__doc__.split("\n\n", 1)[0],
                                epilog=__doc__.split("\n\n", 1)[1],
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("dir", help="directory of EXR renders")
    p.add_argument("--ref", required=True, help="reference image (EXR), same size")
    p.add_argument("--out", required=True, help="output directory (created)")
    p.add_argument("--inset", action="append", default=[], metavar="X0,Y0,X1,Y1",
                   help="a region shown magnified for every image; repeatable")
    p.add_argument("--title", help="page title (default: the directory name)")
    p.add_argument("--candela", default=DEFAULT_CANDELA,
                   help="candela executable whose libcandela.so is used (default: build/candela)")
    return p.parse_args(argv)


def main(argv):
    opt = parse_args(argv)
    try:
        if not os.path.isfile(opt.ref):
            raise ReportError(f"--ref: no such file: {opt.ref}")
        found = scan_dir(opt.dir, opt.ref)
        cdl = load_candela(opt.candela)
        try:
            ref = cdl.read(opt.ref)
        except cdl.Error as e:
            raise ReportError(f"--ref: {e}") from None
        h, w = ref.shape[:2]
        insets = [parse_inset(t, w, h) for t in opt.inset]
        flip = flip_function(cdl)
        flip_dir = os.path.join(opt.out, "assets", "flip")
        os.makedirs(flip_dir, exist_ok=True)
        entries = []
        for k, (method, budget, _, path) in enumerate(found):
            try:
                img = cdl.read(path)
                d = cdl.diff(img, ref)
            except cdl.Error as e:
                raise ReportError(f"{path}: {e}") from None
            png = os.path.join(flip_dir, f"{k}.png") if flip else None
            entries.append(dict(method=method, budget=budget, image=img, time=budget,
                                relmse=d["relmse"], flip=measure_flip(cdl, img, ref, png),
                                flip_png=png))
            print(f"[{k + 1}/{len(found)}] {os.path.basename(path)}: relmse {d['relmse']:.4e}",
                  file=sys.stderr)
        title = opt.title or os.path.basename(os.path.normpath(opt.dir))
        page = write_page(opt.out, ref, entries, title, insets, flip is not None,
                          notes=[f"Images from {opt.dir}, reference {opt.ref}."])
    except ReportError as e:
        print(f"{PROG}: error: {e}", file=sys.stderr)
        return 1
    except OSError as e:
        print(f"{PROG}: error: {e.filename or ''}: {e.strerror}", file=sys.stderr)
        return 1
    print(f"{PROG}: wrote {page}", file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
