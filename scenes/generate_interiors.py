#!/usr/bin/python3
"""Realistic furnished interiors for checking that the biased methods (photon
mapping, kernel density estimation, photon splatting) converge to the path
tracer's image.

    scenes/generate_interiors.py OUTDIR [NAME ...]

writes, for every named scene (default: all of them), into OUTDIR:

    livingroom       livingroom.obj/.mtl/.cam: lit only through three windows
                     (emitting quads in the openings); glossy floor, lacquered
                     cabinet, a mirror
    livingroom_sky   livingroom_sky.pbrt (pbrt-v3): the same room, windows open,
                     lit by a constant sky (infinite light) and a distant sun
    livingroom_mitsuba  livingroom_mitsuba/livingroom.xml (Mitsuba 3) and one OBJ
                     per material beside it: the same room as `livingroom`
    doorajar         two rooms, the door between them ajar by 15 degrees; the
                     camera in the dark room
    stairwell        two storeys joined by a floor opening with a stair; lights
                     only upstairs, the camera downstairs
    sealed0, sealed2 two rooms sharing one wall (0 or 2 cm thick) under one floor
                     and one ceiling slab; one room lit, the camera in the other
                     (its image is exactly black), sealedN_lit.cam in the lit one

It follows the conventions of scenes/generate.py (whose Scene class and
furniture helpers it imports): metres, y up, every wall, floor and ceiling a
closed box wound counter-clockwise seen from outside, light panels single
quads 1 cm below the ceiling facing down, NAME.cam one line of `--lookat ...
--fov ...`. Window emitters are single quads exactly filling their opening in
the wall's outer face, facing into the room, so the room stays closed and light
enters only through them. Deterministic: the few random choices (book sizes)
come from random.Random with fixed seeds, so every run writes the same bytes.
"""

import os
import sys

sys.dont_write_bytecode = True      # no scenes/__pycache__ from the import below
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import generate                     # noqa: E402  (Scene, furniture helpers)
from generate import Scene, chair, desk, shelf, H_DOOR  # noqa: E402

_fmt = generate._fmt
BOOK_COLOURS = [(0.6, 0.1, 0.1), (0.1, 0.2, 0.5), (0.7, 0.6, 0.3), (0.15, 0.4, 0.15),
                (0.75, 0.75, 0.7), (0.3, 0.15, 0.3)]


class Interior(Scene):
    """generate.Scene whose files name this script, with extra cameras."""

    def __init__(self, name):
        super().__init__(name)
        self.extra_cams = {}    # file suffix -> (eye, target, fov)
        self.lift = 0.0         # added to the y of every box (furniture upstairs)

    def box(self, lo, hi, mtl, face_mtl=None, rot=None):
        if self.lift:
            lo, hi = (lo[0], lo[1] + self.lift, lo[2]), (hi[0], hi[1] + self.lift, hi[2])
        super().box(lo, hi, mtl, face_mtl, rot)

    def write(self, outdir):
        super().write(outdir)
        base = os.path.join(outdir, self.name)
        for ext in (".obj", ".mtl"):
            with open(base + ext) as f:
                text = f.read()
            with open(base + ext, "w") as f:
                f.write(text.replace("written by scenes/generate.py",
                                     "written by scenes/generate_interiors.py", 1))
        for suffix, cam in sorted(self.extra_cams.items()):
            with open(base + suffix + ".cam", "w") as f:
                f.write(cam_line(cam) + "\n")


def cam_line(cam):
    eye, target, fov = cam
    return "--lookat %s,%s,%s,%s,%s,%s,0,1,0 --fov %s" % (
        tuple(_fmt(c) for c in eye) + tuple(_fmt(c) for c in target) + (_fmt(fov),))


# --- geometry helpers -------------------------------------------------------------

def _rects_minus(a_lo, a_hi, b_lo, b_hi, holes):
    """The rectangle [a_lo, a_hi] x [b_lo, b_hi] minus the holes (a0, a1, b0, b1),
    as a list of rectangles: columns between the holes' a edges, each split in b
    around the holes it crosses; neighbouring columns with the same split merged."""
    cuts = sorted({a_lo, a_hi} | {c for h in holes for c in h[:2] if a_lo < c < a_hi})
    cols = []
    for ca, cb in zip(cuts, cuts[1:]):
        cover = sorted((h[2], h[3]) for h in holes if h[0] <= ca and h[1] >= cb)
        spans, cur = [], b_lo
        for b0, b1 in cover:
            if b0 > cur:
                spans.append((cur, b0))
            cur = max(cur, b1)
        if cur < b_hi:
            spans.append((cur, b_hi))
        if cols and cols[-1][2] == spans:
            cols[-1][1] = cb
        else:
            cols.append([ca, cb, spans])
    return [(ca, cb, b0, b1) for ca, cb, spans in cols for b0, b1 in spans]


def wall_with_openings(s, side, x0, x1, z0, z1, h, t, mtl, openings, inner_mtl=None):
    """The outer wall on `side` ('-x', '+x', '-z', '+z': at x0, x1, z0, z1) of the
    interior [x0, x1] x [0, h] x [z0, z1], t thick, from y = -t/2 to h + t/2 and
    t beyond both ends (as Scene.shell's walls), with openings (a0, a1, y0, y1),
    a along the wall (x for the z walls, z for the x walls): holes right through
    it. inner_mtl: the material of the face towards the room."""
    y_lo, y_hi = -t / 2, h + t / 2
    holes = [(a0, a1, b0, b1) for a0, a1, b0, b1 in openings]
    if side in ("-z", "+z"):
        c0, c1 = (z0 - t, z0) if side == "-z" else (z1, z1 + t)
        inner = "+z" if side == "-z" else "-z"
        for a0, a1, b0, b1 in _rects_minus(x0 - t, x1 + t, y_lo, y_hi, holes):
            s.box((a0, b0, c0), (a1, b1, c1), mtl, {inner: inner_mtl} if inner_mtl else None)
    else:
        c0, c1 = (x0 - t, x0) if side == "-x" else (x1, x1 + t)
        inner = "+x" if side == "-x" else "-x"
        for a0, a1, b0, b1 in _rects_minus(z0 - t, z1 + t, y_lo, y_hi, holes):
            s.box((c0, b0, a0), (c1, b1, a1), mtl, {inner: inner_mtl} if inner_mtl else None)


