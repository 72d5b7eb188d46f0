#!/usr/bin/python3
"""Procedural test scenes for candela (Wavefront OBJ + MTL).

    scenes/generate.py OUTDIR [NAME ...]

writes NAME.obj, NAME.mtl and NAME.cam for every named scene (default: all but the
large `building`, which is written only when named and is not committed) into
OUTDIR. NAME.cam is one line of `--lookat ... --fov ...` arguments for a good
default view, so that a script can run

    candela render OUTDIR/NAME.obj $(cat OUTDIR/NAME.cam) ...

Conventions: metres, y up. Every wall, floor and ceiling is a closed box (a solid
slab) made of quads of two triangles each, wound counter-clockwise seen from outside
the slab, so that the faces bounding a room face into it (the floor's top face has
normal +y). Walls reach 0.1 m into the floor and ceiling slabs and half a wall
thickness into the walls they meet, so no crack lets light through; every building
is enclosed by its outer walls, floor and ceiling. Light panels are single quads just
below the ceiling whose front (emitting) face points down. The output is
deterministic: no randomness except random.Random with fixed seeds.
"""

import math
import os
import random
import sys

H_DOOR = 2.1  # door opening height (m)


def _fmt(x):
    s = "%.4f" % x
    s = s.rstrip("0").rstrip(".")
    return "0" if s in ("-0", "") else s


def _sub(a, b):
    return (a[0] - b[0], a[1] - b[1], a[2] - b[2])


