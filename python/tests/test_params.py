"""Every parameter of every method through the command line, the C API
(via the package) and Python: the same default, range and choices; an
option a method does not read is refused; `-i METHOD --help` lists exactly
the method's options."""
import os
import subprocess

import pytest

import candela

CLI = os.environ.get("CANDELA_CLI", "candela")
METHODS = sorted(candela.integrators())


def flag(name):
    return ("-" if len(name) == 1 else "--") + name.replace("_", "-")


def readers(o):
    return o["integrators"].split(",") if o["integrators"] else METHODS


def samples(o):
    """(value, accepted) pairs that probe the row's default, range or choices."""
    out = []
    if o["default"] and not o["repeatable"]:
        out.append((o["default"], True))
    if o["type"] in ("int", "float"):
        fmt = (lambda v: "%d" % v) if o["type"] == "int" else (lambda v: repr(float(v)))
        step = 1 if o["type"] == "int" else max(abs(o["max"]), 1.0) * 1e-3
        out.append((fmt(o["max"]), not o["max_open"]))
        out.append((fmt(o["max"] + step), False))
        out.append((fmt(o["min"]), not o["min_open"]))
        out.append((fmt(o["min"] - (1 if o["type"] == "int" else max(abs(o["min"]), 1.0) * 1e-3)), False))
    if o["type"] == "choice":
        out += [(c, True) for c in o["choices"]] + [("bogus", False)]
    if o["type"] == "switch":
        out += [("on", True), ("off", True), ("maybe", False)]
    return out


def api_accepts(method, name, value):
    try:
        candela._Settings({"integrator": method, name: value}).close()
        return True
    except candela.UsageError:
        return False


def cli_status(method, name, value):
    """2: refused as an option; 1: accepted (the scene file then fails to load).
    value None: a bare switch."""
    words = [flag(name)] + ([] if value is None else [value])
    r = subprocess.run([CLI, "render", "/nonexistent/scene.obj", "-i", method, "-q", "-o", "/tmp/x.exr"] + words,
                       capture_output=True, text=True)
    return r.returncode, r.stderr


@pytest.mark.parametrize("method", METHODS)
def test_each_parameter_same_everywhere(method):
    checked = 0
    for o in candela.options(method):
        if o["name"] in ("integrator",) or o["type"] == "name":
            continue
        for value, ok in samples(o):
            assert api_accepts(method, o["name"], value) == ok, (method, o["name"], value)
            if not o["value"]:  # a bare switch on the command line
                if value != "on":
                    continue
                value = None
            code, err = cli_status(method, o["name"], value)
            assert code == (1 if ok else 2), (method, o["name"], value, err)
            if not ok:
                assert flag(o["name"]) in err, err
            checked += 1
    assert checked > 20


def test_unread_options_refused():
    code, err = cli_status("path", "knn", "50")
    assert code == 2 and "knn" in err and "path" in err
    with pytest.raises(candela.UsageError) as e:
        candela._Settings({"integrator": "splat", "max_radius": 0.5})
    assert "max_radius" in str(e.value) and "splat" in str(e.value)
    for m in METHODS:
        mine = {o["name"] for o in candela.options(m)}
        others = {o["name"] for o in candela.options()} - mine
        for name in sorted(others)[:5]:
            assert not api_accepts(m, name, "1"), (m, name)


@pytest.mark.parametrize("method", METHODS)
def test_method_help_lists_its_options(method):
    out = subprocess.run([CLI, "render", "-i", method, "--help"], capture_output=True, text=True, check=True).stdout
    listed, defaults = set(), {}
    for line in out.splitlines():
        words = line.split()
        if words and words[0].startswith("-") and len(line) - len(line.lstrip()) <= 6:
            f = words[1] if words[0].endswith(",") else words[0]
            listed.add(f)
    want = {flag(o["name"]) for o in candela.options(method)} | {"--output"}
    assert listed == want, (sorted(listed - want), sorted(want - listed))
    # every default as the tables say it
    text = " ".join(out.split())
    for o in candela.options(method):
        if o["default"] and o["value"] and "default" not in o["help"]:
            assert f"(default {o['default']})" in text, o["name"]


PBRT = """LookAt 0 1 3.9  0 1 0  0 1 0
Camera "perspective" "float fov" 40
Film "rgb" "integer xresolution" 24 "integer yresolution" 24
Integrator "pm" "integer knn" [ 1 ] "integer photons" [ 3000 ] "string lightsampler" "bvh"
WorldBegin
LightSource "point" "rgb I" [5 5 5] "point3 from" [0 1.5 0.5]
Shape "trianglemesh" "point3 P" [-1 0 -1 1 0 -1 1 0 1 -1 0 1] "integer indices" [0 1 2 0 2 3]
Shape "trianglemesh" "point3 P" [-1 0 -1 -1 2 -1 1 2 -1 1 0 -1] "integer indices" [0 1 2 0 2 3]
"""

MITSUBA = """<scene version="3.0.0">
  <integrator type="photonmapper"><integer name="lookup_size" value="1"/><integer name="global_photons" value="3000"/>
    <integer name="rr_depth" value="5"/></integrator>
  <sensor type="perspective"><float name="fov" value="40"/>
    <transform name="to_world"><lookat origin="0, 1, 3.9" target="0, 1, 0" up="0, 1, 0"/></transform>
    <film type="hdrfilm"><integer name="width" value="24"/><integer name="height" value="24"/></film></sensor>
  <emitter type="point"><point name="position" x="0" y="1.5" z="0.5"/><rgb name="intensity" value="5"/></emitter>
  <shape type="rectangle"><transform name="to_world"><rotate x="1" angle="-90"/></transform></shape>
  <shape type="rectangle"><transform name="to_world"><translate z="-1"/></transform></shape>
</scene>
"""


@pytest.mark.parametrize("kind", ["pbrt", "xml"])
def test_scene_file_integrator_parameters(tmp_path, kind):
    """A file's integrator parameters go through the method's table: read
    (the same image as the option), overridden by the option, and a warning
    with file and line for one the method does not read."""
    scene = tmp_path / f"s.{kind}"
    scene.write_text(PBRT if kind == "pbrt" else MITSUBA)

    def render(name, *extra):
        out = tmp_path / f"{name}.exr"
        r = subprocess.run([CLI, "render", str(scene), "--spp", "2", "-o", str(out)] + list(extra),
                           capture_output=True, text=True, check=True)
        return candela.read(out), r.stderr

    from_file, err = render("file")
    unread, line = ("lightsampler", 4) if kind == "pbrt" else ("rr_depth", 3)
    assert f"s.{kind}:{line}: integrator parameter \"{unread}\": pm does not read it" in err, err
    same, _ = render("same", "--knn", "1", "--photons", "3000")
    other, _ = render("other", "--knn", "20")
    assert (from_file == same).all()
    assert not (from_file == other).all()