def window_emitter(s, side, x0, x1, z0, z1, t, opening, mtl):
    """An emitting quad exactly filling `opening` (a0, a1, y0, y1) in the outer face
    of the wall on `side`, its front towards the room."""
    a0, a1, b0, b1 = opening
    if side in ("-z", "+z"):
        z = z0 - t if side == "-z" else z1 + t
        p = ((a0, b0, z), (a1, b0, z), (a1, b1, z), (a0, b1, z))
        n = (0, 0, 1) if side == "-z" else (0, 0, -1)
    else:
        x = x0 - t if side == "-x" else x1 + t
        p = ((x, b0, a0), (x, b0, a1), (x, b1, a1), (x, b1, a0))
        n = (1, 0, 0) if side == "-x" else (-1, 0, 0)
    s.quad(p, n, mtl)
    s.light_panels += 1
    s.light_area += (a1 - a0) * (b1 - b0)


def window_frame(s, side, x0, x1, z0, z1, t, opening, frame_mtl, sill_mtl):
    """A frame (5 cm) round the opening and a cross of mullions, 1 to 7 cm inside
    the wall's outer face, and a sill board on the room side."""
    a0, a1, b0, b1 = opening
    f, am, bm = 0.05, (a0 + a1) / 2, b0 + 0.62 * (b1 - b0)
    parts = [(a0, a1, b0, b0 + f), (a0, a1, b1 - f, b1), (a0, a0 + f, b0, b1),
             (a1 - f, a1, b0, b1), (am - 0.025, am + 0.025, b0, b1),
             (a0, a1, bm - 0.025, bm + 0.025)]
    if side in ("-z", "+z"):
        sg = 1 if side == "-z" else -1
        zo = z0 - t if side == "-z" else z1 + t      # outer face
        zi = z0 if side == "-z" else z1              # inner face
        for p0, p1, q0, q1 in parts:
            za, zb = sorted((zo + sg * 0.01, zo + sg * 0.07))
            s.box((p0, q0, za), (p1, q1, zb), frame_mtl)
        za, zb = sorted((zi - sg * 0.06, zi + sg * 0.04))
        s.box((a0 - 0.05, b0 - 0.03, za), (a1 + 0.05, b0 + 0.02, zb), sill_mtl)
    else:
        sg = 1 if side == "-x" else -1
        xo = x0 - t if side == "-x" else x1 + t
        xi = x0 if side == "-x" else x1
        for p0, p1, q0, q1 in parts:
            xa, xb = sorted((xo + sg * 0.01, xo + sg * 0.07))
            s.box((xa, q0, p0), (xb, q1, p1), frame_mtl)
        xa, xb = sorted((xi - sg * 0.06, xi + sg * 0.04))
        s.box((xa, b0 - 0.03, a0 - 0.05), (xb, b0 + 0.02, a1 + 0.05), sill_mtl)


def prism_x(s, xa, xb, profile, mtl):
    """A closed prism from x = xa to xb over a convex polygon `profile` of (z, y)
    points (in order round its edge), wound outwards."""
    n = len(profile)
    cz = sum(p[0] for p in profile) / n
    cy = sum(p[1] for p in profile) / n
    for i in range(n):
        (za, ya), (zb, yb) = profile[i], profile[(i + 1) % n]
        mid = ((za + zb) / 2 - cz, (ya + yb) / 2 - cy)
        # the side's normal in (z, y): perpendicular to the edge, away from the centre
        nz, ny = (yb - ya), -(zb - za)
        if nz * mid[0] + ny * mid[1] < 0:
            nz, ny = -nz, -ny
        s.quad(((xa, ya, za), (xb, ya, za), (xb, yb, zb), (xa, yb, zb)), (0, ny, nz), mtl)
    for x, nx in ((xa, -1), (xb, 1)):
        for i in range(1, n - 1):
            pts = [profile[0], profile[i], profile[i + 1]]
            a, b, c = ((x, p[1], p[0]) for p in pts)
            g = generate._cross(generate._sub(b, a), generate._sub(c, a))
            if g[0] * nx < 0:
                b, c = c, b
            s.tri(a, b, c, mtl)


def frustum(s, c, y0, y1, r0, r1, mtl):
    """A closed square frustum about the vertical axis through c = (x, z): half
    width r0 at y0, r1 at y1 (a lamp shade)."""
    x, z = c
    lo = [(x - r0, y0, z - r0), (x + r0, y0, z - r0), (x + r0, y0, z + r0), (x - r0, y0, z + r0)]
    hi = [(x - r1, y1, z - r1), (x + r1, y1, z - r1), (x + r1, y1, z + r1), (x - r1, y1, z + r1)]
    s.quad(lo, (0, -1, 0), mtl)
    s.quad(hi, (0, 1, 0), mtl)
    for i in range(4):
        j = (i + 1) % 4
        mid = tuple((lo[i][k] + lo[j][k]) / 2 - (x, 0, z)[k] for k in range(3))
        s.quad((lo[i], lo[j], hi[j], hi[i]), (mid[0], 0, mid[2]), mtl)


class Frame:
    """A piece of furniture's local frame: u across it, v from back (-v) to front
    (+v), y up, origin at (x, 0, z); `angle` turns it counter-clockwise seen from
    above (0: the front faces +z, 90: +x, -90: -x, 180: -z)."""

    def __init__(self, x, z, angle=0.0):
        self.x, self.z, self.angle = x, z, angle

    def box(self, s, lo, hi, mtl, face_mtl=None):
        rot = (self.angle, (self.x, self.z)) if self.angle else None
        s.box((self.x + lo[0], lo[1], self.z + lo[2]), (self.x + hi[0], hi[1], self.z + hi[2]),
              mtl, face_mtl, rot=rot)


