"""candela: physically based global illumination from Python.

    import candela
    scene = candela.Scene("CornellBox-Original.obj")
    img = candela.render(scene, integrator="bdpt", spp=16, res=(256, 256),
                         lookat=(0, 1, 3.9, 0, 1, 0, 0, 1, 0), fov=39.3077)
    ref = candela.read("reference.exr")
    print(candela.diff(img, ref)["relmse"])

Options are the library's parameters (`candela render --help` spells them
with "-" for "_"): res=(w, h), lookat=(9 numbers), fov=, seed=, maxdepth=,
threads=, photons=, max_radius=, importance=True, C=0.6, ... `options()`
lists them with types, defaults and ranges, `options("pm")` pm's; one the
method does not read raises UsageError.
Images are NumPy float32 arrays of shape (height, width, 3), linear RGB.
Errors raise candela.Error (UsageError for options and calls, InputError
for files) carrying .file, .line and .message. The GIL is released while
rendering, so renders on several threads run at once; Ctrl-C stops a render
after its current pass and raises KeyboardInterrupt whose .image holds the
passes done.
"""

import ctypes
import os
import signal
import threading

import numpy as np

from . import _lib
from ._lib import lib

__all__ = ["Error", "UsageError", "InputError", "Scene", "Renderer", "render", "diff", "flip", "read", "write",
           "options", "integrators", "version"]


class Error(Exception):
    """A failure reported by libcandela: .code, .file, .line, .message."""

    def __init__(self, code, file, line, message):
        self.code, self.file, self.line, self.message = code, file, line, message
        where = f"{file}:{line}: " if file and line else f"{file}: " if file else ""
        super().__init__(where + message)


class InputError(Error):
    """A bad scene file, image or value read from a file."""


class UsageError(Error, ValueError):
    """A bad option, value or call."""


def _raise(err):
    cls = {1: InputError, 2: UsageError}.get(err.code, Error)
    raise cls(err.code, err.file.decode(errors="replace"), err.line, err.msg.decode(errors="replace"))


def _call(fn, *args):
    err = _lib.Error()
    if fn(*args, ctypes.byref(err)):
        _raise(err)


def version():
    return lib.cdl_version().decode()


def integrators():
    """{name: one-line summary} of every method."""
    return {lib.cdl_integrator_name(i).decode(): lib.cdl_integrator_summary(i).decode()
            for i in range(lib.cdl_integrator_count())}


def options(integrator=None):
    """The parameters as dicts: name, value (what it takes), integrators (the
    methods that read it, "" for all), default, help, section, type ("int",
    "float", "switch", "choice", "floats", "res", "name"), min, max, min_open,
    max_open, choices (list), unit, repeatable; with integrator, the ones it
    reads (the common ones included)."""
    out = []
    for i in range(lib.cdl_option_count()):
        o = lib.cdl_option_get(i).contents
        d = {k: getattr(o, f).decode() for k, f in (("name", "name"), ("value", "value"),
                                                    ("integrators", "integrators"), ("default", "default_value"),
                                                    ("help", "help"), ("section", "section"), ("type", "type"),
                                                    ("unit", "unit"))}
        d.update(min=o.min, max=o.max, min_open=bool(o.min_open), max_open=bool(o.max_open),
                 choices=[c for c in o.choices.decode().split("|") if c], repeatable=bool(o.repeatable))
        if integrator is None or not d["integrators"] or integrator in d["integrators"].split(","):
            out.append(d)
    return out


def _text(value):
    """A Python value written as on the command line."""
    if isinstance(value, bool):
        return "on" if value else "off"
    if isinstance(value, (float, np.floating)):
        return repr(float(value))
    if isinstance(value, (tuple, list, np.ndarray)):
        return ",".join(_text(v) for v in value)
    return str(value)


def _argv_pairs(argv):
    """Command-line words ("-i", "bdpt", "--importance", ...) as (name, value)
    pairs, a flag's value None: the command's own reading of them."""
    kinds = {o["name"]: bool(o["value"]) for o in options()}
    pairs, i = [], 0
    while i < len(argv):
        word = str(argv[i])
        name = {"i": "integrator", "q": "quiet"}.get(word.lstrip("-"), word.lstrip("-").replace("-", "_"))
        if not word.startswith("-") or name not in kinds:
            raise UsageError(2, word, 0, "unknown option (see candela render --help)")
        if kinds[name]:
            if i + 1 >= len(argv):
                raise UsageError(2, word, 0, "expects a value")
            pairs.append((name, str(argv[i + 1])))
            i += 2
        else:
            pairs.append((name, None))
            i += 1
    return pairs


