#!/usr/bin/python3
"""Writes the malformed-PLY corpus and its MANIFEST.tsv into this directory.

    /usr/bin/python3 tests/bad_ply/make.py

Standard library only; the output is deterministic (the garbage bytes come
from a SHA-256 chain) and is committed. Each case must be rejected by
cdl_ply_read; the rows are run by tests/bad_input/run.sh with the
ply_check driver standing in for @CANDELA@:

    bash tests/bad_input/run.sh build/tests/ply_check tests/bad_ply

Expected substrings are FILE:LINE: for the header and ASCII bodies, and
FILE: plus the message for whole-file and binary-body problems (binary
bodies have no lines; their messages name the element instead).
"""
import hashlib
import os
import struct

HERE = os.path.dirname(os.path.abspath(__file__))

cases = []  # (name, status, substring, command)

# Start clean so that renamed cases leave no stale files behind.
for old in os.listdir(HERE):
    if old.endswith(".ply"):
        os.remove(os.path.join(HERE, old))


def case(name, data, expect, status=1, cmd=None):
    if isinstance(data, str):
        data = data.encode()
    if data is not None:
        with open(os.path.join(HERE, name + ".ply"), "wb") as f:
            f.write(data)
    cases.append((name, status, expect, cmd or "@CANDELA@ %s.ply" % name))


def header(fmt="ascii", nv=3, nf=1, vprops="xyz", flist="property list uchar int vertex_indices",
           extra=""):
    h = "ply\nformat %s 1.0\nelement vertex %d\n" % (fmt, nv)
    h += "".join("property float %s\n" % p for p in vprops)
    h += extra
    h += "element face %d\n%s\nend_header\n" % (nf, flist)
    return h


def bheader(*args, **kw):
    return header(*args, **kw).encode()


ASCII_TRI = "0 0 0\n1 0 0\n0 1 0\n"  # three vertices on lines 10-12 of header()


def le_verts(pts):
    return b"".join(struct.pack("<3f", *p) for p in pts)


TRI = [(0, 0, 0), (1, 0, 0), (0, 1, 0)]


def garbage(n, seed):
    out, h = b"", seed.encode()
    while len(out) < n:
        h = hashlib.sha256(h).digest()
        out += h
    return out[:n]


# ---- whole file and magic
case("empty", b"", "empty.ply: empty file")
case("no_magic", "plx\nformat ascii 1.0\nend_header\n", "no_magic.ply:1: not a PLY file")
case("garbage", b"\x89\x00" + garbage(510, "candela bad ply"), "garbage.ply:1: not a PLY file")
case("binary_in_header", b"ply\n" + garbage(200, "header"),
     "binary_in_header.ply:2: binary data in the header")
case("missing", None, "missing.ply: cannot open")
case("directory", None, "adir: is a directory", cmd="@CANDELA@ @OUT@/adir")

# ---- header
case("unknown_format", header("binary_middle_endian") + ASCII_TRI + "3 0 1 2\n",
     "unknown_format.ply:2: unknown format 'binary_middle_endian'")
case("bad_version", "ply\nformat ascii 2.0\nelement vertex 0\nend_header\n",
     "bad_version.ply:2: unsupported PLY version '2.0'")
case("no_format", "ply\nelement vertex 3\nproperty float x\nend_header\n",
     "no_format.ply:4: no format line before end_header")
case("unknown_keyword", "ply\nformat ascii 1.0\nelemant vertex 3\nend_header\n",
     "unknown_keyword.ply:3: unknown header keyword 'elemant'")
case("unknown_type", "ply\nformat ascii 1.0\nelement vertex 3\nproperty float128 x\nend_header\n",
     "unknown_type.ply:4: unknown property type 'float128'")
case("count_not_number", "ply\nformat ascii 1.0\nelement vertex lots\nend_header\n",
     "count_not_number.ply:3: element count 'lots' is not a number")
case("count_negative", "ply\nformat ascii 1.0\nelement vertex -3\nend_header\n",
     "count_negative.ply:3: element count -3 is negative")
case("count_huge", "ply\nformat ascii 1.0\nelement vertex 99999999999\nend_header\n",
     "count_huge.ply:3: element count 99999999999 is too large")
case("count_overflow", "ply\nformat ascii 1.0\nelement vertex 123456789012345678901234567890\n"
     "end_header\n", "count_overflow.ply:3: element count 123456789012345678901234567890 is too large")
case("property_first", "ply\nformat ascii 1.0\nproperty float x\nend_header\n",
     "property_first.ply:3: property before any element")