def sofa(s, fr, w, d, fabric, cushion, leg, seats=3):
    """A sofa (or an armchair, seats=1) w wide and d deep centred at the frame's
    origin, facing +v: base, back rest, arms, seat and back cushions, legs."""
    hw, hd, arm = w / 2, d / 2, 0.17
    for u in (-hw + 0.04, hw - 0.09):
        for v in (-hd + 0.04, hd - 0.09):
            fr.box(s, (u, 0, v), (u + 0.05, 0.08, v + 0.05), leg)
    fr.box(s, (-hw, 0.08, -hd), (hw, 0.38, hd), fabric)
    fr.box(s, (-hw, 0.38, -hd), (hw, 0.82, -hd + 0.2), fabric)
    for u0 in (-hw, hw - arm):
        fr.box(s, (u0, 0.38, -hd + 0.2), (u0 + arm, 0.62, hd), fabric)
    inner = w - 2 * arm
    cw = inner / seats
    for i in range(seats):
        u0 = -hw + arm + i * cw + 0.005
        fr.box(s, (u0, 0.38, -hd + 0.2), (u0 + cw - 0.01, 0.5, hd - 0.01), cushion)
        fr.box(s, (u0, 0.5, -hd + 0.2), (u0 + cw - 0.01, 0.78, -hd + 0.36), cushion)


def bed(s, fr, w, l, frame_m, sheet, duvet, pillow):
    """A bed w wide and l long centred at the frame's origin, the head at -v."""
    hw, hl = w / 2, l / 2
    for u in (-hw + 0.03, hw - 0.09):
        for v in (-hl + 0.03, hl - 0.09):
            fr.box(s, (u, 0, v), (u + 0.06, 0.12, v + 0.06), frame_m)
    fr.box(s, (-hw, 0.12, -hl), (hw, 0.32, hl), frame_m)
    fr.box(s, (-hw, 0, -hl - 0.06), (hw, 1.0, -hl), frame_m)            # headboard
    fr.box(s, (-hw + 0.03, 0.32, -hl + 0.02), (hw - 0.03, 0.54, hl - 0.03), sheet)
    fr.box(s, (-hw - 0.02, 0.3, -hl + 0.55), (hw + 0.02, 0.58, hl + 0.02), duvet)
    for u0 in (-hw + 0.08, 0.04):
        fr.box(s, (u0, 0.54, -hl + 0.08), (u0 + hw - 0.12, 0.67, -hl + 0.45), pillow)


def cabinet(s, fr, w, d, h, body, plinth, handle, doors=2):
    """A sideboard w x d x h centred at the frame's origin, doors at the front (+v)."""
    hw, hd = w / 2, d / 2
    fr.box(s, (-hw + 0.04, 0, -hd + 0.04), (hw - 0.04, 0.08, hd - 0.04), plinth)
    fr.box(s, (-hw, 0.08, -hd), (hw, h, hd), body)
    dw = w / doors
    for i in range(doors):
        uc = -hw + (i + 0.5) * dw + (dw / 2 - 0.1) * (1 if i % 2 == 0 else -1)
        fr.box(s, (uc - 0.015, h - 0.25, hd), (uc + 0.015, h - 0.08, hd + 0.025), handle)
        if i:
            u = -hw + i * dw
            fr.box(s, (u - 0.003, 0.1, hd - 0.01), (u + 0.003, h - 0.02, hd + 0.002), plinth)


def plant(s, x, z, pot, leaf, h=0.35, r=0.16):
    s.box((x - r, 0, z - r), (x + r, h, z + r), pot)
    for dx, dy, dz, rr in ((0, 0.28, 0, 0.26), (0.1, 0.5, -0.06, 0.18), (-0.09, 0.45, 0.08, 0.17)):
        s.sphere((x + dx, h + dy, z + dz), rr, leaf, nu=14, nv=7)


# --- livingroom ---------------------------------------------------------------------

LR_W, LR_D, LR_H, LR_T = 5.0, 4.0, 2.6, 0.2
LR_WINDOWS = {"-z": [(0.5, 1.5, 0.85, 2.25), (3.5, 4.5, 0.85, 2.25)],
              "-x": [(1.3, 2.5, 0.85, 2.25)]}
LR_CAMERA = ((4.75, 1.55, 3.7), (0.9, 0.8, 1.35), 62)
LR_KE = (11, 12, 13)            # window radiance (a slightly blue daylight)
LR_SKY = 3.0                    # livingroom_sky: radiance of the constant sky
LR_SUN = (9.0, 8.5, 7.5)        # and the sun's irradiance (W/m^2 normal to it)
LR_SUN_DIR = (0.35, -0.62, 0.70)  # direction the sunlight travels (into the room)