class _Settings:
    def __init__(self, opts, argv=None):
        self.h = lib.cdl_settings_create()
        if not self.h:
            raise MemoryError("cdl_settings_create")
        try:
            for word, value in _argv_pairs(argv or []):
                _call(lib.cdl_settings_set, self.h, word.encode(), value.encode() if value is not None else None)
            for key, value in opts.items():
                if value is None:
                    continue
                if key == "res" and isinstance(value, (tuple, list)):
                    if len(value) != 2:
                        raise UsageError(2, "res", 0, f"expected (width, height), got {value!r}")
                    value = f"{value[0]}x{value[1]}"
                if key == "point_light" and value and isinstance(value[0], (tuple, list)):
                    for light in value:  # several lights
                        _call(lib.cdl_settings_set, self.h, b"point_light", _text(light).encode())
                    continue
                if key == "aov" and isinstance(value, (tuple, list)):
                    for layer in value:
                        _call(lib.cdl_settings_set, self.h, b"aov", str(layer).encode())
                    continue
                flag = isinstance(value, bool)
                _call(lib.cdl_settings_set, self.h, key.encode(), None if flag and value else _text(value).encode())
            _call(lib.cdl_settings_check, self.h)
        except BaseException:
            self.close()
            raise

    def close(self):
        if self.h:
            lib.cdl_settings_release(self.h)
            self.h = None


class _Handle:
    """A C handle given back by _release when closed, collected or left."""

    h = None
    _release = None

    def close(self):
        if self.h:
            type(self)._release(self.h)
            self.h = None

    def __del__(self):
        self.close()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()


class Scene(_Handle):
    """A loaded scene (OBJ + MTL or pbrt-v3/v4). point_light= adds point
    lights: (x, y, z, r, g, b) or a list of them; quiet=True drops warnings."""

    _release = lib.cdl_scene_release

    def __init__(self, path, point_light=None, quiet=None):
        self.path = str(path)
        self.h = None
        s = _Settings({"point_light": point_light, "quiet": quiet})
        try:
            h = ctypes.c_void_p()
            _call(lib.cdl_scene_open, self.path.encode(), s.h, ctypes.byref(h))
            self.h = h.value
        finally:
            s.close()

    @property
    def info(self):
        i = _lib.SceneInfo()
        lib.cdl_scene_get_info(self.h, ctypes.byref(i))
        return {"triangles": i.triangles, "spheres": i.spheres, "lights": i.lights, "materials": i.materials,
                "bounds": (tuple(i.bounds_min), tuple(i.bounds_max)), "has_camera": bool(i.has_camera),
                "res": (i.width, i.height), "spp": i.spp}



def _to_array(h):
    """A copy of a cdl_image's pixels; releases the image."""
    try:
        w, hh = lib.cdl_image_width(h), lib.cdl_image_height(h)
        px = np.ctypeslib.as_array(lib.cdl_image_pixels(h), shape=(hh, w, 3))
        return np.array(px, dtype=np.float32, copy=True)
    finally:
        lib.cdl_image_release(h)


def _from_array(a):
    """A new cdl_image holding a (H, W, 3) array; the caller releases it."""
    a = np.ascontiguousarray(a, dtype=np.float32)
    if a.ndim != 3 or a.shape[2] != 3:
        raise UsageError(2, "", 0, f"an image is an array of shape (height, width, 3), got {a.shape}")
    h = ctypes.c_void_p()
    _call(lib.cdl_image_create, a.shape[1], a.shape[0], ctypes.byref(h))
    ctypes.memmove(lib.cdl_image_pixels(h.value), a.ctypes.data, a.nbytes)
    return h.value