case("duplicate_vertex", "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\n"
     "element vertex 1\nend_header\n", "duplicate_vertex.ply:5: duplicate element 'vertex'")
case("duplicate_property", "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\n"
     "property double x\nend_header\n", "duplicate_property.ply:5: duplicate property 'x'")
case("list_count_float", header(flist="property list float int vertex_indices") + ASCII_TRI +
     "3 0 1 2\n", "list_count_float.ply:8: list count type must be an integer type, not 'float'")
case("index_type_float", header(flist="property list uchar float vertex_indices") + ASCII_TRI +
     "3 0 1 2\n", "index_type_float.ply:8: face property 'vertex_indices' must hold integers")
case("indices_not_list", header(flist="property int vertex_indices") + ASCII_TRI + "0\n",
     "indices_not_list.ply:8: face property 'vertex_indices' must be a list")
case("no_x", header(vprops="yz") + "0 0\n1 0\n0 1\n3 0 1 2\n",
     "no_x.ply:3: vertex element has no 'x' property")
case("x_is_list", "ply\nformat ascii 1.0\nelement vertex 1\nproperty list uchar float x\n"
     "property float y\nproperty float z\nelement face 0\nproperty list uchar int vertex_indices\n"
     "end_header\n1 0 0 0\n", "x_is_list.ply:4: vertex property 'x' must not be a list")
case("no_vertex_element", "ply\nformat ascii 1.0\nelement face 0\n"
     "property list uchar int vertex_indices\nend_header\n", "no_vertex_element.ply: no vertex element")
case("no_face_element", "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\n"
     "property float y\nproperty float z\nend_header\n0 0 0\n",
     "no_face_element.ply: no face element")
case("no_face_list", header(flist="property int flags") + ASCII_TRI + "0\n",
     "no_face_list.ply:7: face element has no vertex_indices list")
case("no_end_header", "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\n",
     "no_end_header.ply: no end_header line")

# ---- counts against the file size
case("header_only", header("binary_little_endian"),
     "header_only.ply: truncated: expected 3 vertices, file ends after 0")
case("header_only_ascii", header(),
     "header_only_ascii.ply: truncated: expected 3 vertices, file ends after 0")
case("vertex_count_4g", header("binary_little_endian", nv=4000000000) + "0123456789ab",
     "vertex_count_4g.ply: truncated: expected 4000000000 vertices, file ends after 1")
case("face_count_4g_ascii", header(nf=4294967295) + ASCII_TRI + "3 0 1 2\n",
     "face_count_4g_ascii.ply: truncated: expected 4294967295 faces, file ends after 1")
case("no_faces", header(nf=0) + ASCII_TRI, "no_faces.ply: no faces")

# ---- ASCII bodies (vertex lines are 10-12, the first face line 13)
case("ascii_word", header() + "0 0 0\n1 0 0\n0 1 abc\n3 0 1 2\n",
     "ascii_word.ply:12: vertex 2: 'abc' is not a number")
case("ascii_control_byte", header() + "0 0 0\n1 0\x01 0\n0 1 0\n3 0 1 2\n",
     "ascii_control_byte.ply:11: vertex 1: '0?' is not a number")
case("ascii_too_few", header() + "0 0 0\n1 0\n0 1 0\n3 0 1 2\n",
     "ascii_too_few.ply:11: vertex 1: too few values on the line")
case("ascii_too_many", header() + "0 0 0\n1 0 0 1\n0 1 0\n3 0 1 2\n",
     "ascii_too_many.ply:11: vertex 1: too many values on the line")
case("ascii_index_range", header(nf=2) + ASCII_TRI + "3 0 1 2\n3 0 1 3\n",
     "ascii_index_range.ply:14: face 1: vertex index 3 out of range (3 vertices)")
case("ascii_index_negative", header() + ASCII_TRI + "3 0 -1 2\n",
     "ascii_index_negative.ply:13: face 0: vertex index -1 out of range (3 vertices)")
case("ascii_index_fraction", header() + ASCII_TRI + "3 0 1.5 2\n",
     "ascii_index_fraction.ply:13: face 0: '1.5' is not an integer")
case("ascii_nan", header() + "0 0 0\nnan 0 0\n0 1 0\n3 0 1 2\n",
     "ascii_nan.ply:11: vertex 1: x is not finite")
case("ascii_inf", header() + "0 0 0\n1 0 0\n0 -inf 0\n3 0 1 2\n",
     "ascii_inf.ply:12: vertex 2: y is not finite")
case("ascii_coord_huge", header() + "0 0 0\n1 0 1e21\n0 1 0\n3 0 1 2\n",
     "ascii_coord_huge.ply:11: vertex 1: z = 1e+21 is out of range")