def livingroom_scene(name="livingroom", emitters=True):
    """The living room: x in [0, 5], z in [0, 4], 2.6 m high; two windows in the
    south wall (z = 0), one in the west wall (x = 0). With emitters, each opening
    is closed by an emitting quad in the wall's outer face."""
    s = Interior(name)
    W, D, H, T = LR_W, LR_D, LR_H, LR_T
    white = s.material("wall_white", kd=(0.75, 0.73, 0.69))
    sage = s.material("wall_sage", kd=(0.42, 0.52, 0.42))
    ceil = s.material("ceiling", kd=(0.80, 0.80, 0.80))
    floor = s.material("floor_oak", kd=(0.40, 0.28, 0.17), ks=(0.2, 0.2, 0.2), ns=100)
    frame_m = s.material("window_frame", kd=(0.80, 0.80, 0.78))
    rug = s.material("rug", kd=(0.55, 0.20, 0.16))
    fabric = s.material("sofa_fabric", kd=(0.22, 0.28, 0.40))
    cushion = s.material("cushion", kd=(0.70, 0.60, 0.40))
    wood = s.material("wood", kd=(0.45, 0.30, 0.18), ks=(0.05, 0.05, 0.05), ns=60)
    dark = s.material("dark_wood", kd=(0.12, 0.08, 0.06))
    lacquer = s.material("lacquer", kd=(0.06, 0.30, 0.28), ks=(0.3, 0.3, 0.3), ns=300)
    metal = s.material("metal", kd=(0.08, 0.08, 0.08), ks=(0.6, 0.6, 0.6), ns=200)
    mirror = s.material("mirror", kd=(0, 0, 0), ks=(0.9, 0.9, 0.9), illum=5)
    pot = s.material("pot", kd=(0.55, 0.32, 0.22))
    leaf = s.material("leaf", kd=(0.12, 0.32, 0.10))
    canvas = [s.material("picture_%d" % i, kd=c) for i, c in enumerate(
        [(0.70, 0.55, 0.30), (0.25, 0.40, 0.55)])]
    books = [s.material("book_%d" % i, kd=c) for i, c in enumerate(BOOK_COLOURS)]
    lamp = s.material("window_light", kd=(0, 0, 0), ke=LR_KE) if emitters else None

    s.group("floor")
    s.box((-T, -T, -T), (W + T, 0, D + T), floor)
    s.group("ceiling")
    s.box((-T, H, -T), (W + T, H + T, D + T), ceil)
    s.group("outer_walls")
    for side in ("-x", "+x", "-z", "+z"):
        wall_with_openings(s, side, 0, W, 0, D, H, T, white, LR_WINDOWS.get(side, ()),
                           inner_mtl=sage if side == "+z" else None)
    s.group("windows")
    for side, ops in sorted(LR_WINDOWS.items()):
        for op in ops:
            window_frame(s, side, 0, W, 0, D, T, op, frame_m, frame_m)
    if emitters:
        s.group("window_lights")
        for side, ops in sorted(LR_WINDOWS.items()):
            for op in ops:
                window_emitter(s, side, 0, W, 0, D, T, op, lamp)

    s.group("rug")
    s.box((1.15, 0, 1.45), (3.85, 0.01, 3.25), rug)
    s.group("sofa")             # against the north wall, facing south
    sofa(s, Frame(2.5, 3.53, 180), 2.1, 0.9, fabric, cushion, dark)
    s.group("coffee_table")
    desk(s, 1.95, 2.0, 1.1, 0.6, wood, wood, h=0.42, top=0.04, leg=0.05)
    s.box((2.2, 0.42, 2.15), (2.5, 0.46, 2.4), books[1])       # a book on it
    s.group("armchair")         # in the south-west corner, turned to the room
    sofa(s, Frame(1.0, 0.95, 45), 0.85, 0.85, fabric, cushion, dark, seats=1)
    s.group("bookshelf")        # against the west wall, north of its window
    shelf(s, 0.01, 2.85, 1.05, 0.35, 2.0, wood, books, seed=11, along="z")
    s.group("sideboard")        # lacquered, against the south wall between the windows
    cabinet(s, Frame(2.5, 0.23), 1.4, 0.45, 0.7, lacquer, dark, metal)
    s.box((2.95, 0.7, 0.15), (3.1, 0.95, 0.3), pot)            # a vase
    s.group("mirror")           # above the sideboard: a dark frame, a mirror face
    s.box((2.05, 1.15, 0.002), (2.95, 1.95, 0.025), dark, {"+z": mirror})
    s.group("pictures")         # on the north wall above the sofa
    for (x0, x1), c in zip(((1.7, 2.3), (2.7, 3.3)), canvas):
        s.box((x0, 1.35, D - 0.027), (x1, 1.85, D - 0.002), dark, {"-z": c})
    s.group("floor_lamp")       # a metal lamp between the shelf and the sofa
    lx, lz = 0.95, 3.55
    s.box((lx - 0.15, 0, lz - 0.15), (lx + 0.15, 0.02, lz + 0.15), metal)
    s.box((lx - 0.015, 0.02, lz - 0.015), (lx + 0.015, 1.45, lz + 0.015), metal)
    frustum(s, (lx, lz), 1.45, 1.72, 0.2, 0.12, metal)
    s.group("plant")            # in the south-east corner
    plant(s, 4.65, 0.45, pot, leaf)
    s.group("side_table")
    s.box((3.85, 0, 3.3), (4.3, 0.5, 3.75), wood)
    s.camera = LR_CAMERA
    return s


def livingroom():
    return livingroom_scene()


def _mtl_dict(lines):
    d = {}
    for l in lines:
        k, *v = l.split()
        d[k] = [float(x) for x in v]
    return d


def _faces_by_material(s):
    """{material: (vertices, triangles)} in the MTL's order of materials: vertices
    (position, normal or None) in first-use order, triangles as index triples.
    A material's faces all have vertex normals or none do."""
    out = {}
    for _, faces in s.groups:
        for mtl, face in faces:
            verts, tris, index = out.setdefault(mtl, ([], [], {}))
            t = []
            for vi, ni in face:
                j = index.get((vi, ni))
                if j is None:
                    j = index[vi, ni] = len(verts)
                    verts.append((s.verts[vi - 1], None if ni is None else s.normals[ni - 1]))
                t.append(j)
            tris.append(tuple(t))
    for m, (verts, _, _) in out.items():
        assert len({v[1] is None for v in verts}) == 1, m
    return {m: (out[m][0], out[m][1]) for m in s.mtls if m in out}


def _wrap(items, per_line):
    return "\n    ".join(" ".join(items[i:i + per_line]) for i in range(0, len(items), per_line))