def _cross(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def _dot(a, b):
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def _norm(a):
    n = math.sqrt(_dot(a, a))
    return (a[0] / n, a[1] / n, a[2] / n)


class Scene:
    def __init__(self, name):
        self.name = name
        self.verts = []
        self.vindex = {}
        self.normals = []
        self.nindex = {}
        self.groups = []  # [name, [(mtl, ((v, n), (v, n), (v, n)))...]]
        self.mtls = {}  # name -> list of MTL lines
        self.light_panels = 0
        self.light_area = 0.0
        self.camera = None

    # --- materials ------------------------------------------------------------
    def material(self, name, kd=(0.5, 0.5, 0.5), ks=None, ns=None, ke=None, illum=None,
                 ni=None):
        if name in self.mtls:
            return name
        lines = ["Kd %s %s %s" % tuple(_fmt(c) for c in kd)]
        if ks is not None:
            lines.append("Ks %s %s %s" % tuple(_fmt(c) for c in ks))
        if ns is not None:
            lines.append("Ns %s" % _fmt(ns))
        if ni is not None:
            lines.append("Ni %s" % _fmt(ni))
        if ke is not None:
            lines.append("Ke %s %s %s" % tuple(_fmt(c) for c in ke))
        if illum is not None:
            lines.append("illum %d" % illum)
        self.mtls[name] = lines
        return name

    # --- geometry -------------------------------------------------------------
    def group(self, name):
        self.groups.append([name, []])

    def _v(self, p):
        key = tuple(_fmt(c) for c in p)
        i = self.vindex.get(key)
        if i is None:
            self.verts.append(key)
            i = self.vindex[key] = len(self.verts)
        return i

    def _n(self, n):
        key = tuple(_fmt(c) for c in n)
        i = self.nindex.get(key)
        if i is None:
            self.normals.append(key)
            i = self.nindex[key] = len(self.normals)
        return i

    def tri(self, a, b, c, mtl, na=None, nb=None, nc=None):
        if not self.groups:
            self.group("default")
        if na is None:
            f = ((self._v(a), None), (self._v(b), None), (self._v(c), None))
        else:
            f = ((self._v(a), self._n(na)), (self._v(b), self._n(nb)), (self._v(c), self._n(nc)))
        self.groups[-1][1].append((mtl, f))

    def quad(self, p, normal, mtl):
        """A planar quad p[0..3] (in order around its edge) as two triangles wound
        counter-clockwise seen from the side `normal` points to."""
        n = _cross(_sub(p[1], p[0]), _sub(p[2], p[0]))
        if _dot(n, normal) < 0:
            p = p[::-1]
        assert _dot(_cross(_sub(p[1], p[0]), _sub(p[2], p[0])), normal) > 0
        self.tri(p[0], p[1], p[2], mtl)
        self.tri(p[0], p[2], p[3], mtl)

    def box(self, lo, hi, mtl, face_mtl=None, rot=None):
        """Closed box [lo, hi], faces wound outwards. face_mtl maps any of
        '-x' '+x' '-y' '+y' '-z' '+z' to another material. rot = (angle in degrees
        about the y axis, pivot (x, z)) turns the box about a vertical axis."""
        assert all(hi[i] > lo[i] for i in range(3)), (lo, hi)
        face_mtl = face_mtl or {}
        if rot:
            a = math.radians(rot[0])
            ca, sa = math.cos(a), math.sin(a)
            px, pz = rot[1]

            def tr(p):  # counter-clockwise seen from above (+y) for a > 0
                dx, dz = p[0] - px, p[2] - pz
                return (px + ca * dx + sa * dz, p[1], pz - sa * dx + ca * dz)

            def tn(n):
                return (ca * n[0] + sa * n[2], n[1], -sa * n[0] + ca * n[2])
        else:
            def tr(p):
                return p

            def tn(n):
                return n
        x0, y0, z0 = lo
        x1, y1, z1 = hi
        faces = {
            "-x": ((x0, y0, z0), (x0, y0, z1), (x0, y1, z1), (x0, y1, z0)),
            "+x": ((x1, y0, z0), (x1, y0, z1), (x1, y1, z1), (x1, y1, z0)),
            "-y": ((x0, y0, z0), (x1, y0, z0), (x1, y0, z1), (x0, y0, z1)),
            "+y": ((x0, y1, z0), (x1, y1, z0), (x1, y1, z1), (x0, y1, z1)),
            "-z": ((x0, y0, z0), (x1, y0, z0), (x1, y1, z0), (x0, y1, z0)),
            "+z": ((x0, y0, z1), (x1, y0, z1), (x1, y1, z1), (x0, y1, z1)),
        }
        normals = {"-x": (-1, 0, 0), "+x": (1, 0, 0), "-y": (0, -1, 0), "+y": (0, 1, 0),
                   "-z": (0, 0, -1), "+z": (0, 0, 1)}
        for k in ("-y", "+y", "-x", "+x", "-z", "+z"):
            self.quad([tr(p) for p in faces[k]], tn(normals[k]), face_mtl.get(k, mtl))

    def light(self, cx, cz, sx, sz, y, mtl):
        """A light panel: one quad of sx by sz metres centred at (cx, y, cz), emitting
        downwards (front face normal -y)."""
        x0, x1, z0, z1 = cx - sx / 2, cx + sx / 2, cz - sz / 2, cz + sz / 2
        self.quad(((x0, y, z0), (x1, y, z0), (x1, y, z1), (x0, y, z1)), (0, -1, 0), mtl)
        self.light_panels += 1
        self.light_area += sx * sz

    def wall(self, axis, c, a0, a1, t, mtl, doors=(), y0=-0.1, y1=3.1, face_mtl=None,
             door_h=H_DOOR):
        """A straight wall of thickness t centred on the line {axis-coordinate free,
        other horizontal coordinate = c} from a0 to a1 along `axis` ('x' or 'z'),
        extended by t/2 at both ends, from y0 to y1, with door gaps (d0, d1) along the
        axis up to door_h (a lintel above each)."""
        lo_a, hi_a = a0 - t / 2, a1 + t / 2
        pieces = []
        cur = lo_a
        for d0, d1 in sorted(doors):
            assert d0 > cur and d1 > d0
            pieces.append((cur, d0, y0, y1))
            pieces.append((d0, d1, door_h, y1))
            cur = d1
        pieces.append((cur, hi_a, y0, y1))
        for p0, p1, q0, q1 in pieces:
            if axis == "x":
                self.box((p0, q0, c - t / 2), (p1, q1, c + t / 2), mtl, face_mtl)
            else:
                self.box((c - t / 2, q0, p0), (c + t / 2, q1, p1), mtl, face_mtl)

    def shell(self, x0, x1, z0, z1, h, t, wall_mtl, floor_mtl, ceil_mtl, wall_face_mtl=None):
        """Floor and ceiling slabs and the four outer walls around the interior
        [x0, x1] x [0, h] x [z0, z1]. wall_face_mtl: side ('-x', '+x', '-z', '+z', i.e.
        the wall at x0, x1, z0, z1) -> material of that wall's inner face."""
        wf = wall_face_mtl or {}
        self.group("floor")
        self.box((x0 - t, -t, z0 - t), (x1 + t, 0, z1 + t), floor_mtl)
        self.group("ceiling")
        self.box((x0 - t, h, z0 - t), (x1 + t, h + t, z1 + t), ceil_mtl)
        self.group("outer_walls")
        y0, y1 = -t / 2, h + t / 2
        self.box((x0 - t, y0, z0 - t), (x0, y1, z1 + t), wall_mtl,
                 {"+x": wf["-x"]} if "-x" in wf else None)
        self.box((x1, y0, z0 - t), (x1 + t, y1, z1 + t), wall_mtl,
                 {"-x": wf["+x"]} if "+x" in wf else None)
        self.box((x0 - t, y0, z0 - t), (x1 + t, y1, z0), wall_mtl,
                 {"+z": wf["-z"]} if "-z" in wf else None)
        self.box((x0 - t, y0, z1), (x1 + t, y1, z1 + t), wall_mtl,
                 {"-z": wf["+z"]} if "+z" in wf else None)

    def sphere(self, c, r, mtl, nu=48, nv=24):
        """UV sphere with vertex normals, wound outwards."""
        def pt(i, j):
            th = math.pi * j / nv
            ph = 2 * math.pi * i / nu
            n = (math.sin(th) * math.cos(ph), math.cos(th), -math.sin(th) * math.sin(ph))
            return (c[0] + r * n[0], c[1] + r * n[1], c[2] + r * n[2]), n
        for j in range(nv):
            for i in range(nu):
                (a, na), (b, nb) = pt(i, j), pt(i + 1, j)
                (cc, nc), (d, nd) = pt(i + 1, j + 1), pt(i, j + 1)
                # outward: counter-clockwise seen from outside
                if j != 0:
                    self._tri_out(a, d, b, na, nd, nb, mtl, c)
                if j != nv - 1:
                    self._tri_out(b, d, cc, nb, nd, nc, mtl, c)

    def _tri_out(self, a, b, c, na, nb, nc, mtl, centre):
        n = _cross(_sub(b, a), _sub(c, a))
        mid = tuple((a[k] + b[k] + c[k]) / 3 - centre[k] for k in range(3))
        if _dot(n, mid) < 0:
            b, c, nb, nc = c, b, nc, nb
        self.tri(a, b, c, mtl, na, nb, nc)

    def ring(self, cx, cz, r_in, r_out, h, mtl, outer_mtl=None, n=96):
        """A closed thick ring (tube wall) standing on y = 0, with vertex normals; the
        inner wall is made of mtl, the outer wall and the rims of outer_mtl."""
        outer_mtl = outer_mtl or mtl
        up, down = (0, 1, 0), (0, -1, 0)

        def p(d, r, y):
            return (cx + r * d[0], y, cz + r * d[2])
        for part in ("inner", "outer", "top", "bottom"):
            for i in range(n):
                a0, a1 = 2 * math.pi * i / n, 2 * math.pi * (i + 1) / n
                d0 = (math.cos(a0), 0, math.sin(a0))
                d1 = (math.cos(a1), 0, math.sin(a1))
                neg0, neg1 = (-d0[0], 0, -d0[2]), (-d1[0], 0, -d1[2])
                if part == "inner":     # normal towards the axis
                    self._quad_n(p(d0, r_in, 0), p(d1, r_in, 0), p(d1, r_in, h),
                                 p(d0, r_in, h), neg0, neg1, neg1, neg0, mtl, neg0)
                elif part == "outer":   # normal outwards
                    self._quad_n(p(d0, r_out, 0), p(d1, r_out, 0), p(d1, r_out, h),
                                 p(d0, r_out, h), d0, d1, d1, d0, outer_mtl, d0)
                else:
                    y, nn = (h, up) if part == "top" else (0, down)
                    self._quad_n(p(d0, r_in, y), p(d1, r_in, y), p(d1, r_out, y),
                                 p(d0, r_out, y), nn, nn, nn, nn, outer_mtl, nn)

    def _quad_n(self, a, b, c, d, na, nb, nc, nd, mtl, normal):
        n = _cross(_sub(b, a), _sub(c, a))
        if _dot(n, normal) < 0:
            a, b, c, d, na, nb, nc, nd = d, c, b, a, nd, nc, nb, na
        self.tri(a, b, c, mtl, na, nb, nc)
        self.tri(a, c, d, mtl, na, nc, nd)

    # --- output ---------------------------------------------------------------
    def triangles(self):
        return sum(len(g[1]) for g in self.groups)

    def emitting_triangles(self):
        emitters = {k for k, v in self.mtls.items() if any(l.startswith("Ke") for l in v)}
        return sum(1 for g in self.groups for m, _ in g[1] if m in emitters)

    def write(self, outdir):
        base = os.path.join(outdir, self.name)
        with open(base + ".mtl", "w") as f:
            f.write("# %s.mtl, written by scenes/generate.py\n" % self.name)
            for k, lines in self.mtls.items():
                f.write("\nnewmtl %s\n" % k)
                for l in lines:
                    f.write("  %s\n" % l)
        with open(base + ".obj", "w") as f:
            f.write("# %s.obj, written by scenes/generate.py (metres, y up)\n" % self.name)
            f.write("# %d triangles, %d light panels\n" % (self.triangles(), self.light_panels))
            f.write("mtllib %s.mtl\n" % self.name)
            for v in self.verts:
                f.write("v %s %s %s\n" % v)
            for n in self.normals:
                f.write("vn %s %s %s\n" % n)
            for gname, faces in self.groups:
                if not faces:
                    continue
                f.write("g %s\n" % gname)
                cur = None
                for mtl, face in faces:
                    if mtl != cur:
                        f.write("usemtl %s\n" % mtl)
                        cur = mtl
                    if face[0][1] is None:
                        f.write("f %d %d %d\n" % (face[0][0], face[1][0], face[2][0]))
                    else:
                        f.write("f %d//%d %d//%d %d//%d\n" % (
                            face[0][0], face[0][1], face[1][0], face[1][1],
                            face[2][0], face[2][1]))
        eye, target, fov = self.camera
        with open(base + ".cam", "w") as f:
            f.write("--lookat %s,%s,%s,%s,%s,%s,0,1,0 --fov %s\n" % (
                tuple(_fmt(c) for c in eye) + tuple(_fmt(c) for c in target) + (_fmt(fov),)))


# --- furniture ------------------------------------------------------------------

def desk(s, x0, z0, w, d, mtl_top, mtl_leg, h=0.75, top=0.03, leg=0.05):
    s.box((x0, h - top, z0), (x0 + w, h, z0 + d), mtl_top)
    for lx in (x0 + 0.03, x0 + w - 0.03 - leg):
        for lz in (z0 + 0.03, z0 + d - 0.03 - leg):
            s.box((lx, 0, lz), (lx + leg, h - top, lz + leg), mtl_leg)


def chair(s, cx, cz, mtl_seat, mtl_leg, facing=0.0, w=0.46, seat_h=0.46, back_h=0.9):
    """A chair centred at (cx, cz); facing (degrees, counter-clockwise seen from
    above) = 0 faces -z (the back rest is on the +z side)."""
    rot = (facing, (cx, cz))
    hw = w / 2
    s.box((cx - hw, seat_h - 0.05, cz - hw), (cx + hw, seat_h, cz + hw), mtl_seat, rot=rot)
    s.box((cx - hw, seat_h, cz + hw - 0.05), (cx + hw, back_h, cz + hw), mtl_seat, rot=rot)
    for lx in (cx - hw + 0.02, cx + hw - 0.05):
        for lz in (cz - hw + 0.02, cz + hw - 0.05):
            s.box((lx, 0, lz), (lx + 0.03, seat_h - 0.05, lz + 0.03), mtl_leg, rot=rot)


def shelf(s, x0, z0, w, d, h, mtl, book_mtls, boards=5, seed=0, along="x", flip=False):
    """A bookshelf with books standing on the floor: w wide along `along`, d deep.
    along == 'x': [x0, x0 + w] x [z0, z0 + d], back at z0, open towards +z;
    along == 'z': [x0, x0 + d] x [z0, z0 + w], back at x0, open towards +x.
    flip puts the back on the other side (open towards -z or -x)."""
    rng = random.Random(seed)
    th = 0.02

    def B(a0, b0, y0, a1, b1, y1, m):
        if flip:
            b0, b1 = d - b1, d - b0
        if along == "x":
            s.box((x0 + a0, y0, z0 + b0), (x0 + a1, y1, z0 + b1), m)
        else:
            s.box((x0 + b0, y0, z0 + a0), (x0 + b1, y1, z0 + a1), m)
    B(0, 0, 0, th, d, h, mtl)
    B(w - th, 0, 0, w, d, h, mtl)
    B(th, 0, 0, w - th, th, h, mtl)  # back
    step = (h - th) / boards
    for k in range(boards + 1):
        y = k * step
        B(th, th, y, w - th, d, y + th, mtl)
        if k == boards:
            break
        # books on this board
        a = th + 0.02
        while True:
            bw = rng.uniform(0.025, 0.06)
            if a + bw > w - th - 0.02:
                break
            if rng.random() < 0.12:
                a += rng.uniform(0.05, 0.15)
                continue
            bh = rng.uniform(0.6, 0.85) * (step - th)
            bd = rng.uniform(0.6, 0.9) * (d - th)
            B(a, th + 0.01, y + th, a + bw, th + 0.01 + bd, y + th + bh,
              book_mtls[rng.randrange(len(book_mtls))])
            a += bw + 0.003


# --- scenes ---------------------------------------------------------------------

def office():
    s = Scene("office")
    W, D, H, T = 6.0, 4.0, 3.0, 0.2
    white = s.material("wall_white", kd=(0.72, 0.71, 0.68))
    blue = s.material("wall_blue", kd=(0.22, 0.33, 0.55))
    terra = s.material("wall_terracotta", kd=(0.60, 0.38, 0.28))
    floor = s.material("carpet", kd=(0.30, 0.30, 0.33))
    ceil = s.material("ceiling", kd=(0.80, 0.80, 0.80))
    wood = s.material("wood", kd=(0.50, 0.34, 0.20), ks=(0.04, 0.04, 0.04), ns=60)
    metal = s.material("metal", kd=(0.25, 0.25, 0.27), ks=(0.30, 0.30, 0.30), ns=80)
    red = s.material("fabric_red", kd=(0.55, 0.08, 0.07))
    navy = s.material("fabric_navy", kd=(0.08, 0.12, 0.35))
    part = s.material("partition", kd=(0.35, 0.45, 0.32))
    black = s.material("screen", kd=(0.03, 0.03, 0.03), ks=(0.2, 0.2, 0.2), ns=200)
    books = [s.material("book_%d" % i, kd=c) for i, c in enumerate(
        [(0.6, 0.1, 0.1), (0.1, 0.2, 0.5), (0.7, 0.6, 0.3), (0.15, 0.4, 0.15),
         (0.75, 0.75, 0.7), (0.3, 0.15, 0.3)])]
    lamp = s.material("light", kd=(0.8, 0.8, 0.8), ke=(15, 15, 15))
    # west wall (x = 0) blue, south wall (z = 0) terracotta, the rest white
    s.shell(0, W, 0, D, H, T, white, floor, ceil, {"-x": blue, "-z": terra})

    # lit half: x < 3; three panels over it
    s.group("lights")
    for cz in (0.8, 2.0, 3.2):
        s.light(1.5, cz, 1.2, 0.6, H - 0.01, lamp)

    s.group("partition")  # a screen 1.7 m high from the south wall
    s.box((3.15, 0, -0.05), (3.2, 1.7, 2.6), part)
    s.box((3.1, 0, 2.6), (3.25, 1.72, 2.65), metal)

    s.group("desks")
    desk(s, 0.5, 0.15, 1.6, 0.8, wood, metal)     # lit half, against the south wall
    desk(s, 0.9, 3.05, 1.6, 0.8, wood, metal)     # lit half, against the north wall
    desk(s, 4.3, 0.15, 1.6, 0.8, wood, metal)     # dark half
    s.group("monitors")
    for (mx, mz) in ((1.3, 0.35), (5.1, 0.35)):
        s.box((mx - 0.28, 0.85, mz), (mx + 0.28, 1.2, mz + 0.03), black)
        s.box((mx - 0.03, 0.75, mz), (mx + 0.03, 0.85, mz + 0.06), metal)
        s.box((mx - 0.12, 0.75, mz - 0.05), (mx + 0.12, 0.76, mz + 0.12), metal)
    s.group("chairs")
    chair(s, 1.3, 1.35, navy, metal, facing=0)
    chair(s, 1.7, 2.75, red, metal, facing=180)
    chair(s, 5.1, 1.4, navy, metal, facing=-10)
    chair(s, 5.0, 2.6, red, metal, facing=60)
    s.group("shelves")   # against the south wall, either side of the partition
    shelf(s, 2.2, 0.0, 0.85, 0.35, 2.0, wood, books, seed=1)
    shelf(s, 3.3, 0.0, 0.9, 0.35, 2.2, wood, books, seed=3)
    s.group("shelves_east")   # against the east wall, books facing -x
    s.box((5.55, 0, 1.3), (6.0, 1.0, 2.5), wood)                           # low cabinet
    shelf(s, 5.6, 2.6, 1.2, 0.4, 2.2, wood, books, seed=2, along="z", flip=True)
    s.group("table")
    s.box((3.6, 0.70, 3.0), (4.6, 0.74, 3.8), wood)
    s.box((4.05, 0, 3.35), (4.15, 0.70, 3.45), metal)
    s.camera = ((3.0, 1.9, 3.85), (3.0, 0.8, 0.0), 60)
    return s


def _conference_shell(s, W, D, H, T, floor, ceil, beige, accent, door_m):
    """The conference rooms' floor, ceiling and walls, the south wall with a
    door recess (opening x in [4, 5], the door 0.12 m deep in it); returns
    the opening's x range."""
    s.group("floor")
    s.box((-T, -T, -T), (W + T, 0, D + T), floor)
    s.group("ceiling")
    s.box((-T, H, -T), (W + T, H + T, D + T), ceil)
    s.group("walls")
    s.box((-T, -0.1, -T), (0, H + 0.1, D + T), beige)               # west
    s.box((W, -0.1, -T), (W + T, H + 0.1, D + T), beige, {"-x": accent})  # east
    s.box((-T, -0.1, D), (W + T, H + 0.1, D + T), beige)            # north
    dx0, dx1 = 4.0, 5.0
    s.wall("x", -T / 2, -T / 2, W + T / 2, T, beige, doors=[(dx0, dx1)], y0=-0.1,
           y1=H + 0.1)
    s.group("door")
    s.box((dx0 - 0.05, -0.05, -T), (dx1 + 0.05, H_DOOR + 0.05, -0.12), door_m)
    return dx0, dx1


def conference():
    s = Scene("conference")
    W, D, H, T = 10.0, 6.0, 3.0, 0.2
    beige = s.material("wall_beige", kd=(0.70, 0.66, 0.58))
    accent = s.material("wall_bluegrey", kd=(0.30, 0.38, 0.48))
    floor = s.material("carpet", kd=(0.22, 0.24, 0.30))
    ceil = s.material("ceiling", kd=(0.80, 0.80, 0.80))
    wood = s.material("wood_table", kd=(0.45, 0.28, 0.15), ks=(0.06, 0.06, 0.06), ns=80)
    door_m = s.material("wood_door", kd=(0.55, 0.40, 0.25))
    metal = s.material("metal", kd=(0.25, 0.25, 0.27), ks=(0.30, 0.30, 0.30), ns=80)
    seat = s.material("fabric_black", kd=(0.06, 0.06, 0.07))
    board = s.material("whiteboard", kd=(0.78, 0.78, 0.78), ks=(0.1, 0.1, 0.1), ns=300)
    lamp = s.material("light", kd=(0.8, 0.8, 0.8), ke=(20, 20, 20))

    dx0, dx1 = _conference_shell(s, W, D, H, T, floor, ceil, beige, accent, door_m)
    s.box((dx1 - 0.15, 0.98, -0.12), (dx1 - 0.05, 1.02, -0.07), metal)   # handle

    s.group("lights")
    for cx in (3.0, 5.0, 7.0):
        for cz in (2.1, 3.9):
            s.light(cx, cz, 0.6, 0.6, H - 0.01, lamp)

    s.group("table")
    tx0, tx1, tz0, tz1 = 2.0, 8.0, 2.3, 3.7
    s.box((tx0, 0.71, tz0), (tx1, 0.76, tz1), wood)
    for lx in (2.5, 7.4):
        s.box((lx, 0, 2.6), (lx + 0.1, 0.71, 3.4), metal)
    s.box((2.6, 0.55, 2.95), (7.4, 0.65, 3.05), metal)
    s.group("chairs")
    for cx in (2.8, 3.9, 5.0, 6.1, 7.2):
        chair(s, cx, tz0 - 0.45, seat, metal, facing=180)
        chair(s, cx, tz1 + 0.45, seat, metal, facing=0)
    chair(s, tx0 - 0.45, 3.0, seat, metal, facing=-90)
    chair(s, tx1 + 0.45, 3.0, seat, metal, facing=90)
    s.group("whiteboard")
    s.box((0, 0.9, 1.5), (0.03, 2.1, 4.5), board)
    s.group("sideboard")
    s.box((6.0, 0, 5.5), (9.0, 0.9, 6.0), wood)
    s.camera = ((9.6, 2.1, 5.0), (2.5, 0.5, 1.8), 60)
    return s


def rooms10x10():
    s = Scene("rooms10x10")
    N, P, T, H = 10, 4.2, 0.2, 3.0   # rooms per side, grid pitch, wall thickness, height
    wall_a = s.material("wall_warm", kd=(0.72, 0.68, 0.60))
    wall_b = s.material("wall_cool", kd=(0.60, 0.66, 0.72))
    floor = s.material("floor", kd=(0.40, 0.36, 0.32))
    ceil = s.material("ceiling", kd=(0.80, 0.80, 0.80))
    wood = s.material("wood", kd=(0.50, 0.34, 0.20))
    cols = [s.material("box_%d" % i, kd=c) for i, c in enumerate(
        [(0.6, 0.15, 0.1), (0.15, 0.45, 0.15), (0.15, 0.2, 0.55), (0.7, 0.6, 0.2)])]
    lamp = s.material("light", kd=(0.8, 0.8, 0.8), ke=(20, 20, 20))
    L = N * P   # wall centre lines at 0, P, ..., N P; room interiors 4.0 m square
    s.group("floor")
    s.box((-T / 2, -T, -T / 2), (L + T / 2, 0, L + T / 2), floor)
    s.group("ceiling")
    s.box((-T / 2, H, -T / 2), (L + T / 2, H + T, L + T / 2), ceil)

    def door(k, parity):
        """door gap along the wall segment [k P, (k+1) P]: near one end or the other"""
        return (k * P + 0.8, k * P + 1.8) if parity == 0 else (k * P + 2.4, k * P + 3.4)
    s.group("walls_x")   # walls running along x, at z = j P
    for j in range(N + 1):
        if j in (0, N):
            s.wall("x", j * P, 0, L, T, wall_a, y1=H + 0.1)
        else:
            for i in range(N):
                s.wall("x", j * P, i * P, (i + 1) * P, T, wall_a,
                       doors=[door(i, (i + j) % 2)], y1=H + 0.1)
    s.group("walls_z")   # walls running along z, at x = i P
    for i in range(N + 1):
        if i in (0, N):
            s.wall("z", i * P, 0, L, T, wall_b, y1=H + 0.1)
        else:
            for j in range(N):
                s.wall("z", i * P, j * P, (j + 1) * P, T, wall_b,
                       doors=[door(j, (i + j + 1) % 2)], y1=H + 0.1)
    s.group("lights")
    for j in range(N):
        for i in range(N):
            s.light((i + 0.5) * P, (j + 0.5) * P, 0.8, 0.8, H - 0.01, lamp)
    s.group("furniture")
    rng = random.Random(10)
    for j in range(N):
        for i in range(N):
            x0, z0 = i * P + T / 2, j * P + T / 2   # interior corner
            # a table somewhere in the middle and a cabinet against the back wall
            tx = x0 + rng.uniform(0.8, 2.0)
            tz = z0 + rng.uniform(1.0, 2.0)
            desk(s, tx, tz, 1.2, 0.7, wood, wood, h=0.72, top=0.04, leg=0.06)
            # keep clear of the door in the north wall (line j + 1)
            if (i + j + 1) % 2 == 0:      # door at x0 + [0.7, 1.7]
                cx = x0 + rng.uniform(2.0, 3.2)
            else:                          # door at x0 + [2.3, 3.3]
                cx = x0 + rng.uniform(0.1, 1.5)
            s.box((cx, 0, z0 + 4.0 - 0.45), (cx + 0.7, rng.uniform(0.8, 1.8), z0 + 4.0 - 0.01),
                  cols[rng.randrange(len(cols))])
    # camera in room (4, 4), in its south-west corner looking north-east at the
    # two doors leading to rooms (4, 5) and (5, 4)
    x0, z0 = 4 * P + T / 2, 4 * P + T / 2
    s.camera = ((x0 + 0.3, 1.6, z0 + 0.3), (x0 + 3.3, 1.1, z0 + 3.4), 60)
    return s


def doorslit():
    s = Scene("doorslit")
    W, D, H, T = 4.0, 4.0, 3.0, 0.2     # each room W x D x H
    white = s.material("wall_white", kd=(0.75, 0.74, 0.71))
    floor = s.material("floor", kd=(0.45, 0.40, 0.34))
    ceil = s.material("ceiling", kd=(0.80, 0.80, 0.80))
    door_m = s.material("wood_door", kd=(0.60, 0.45, 0.30))
    red = s.material("fabric_red", kd=(0.55, 0.08, 0.07))
    blue = s.material("wall_blue", kd=(0.25, 0.35, 0.60))
    lamp = s.material("light", kd=(0.8, 0.8, 0.8), ke=(250, 250, 250))
    X1 = W + T          # right room interior x in [X1, X1 + W]
    # both rooms in one shell, split by the shared wall at x in [W, W + T]
    s.shell(0, X1 + W, 0, D, H, T, white, floor, ceil, {"+x": blue})
    s.group("shared_wall")
    z0, z1 = 1.5, 2.4   # door opening
    s.wall("z", W + T / 2, -T / 2, D + T / 2, T, white, doors=[(z0, z1)], y1=H + 0.1)
    # The door (0.9 x 0.04 m) is hinged at z0 on the wall's centre line and opened
    # into the left room by the angle that leaves a straight slit 5 cm wide (seen
    # along x) between its free edge and the frame.
    s.group("door")
    hx, dt, dw, gap = W + T / 2, 0.04, z1 - z0 - 0.003, 0.05

    def slit(a):  # z1 minus the largest z of the door (its +x face's free corner)
        return z1 - (z0 + dt / 2 * math.sin(a) + dw * math.cos(a))
    lo_a, hi_a = 0.0, 0.8
    for _ in range(60):
        mid = (lo_a + hi_a) / 2
        if slit(mid) < gap:
            lo_a = mid
        else:
            hi_a = mid
    ang = math.degrees(hi_a)
    # box in the closed position (centred on x = hx, z from z0 - 0.03 into the
    # frame to z1 - 0.003), then turned about the hinge by -ang (clockwise seen from
    # above), which moves the free edge (+z) towards -x.
    s.box((hx - dt / 2, -0.02, z0 - 0.03), (hx + dt / 2, H_DOOR + 0.01, z1 - 0.003), door_m,
          rot=(-ang, (hx, z0)))
    s.group("light")
    s.light(W / 2, D / 2, 2.0, 2.0, H - 0.01, lamp)
    s.group("furniture")
    chair(s, 1.2, 1.2, red, door_m, facing=30)
    s.box((X1 + 2.6, 0, 2.8), (X1 + 3.8, 0.75, 3.8), door_m)   # a crate in the right room
    s.box((X1 + 0.8, 0, 0.4), (X1 + 1.3, 0.5, 0.9), red)
    s.camera = ((X1 + W - 0.3, 1.5, D - 0.3), (W + T, 1.0, 1.6), 60)
    return s


def tworoom():
    """Two rooms sharing one thin (5 cm) wall with an open doorway, the light in
    the left one; the camera stands in the right room, seeing the dark side of
    the shared wall on the left of the image and the lit room through the
    doorway on the right. Floor and ceiling slabs run on under and over the
    wall: a density estimate that ignores it reads the lit room's photons on
    the dark side of the wall's foot."""
    s = Scene("tworoom")
    W, D, H, T, TS = 3.5, 3.5, 2.5, 0.05, 0.2
    white = s.material("wall_white", kd=(0.75, 0.74, 0.71))
    floor = s.material("floor", kd=(0.50, 0.45, 0.38))
    ceil = s.material("ceiling", kd=(0.80, 0.80, 0.80))
    green = s.material("wall_green", kd=(0.20, 0.45, 0.25))
    wood = s.material("wood", kd=(0.60, 0.45, 0.30))
    lamp = s.material("light", kd=(0.8, 0.8, 0.8), ke=(40, 40, 40))
    X1 = W + T
    s.shell(0, X1 + W, 0, D, H, TS, white, floor, ceil, {"-x": green})
    s.group("shared_wall")
    s.wall("z", W + T / 2, -TS / 2, D + TS / 2, T, white, doors=[(2.3, 3.2)], y1=H + 0.1,
           door_h=2.0)
    s.group("light")
    s.light(1.4, 1.2, 1.0, 1.0, H - 0.01, lamp)
    s.group("furniture")
    s.box((0.5, 0, 2.2), (1.3, 0.8, 3.0), wood)             # a crate in the lit room
    s.box((X1 + 1.6, 0, 0.5), (X1 + 2.4, 0.45, 1.3), wood)  # a low table in the dark one
    s.camera = ((X1 + W - 0.3, 1.4, 0.35), (W, 0.9, 2.3), 70)
    return s


def floor_many_lights():
    s = Scene("floor_many_lights")
    W, D, H, T = 40.0, 20.0, 3.0, 0.2
    wall_m = s.material("wall_white", kd=(0.72, 0.70, 0.66))
    corr_m = s.material("wall_corridor", kd=(0.55, 0.62, 0.58))
    floor = s.material("floor", kd=(0.38, 0.36, 0.34))
    ceil = s.material("ceiling", kd=(0.80, 0.80, 0.80))
    wood = s.material("wood", kd=(0.50, 0.34, 0.20))
    metal = s.material("metal", kd=(0.25, 0.25, 0.27), ks=(0.3, 0.3, 0.3), ns=80)
    seat = s.material("fabric_navy", kd=(0.08, 0.12, 0.35))
    cols = [s.material("cabinet_%d" % i, kd=c) for i, c in enumerate(
        [(0.6, 0.15, 0.1), (0.15, 0.45, 0.15), (0.7, 0.6, 0.2), (0.5, 0.5, 0.5)])]
    lamp = s.material("light", kd=(0.8, 0.8, 0.8), ke=(10, 10, 10))
    # wall centre lines; outer walls centred on x = 0, W and z = 0, D
    s.group("floor")
    s.box((-T / 2, -T, -T / 2), (W + T / 2, 0, D + T / 2), floor)
    s.group("ceiling")
    s.box((-T / 2, H, -T / 2), (W + T / 2, H + T, D + T / 2), ceil)
    s.group("walls")
    y1 = H + 0.1
    s.wall("x", 0, 0, W, T, wall_m, y1=y1)
    s.wall("x", D, 0, W, T, wall_m, y1=y1)
    s.wall("z", 0, 0, D, T, wall_m, y1=y1)
    s.wall("z", W, 0, D, T, wall_m, y1=y1)
    # rows of offices (z ranges) and the corridors between them:
    #   south offices z in [0, 5], corridor A [5, 7], middle rows [7, 10] and [10, 13]
    #   (split at x in [19, 21] by a cross corridor), corridor B [13, 15], north [15, 20]
    offices = []   # (x0, x1, z0, z1, door wall z, door (d0, d1))
    xs_full = [5.0 * k for k in range(9)]
    xs_mid = [0.0, 4.75, 9.5, 14.25, 19.0, 21.0, 25.75, 30.5, 35.25, 40.0]

    def door_at(x0, x1, k):
        return (x0 + 0.6, x0 + 1.6) if k % 2 == 0 else (x1 - 1.6, x1 - 0.6)
    for k in range(8):
        x0, x1 = xs_full[k], xs_full[k + 1]
        offices.append((x0, x1, 0.0, 5.0, 5.0, door_at(x0, x1, k)))
        offices.append((x0, x1, 15.0, 20.0, 15.0, door_at(x0, x1, k + 1)))
    for k in range(9):
        if k == 4:
            continue   # the cross corridor
        x0, x1 = xs_mid[k], xs_mid[k + 1]
        offices.append((x0, x1, 7.0, 10.0, 7.0, door_at(x0, x1, k + 1)))
        offices.append((x0, x1, 10.0, 13.0, 13.0, door_at(x0, x1, k)))
    # corridor walls with the doors of the offices on them
    for zc in (5.0, 7.0, 13.0, 15.0):
        for (x0, x1, oz0, oz1, dz, d) in offices:
            if dz == zc:
                s.wall("x", zc, x0, x1, T, corr_m, doors=[d], y1=y1)
    # the cross corridor's side walls and the walls between the two middle rows
    s.wall("z", 19.0, 7.0, 13.0, T, corr_m, y1=y1)
    s.wall("z", 21.0, 7.0, 13.0, T, corr_m, y1=y1)
    s.wall("x", 10.0, 0.0, 19.0, T, wall_m, y1=y1)
    s.wall("x", 10.0, 21.0, 40.0, T, wall_m, y1=y1)
    # walls between neighbouring offices
    for k in range(1, 8):
        s.wall("z", xs_full[k], 0.0, 5.0, T, wall_m, y1=y1)
        s.wall("z", xs_full[k], 15.0, 20.0, T, wall_m, y1=y1)
    for k in range(1, 9):
        if xs_mid[k] in (19.0, 21.0):
            continue
        s.wall("z", xs_mid[k], 7.0, 10.0, T, wall_m, y1=y1)
        s.wall("z", xs_mid[k], 10.0, 13.0, T, wall_m, y1=y1)

    s.group("lights")
    for (x0, x1, z0, z1, dz, d) in offices:   # 2 x 2 panels per office
        for fx in (0.28, 0.72):
            for fz in (0.3, 0.7):
                s.light(x0 + fx * (x1 - x0), z0 + fz * (z1 - z0), 0.6, 0.6, H - 0.01, lamp)
    for zc in (6.0, 14.0):                     # corridors: one every 4 m
        for k in range(10):
            s.light(2.0 + 4.0 * k, zc, 0.6, 0.6, H - 0.01, lamp)
    s.light(20.0, 10.0, 0.6, 0.6, H - 0.01, lamp)   # cross corridor

    s.group("furniture")
    rng = random.Random(5)
    for (x0, x1, z0, z1, dz, d) in offices:
        # a desk against the side wall next to the door, in the back half of the
        # office, with its chair; a cabinet against the other side wall
        inner0, inner1 = x0 + T / 2, x1 - T / 2
        back = z0 + T / 2 if dz == z1 else z1 - T / 2   # inner face of the back wall
        sgn = 1 if back < dz else -1                      # from the back wall inwards
        door_low = d[0] - x0 < x1 - d[1]                  # door near x0?
        dl = 1.6                                          # desk length along z
        za = back + sgn * rng.uniform(0.15, 0.35)
        zb = za + sgn * dl
        dz0, dz1 = min(za, zb), max(za, zb)
        zc = (dz0 + dz1) / 2 + rng.uniform(-0.3, 0.3)
        if door_low:
            desk(s, inner0 + 0.02, dz0, 0.8, dl, wood, metal)
            chair(s, inner0 + 1.2, zc, seat, metal, facing=90 + rng.uniform(-30, 30))  # faces -x
            cx0 = inner1 - 0.46
        else:
            desk(s, inner1 - 0.82, dz0, 0.8, dl, wood, metal)
            chair(s, inner1 - 1.2, zc, seat, metal, facing=-90 + rng.uniform(-30, 30))
            cx0 = inner0 + 0.01
        zm = (z0 + z1) / 2 + rng.uniform(-0.4, 0.4)
        s.box((cx0, 0, zm - 0.4), (cx0 + 0.45, rng.uniform(1.0, 2.0), zm + 0.4),
              cols[rng.randrange(len(cols))])
    # camera in the south office at x in [15, 20], from its south-west corner towards
    # its door (x in [18.4, 19.4]) onto corridor A
    s.camera = ((15.3, 1.7, 0.3), (19.5, 0.8, 3.3), 60)
    return s


def grazing():
    """Bekaert et al. 2003, Fig. 4: a planar blue light standing on a large
    diffuse floor, tilted back by 10 degrees, so that the floor sees it at
    grazing angles far away and is lit at grazing emission angles close to
    it; a box in front casts a shadow (a silhouette). gkde's approximate
    footprint normalization (§3) shows its bias here."""
    s = Scene("grazing")
    floor = s.material("floor", kd=(0.7, 0.7, 0.7))
    crate = s.material("crate", kd=(0.6, 0.45, 0.3))
    lamp = s.material("blue_light", kd=(0.0, 0.0, 0.0), ke=(10.0, 20.0, 60.0))
    s.group("floor")
    s.box((-5.0, -0.1, -3.0), (5.0, 0.0, 9.0), floor)
    s.group("light")
    a = math.radians(10.0)
    h, w, y0 = 0.6, 2.0, 0.02
    top = (h * math.cos(a), -h * math.sin(a))  # (dy, dz): leaning back (-z)
    n = (0.0, math.sin(a), math.cos(a))  # front: towards +z, a little up
    p = ((-w / 2, y0, 0.0), (w / 2, y0, 0.0), (w / 2, y0 + top[0], top[1]), (-w / 2, y0 + top[0], top[1]))
    s.quad(p, n, lamp)
    s.light_panels += 1
    s.light_area += w * h
    s.group("furniture")
    s.box((0.6, 0.0, 1.2), (1.0, 0.4, 1.6), crate)
    s.camera = ((0.0, 3.0, -1.2), (0.0, 0.0, 2.2), 60)
    return s


def caustic_ring():
    s = Scene("caustic_ring")
    R, H, T = 3.0, 2.0, 0.2       # room x, z in [-R, R], height H
    wall = s.material("wall_grey", kd=(0.55, 0.55, 0.55))
    floor = s.material("floor", kd=(0.70, 0.68, 0.64))
    ceil = s.material("ceiling", kd=(0.70, 0.70, 0.70))
    mirror = s.material("mirror", kd=(0, 0, 0), ks=(0.95, 0.93, 0.88), illum=5)
    glass = s.material("glass", kd=(0, 0, 0), ks=(1, 1, 1), ni=1.5, illum=7)
    ring_out = s.material("ring_outside", kd=(0.25, 0.25, 0.27), ks=(0.3, 0.3, 0.3), ns=60)
    lamp = s.material("light", kd=(0.8, 0.8, 0.8), ke=(200, 200, 200))
    s.shell(-R, R, -R, R, H, T, wall, floor, ceil)
    s.group("light")
    s.light(-2.6, -1.4, 0.3, 0.3, H - 0.01, lamp)   # seen from the ring at ~30 degrees
    s.group("ring")
    s.ring(0.4, 0.2, 0.45, 0.47, 0.4, mirror, ring_out)
    s.group("sphere")
    s.sphere((-0.5, 0.3, -0.8), 0.3, glass)
    s.camera = ((0.0, 1.9, 1.6), (0.2, 0.0, -0.2), 55)
    return s


def wave():
    """Herzog et al. 2007, Table 7.1's WAVE row: a Cornell-like box (2 m) whose
    floor and back wall are smooth bumpy height fields (about 20000 triangles
    with vertex normals, like the report's 19635), a glossy box and a glass
    sphere: curved surfaces where a photon map's disc around a point is not
    the surface, and 2 % non-diffuse material."""
    s = Scene("wave")
    L, H, T = 2.0, 2.0, 0.1
    white = s.material("white", kd=(0.72, 0.71, 0.68))
    red = s.material("red", kd=(0.63, 0.07, 0.05))
    green = s.material("green", kd=(0.15, 0.48, 0.09))
    bumpy = s.material("bumpy", kd=(0.70, 0.70, 0.66))
    glossy = s.material("glossy", kd=(0.25, 0.25, 0.3), ks=(0.45, 0.45, 0.45), ns=40)
    glass = s.material("glass", kd=(0, 0, 0), ks=(1, 1, 1), ni=1.5, illum=7)
    lamp = s.material("light", kd=(0.78, 0.78, 0.78), ke=(17, 12, 4))
    s.shell(-L / 2, L / 2, -L / 2, L / 2, H, T, white, white, white, {"-x": red, "+x": green})
    s.group("light")
    s.light(0.0, 0.0, 0.47, 0.38, H - 0.005, lamp)
    N = 70

    def field(u, v):  # bumps in [0, 1] over the unit square, smooth at the edges
        return 0.5 + 0.25 * math.sin(7.0 * u + 1.3) * math.sin(6.0 * v + 0.4) + 0.25 * math.sin(13.0 * u * v)

    def surface(origin, du, dv, dn, amp, mtl):
        """A height field origin + u du + v dv + amp field(u, v) dn, u, v in [0, 1],
        with vertex normals from its partial derivatives."""
        eps = 1e-4
        pts, nrm = {}, {}
        for i in range(N + 1):
            for j in range(N + 1):
                u, v = i / N, j / N
                f = field(u, v)
                fu = (field(u + eps, v) - field(u - eps, v)) / (2 * eps)
                fv = (field(u, v + eps) - field(u, v - eps)) / (2 * eps)
                pts[i, j] = tuple(origin[k] + u * du[k] + v * dv[k] + amp * f * dn[k] for k in range(3))
                tu = tuple(du[k] + amp * fu * dn[k] for k in range(3))
                tv = tuple(dv[k] + amp * fv * dn[k] for k in range(3))
                n = _norm(_cross(tu, tv))
                nrm[i, j] = n if _dot(n, dn) > 0 else (-n[0], -n[1], -n[2])
        for i in range(N):
            for j in range(N):
                a, b, c, d = (i, j), (i + 1, j), (i + 1, j + 1), (i, j + 1)
                for tri in ((a, b, c), (a, c, d)):
                    p = [pts[t] for t in tri]
                    if _dot(_cross(_sub(p[1], p[0]), _sub(p[2], p[0])), dn) < 0:
                        tri = tri[::-1]
                    s.tri(pts[tri[0]], pts[tri[1]], pts[tri[2]], mtl, nrm[tri[0]], nrm[tri[1]], nrm[tri[2]])
    s.group("bumpy_floor")
    surface((-L / 2, 0.0, -L / 2), (L, 0, 0), (0, 0, L), (0, 1, 0), 0.08, bumpy)
    s.group("bumpy_back_wall")
    surface((-L / 2, 0.0, -L / 2), (L, 0, 0), (0, H, 0), (0, 0, 1), 0.08, bumpy)
    s.group("glossy_box")
    s.box((0.15, 0.05, -0.55), (0.6, 0.65, -0.1), glossy, rot=(-17, (0.375, -0.325)))
    s.group("glass_sphere")
    s.sphere((-0.45, 0.4, -0.2), 0.22, glass, nu=32, nv=16)
    s.camera = ((0.0, 1.45, 0.97), (0.0, 0.45, -1.0), 78)  # inside: the shell is closed
    return s


def building():
    """Bekaert et al. 2003, Fig. 6: a large building floor (120 x 60 m) of 276
    furnished offices along five long corridors and three cross corridors, lit by
    3672 small ceiling panels, most of them hidden from any one point."""
    s = Scene("building")
    P, NX, H, T = 4.0, 30, 3.0, 0.2   # office pitch along x, offices per row, height, walls
    DO, DC = 5.0, 2.0                 # office and corridor depth along z (centre lines)
    W = NX * P
    CROSS = (7, 15, 22)               # slots of the cross corridors through the inner rows
    white = s.material("wall_white", kd=(0.72, 0.71, 0.68))
    corr_m = s.material("wall_corridor", kd=(0.55, 0.62, 0.58))
    floor = s.material("floor", kd=(0.36, 0.35, 0.34))
    ceil = s.material("ceiling", kd=(0.80, 0.80, 0.80))
    wood = s.material("wood", kd=(0.50, 0.34, 0.20), ks=(0.04, 0.04, 0.04), ns=60)
    door_m = s.material("wood_door", kd=(0.60, 0.45, 0.30))
    metal = s.material("metal", kd=(0.25, 0.25, 0.27), ks=(0.30, 0.30, 0.30), ns=80)
    black = s.material("screen", kd=(0.03, 0.03, 0.03), ks=(0.2, 0.2, 0.2), ns=200)
    seats = [s.material("fabric_%s" % n, kd=c) for n, c in (
        ("navy", (0.08, 0.12, 0.35)), ("red", (0.55, 0.08, 0.07)),
        ("black", (0.06, 0.06, 0.07)), ("green", (0.12, 0.35, 0.15)))]
    cols = [s.material("cabinet_%d" % i, kd=c) for i, c in enumerate(
        [(0.6, 0.15, 0.1), (0.15, 0.45, 0.15), (0.7, 0.6, 0.2), (0.5, 0.5, 0.5)])]
    books = [s.material("book_%d" % i, kd=c) for i, c in enumerate(
        [(0.6, 0.1, 0.1), (0.1, 0.2, 0.5), (0.7, 0.6, 0.3), (0.15, 0.4, 0.15),
         (0.75, 0.75, 0.7), (0.3, 0.15, 0.3)])]
    lamp = s.material("light", kd=(0.8, 0.8, 0.8), ke=(12, 12, 12))
    # bands along z from z = 0: an office row, then (corridor, office row, office row)
    # four times, then a corridor and the last office row: 10 rows, 5 corridors
    bands, z = [], 0.0
    for kind in "OCOOCOOCOOCOOCO":
        dz = DO if kind == "O" else DC
        bands.append((kind, z, z + dz))
        z += dz
    D = z
    corridors = [(z0, z1) for k, z0, z1 in bands if k == "C"]
    rows = []   # (z0, z1, door wall z, corridor index, inner row?)
    for i, (k, z0, z1) in enumerate(bands):
        if k != "O":
            continue
        if i + 1 < len(bands) and bands[i + 1][0] == "C":
            dz, c = z1, corridors.index(bands[i + 1][1:])
        else:
            dz, c = z0, corridors.index(bands[i - 1][1:])
        rows.append((z0, z1, dz, c, 0 < i < len(bands) - 1))
    y1 = H + 0.1
    s.group("floor")
    s.box((-T / 2, -T, -T / 2), (W + T / 2, 0, D + T / 2), floor)
    s.group("ceiling")
    s.box((-T / 2, H, -T / 2), (W + T / 2, H + T, D + T / 2), ceil)
    s.group("outer_walls")
    s.wall("x", 0, 0, W, T, white, y1=y1)
    s.wall("x", D, 0, W, T, white, y1=y1)
    s.wall("z", 0, 0, D, T, white, y1=y1)
    s.wall("z", W, 0, D, T, white, y1=y1)

    offices = []   # (x0, x1, z0, z1, door wall z, door (d0, d1), door near x0?, corridor)
    for (z0, z1, dz, c, inner) in rows:
        for k in range(NX):
            if inner and k in CROSS:
                continue
            x0, x1 = k * P, (k + 1) * P
            low = (k + c) % 2 == 0   # facing offices across a corridor share the door
            d = (x0 + 0.6, x0 + 1.6) if low else (x1 - 1.6, x1 - 0.6)
            offices.append((x0, x1, z0, z1, dz, d, low, c))
    s.group("corridor_walls")   # with the office doors; the corridor side green-grey
    for (x0, x1, z0, z1, dz, d, low, c) in offices:
        side = "-z" if dz == z1 else "+z"   # the face towards the office
        s.wall("x", dz, x0, x1, T, corr_m, doors=[d], y1=y1, face_mtl={side: white})
    s.group("office_walls")
    for (z0, z1, dz, c, inner) in rows:
        back = z0 if dz == z1 else z1
        for k in range(NX):
            if inner and k not in CROSS:   # back-to-back rows: the wall between them
                if back == z1:
                    s.wall("x", back, k * P, (k + 1) * P, T, white, y1=y1)
            if k > 0:                      # between neighbouring offices
                s.wall("z", k * P, z0, z1, T, white, y1=y1)

    s.group("lights")
    ly = H - 0.01
    for (x0, x1, z0, z1, dz, d, low, c) in offices:   # 3 x 4 panels of 0.3 x 0.3 m
        for fx in (1 / 6, 3 / 6, 5 / 6):
            for fz in (1 / 8, 3 / 8, 5 / 8, 7 / 8):
                s.light(x0 + T / 2 + fx * (P - T), z0 + T / 2 + fz * (DO - T), 0.3, 0.3,
                        ly, lamp)
    for (z0, z1) in corridors:                        # one every 2 m along the corridors
        for j in range(NX * 2):
            s.light(1.0 + 2.0 * j, (z0 + z1) / 2, 0.3, 0.3, ly, lamp)
    for k in CROSS:                                   # and along the cross corridors
        for (ca, cb) in zip(corridors, corridors[1:]):
            for j in range(5):
                s.light((k + 0.5) * P, ca[1] + 1.0 + 2.0 * j, 0.3, 0.3, ly, lamp)

    # the camera: in the office south of corridor 2 at slot 12, looking through its
    # door and across the corridor into the office opposite
    cam_slot, cam_c = 12, 2
    rng = random.Random(2003)
    s.group("furniture")
    for (x0, x1, z0, z1, dz, d, low, c) in offices:
        # local frame: u along the door wall from the side wall next to the door,
        # v from the back wall towards the door wall; interior Wi x Di
        Wi, Di = P - T, DO - T
        back = z0 + T / 2 if dz == z1 else z1 - T / 2
        sgn = 1 if dz == z1 else -1
        xa = x0 + T / 2 if low else x1 - T / 2
        su = 1 if low else -1

        def X(u):
            return xa + su * u

        def Z(v):
            return back + sgn * v

        def lb(u0, v0, q0, u1, v1, q1, m):
            xs, zs = sorted((X(u0), X(u1))), sorted((Z(v0), Z(v1)))
            s.box((xs[0], q0, zs[0]), (xs[1], q1, zs[1]), m)

        def facing(a):   # local facing (0: towards -v) -> world
            if sgn < 0:
                a = 180 - a
            if su < 0:
                a = -a
            return a
        # a desk against the back wall with a monitor and a chair facing the wall
        ua = rng.uniform(0.3, 1.6)
        u0, u1 = sorted((X(ua), X(ua + 1.6)))
        v0, v1 = sorted((Z(0.02), Z(0.82)))
        desk(s, u0, v0, 1.6, 0.8, wood, metal)
        um = ua + rng.uniform(0.5, 1.1)
        lb(um - 0.28, 0.15, 0.85, um + 0.28, 0.18, 1.2, black)
        lb(um - 0.03, 0.15, 0.75, um + 0.03, 0.21, 0.85, metal)
        lb(um - 0.12, 0.10, 0.75, um + 0.12, 0.27, 0.76, metal)
        uc, vc = ua + 0.8 + rng.uniform(-0.3, 0.3), 1.25 + rng.uniform(-0.1, 0.2)
        seat = seats[rng.randrange(len(seats))]
        chair(s, X(uc), Z(vc), seat, metal, facing=facing(rng.uniform(-25, 25)))
        # a bookshelf against the far side wall (u = Wi), open towards the room
        sw, sd = rng.uniform(0.8, 1.0), 0.35
        va = rng.uniform(1.1, 2.6)
        sx0 = min(X(Wi - sd), X(Wi))
        sz0 = min(Z(va), Z(va + sw))
        shelf(s, sx0, sz0, sw, sd, rng.uniform(1.8, 2.2), wood, books,
              boards=rng.choice((4, 5)), seed=rng.randrange(1 << 30), along="z",
              flip=(su > 0))
        # a cabinet against the side wall next to the door, clear of the open door
        vk = rng.uniform(1.4, 2.2)
        lb(0.01, vk, 0, 0.46, vk + 0.8, rng.uniform(0.9, 1.6), cols[rng.randrange(len(cols))])
        # a small meeting table with a second chair in some offices
        if rng.random() < 0.4:
            ut, vt = rng.uniform(1.7, 2.2), rng.uniform(2.8, 3.2)
            lb(ut, vt, 0.70, ut + 0.8, vt + 0.8, 0.74, wood)
            lb(ut + 0.36, vt + 0.36, 0, ut + 0.44, vt + 0.44, 0.70, metal)
            chair(s, X(ut + 0.4), Z(vt + 1.2), seats[rng.randrange(len(seats))], metal,
                  facing=facing(rng.uniform(-20, 20)))
        # the door leaf (0.04 m), hinged at the door's end near u = 0 on the wall's
        # centre line; open into the office by 60-100 degrees, closed in one office
        # in six (never on the camera's line of sight)
        near_cam = c == cam_c and x0 == cam_slot * P
        ang = 0.0 if (rng.random() < 1 / 6 and not near_cam) else rng.uniform(60, 100)
        hx = d[0] if low else d[1]
        dt = 0.04
        # closed: u in [0.5 + 0.003, 1.5 - 0.003] around the hinge; world angle
        # counter-clockwise seen from above turns +x into -z
        a = ang * (1 if low else -1) * (1 if sgn > 0 else -1)
        # check: the free end turns into the office (towards the back wall)
        fz = dz - math.sin(math.radians(a)) * su
        assert ang == 0 or (fz - dz) * (back - dz) > 0
        xs = sorted((hx + su * 0.003, hx + su * 0.997))
        s.box((xs[0], -0.02, dz - dt / 2), (xs[1], H_DOOR + 0.01, dz + dt / 2), door_m,
              rot=(a, (hx, dz)) if ang else None)
    # the camera stands near the back wall behind the door and looks through it and
    # the opposite office's door (both at x0 + [0.6, 1.6] or x1 - [1.6, 0.6])
    x0 = cam_slot * P
    zc = [r for r in rows if r[3] == cam_c and r[2] == r[1]][0][1]   # the door wall z
    su = 1 if (cam_slot + cam_c) % 2 == 0 else -1
    xa = x0 if su > 0 else x0 + P
    s.camera = ((xa + su * 1.5, 1.6, zc - DO + 0.5), (xa + su * 1.0, 1.1, zc + DC + 2.5), 65)
    return s


# --- finely tessellated furniture (conference_fg) ---------------------------------

class _Xf:
    """An affine map p -> M p + t with M a rotation (so normals map by M too)."""

    def __init__(self, m=((1, 0, 0), (0, 1, 0), (0, 0, 1)), t=(0, 0, 0)):
        self.m, self.t = m, t

    def p(self, q):
        m, t = self.m, self.t
        return tuple(m[i][0] * q[0] + m[i][1] * q[1] + m[i][2] * q[2] + t[i] for i in range(3))

    def n(self, q):
        m = self.m
        return tuple(m[i][0] * q[0] + m[i][1] * q[1] + m[i][2] * q[2] for i in range(3))

    def then(self, b):
        """self first, then b"""
        m = tuple(tuple(sum(b.m[i][k] * self.m[k][j] for k in range(3)) for j in range(3))
                  for i in range(3))
        return _Xf(m, b.p(self.t))

    @staticmethod
    def move(x, y, z):
        return _Xf(t=(x, y, z))

    @staticmethod
    def yaw(deg, pivot=(0, 0, 0)):
        """about the vertical axis through pivot, counter-clockwise seen from above
        (as Scene.box's rot: +x turns towards -z for deg > 0)"""
        a = math.radians(deg)
        ca, sa = math.cos(a), math.sin(a)
        r = _Xf(((ca, 0, sa), (0, 1, 0), (-sa, 0, ca)))
        return _Xf.move(*(-c for c in pivot)).then(r).then(_Xf.move(*pivot))

    @staticmethod
    def pitch(deg, pivot=(0, 0, 0)):
        """about the x axis through pivot; deg > 0 turns +y towards +z"""
        a = math.radians(deg)
        ca, sa = math.cos(a), math.sin(a)
        r = _Xf(((1, 0, 0), (0, ca, -sa), (0, sa, ca)))
        return _Xf.move(*(-c for c in pivot)).then(r).then(_Xf.move(*pivot))


def _tri_n(s, xf, a, b, c, na, nb, nc, mtl):
    """A triangle in xf's local frame with vertex normals, wound counter-clockwise
    seen from the side its vertex normals point to."""
    a, b, c = xf.p(a), xf.p(b), xf.p(c)
    na, nb, nc = xf.n(na), xf.n(nb), xf.n(nc)
    g = _cross(_sub(b, a), _sub(c, a))
    if _dot(g, (na[0] + nb[0] + nc[0], na[1] + nb[1] + nc[1], na[2] + nb[2] + nc[2])) < 0:
        b, c, nb, nc = c, b, nc, nb
    s.tri(a, b, c, mtl, na, nb, nc)


def _grid(s, xf, pts, nrm, nu, nv, mtl):
    """quads (i, j)-(i+1, j+1) of a (nu + 1) x (nv + 1) grid of points and normals"""
    for i in range(nu):
        for j in range(nv):
            a, b, c, d = (i, j), (i + 1, j), (i + 1, j + 1), (i, j + 1)
            _tri_n(s, xf, pts[a], pts[b], pts[c], nrm[a], nrm[b], nrm[c], mtl)
            _tri_n(s, xf, pts[a], pts[c], pts[d], nrm[a], nrm[c], nrm[d], mtl)


def rounded_box(s, xf, c, h, r, mtl, nb=4, nf=(2, 2, 2)):
    """A box of half extents h centred at c (local frame xf) with edges and corners
    rounded to radius r: each face a grid of 2 nb + nf[axis] cells per axis, nb of
    them (even steps in angle) on each rounded band; exact vertex normals."""
    assert all(hk > 1.05 * r for hk in h), (h, r)
    axes = []
    for k in range(3):
        e = h[k] - r
        band = [r * math.tan(math.radians(45.0 * i / nb)) for i in range(1, nb + 1)]
        axes.append([-e - t for t in reversed(band)]
                    + [-e + 2 * e * j / nf[k] for j in range(nf[k] + 1)]
                    + [e + t for t in band])

    def point(g):
        inner = tuple(max(-(h[k] - r), min(h[k] - r, g[k])) for k in range(3))
        n = _norm(_sub(g, inner))
        return (tuple(c[k] + inner[k] + r * n[k] for k in range(3)), n)
    for k in range(3):            # faces normal to axis k
        u, v = (k + 1) % 3, (k + 2) % 3
        for sgn in (-1, 1):
            pts, nrm = {}, {}
            for i, gu in enumerate(axes[u]):
                for j, gv in enumerate(axes[v]):
                    g = [0, 0, 0]
                    g[k], g[u], g[v] = sgn * h[k], gu, gv
                    pts[i, j], nrm[i, j] = point(g)
            _grid(s, xf, pts, nrm, len(axes[u]) - 1, len(axes[v]) - 1, mtl)


def cylinder(s, xf, p0, p1, r0, mtl, n=24, r1=None, caps=True):
    """A closed (truncated) cone from p0 (radius r0) to p1 (radius r1, default r0),
    smooth sides, flat caps."""
    r1 = r0 if r1 is None else r1
    ax = _sub(p1, p0)
    ln = math.sqrt(_dot(ax, ax))
    w = _norm(ax)
    u = _norm(_cross(w, (1, 0, 0) if abs(w[0]) < 0.9 else (0, 0, 1)))
    v = _cross(w, u)
    slope = (r0 - r1) / ln      # the side normal leans towards p1 if r narrows

    def ring(p, r, a):
        d = tuple(math.cos(a) * u[k] + math.sin(a) * v[k] for k in range(3))
        nn = _norm(tuple(d[k] + slope * w[k] for k in range(3)))
        return tuple(p[k] + r * d[k] for k in range(3)), nn
    pts, nrm = {}, {}
    for i in range(n + 1):
        a = 2 * math.pi * (i % n) / n
        pts[i, 0], nrm[i, 0] = ring(p0, r0, a)
        pts[i, 1], nrm[i, 1] = ring(p1, r1, a)
    _grid(s, xf, pts, nrm, n, 1, mtl)
    if caps:
        mw = (-w[0], -w[1], -w[2])
        for i in range(n):
            _tri_n(s, xf, p0, pts[i, 0], pts[i + 1, 0], mw, mw, mw, mtl)
            _tri_n(s, xf, p1, pts[i, 1], pts[i + 1, 1], w, w, w, mtl)


def torus(s, xf, c, big_r, small_r, mtl, nu=32, nv=12, arc=360.0):
    """A torus about the local vertical axis through c (tube radius small_r), or the
    part of it up to `arc` degrees around (open ends: for handles that meet a body)."""
    full = arc >= 360.0
    pts, nrm = {}, {}
    for i in range(nu + 1):
        a = math.radians(arc * ((i % nu) if full else i) / nu)
        for j in range(nv + 1):
            b = 2 * math.pi * (j % nv) / nv
            nn = (math.cos(b) * math.cos(a), math.sin(b), -math.cos(b) * math.sin(a))
            rr = big_r + small_r * math.cos(b)
            pts[i, j] = (c[0] + rr * math.cos(a), c[1] + small_r * math.sin(b),
                         c[2] - rr * math.sin(a))
            nrm[i, j] = nn
    _grid(s, xf, pts, nrm, nu, nv, mtl)


def ball(s, xf, c, r, mtl, nu=16, nv=8):
    """Scene.sphere at the point c of the local frame"""
    s.sphere(xf.p(c), r, mtl, nu=nu, nv=nv)


def office_chair(s, cx, cz, facing, seat_m, frame_m, caster_m):
    """A swivel chair with arms on five castered legs, centred at (cx, cz); facing as
    chair()'s (0: faces -z, back rest on the +z side). 8000 triangles."""
    xf = _Xf.yaw(facing).then(_Xf.move(cx, 0, cz))
    for k in range(5):                                    # star base and casters
        a = 90.0 + 72.0 * k + 36.0
        leg = _Xf.yaw(a).then(xf)
        rounded_box(s, leg, (0.165, 0.078, 0), (0.135, 0.022, 0.024), 0.014, frame_m,
                    nb=2, nf=(2, 1, 1))
        ball(s, leg, (0.30, 0.03, 0), 0.03, caster_m)
    cylinder(s, xf, (0, 0.05, 0), (0, 0.11, 0), 0.06, frame_m, n=32)          # hub
    torus(s, xf, (0, 0.11, 0), 0.045, 0.012, frame_m, nu=24, nv=8)
    cylinder(s, xf, (0, 0.11, 0), (0, 0.28, 0), 0.035, frame_m, n=24)         # sleeve
    cylinder(s, xf, (0, 0.28, 0), (0, 0.44, 0), 0.024, frame_m, n=24)         # column
    rounded_box(s, xf, (0, 0.44, 0), (0.2, 0.015, 0.19), 0.01, frame_m, nb=2,
                nf=(2, 1, 2))                                                # seat pan
    rounded_box(s, xf, (0, 0.495, 0), (0.25, 0.045, 0.24), 0.04, seat_m, nb=4,
                nf=(3, 1, 3))                                                # cushion
    # the back rest, tilted back by 8 degrees, on a spine from the seat pan
    back = _Xf.pitch(8, (0, 0.5, 0.25)).then(xf)
    rounded_box(s, back, (0, 0.86, 0.27), (0.23, 0.26, 0.035), 0.03, seat_m, nb=4,
                nf=(2, 2, 1))
    rounded_box(s, back, (0, 0.6, 0.285), (0.045, 0.16, 0.012), 0.01, frame_m, nb=2,
                nf=(1, 2, 1))
    rounded_box(s, xf, (0, 0.445, 0.22), (0.045, 0.012, 0.07), 0.01, frame_m, nb=2,
                nf=(1, 1, 2))
    for sx in (-1, 1):                                   # arms
        cylinder(s, xf, (sx * 0.12, 0.44, 0.02), (sx * 0.285, 0.44, 0.02), 0.012, frame_m,
                 n=16)
        cylinder(s, xf, (sx * 0.285, 0.44, 0.02), (sx * 0.285, 0.665, 0.02), 0.014, frame_m,
                 n=16)
        rounded_box(s, xf, (sx * 0.285, 0.68, 0.0), (0.032, 0.016, 0.13), 0.014, seat_m,
                    nb=2, nf=(1, 1, 3))


def cup(s, x, z, y, handle_deg, mtl):
    """A mug standing at (x, y, z): a body, a rounded rim and a handle (half a torus
    in a vertical plane, its ends in the body), the handle turned by handle_deg."""
    xf = _Xf.move(x, y, z)
    cylinder(s, xf, (0, 0, 0), (0, 0.09, 0), 0.04, mtl, n=32)
    torus(s, xf, (0, 0.09, 0), 0.036, 0.005, mtl, nu=32, nv=8)
    # the torus' half ring (+x through -z to -x) turned upright: x -> y, -z -> x
    up = _Xf(((0, 0, -1), (1, 0, 0), (0, -1, 0)))
    hx = up.then(_Xf.move(0.038, 0.045, 0)).then(_Xf.yaw(handle_deg)).then(xf)
    torus(s, hx, (0, 0, 0), 0.026, 0.007, mtl, nu=16, nv=8, arc=180.0)


def conference_fg():
    """Herzog et al. 2007, Table 7.1's "Conference" row (265,880 primitives, 86 %
    diffuse, final gathering): a closed 10 x 6 x 3 m conference room, every
    material Lambertian, lit only by six suspended luminaires 0.4 m below the
    ceiling that emit upwards, so that the ceiling alone is lit directly and the
    rest of the room by interreflection. Nearly all of its 261k triangles are
    finely tessellated furniture (24 swivel chairs of 8000, mugs, fruit, plants):
    many small curved objects and concave contacts, where a photon map's density
    estimate is biased. Too large to commit: written only when named."""
    s = Scene("conference_fg")
    W, D, H, T = 10.0, 6.0, 3.0, 0.2
    beige = s.material("wall_beige", kd=(0.76, 0.72, 0.64))
    accent = s.material("wall_bluegrey", kd=(0.40, 0.48, 0.58))
    floor = s.material("carpet", kd=(0.44, 0.42, 0.46))
    ceil = s.material("ceiling", kd=(0.80, 0.80, 0.80))
    wood = s.material("wood_table", kd=(0.50, 0.34, 0.22))
    door_m = s.material("wood_door", kd=(0.55, 0.40, 0.25))
    frame = s.material("frame_grey", kd=(0.36, 0.36, 0.38))
    dark = s.material("caster_dark", kd=(0.20, 0.20, 0.21))
    fabric = s.material("fabric_charcoal", kd=(0.28, 0.29, 0.33))
    fabric2 = s.material("fabric_teal", kd=(0.20, 0.40, 0.42))
    board = s.material("whiteboard", kd=(0.78, 0.78, 0.78))
    white = s.material("ceramic_white", kd=(0.75, 0.74, 0.70))
    paper = s.material("paper", kd=(0.78, 0.78, 0.76))
    fruit = [s.material("fruit_%s" % n, kd=c) for n, c in (
        ("orange", (0.75, 0.40, 0.20)), ("green", (0.40, 0.60, 0.20)),
        ("red", (0.60, 0.20, 0.20)), ("yellow", (0.75, 0.65, 0.25)))]
    leaf = s.material("leaves", kd=(0.20, 0.40, 0.22))
    pot = s.material("terracotta", kd=(0.60, 0.38, 0.28))
    housing = s.material("luminaire", kd=(0.70, 0.70, 0.70))
    lamp = s.material("light", kd=(0.8, 0.8, 0.8), ke=(30, 30, 30))
    for m in s.mtls.values():   # Lambertian only, albedo 0.2-0.8
        assert all(l.startswith(("Kd", "Ke")) for l in m), m
        assert all(0.2 <= float(c) <= 0.8 for c in m[0].split()[1:]), m

    dx0, dx1 = _conference_shell(s, W, D, H, T, floor, ceil, beige, accent, door_m)
    dxf = _Xf.move(dx1 - 0.12, 1.0, -0.12)
    cylinder(s, dxf, (0, 0, 0), (0, 0, 0.02), 0.03, frame, n=24)             # rose
    cylinder(s, dxf, (0, 0, 0.01), (0, 0, 0.06), 0.009, frame, n=16)
    cylinder(s, dxf, (0.005, 0, 0.055), (-0.12, 0, 0.055), 0.01, frame, n=16)  # lever

    # six indirect luminaires hanging 0.4 m below the ceiling: a housing 2.2 x 0.2 m
    # on two wires, its top an emitter whose front face points up (+y)
    s.group("luminaires")
    ly = H - 0.4
    for cz in (1.9, 4.1):
        for cx in (2.3, 5.0, 7.7):
            xf = _Xf.move(cx, 0, cz)
            rounded_box(s, xf, (0, ly - 0.03, 0), (1.1, 0.03, 0.1), 0.012, housing, nb=2,
                        nf=(6, 1, 2))
            for wx in (-0.9, 0.9):
                cylinder(s, xf, (wx, ly, 0), (wx, H, 0), 0.003, frame, n=8)
    s.group("lights")
    for cz in (1.9, 4.1):
        for cx in (2.3, 5.0, 7.7):
            sx, sz, y = 2.16, 0.16, ly + 0.001
            x0, x1, z0, z1 = cx - sx / 2, cx + sx / 2, cz - sz / 2, cz + sz / 2
            s.quad(((x0, y, z0), (x1, y, z0), (x1, y, z1), (x0, y, z1)), (0, 1, 0), lamp)
            for m, f in s.groups[-1][1][-2:]:   # the front (emitting) face looks up
                a, b, c = (tuple(float(t) for t in s.verts[v - 1]) for v, _ in f)
                assert m == lamp and _cross(_sub(b, a), _sub(c, a))[1] > 0
            s.light_panels += 1
            s.light_area += sx * sz

    s.group("table")   # 7 x 1.5 m, top at 0.76 m, on four round legs with foot rings
    tx0, tx1, tz0, tz1 = 1.5, 8.5, 2.25, 3.75
    ty = 0.76
    txf = _Xf.move((tx0 + tx1) / 2, 0, (tz0 + tz1) / 2)
    rounded_box(s, txf, (0, ty - 0.025, 0), ((tx1 - tx0) / 2, 0.025, (tz1 - tz0) / 2), 0.02,
                wood, nb=4, nf=(24, 1, 6))
    for lx in (-3.05, 3.05):
        for lz in (-0.45, 0.45):
            cylinder(s, txf, (lx, 0, lz), (lx, ty - 0.05, lz), 0.04, frame, n=48)
            torus(s, txf, (lx, 0.015, lz), 0.05, 0.015, frame, nu=32, nv=12)
            torus(s, txf, (lx, ty - 0.065, lz), 0.05, 0.015, frame, nu=32, nv=12)
        cylinder(s, txf, (lx, ty - 0.065, -0.45), (lx, ty - 0.065, 0.45), 0.025, frame, n=24)
    cylinder(s, txf, (-3.05, 0.12, 0), (3.05, 0.12, 0), 0.03, frame, n=32)

    # 24 swivel chairs: 9 along each long side of the table, one at each end, and
    # four spare ones against the north wall
    rng = random.Random(2007)
    s.group("chairs")
    seats = []
    step = (tx1 - tx0) / 9
    for k in range(9):
        cx = tx0 + step * (k + 0.5)
        for side in (-1, 1):   # -1: south side, facing +z (180)
            back = rng.uniform(0.33, 0.55)
            cz = (tz0 - back) if side < 0 else (tz1 + back)
            fa = (180.0 if side < 0 else 0.0) + rng.uniform(-8, 8)
            office_chair(s, cx + rng.uniform(-0.03, 0.03), cz, fa, fabric, frame, dark)
            seats.append((cx, tz0 + 0.3 if side < 0 else tz1 - 0.3, side))
    for side in (-1, 1):       # ends: facing +x at the west end, -x at the east end
        back = rng.uniform(0.35, 0.5)
        cx = (tx0 - back) if side < 0 else (tx1 + back)
        office_chair(s, cx, 3.0 + rng.uniform(-0.05, 0.05), -side * 90 + rng.uniform(-6, 6),
                     fabric, frame, dark)
    for k in range(4):
        office_chair(s, 1.3 + 0.78 * k, D - 0.5, rng.uniform(-5, 5), fabric2, frame, dark)

    s.group("table_things")    # a notepad at each place and a mug right of most
    for (cx, cz, side) in seats:
        nx = cx + rng.uniform(-0.1, 0.1)
        pad = _Xf.yaw(rng.uniform(-15, 15), (nx, 0, cz))
        rounded_box(s, pad, (nx, ty + 0.006, cz), (0.105, 0.006, 0.148), 0.004, paper, nb=2,
                    nf=(2, 1, 3))
        if rng.random() < 0.8:
            cup(s, cx + 0.29 + rng.uniform(-0.01, 0.03), cz + side * rng.uniform(0.0, 0.12),
                ty, rng.uniform(0, 360), white)
    for bx in (3.2, 5.0, 6.8):   # fruit bowls: a dish, a rim and fruit piled in it
        bxf = _Xf.move(bx, ty, 3.0)
        cylinder(s, bxf, (0, 0, 0), (0, 0.03, 0), 0.12, white, n=48, r1=0.17)
        torus(s, bxf, (0, 0.03, 0), 0.165, 0.01, white, nu=48, nv=8)
        for k in range(7):
            a = 2 * math.pi * k / 7 + bx
            ball(s, bxf, (0.095 * math.cos(a), 0.075, 0.095 * math.sin(a)), 0.045,
                 fruit[rng.randrange(len(fruit))], nu=20, nv=10)
        ball(s, bxf, (0, 0.1, 0), 0.05, fruit[rng.randrange(len(fruit))], nu=20, nv=10)
        for k in range(3):
            a = 2 * math.pi * k / 3 + 0.5
            ball(s, bxf, (0.05 * math.cos(a), 0.148, 0.05 * math.sin(a)), 0.043,
                 fruit[rng.randrange(len(fruit))], nu=20, nv=10)

    s.group("whiteboard")      # on the west wall, with a pen tray
    s.box((0, 0.9, 1.5), (0.03, 2.1, 4.5), board)
    cylinder(s, _Xf(), (0.05, 0.88, 1.6), (0.05, 0.88, 4.4), 0.025, frame, n=24)

    s.group("sideboard")       # against the north wall, with two vases
    rounded_box(s, _Xf(), (7.2, 0.45, D - 0.26), (1.5, 0.45, 0.25), 0.02, wood, nb=3,
                nf=(12, 6, 3))
    for vx, vh in ((6.3, 0.35), (7.9, 0.25)):
        vxf = _Xf.move(vx, 0.9, D - 0.26)
        cylinder(s, vxf, (0, 0, 0), (0, vh, 0), 0.07, white, n=32, r1=0.05)
        torus(s, vxf, (0, vh, 0), 0.05, 0.008, white, nu=32, nv=8)
        ball(s, vxf, (0, 0.09, 0), 0.095, white, nu=32, nv=16)

    s.group("plants")          # two potted plants: a pot, a stem and leafy balls
    for px, pz in ((0.45, D - 0.45), (0.45, 0.45)):
        pxf = _Xf.move(px, 0, pz)
        cylinder(s, pxf, (0, 0, 0), (0, 0.42, 0), 0.17, pot, n=48, r1=0.22)
        torus(s, pxf, (0, 0.42, 0), 0.21, 0.02, pot, nu=48, nv=12)
        cylinder(s, pxf, (0, 0.4, 0), (0, 1.0, 0), 0.02, door_m, n=12)
        for k in range(16):
            a = rng.uniform(0, 2 * math.pi)
            rr = rng.uniform(0.0, 0.22)
            ball(s, pxf, (rr * math.cos(a), rng.uniform(0.65, 1.45), rr * math.sin(a)),
                 rng.uniform(0.09, 0.15), leaf, nu=20, nv=10)

    s.camera = ((9.6, 1.7, 5.1), (3.0, 0.45, 2.3), 62)
    return s


SCENES = {
    "office": office,
    "conference": conference,
    "rooms10x10": rooms10x10,
    "doorslit": doorslit,
    "tworoom": tworoom,
    "grazing": grazing,
    "floor_many_lights": floor_many_lights,
    "caustic_ring": caustic_ring,
    "wave": wave,
}
# Written only when named: too large to commit (about 300k triangles, 15 MB of OBJ),
# so not part of the default "all scenes" and not in scenes/generated in git.
ON_DEMAND = {
    "building": building,
    "conference_fg": conference_fg,
}


def main(argv):
    known = dict(SCENES, **ON_DEMAND)
    if len(argv) < 2 or argv[1] in ("-h", "--help"):
        sys.stderr.write("usage: %s OUTDIR [NAME ...]\n"
                         "scenes (default: all of these): %s\n"
                         "written only when named (large, not committed): %s\n" % (
                             argv[0], " ".join(SCENES), " ".join(ON_DEMAND)))
        return 2
    outdir = argv[1]
    names = argv[2:] or list(SCENES)
    for n in names:
        if n not in known:
            sys.stderr.write("%s: unknown scene '%s' (scenes: %s)\n" % (
                argv[0], n, " ".join(known)))
            return 2
    os.makedirs(outdir, exist_ok=True)
    for n in names:
        s = known[n]()
        s.write(outdir)
        print("%-18s %7d triangles, %4d light panels (%d emitting triangles), %.2f m^2 of light;"
              " camera: %s" % (n, s.triangles(), s.light_panels, s.emitting_triangles(),
                               s.light_area,
                               open(os.path.join(outdir, n + ".cam")).read().strip()))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