case("ascii_face_2", header() + ASCII_TRI + "2 0 1\n",
     "ascii_face_2.ply:13: face 0: 2 vertices (a face needs at least 3)")
case("ascii_list_negative", header(flist="property list char int vertex_indices") + ASCII_TRI +
     "-3 0 1 2\n", "ascii_list_negative.ply:13: face 0: list 'vertex_indices' has negative length -3")
case("ascii_face_short", header() + ASCII_TRI + "4 0 1 2\n",
     "ascii_face_short.ply:13: face 0: too few values on the line")

# ---- binary bodies
BLE = "binary_little_endian"
case("bin_trunc_mid_face", bheader(BLE, nf=2) + le_verts(TRI) + b"\x03" + struct.pack("<3i", 0, 1, 2)
     + b"\x03" + struct.pack("<2i", 0, 1),
     "bin_trunc_mid_face.ply: truncated: expected 2 faces, file ends after 1")
case("bin_trunc_mid_vertex", bheader(BLE) + le_verts(TRI)[:30],
     "bin_trunc_mid_vertex.ply: truncated: expected 3 vertices, file ends after 2")
case("bin_index_range", bheader(BLE, nf=2) + le_verts(TRI) + b"\x03" + struct.pack("<3i", 0, 1, 2)
     + b"\x03" + struct.pack("<3i", 0, 4096, 2),
     "bin_index_range.ply: face 1: vertex index 4096 out of range (3 vertices)")
case("bin_be_index_range", bheader("binary_big_endian", flist="property list uchar uint vertex_indices")
     + b"".join(struct.pack(">3f", *p) for p in TRI) + b"\x03" + struct.pack(">3I", 0, 0xFFFFFFFF, 2),
     "bin_be_index_range.ply: face 0: vertex index 4294967295 out of range (3 vertices)")
case("bin_face_0", bheader(BLE) + le_verts(TRI) + b"\x00",
     "bin_face_0.ply: face 0: 0 vertices (a face needs at least 3)")
case("bin_list_huge", bheader(BLE, flist="property list uint int vertex_indices") + le_verts(TRI)
     + struct.pack("<I", 0xFFFFFFFF) + struct.pack("<3i", 0, 1, 2),
     "bin_list_huge.ply: truncated: expected 1 face, file ends after 0")
case("bin_nan", bheader(BLE) + le_verts([(0, 0, 0), (float("nan"), 0, 0), (0, 1, 0)])
     + b"\x03" + struct.pack("<3i", 0, 1, 2), "bin_nan.ply: vertex 1: x is not finite")
case("bin_inf", bheader(BLE) + le_verts([(0, 0, 0), (1, 0, 0), (0, 1, float("inf"))])
     + b"\x03" + struct.pack("<3i", 0, 1, 2), "bin_inf.ply: vertex 2: z is not finite")
case("bin_double_huge", "ply\nformat binary_little_endian 1.0\nelement vertex 3\n"
     "property double x\nproperty double y\nproperty double z\nelement face 1\n"
     "property list uchar int vertex_indices\nend_header\n".encode()
     + b"".join(struct.pack("<3d", *p) for p in [(0, 0, 0), (1, 0, 0), (0, 1e300, 0)])
     + b"\x03" + struct.pack("<3i", 0, 1, 2), "bin_double_huge.ply: vertex 2: y = 1e+300 is out of range")
edge = "element edge 2\nproperty int vertex1\nproperty list uchar float weights\n"
case("bin_edge_trunc", header(BLE).replace("element face", edge + "element face").encode()
     + le_verts(TRI) + struct.pack("<iB2f", 0, 2, 0.5, 0.5) + struct.pack("<iB", 1, 200) + b"\0" * 16,
     "bin_edge_trunc.ply: truncated: expected 2 'edge' elements, file ends after 1")
case("bin_garbage_body", bheader(BLE, nf=50) + le_verts(TRI) + garbage(300, "body"), "bin_garbage_body.ply: face 0:")

with open(os.path.join(HERE, "MANIFEST.tsv"), "w") as f:
    f.write("# name\texpected_status\texpected_substring\tcommand (generated by make.py; "
            "@CANDELA@ = the ply_check driver, @OUT@ = fresh temporary directory with an empty adir/)\n")
    for name, status, expect, cmd in cases:
        assert "\t" not in expect and "\n" not in expect
        f.write("%s\t%d\t%s\t%s\n" % (name, status, expect, cmd))
print("%d cases" % len(cases))