def livingroom_sky():
    """The living room as a pbrt-v3 scene: windows open, a constant sky and a sun."""
    s = livingroom_scene("livingroom_sky", emitters=False)
    eye, target, fov = s.camera
    out = ["# livingroom_sky.pbrt, written by scenes/generate_interiors.py (metres, y up):",
           "# the livingroom's geometry with its three windows open (no glass, no emitters),",
           "# lit only by a constant sky (infinite light) and a distant sun through the",
           "# south windows. The room floats in empty space, closed but for its windows.",
           "# pbrt's camera space is left-handed: mirrored in x, so that the image is",
           "# livingroom.obj's with the same view (livingroom.cam)",
           "Scale -1 1 1",
           "LookAt %s %s %s  %s %s %s  0 1 0" % (tuple(_fmt(c) for c in eye)
                                                 + tuple(_fmt(c) for c in target)),
           'Camera "perspective" "float fov" [%s]' % _fmt(fov),
           'Film "image" "integer xresolution" [160] "integer yresolution" [120]'
           ' "string filename" "livingroom_sky.exr"',
           'Integrator "path" "integer maxdepth" [64]',
           "WorldBegin",
           'LightSource "infinite" "rgb L" [%s %s %s]' % ((_fmt(LR_SKY),) * 3),
           'LightSource "distant" "point from" [%s %s %s] "point to" [0 0 0]'
           ' "rgb L" [%s %s %s]' % (tuple(_fmt(-c) for c in LR_SUN_DIR)
                                     + tuple(_fmt(c) for c in LR_SUN))]
    for mtl, (verts, tris) in _faces_by_material(s).items():
        p = _mtl_dict(s.mtls[mtl])
        kd = " ".join(_fmt(c) for c in p["Kd"])
        out.append("AttributeBegin  # %s" % mtl)
        if p.get("illum") == [5.0]:
            out.append('  Material "mirror" "rgb Kr" [%s]' % " ".join(_fmt(c) for c in p["Ks"]))
        elif "Ks" in p:
            out.append('  Material "plastic" "rgb Kd" [%s] "rgb Ks" [%s] "float roughness" [0.05]'
                       % (kd, " ".join(_fmt(c) for c in p["Ks"])))
        else:
            out.append('  Material "matte" "rgb Kd" [%s]' % kd)
        shape = ('  Shape "trianglemesh" "integer indices" [\n    %s\n  ] "point P" [\n    %s\n  ]'
                 % (_wrap(["%d %d %d" % t for t in tris], 8),
                    _wrap(["%s %s %s" % v[0] for v in verts], 6)))
        if verts[0][1] is not None:
            shape += ' "normal N" [\n    %s\n  ]' % _wrap(["%s %s %s" % v[1] for v in verts], 6)
        out.append(shape)
        out.append("AttributeEnd")
    out.append("WorldEnd")
    s.pbrt_text = "\n".join(out) + "\n"
    s.tri_count = s.triangles()
    return s


# Mitsuba bsdfs of the living room's materials (the rest: diffuse with Kd)
LR_MITSUBA_BSDF = {
    "floor_oak": ("roughplastic", 0.1),
    "wood": ("roughplastic", 0.3),
    "lacquer": ("plastic", None),
    "mirror": ("conductor", None),
    "metal": ("roughconductor", 0.2),
}


def livingroom_mitsuba():
    """The living room for Mitsuba 3: livingroom_mitsuba/livingroom.xml and one OBJ
    per material (Mitsuba's obj shape is one mesh with one bsdf)."""
    s = livingroom_scene("livingroom_mitsuba", emitters=True)
    eye, target, fov = s.camera
    objs = {}
    xml = ['<?xml version="1.0" encoding="utf-8"?>',
           "<!-- livingroom.xml, written by scenes/generate_interiors.py (metres, y up):",
           "     the livingroom scene (livingroom.obj) for Mitsuba 3, one OBJ per material;",
           "     lit only through its three windows (area emitters). -->",
           '<scene version="3.0.0">',
           '  <integrator type="path">',
           '    <integer name="max_depth" value="65"/>',
           "  </integrator>",
           '  <sensor type="perspective">',
           '    <float name="fov" value="%s"/>' % _fmt(fov),
           '    <string name="fov_axis" value="y"/>',
           '    <transform name="to_world">',
           '      <lookat origin="%s, %s, %s" target="%s, %s, %s" up="0, 1, 0"/>'
           % (tuple(_fmt(c) for c in eye) + tuple(_fmt(c) for c in target)),
           "    </transform>",
           '    <sampler type="independent">',
           '      <integer name="sample_count" value="64"/>',
           "    </sampler>",
           '    <film type="hdrfilm">',
           '      <integer name="width" value="160"/>',
           '      <integer name="height" value="120"/>',
           '      <rfilter type="box"/>',
           "    </film>",
           "  </sensor>"]

    def rgb(v):
        return ", ".join(_fmt(c) for c in v)
    for mtl, (verts, tris) in _faces_by_material(s).items():
        p = _mtl_dict(s.mtls[mtl])
        fname = mtl + ".obj"
        smooth = verts[0][1] is not None
        text = ["# %s, written by scenes/generate_interiors.py: material %s of "
                "livingroom_mitsuba/livingroom.xml\n" % (fname, mtl)]
        text += ["v %s %s %s\n" % v[0] for v in verts]
        if smooth:
            text += ["vn %s %s %s\n" % v[1] for v in verts]
            text += ["f %d//%d %d//%d %d//%d\n" % (a + 1, a + 1, b + 1, b + 1, c + 1, c + 1)
                     for a, b, c in tris]
        else:
            text += ["f %d %d %d\n" % (a + 1, b + 1, c + 1) for a, b, c in tris]
        objs[fname] = "".join(text)
        xml.append('  <shape type="obj">  <!-- %d triangles -->' % len(tris))
        xml.append('    <string name="filename" value="%s"/>' % fname)
        if not smooth:         # boxes: flat faces, not normals averaged over their corners
            xml.append('    <boolean name="face_normals" value="true"/>')
        kind, alpha = LR_MITSUBA_BSDF.get(mtl, ("diffuse", None))
        if "Ke" in p:
            xml.append('    <bsdf type="diffuse"><rgb name="reflectance" value="%s"/></bsdf>'
                       % rgb(p["Kd"]))
            xml.append('    <emitter type="area"><rgb name="radiance" value="%s"/></emitter>'
                       % rgb(p["Ke"]))
        elif kind == "diffuse":
            xml.append('    <bsdf type="diffuse"><rgb name="reflectance" value="%s"/></bsdf>'
                       % rgb(p["Kd"]))
        elif kind in ("plastic", "roughplastic"):
            xml.append('    <bsdf type="%s">' % kind)
            if alpha is not None:
                xml.append('      <string name="distribution" value="ggx"/>')
                xml.append('      <float name="alpha" value="%s"/>' % _fmt(alpha))
            xml.append('      <rgb name="diffuse_reflectance" value="%s"/>' % rgb(p["Kd"]))
            xml.append("    </bsdf>")
        elif kind == "conductor":
            xml.append('    <bsdf type="conductor">')
            xml.append('      <string name="material" value="none"/>')
            xml.append('      <rgb name="specular_reflectance" value="%s"/>' % rgb(p["Ks"]))
            xml.append("    </bsdf>")
        else:
            xml.append('    <bsdf type="roughconductor">')
            xml.append('      <string name="material" value="Al"/>')
            xml.append('      <string name="distribution" value="ggx"/>')
            xml.append('      <float name="alpha" value="%s"/>' % _fmt(alpha))
            xml.append("    </bsdf>")
        xml.append("  </shape>")
    xml.append("</scene>")
    s.mitsuba = ("\n".join(xml) + "\n", objs)
    s.tri_count = s.triangles()
    return s


