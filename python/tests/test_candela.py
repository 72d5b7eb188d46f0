"""The Python package against the command line and the C API's promises.

Environment: CANDELA_LIBRARY (libcandela.so), CANDELA_CLI (the candela
binary) and CANDELA_SOURCE (the repository, for its scenes); without them the
source tree's build/ is used."""

import os
import signal
import subprocess
import threading

import numpy as np
import pytest

import candela

SRC = os.environ.get("CANDELA_SOURCE", os.path.join(os.path.dirname(__file__), "..", ".."))
CLI = os.environ.get("CANDELA_CLI", os.path.join(SRC, "build", "candela"))
BOX = os.path.join(SRC, "scenes", "cornell-box", "CornellBox-Original.obj")
CAM = dict(lookat=(0, 1, 3.9, 0, 1, 0, 0, 1, 0), fov=39.3077)
CAM_ARGS = ["--lookat", "0,1,3.9,0,1,0,0,1,0", "--fov", "39.3077"]
BAD_PBRT = os.path.join(SRC, "tests", "bad_pbrt", "bool_not_bool.pbrt")

# Per method: options that keep a pass short on a 48x48 box.
FAST = {
    "path": {},
    "bdpt": {},
    "rigi": {"light_paths": 64, "interleave": 2},
    "pm": {"photons": 5000, "gather": 2},
    "sppm": {"photons": 5000},
    "vcm": {"vcm_mode": "full"},
}


def cli_args(opts):
    out = []
    for k, v in opts.items():
        out += ["--" + k.replace("_", "-"), str(v)]
    return out


@pytest.fixture(scope="module")
def box():
    with candela.Scene(BOX) as s:
        yield s


@pytest.mark.parametrize("integ", sorted(FAST))
def test_bit_identical_to_cli(tmp_path, box, integ):
    out = tmp_path / "cli.exr"
    cmd = [CLI, "render", BOX, "-i", integ, "--res", "48x48", "--spp", "3", "--seed", "7", "-q", "-o", str(out)]
    subprocess.run(cmd + CAM_ARGS + cli_args(FAST[integ]), check=True, capture_output=True)
    ref = candela.read(out)
    img = candela.render(box, integrator=integ, res=(48, 48), spp=3, seed=7, **CAM, **FAST[integ])
    assert img.dtype == np.float32 and img.shape == (48, 48, 3)
    assert img.mean() > 0.01
    assert np.array_equal(img, ref), f"{integ}: max difference {np.abs(img - ref).max()}"


def test_seed_changes_image(box):
    a = candela.render(box, res=(32, 32), spp=2, seed=1, **CAM)
    b = candela.render(box, res=(32, 32), spp=2, seed=2, **CAM)
    assert not np.array_equal(a, b)


def test_bad_scene_names_file_and_line():
    with pytest.raises(candela.InputError) as e:
        candela.Scene(BAD_PBRT)
    assert e.value.file.endswith("bool_not_bool.pbrt") and e.value.line == 6
    assert "bool_not_bool.pbrt:6:" in str(e.value)


def test_missing_scene():
    with pytest.raises(candela.Error) as e:
        candela.Scene("/nonexistent/box.obj")
    assert "/nonexistent/box.obj" in e.value.file


def test_unknown_option_raises_before_rendering(box):
    called = []
    with pytest.raises(candela.UsageError) as e:
        candela.render(box, spp=64, res=(512, 512), no_such_option=3, progress=lambda *a: called.append(a))
    assert "no-such-option" in e.value.file or "no_such_option" in e.value.file
    assert not called
    with pytest.raises(candela.UsageError) as e:
        candela.render(box, integrator="pm", photons=-5)
    assert "photons" in e.value.file
    with pytest.raises(candela.UsageError):
        candela.render(box, integrator="no-such-method")
    with pytest.raises(candela.UsageError):
        candela.render(box, spp=4, time=1.0)