class Renderer(_Handle):
    """One method on one scene, rendered in progressive passes:

        r = Renderer(scene, integrator="pm", photons=50000, res=(256, 256))
        for _ in range(8):
            r.render_passes(1)
            errors.append(diff(r.image(), ref)["relmse"])
    """

    _release = lib.cdl_renderer_release

    def __init__(self, scene, integrator=None, args=None, **opts):
        """args: command-line words (["-i", "bdpt", "--mis", "power"]), read
        before the keyword options, which may override them."""
        self.h = None
        self.scene = scene if isinstance(scene, Scene) else Scene(scene, quiet=opts.get("quiet"))
        s = _Settings(dict(integrator=integrator, **opts), argv=args)
        try:
            h = ctypes.c_void_p()
            _call(lib.cdl_renderer_create, self.scene.h, s.h, ctypes.byref(h))
            self.h = h.value
        finally:
            s.close()

    def _run(self, fn, *args, progress=None):
        errors, interrupted = [], []

        def on_progress(user, p):
            try:
                if interrupted:
                    return 1
                if progress is not None and progress(p.contents.passes, p.contents.seconds, p.contents.fraction):
                    return 1
                return 0
            except BaseException as e:  # noqa: BLE001 (re-raised below)
                errors.append(e)
                return 1

        def on_sigint(sig, frame):
            interrupted.append(sig)
            lib.cdl_renderer_cancel(self.h)

        cb = _lib.PROGRESS_FN(on_progress)
        main = threading.current_thread() is threading.main_thread()
        old = signal.signal(signal.SIGINT, on_sigint) if main else None
        try:
            _call(fn, self.h, *args, cb, None)
        finally:
            if main:
                signal.signal(signal.SIGINT, old)
        if interrupted or any(isinstance(e, KeyboardInterrupt) for e in errors):
            e = KeyboardInterrupt(f"render stopped after {self.passes} passes")
            e.image = self.image()
            raise e
        if errors:
            raise errors[0]
        return self

    def render(self, progress=None):
        """Passes until the budget (spp= or time= of the options, else the
        scene file's spp, else 64). progress(passes, seconds, fraction) is
        called after each pass; a true return stops the render there."""
        return self._run(lib.cdl_renderer_render, progress=progress)

    def render_passes(self, n, progress=None):
        """n more passes, whatever the budget."""
        return self._run(lib.cdl_renderer_render_passes, int(n), progress=progress)

    def render_pass(self, index):
        """Renders the pass with this index (deterministic given the seed and
        the index) as one more pass: several processes can render disjoint
        passes of one render (see accumulators)."""
        _call(lib.cdl_renderer_render_pass, self.h, int(index))
        return self

    @property
    def accumulators(self):
        """The film's sums, sample counts, splats and counters as a float64
        vector; those of renders of disjoint passes add up (e.g. with mpi4py's
        comm.reduce) and set back make this render that of all the passes."""
        n = lib.cdl_renderer_accum_size(self.h)
        out = np.zeros(n, dtype=np.float64)
        _call(lib.cdl_renderer_accum_get, self.h, out.ctypes.data_as(ctypes.POINTER(ctypes.c_double)), n)
        return out

    @accumulators.setter
    def accumulators(self, value):
        a = np.ascontiguousarray(value, dtype=np.float64)
        _call(lib.cdl_renderer_accum_set, self.h, a.ctypes.data_as(ctypes.POINTER(ctypes.c_double)), a.size)

    def adapt_size(self):
        """Size of the state a method adapts across passes (gkde), 0 if none."""
        n = ctypes.c_size_t()
        _call(lib.cdl_renderer_adapt_size, self.h, ctypes.byref(n))
        return n.value

    @property
    def adapt_next(self):
        """The pass index of the method's next fold (see candela.h)."""
        return lib.cdl_renderer_adapt_next(self.h)

    def adapt_get(self):
        n = self.adapt_size()
        out = np.zeros(n, dtype=np.float64)
        _call(lib.cdl_renderer_adapt_get, self.h, out.ctypes.data_as(ctypes.POINTER(ctypes.c_double)), n)
        return out

    def adapt_fold(self, total):
        """Folds the adaptive state summed over every process."""
        a = np.ascontiguousarray(total, dtype=np.float64)
        _call(lib.cdl_renderer_adapt_fold, self.h, a.ctypes.data_as(ctypes.POINTER(ctypes.c_double)), a.size)

    def cancel(self):
        """Stops the render after its current pass (from any thread)."""
        lib.cdl_renderer_cancel(self.h)

    @property
    def cancelled(self):
        return bool(lib.cdl_renderer_cancelled(self.h))

    @property
    def passes(self):
        return lib.cdl_renderer_passes(self.h)

    @property
    def integrator(self):
        return lib.cdl_renderer_integrator(self.h).decode()

    @property
    def layers(self):
        return [lib.cdl_renderer_layer_name(self.h, i).decode() for i in range(lib.cdl_renderer_layer_count(self.h))]

    def image(self, layer=None):
        """The film so far as a float32 (H, W, 3) array; layer: an AOV."""
        h = ctypes.c_void_p()
        _call(lib.cdl_renderer_image, self.h, layer.encode() if layer else None, ctypes.byref(h))
        return _to_array(h.value)

    def stats(self):
        """{name: value}: passes, seconds, rays, mrays_per_s, nonfinite, threads,
        peak_rss_mib and the method's own (t_photons, t_solve, memory_mib, ...)."""
        out = {}
        name, value = ctypes.c_char_p(), ctypes.c_double()
        for i in range(lib.cdl_renderer_stat_count(self.h)):
            lib.cdl_renderer_stat(self.h, i, ctypes.byref(name), ctypes.byref(value))
            out[name.value.decode()] = value.value
        return out

    @property
    def report(self):
        return lib.cdl_renderer_report(self.h).decode()

    def write(self, path, command_line=None):
        """EXR (with the AOV layers), PNG or PFM, by the extension."""
        _call(lib.cdl_renderer_write, self.h, str(path).encode(), command_line.encode() if command_line else None)