# --- doorajar -----------------------------------------------------------------------

DA_W, DA_D, DA_H, DA_T = 4.0, 4.0, 2.6, 0.2
DA_DOOR = (1.2, 2.1)            # door opening along z in the shared wall
DA_ANGLE = 15.0                 # the door is open by this much, into the dark room


def doorajar():
    """Two rooms (x in [0, 4] lit, [4.2, 8.2] dark) joined by a 0.9 m doorway
    whose 4 cm door stands ajar by 15 degrees into the dark room."""
    s = Interior("doorajar")
    W, D, H, T = DA_W, DA_D, DA_H, DA_T
    white = s.material("wall_white", kd=(0.75, 0.74, 0.71))
    blue = s.material("wall_blue", kd=(0.50, 0.58, 0.70))
    floor = s.material("floor", kd=(0.55, 0.45, 0.35))
    ceil = s.material("ceiling", kd=(0.80, 0.80, 0.80))
    door_m = s.material("door", kd=(0.65, 0.55, 0.42))
    wood = s.material("wood", kd=(0.45, 0.30, 0.18), ks=(0.05, 0.05, 0.05), ns=60)
    metal = s.material("metal", kd=(0.25, 0.25, 0.27), ks=(0.3, 0.3, 0.3), ns=80)
    sheet = s.material("sheet", kd=(0.78, 0.77, 0.74))
    duvet = s.material("duvet", kd=(0.55, 0.22, 0.20))
    fabric = s.material("fabric_green", kd=(0.20, 0.38, 0.25))
    rug = s.material("rug", kd=(0.30, 0.30, 0.45))
    books = [s.material("book_%d" % i, kd=c) for i, c in enumerate(BOOK_COLOURS)]
    lamp = s.material("light", kd=(0.8, 0.8, 0.8), ke=(40, 40, 40))
    X1 = W + T                  # the dark room's interior: x in [X1, X1 + W]
    s.shell(0, X1 + W, 0, D, H, T, white, floor, ceil, {"+x": blue})
    s.group("shared_wall")
    z0, z1 = DA_DOOR
    hx = W + T / 2
    s.wall("z", hx, -T / 2, D + T / 2, T, white, doors=[(z0, z1)], y1=H + 0.1)
    s.group("door")
    # closed, the door is centred on the wall's centre line from 3 cm inside the
    # hinge jamb to 3 mm short of the latch jamb; it turns about the hinge (z0, on
    # the centre line) by +15 degrees, its free edge moving into the dark room (+x)
    dt = 0.04
    s.box((hx - dt / 2, -0.02, z0 - 0.03), (hx + dt / 2, H_DOOR + 0.01, z1 - 0.003), door_m,
          rot=(DA_ANGLE, (hx, z0)))
    s.box((hx + dt / 2, 0.98, z0 + 0.78), (hx + dt / 2 + 0.05, 1.02, z0 + 0.82), metal,
          rot=(DA_ANGLE, (hx, z0)))                             # the handle
    s.group("light")
    s.light(W / 2, D / 2, 2.4, 2.4, H - 0.01, lamp)

    s.group("lit_room")         # a bed against the west wall, a wardrobe, a shelf
    bed(s, Frame(1.08, 2.9, 90), 1.5, 2.0, wood, sheet, duvet, sheet)
    s.box((0.05, 0, 1.45), (0.5, 0.55, 1.95), wood)            # night stand
    s.box((0.6, 0, 0.0), (1.8, 2.1, 0.6), door_m, {"+z": wood})  # wardrobe
    shelf(s, 2.3, 0.0, 1.0, 0.32, 1.8, wood, books, seed=21)
    s.box((2.3, 0, 2.3), (3.3, 0.01, 3.5), rug)
    chair(s, 3.3, 3.3, fabric, metal, facing=200)

    s.group("dark_room")        # a desk with a chair, a shelf, an armchair
    desk(s, X1 + W - 0.75, 0.6, 0.7, 1.5, wood, metal)         # against the east wall
    chair(s, X1 + W - 1.05, 1.35, fabric, metal, facing=-90)
    shelf(s, X1 + 1.3, 0.0, 1.1, 0.35, 2.0, wood, books, seed=22)
    sofa(s, Frame(X1 + 1.0, 3.4, 160), 0.85, 0.85, fabric, duvet, wood, seats=1)
    s.box((X1 + 2.2, 0, 3.5), (X1 + 3.0, 0.8, 3.98), wood)    # a chest of drawers
    s.box((X1 + 1.0, 0, 1.2), (X1 + 2.6, 0.01, 2.6), rug)
    s.camera = ((X1 + W - 0.25, 1.6, D - 0.2), (hx + 0.3, 0.85, 1.75), 64)
    return s


# --- stairwell ----------------------------------------------------------------------

SW_W, SW_D, SW_H, SW_TS, SW_T = 4.0, 5.0, 2.7, 0.2, 0.2
SW_HOLE = (2.8, 4.0, 1.0, 4.0)  # floor opening x0, x1, z0, z1 (against the east wall)