def test_two_threads_same_images(box):
    jobs = [dict(integrator="path", seed=3), dict(integrator="pm", photons=5000, seed=4)]
    common = dict(res=(40, 40), spp=3, threads=1, **CAM)
    alone = [candela.render(box, **j, **common) for j in jobs]
    together = [None, None]

    def run(i):
        together[i] = candela.render(box, **jobs[i], **common)

    threads = [threading.Thread(target=run, args=(i,)) for i in range(2)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    for a, b in zip(alone, together):
        assert np.array_equal(a, b)


def test_cancel_from_callback_keeps_partial_image(box):
    seen = []

    def progress(passes, seconds, fraction):
        seen.append(passes)
        return passes >= 2  # stop after the second pass

    with candela.Renderer(box, res=(40, 40), spp=1000, **CAM) as r:
        r.render(progress=progress)
        assert r.cancelled and r.passes == 2 and seen == [1, 2]
        img = r.image()
        two = candela.render(box, res=(40, 40), spp=2, **CAM)
        assert np.array_equal(img, two)


def test_ctrl_c_raises_keyboard_interrupt_with_image(box):
    def progress(passes, seconds, fraction):
        if passes == 2:
            os.kill(os.getpid(), signal.SIGINT)

    with candela.Renderer(box, res=(40, 40), spp=1000, **CAM) as r:
        with pytest.raises(KeyboardInterrupt) as e:
            r.render(progress=progress)
        assert 2 <= r.passes <= 3
        assert e.value.image.shape == (40, 40, 3) and e.value.image.mean() > 0.01


def test_incremental_passes_equal_one_render(box):
    with candela.Renderer(box, integrator="bdpt", res=(32, 32), seed=5, **CAM) as r:
        r.render_passes(2)
        r.render_passes(2)
        assert r.passes == 4
        img = r.image()
    assert np.array_equal(img, candela.render(box, integrator="bdpt", res=(32, 32), spp=4, seed=5, **CAM))


@pytest.mark.parametrize("integ", ["path", "gkde"])
def test_disjoint_passes_add_up(box, integ):
    """Two renderers with the odd and even passes, their accumulators summed
    (and gkde's adaptive tallies summed at each fold, as the MPI driver does),
    make the 6-pass render."""
    opts = dict(integrator=integ, res=(24, 24), seed=3, threads=1, **CAM)
    if integ == "gkde":
        opts["light_paths"] = 5000
    rs = [candela.Renderer(box, **opts) for _ in range(2)]
    sizes = [r.adapt_size() for r in rs]
    assert sizes[0] == sizes[1] and (sizes[0] > 0) == (integ == "gkde")
    for p in range(6):
        if sizes[0]:
            while rs[0].adapt_next <= p:
                total = rs[0].adapt_get() + rs[1].adapt_get()
                for r in rs:
                    r.adapt_fold(total)
        rs[p % 2].render_pass(p)
    total = rs[0].accumulators + rs[1].accumulators
    rs[0].accumulators = total
    assert rs[0].passes == 6
    img = rs[0].image()
    for r in rs:
        r.close()
    assert np.array_equal(img, candela.render(box, spp=6, **opts))


def test_stats_and_report(box):
    img, st = candela.render(box, integrator="pm", res=(32, 32), spp=2, photons=5000, stats=True, **CAM)
    assert st["passes"] == 2 and st["rays"] > 32 * 32 * 2 and st["seconds"] > 0
    assert st["global_photons"] >= 5000 and st["t_photons"] > 0
    assert st["report"].startswith("pm: ")


def test_aov_layers(box, tmp_path):
    with candela.Renderer(box, integrator="rigi", aov="pathlength", res=(32, 32), spp=2, **CAM) as r:
        r.render()
        assert r.layers == ["pathlength"]
        pl = r.image("pathlength")
        assert pl.shape == (32, 32, 3) and 1.0 <= pl.max() <= 64.0
        with pytest.raises(candela.UsageError):
            r.image("strata1")
        r.write(tmp_path / "x.exr")


def test_diff_write_read(tmp_path):
    rng = np.random.default_rng(1)
    a = rng.random((20, 30, 3), dtype=np.float32)
    for ext in ("exr", "pfm"):
        candela.write(tmp_path / f"a.{ext}", a)
        assert np.array_equal(candela.read(tmp_path / f"a.{ext}"), a)
    d = candela.diff(a * 1.1, a)
    assert abs(d["mean_ratio"] - 1.1) < 1e-5 and d["relmse"] > 0
    assert candela.diff(a, a)["relmse"] == 0.0
    with pytest.raises(candela.Error):
        candela.diff(a, a[:10])
    with pytest.raises(candela.UsageError):
        candela.write(tmp_path / "a.jpg", a)


def test_discovery():
    names = candela.integrators()
    assert set(names) >= {"path", "bdpt", "ir", "rigi", "pm", "gkde", "splat", "sppm", "vcm"}
    pm = {o["name"]: o for o in candela.options("pm")}
    assert pm["photons"]["default"] == "200000" and "spp" in pm and "mode" not in pm
    splat = {o["name"]: o for o in candela.options("splat")}
    assert splat["photons"]["default"] == "200000"
    vcm = {o["name"]: o for o in candela.options("vcm")}
    assert vcm["vcm_mode"]["default"] == "full" and "radius" in vcm and "alpha" in vcm and "photons" not in vcm
    assert candela.version().count(".") == 2


def test_flip(tmp_path):
    rng = np.random.default_rng(2)
    a = rng.random((24, 32, 3), dtype=np.float32)
    assert candela.flip(a, a) == 0.0 and candela.flip(a, a, hdr=False) == 0.0
    # LDR-FLIP is symmetric; more noise, more error
    noisy = [np.clip(a + s * rng.standard_normal(a.shape).astype(np.float32), 0, 1) for s in (0.02, 0.2)]
    e = [candela.flip(n, a, hdr=False) for n in noisy]
    assert 0 < e[0] < e[1] < 1 and candela.flip(a, noisy[0], hdr=False) == e[0]
    mean, m = candela.flip(noisy[1], a, ppd=30, map=True)
    assert 0 < mean < 1 and m.shape == a.shape and m.dtype == np.float32
    candela.write(tmp_path / "a.png", a)
    candela.write(tmp_path / "n.png", noisy[1])
    assert abs(candela.flip(tmp_path / "n.png", tmp_path / "a.png", hdr=False) - e[1]) < 0.02
    with pytest.raises(candela.Error):
        candela.flip(a, a[:10])
    with pytest.raises(candela.UsageError):
        candela.flip(a, a, ppd=0.5)
