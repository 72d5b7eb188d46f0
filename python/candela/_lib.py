"""ctypes bindings of include/candela/candela.h (the C API, one to one)."""

import ctypes
import ctypes.util
import os

c_int, c_uint32, c_double, c_float, c_size_t = ctypes.c_int, ctypes.c_uint32, ctypes.c_double, ctypes.c_float, ctypes.c_size_t
c_char_p, c_void_p, c_size_t = ctypes.c_char_p, ctypes.c_void_p, ctypes.c_size_t


class Error(ctypes.Structure):
    _fields_ = [("code", c_int), ("line", c_int), ("file", ctypes.c_char * 1024), ("msg", ctypes.c_char * 512)]


class OptionInfo(ctypes.Structure):
    _fields_ = [("name", c_char_p), ("value", c_char_p), ("integrators", c_char_p),
                ("default_value", c_char_p), ("help", c_char_p), ("section", c_char_p), ("type", c_char_p),
                ("min", c_double), ("max", c_double), ("min_open", c_int), ("max_open", c_int),
                ("choices", c_char_p), ("unit", c_char_p), ("repeatable", c_int)]


class SceneInfo(ctypes.Structure):
    _fields_ = [("triangles", c_uint32), ("spheres", c_uint32), ("lights", c_uint32), ("materials", c_uint32),
                ("bounds_min", c_float * 3), ("bounds_max", c_float * 3), ("has_camera", c_int),
                ("width", c_int), ("height", c_int), ("spp", c_int), ("output", c_char_p)]


class Diff(ctypes.Structure):
    _fields_ = [(k, c_double) for k in ("rmse", "relmse", "mae", "mean_ratio", "relmse_trimmed",
                                         "block_median_ratio", "block_dev32", "mean_test", "mean_ref")]


class Progress(ctypes.Structure):
    _fields_ = [("passes", c_uint32), ("seconds", c_double), ("fraction", c_double)]


PROGRESS_FN = ctypes.CFUNCTYPE(c_int, c_void_p, ctypes.POINTER(Progress))
MESSAGE_FN = ctypes.CFUNCTYPE(None, c_void_p, c_char_p, c_int, c_char_p)


def _find():
    """The library: $CANDELA_LIBRARY, next to this package (an install), the
    source tree's build/ directory, or the system's."""
    env = os.environ.get("CANDELA_LIBRARY")
    if env:
        return env
    here = os.path.dirname(os.path.abspath(__file__))
    for cand in (os.path.join(here, "libcandela.so"),
                 os.path.join(here, "..", "..", "..", "libcandela.so"),  # PREFIX/lib/python3/dist-packages
                 os.path.join(here, "..", "..", "build", "libcandela.so")):  # the source tree
        if os.path.exists(cand):
            return cand
    found = ctypes.util.find_library("candela")
    if found:
        return found
    raise OSError("libcandela.so not found: build candela (cmake --build build) or set CANDELA_LIBRARY")


# CDLL releases the GIL around every call: renders on several Python threads run at once.
lib = ctypes.CDLL(_find())

P = ctypes.POINTER
_sig = {
    "cdl_version": (c_char_p, []),
    "cdl_error_format": (None, [P(Error), c_char_p, c_size_t]),
    "cdl_settings_create": (c_void_p, []),
    "cdl_settings_release": (None, [c_void_p]),
    "cdl_settings_set": (c_int, [c_void_p, c_char_p, c_char_p, P(Error)]),
    "cdl_settings_check": (c_int, [c_void_p, P(Error)]),
    "cdl_settings_set_message_fn": (None, [c_void_p, MESSAGE_FN, c_void_p]),
    "cdl_option_count": (c_int, []),
    "cdl_option_get": (P(OptionInfo), [c_int]),
    "cdl_integrator_count": (c_int, []),
    "cdl_integrator_name": (c_char_p, [c_int]),
    "cdl_integrator_summary": (c_char_p, [c_int]),
    "cdl_scene_open": (c_int, [c_char_p, c_void_p, P(c_void_p), P(Error)]),
    "cdl_scene_release": (None, [c_void_p]),
    "cdl_scene_get_info": (None, [c_void_p, P(SceneInfo)]),
    "cdl_image_create": (c_int, [c_int, c_int, P(c_void_p), P(Error)]),
    "cdl_image_load": (c_int, [c_char_p, P(c_void_p), P(Error)]),
    "cdl_image_release": (None, [c_void_p]),
    "cdl_image_width": (c_int, [c_void_p]),
    "cdl_image_height": (c_int, [c_void_p]),
    "cdl_image_pixels": (P(c_float), [c_void_p]),
    "cdl_image_save": (c_int, [c_void_p, c_char_p, c_float, P(Error)]),
    "cdl_image_diff": (c_int, [c_void_p, c_void_p, P(Diff), P(Error)]),
    "cdl_image_diff_heatmap": (c_int, [c_void_p, c_void_p, P(c_void_p), P(Error)]),
    "cdl_image_flip": (c_int, [c_void_p, c_void_p, c_int, c_double, P(c_double), P(c_void_p), P(Error)]),
    "cdl_renderer_create": (c_int, [c_void_p, c_void_p, P(c_void_p), P(Error)]),
    "cdl_renderer_release": (None, [c_void_p]),
    "cdl_renderer_render": (c_int, [c_void_p, PROGRESS_FN, c_void_p, P(Error)]),
    "cdl_renderer_render_passes": (c_int, [c_void_p, c_uint32, PROGRESS_FN, c_void_p, P(Error)]),
    "cdl_renderer_render_pass": (c_int, [c_void_p, c_uint32, P(Error)]),
    "cdl_renderer_accum_size": (c_size_t, [c_void_p]),
    "cdl_renderer_accum_get": (c_int, [c_void_p, P(c_double), c_size_t, P(Error)]),
    "cdl_renderer_accum_set": (c_int, [c_void_p, P(c_double), c_size_t, P(Error)]),
    "cdl_renderer_adapt_size": (c_int, [c_void_p, P(c_size_t), P(Error)]),
    "cdl_renderer_adapt_next": (c_uint32, [c_void_p]),
    "cdl_renderer_adapt_get": (c_int, [c_void_p, P(c_double), c_size_t, P(Error)]),
    "cdl_renderer_adapt_fold": (c_int, [c_void_p, P(c_double), c_size_t, P(Error)]),
    "cdl_renderer_cancel": (None, [c_void_p]),
    "cdl_renderer_cancelled": (c_int, [c_void_p]),
    "cdl_renderer_passes": (c_uint32, [c_void_p]),
    "cdl_renderer_width": (c_int, [c_void_p]),
    "cdl_renderer_height": (c_int, [c_void_p]),
    "cdl_renderer_integrator": (c_char_p, [c_void_p]),
    "cdl_renderer_image": (c_int, [c_void_p, c_char_p, P(c_void_p), P(Error)]),
    "cdl_renderer_layer_count": (c_int, [c_void_p]),
    "cdl_renderer_layer_name": (c_char_p, [c_void_p, c_int]),
    "cdl_renderer_write": (c_int, [c_void_p, c_char_p, c_char_p, P(Error)]),
    "cdl_renderer_stat_count": (c_int, [c_void_p]),
    "cdl_renderer_stat": (c_int, [c_void_p, c_int, P(c_char_p), P(c_double)]),
    "cdl_renderer_report": (c_char_p, [c_void_p]),
}
for _name, (_res, _args) in _sig.items():
    _f = getattr(lib, _name)
    _f.restype = _res
    _f.argtypes = _args