def stairwell():
    """Two storeys (x in [0, 4], z in [0, 5], 2.7 m each; the upper floor is the top
    of a 0.2 m slab at y = 2.7) joined by a 1.2 x 3 m opening in the slab with a
    straight open stair rising towards -z through it; lights only upstairs."""
    s = Interior("stairwell")
    W, D, H, TS, T = SW_W, SW_D, SW_H, SW_TS, SW_T
    Y2 = H + TS                 # the upper floor
    TOP = Y2 + H                # the upper ceiling
    white = s.material("wall_white", kd=(0.74, 0.72, 0.68))
    warm = s.material("wall_warm", kd=(0.70, 0.55, 0.42))
    tiles = s.material("floor_tiles", kd=(0.38, 0.36, 0.33), ks=(0.15, 0.15, 0.15), ns=150)
    boards = s.material("floor_boards", kd=(0.48, 0.36, 0.24))
    ceil = s.material("ceiling", kd=(0.80, 0.80, 0.80))
    wood = s.material("wood", kd=(0.50, 0.35, 0.21))
    banister = s.material("banister", kd=(0.22, 0.12, 0.07), ks=(0.3, 0.3, 0.3), ns=150)
    metal = s.material("metal", kd=(0.25, 0.25, 0.27), ks=(0.3, 0.3, 0.3), ns=80)
    fabric = s.material("fabric_grey", kd=(0.35, 0.35, 0.38))
    cushion = s.material("cushion", kd=(0.60, 0.25, 0.15))
    books = [s.material("book_%d" % i, kd=c) for i, c in enumerate(BOOK_COLOURS)]
    lamp = s.material("light", kd=(0.8, 0.8, 0.8), ke=(40, 40, 40))

    s.group("floor")
    s.box((-T, -T, -T), (W + T, 0, D + T), tiles)
    s.group("middle_slab")      # the upper floor with its opening
    hx0, hx1, hz0, hz1 = SW_HOLE
    for a0, a1, b0, b1 in _rects_minus(-T, W + T, -T, D + T, [(hx0, hx1, hz0, hz1)]):
        s.box((a0, H, b0), (a1, Y2, b1), boards, {"-y": ceil})
    s.group("ceiling")
    s.box((-T, TOP, -T), (W + T, TOP + T, D + T), ceil)
    s.group("outer_walls")      # both storeys, through the slab
    y0, y1 = -T / 2, TOP + T / 2
    s.box((-T, y0, -T), (0, y1, D + T), white, {"+x": warm})
    s.box((W, y0, -T), (W + T, y1, D + T), white)
    s.box((-T, y0, -T), (W + T, y1, 0), white)
    s.box((-T, y0, D), (W + T, y1, D + T), white)

    s.group("stair")            # 16 risers up to Y2, arriving at z = hz0
    n, run = 16, 0.25
    rise = Y2 / n
    zb = hz0 + (n - 1) * run    # the bottom riser
    sx0, sx1 = hx0 + 0.05, hx1 - 0.05
    for i in range(1, n):
        za = hz0 + (n - 1 - i) * run
        s.box((sx0, i * rise - 0.05, za - 0.02), (sx1, i * rise, za + run), wood)
    k = rise / run

    def nose(z):                # the line through the treads' nosings
        return k * (zb - z)
    for xa, xb in ((hx0, sx0), (sx1, hx1)):      # stringers
        prism_x(s, xa, xb, [(zb - 0.2 / k, 0), (zb + 0.05, 0), (zb + 0.05, nose(zb + 0.05) + 0.12),
                            (hz0 - 0.02, nose(hz0 - 0.02) + 0.12),
                            (hz0 - 0.02, nose(hz0 - 0.02) - 0.2)], wood)
    s.group("banister")         # the stair's hand rail, newel post and balusters
    rx0, rx1, rail = hx0 + 0.01, hx0 + 0.05, 0.9
    prism_x(s, rx0 - 0.01, rx1 + 0.01, [(zb + 0.05, nose(zb + 0.05) + rail),
                                        (hz0 - 0.02, nose(hz0 - 0.02) + rail),
                                        (hz0 - 0.02, nose(hz0 - 0.02) + rail + 0.06),
                                        (zb + 0.05, nose(zb + 0.05) + rail + 0.06)], banister)
    s.box((rx0 - 0.02, 0, zb - 0.06), (rx1 + 0.02, nose(zb - 0.06) + rail + 0.1, zb + 0.02),
          banister)
    for i in range(1, n):
        zc = hz0 + (n - 1 - i) * run + run / 2
        s.box((rx0 + 0.005, nose(zc + 0.02) + 0.12, zc - 0.015),
              (rx1 - 0.005, nose(zc - 0.02) + rail + 0.01, zc + 0.015), banister)
    s.group("railing")          # round the opening upstairs: west side and north end
    top_y = Y2 + 0.95
    s.box((hx0 - 0.06, Y2, hz0 - 0.06), (hx0, top_y, hz0), banister)       # posts
    s.box((hx0 - 0.06, Y2, hz1), (hx0, top_y, hz1 + 0.06), banister)
    s.box((hx0 - 0.06, top_y - 0.05, hz0 - 0.06), (hx0, top_y + 0.01, hz1 + 0.06), banister)
    s.box((hx0, top_y - 0.05, hz1), (hx1, top_y + 0.01, hz1 + 0.06), banister)
    zz = hz0 + 0.15
    while zz < hz1 - 0.1:
        s.box((hx0 - 0.04, Y2, zz - 0.0125), (hx0 - 0.015, top_y - 0.05, zz + 0.0125), banister)
        zz += 0.15
    xx = hx0 + 0.15
    while xx < hx1 - 0.05:
        s.box((xx - 0.0125, Y2, hz1 + 0.02), (xx + 0.0125, top_y - 0.05, hz1 + 0.045), banister)
        xx += 0.15

    s.group("lights")           # upstairs only
    for cz in (1.5, 3.5):
        s.light(1.4, cz, 1.1, 1.1, TOP - 0.01, lamp)

    s.group("downstairs")       # a sofa, a table, a shelf, a cabinet
    sofa(s, Frame(0.5, 3.3, 90), 2.0, 0.9, fabric, cushion, wood)
    desk(s, 1.3, 2.95, 0.9, 0.6, wood, wood, h=0.42, top=0.04)
    shelf(s, 1.1, 0.0, 1.2, 0.35, 2.0, wood, books, seed=31)
    cabinet(s, Frame(1.95, D - 0.25, 180), 1.2, 0.45, 0.8, wood, metal, metal)
    s.group("upstairs")         # a desk with a chair, a shelf, an armchair
    s.lift = Y2
    desk(s, 0.0, 0.8, 0.7, 1.4, wood, metal)
    chair(s, 0.95, 1.5, fabric, metal, facing=90)
    shelf(s, 0.5, D - 0.36, 1.5, 0.35, 2.0, wood, books, seed=32, flip=True)
    sofa(s, Frame(2.0, 0.5, 0), 0.85, 0.85, fabric, cushion, wood, seats=1)
    s.lift = 0.0
    s.camera = ((0.4, 1.5, 4.6), (3.2, 1.3, 1.4), 68)
    return s