def render(scene, integrator=None, spp=None, time=None, stats=False, progress=None, args=None, **opts):
    """Renders scene (a Scene or a file name) and returns the image as a
    float32 (H, W, 3) array, or (image, stats dict) with stats=True. args:
    command-line words, as Renderer takes them."""
    with Renderer(scene, integrator=integrator, spp=spp, time=time, args=args, **opts) as r:
        r.render(progress=progress)
        img = r.image()
        if stats:
            st = r.stats()
            st["report"] = r.report
            return img, st
        return img


def diff(test, ref):
    """The metrics of `candela diff` (relmse, rmse, mae, mean_ratio,
    relmse_trimmed, block_median_ratio, block_dev32, mean_test, mean_ref)."""
    a = b = None
    try:
        a, b = _from_array(test), _from_array(ref)
        d = _lib.Diff()
        _call(lib.cdl_image_diff, a, b, ctypes.byref(d))
        return {k: getattr(d, k) for k, _ in _lib.Diff._fields_}
    finally:
        lib.cdl_image_release(a)
        lib.cdl_image_release(b)


def flip(test, ref, hdr=None, ppd=None, map=False):
    """Mean FLIP error of test against ref, in [0, 1] (Andersson et al. 2020;
    0 for identical images). test and ref are (H, W, 3) linear RGB arrays or
    image file names. hdr=None or True: HDR-FLIP (exposures from ref's median
    to its largest luminance, ACES tone mapping); hdr=False: LDR-FLIP of the
    pixels clamped to [0, 1] (a PNG as read). ppd: pixels per degree, 1 to
    1000 (None: 67.02). With map=True returns (mean, map), map an (H, W, 3)
    float32 array of the per-pixel error in magma colours, linear RGB (as
    candela.write(..png) expects)."""
    if isinstance(test, (str, os.PathLike)):
        test = read(test)
    if isinstance(ref, (str, os.PathLike)):
        ref = read(ref)
    a = b = None
    try:
        a, b = _from_array(test), _from_array(ref)
        mean = ctypes.c_double()
        m = ctypes.c_void_p()
        _call(lib.cdl_image_flip, a, b, 1 if hdr is None or hdr else 0,
              0.0 if ppd is None else float(ppd), ctypes.byref(mean), ctypes.byref(m) if map else None)
        return (mean.value, _to_array(m.value)) if map else mean.value
    finally:
        lib.cdl_image_release(a)
        lib.cdl_image_release(b)


def read(path):
    """An EXR, PFM or PNG file as a float32 (H, W, 3) array (linear RGB)."""
    h = ctypes.c_void_p()
    _call(lib.cdl_image_load, str(path).encode(), ctypes.byref(h))
    return _to_array(h.value)


def write(path, image, exposure=0.0):
    """Writes image to .exr, .png (sRGB, exposure in stops) or .pfm."""
    h = _from_array(image)
    try:
        _call(lib.cdl_image_save, h, str(path).encode(), float(exposure))
    finally:
        lib.cdl_image_release(h)