# --- sealed0, sealed2 ---------------------------------------------------------------

def sealed(thick):
    """Two rooms 3.5 x 3.5 x 2.5 m (x in [0, 3.5] lit, [3.5, 7] dark) under one
    floor slab and one ceiling slab, separated by one wall at x = 3.5, standing on
    the floor's top face and ending at the ceiling's bottom face (1 mm into both
    and into the outer walls): a single two-sided quad (thick == 0) or a closed
    box `thick` m thick. No light path can reach the dark room."""
    s = Interior("sealed%d" % round(thick * 100))
    W, D, H, T = 3.5, 3.5, 2.5, 0.2
    white = s.material("wall_white", kd=(0.75, 0.74, 0.71))
    green = s.material("wall_green", kd=(0.30, 0.48, 0.32))
    floor = s.material("floor", kd=(0.50, 0.42, 0.32), ks=(0.1, 0.1, 0.1), ns=80)
    ceil = s.material("ceiling", kd=(0.80, 0.80, 0.80))
    shared = s.material("shared_wall", kd=(0.75, 0.74, 0.71))
    wood = s.material("wood", kd=(0.50, 0.35, 0.21))
    fabric = s.material("fabric_red", kd=(0.55, 0.12, 0.10))
    cushion = s.material("cushion", kd=(0.70, 0.62, 0.45))
    metal = s.material("metal", kd=(0.25, 0.25, 0.27), ks=(0.3, 0.3, 0.3), ns=80)
    books = [s.material("book_%d" % i, kd=c) for i, c in enumerate(BOOK_COLOURS)]
    lamp = s.material("light", kd=(0.8, 0.8, 0.8), ke=(20, 20, 20))
    s.shell(0, 2 * W, 0, D, H, T, white, floor, ceil, {"-x": green})
    s.group("shared_wall")
    e = 0.001
    if thick == 0:
        s.quad(((W, -e, -e), (W, -e, D + e), (W, H + e, D + e), (W, H + e, -e)), (1, 0, 0), shared)
    else:
        s.box((W - thick / 2, -e, -e), (W + thick / 2, H + e, D + e), shared)
    face = W - thick / 2        # the lit side's face of the shared wall
    s.group("light")
    s.light(1.6, 1.75, 1.0, 1.0, H - 0.01, lamp)
    s.group("lit_room")         # a shelf and a sofa right against the shared wall
    shelf(s, face - 0.01 - 0.35, 0.25, 1.0, 0.35, 2.0, wood, books, seed=41, along="z", flip=True)
    sofa(s, Frame(face - 0.01 - 0.45, 2.35, -90), 1.7, 0.9, fabric, cushion, wood, seats=2)
    desk(s, 1.6, 1.9, 0.8, 0.6, wood, wood, h=0.42, top=0.04)
    chair(s, 0.6, 0.8, fabric, metal, facing=135)
    s.group("dark_room")        # a table and a chair (never lit)
    desk(s, W + 2.2, 0.4, 1.0, 0.7, wood, metal)
    chair(s, W + 2.7, 1.4, fabric, metal, facing=0)
    s.camera = ((2 * W - 0.3, 1.6, D - 0.25), (W, 0.25, 1.3), 70)
    s.extra_cams["_lit"] = ((0.3, 1.6, D - 0.25), (W, 0.3, 1.3), 70)
    return s


def sealed0():
    return sealed(0.0)


def sealed2():
    return sealed(0.02)


SCENES = {
    "livingroom": livingroom,
    "livingroom_sky": livingroom_sky,
    "livingroom_mitsuba": livingroom_mitsuba,
    "doorajar": doorajar,
    "stairwell": stairwell,
    "sealed0": sealed0,
    "sealed2": sealed2,
}


def write(s, outdir):
    """Writes scene s; returns the list of files written (relative to outdir)."""
    if hasattr(s, "pbrt_text"):
        with open(os.path.join(outdir, s.name + ".pbrt"), "w") as f:
            f.write(s.pbrt_text)
        return [s.name + ".pbrt"]
    if hasattr(s, "mitsuba"):
        xml, objs = s.mitsuba
        d = os.path.join(outdir, s.name)
        os.makedirs(d, exist_ok=True)
        with open(os.path.join(d, "livingroom.xml"), "w") as f:
            f.write(xml)
        for fname, text in sorted(objs.items()):
            with open(os.path.join(d, fname), "w") as f:
                f.write(text)
        return [s.name + "/livingroom.xml"] + [s.name + "/" + k for k in sorted(objs)]
    s.write(outdir)
    return [s.name + e for e in (".obj", ".mtl", ".cam")] + [
        s.name + k + ".cam" for k in sorted(s.extra_cams)]


def main(argv):
    if len(argv) < 2 or argv[1] in ("-h", "--help"):
        sys.stderr.write("usage: %s OUTDIR [NAME ...]\nscenes (default: all): %s\n"
                         % (argv[0], " ".join(SCENES)))
        return 2
    outdir = argv[1]
    names = argv[2:] or list(SCENES)
    for n in names:
        if n not in SCENES:
            sys.stderr.write("%s: unknown scene '%s' (scenes: %s)\n"
                             % (argv[0], n, " ".join(SCENES)))
            return 2
    os.makedirs(outdir, exist_ok=True)
    for n in names:
        s = SCENES[n]()
        files = write(s, outdir)
        print("%-18s %6d triangles, %2d lights (%d emitting triangles), %.2f m^2 of light: %s"
              % (n, s.triangles(), s.light_panels, s.emitting_triangles(), s.light_area,
                 " ".join(files[:4]) + (" ..." if len(files) > 4 else "")))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
