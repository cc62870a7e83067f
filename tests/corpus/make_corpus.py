"""A corpus of broken and hostile mesh files, written by code (no binaries in the repository).

Every entry is a file name, the kind of input it stands for, the exit code ``inertia-tool analyze --json``
must return, a regular expression the one-line error (exit 3) or a warning (exit 0) must match, and, for
accepted files, the clean bodies (vertices in m, outward-wound faces) whose exact mass properties the
output must reproduce.  The README's "Bad input" table is printed by ``python make_corpus.py --table``.

Usage::

    python tests/corpus/make_corpus.py OUTDIR          # write the corpus
    python tests/corpus/make_corpus.py --table         # print the README table
"""

from __future__ import annotations

import os
import re
import struct
import sys
import zlib
from dataclasses import dataclass, field

import numpy as np

__all__ = ["Entry", "ENTRIES", "make_corpus", "exact_reference", "box", "write_binary_stl", "write_ascii_stl",
           "write_obj"]


@dataclass
class Entry:
    """One corpus file and what the tool must do with it."""

    name: str
    kind: str
    exit_code: int
    says: str
    build: object = field(repr=False, default=None)
    args: tuple = ()
    shown: str = ""          # what the README table says (defaults to ``says``)


ENTRIES: list[Entry] = []


def entry(name, kind, exit_code, says, *, args=(), shown=""):
    """Register a builder ``build(path) -> list of clean bodies (v, f) or None``."""
    def register(fn):
        ENTRIES.append(Entry(name, kind, exit_code, says, fn, tuple(args), shown or says))
        return fn
    return register


# -- geometry and writers ---------------------------------------------------------------------------

_BOX_FACES = np.array([[0, 2, 1], [0, 3, 2], [4, 5, 6], [4, 6, 7], [0, 1, 5], [0, 5, 4],
                       [1, 2, 6], [1, 6, 5], [2, 3, 7], [2, 7, 6], [3, 0, 4], [3, 4, 7]])


def box(extents=(1.0, 2.0, 3.0), center=(0.0, 0.0, 0.0)):
    """Outward-wound axis-aligned box: ``vertices (8, 3)``, ``faces (12, 3)``."""
    e = np.asarray(extents, dtype=float) / 2
    c = np.asarray(center, dtype=float)
    corners = np.array([[-1, -1, -1], [1, -1, -1], [1, 1, -1], [-1, 1, -1],
                        [-1, -1, 1], [1, -1, 1], [1, 1, 1], [-1, 1, 1]], dtype=float)
    return c + corners * e, _BOX_FACES.copy()


def prism(n=64, radius=0.5, height=2.0):
    """Closed regular n-gonal prism along z, caps fanned from their centres (two equal moments for n ≥ 3)."""
    t = 2 * np.pi * np.arange(n) / n
    ring = np.c_[radius * np.cos(t), radius * np.sin(t)]
    v = np.r_[np.c_[ring, np.full(n, -height / 2)], np.c_[ring, np.full(n, height / 2)],
              [[0, 0, -height / 2], [0, 0, height / 2]]]
    i = np.arange(n)
    j = (i + 1) % n
    bottom = np.c_[np.full(n, 2 * n), j, i]
    top = np.c_[np.full(n, 2 * n + 1), n + i, n + j]
    side = np.r_[np.c_[i, j, n + j], np.c_[i, n + j, n + i]]
    return v, np.r_[bottom, top, side]


def exact_reference(bodies, density=1000.0):
    """What an accepted corpus file must give: the exact engine (signed-tetrahedron integrals, no reading,
    welding or shell logic) on the clean ``bodies`` — outward-wound closed shells, a cavity wound inward,
    overlapping bodies counted twice.  Returns ``mass`` (kg), ``volume`` (m³), ``center_of_mass`` (m) and
    ``inertia`` (kg·m² about the centre of mass) at ``density`` kg/m³."""
    from types import SimpleNamespace

    from inertia_tool.integrals import second_moment_to_inertia, volume_moments
    vertices, faces, offset = [], [], 0
    for v, f in bodies:
        vertices.append(np.asarray(v, dtype=float))
        faces.append(np.asarray(f) + offset)
        offset += len(v)
    m = volume_moments(np.concatenate(vertices), np.concatenate(faces))
    return SimpleNamespace(mass=density * m.volume, volume=m.volume, center_of_mass=m.centroid,
                           inertia=second_moment_to_inertia(m.second_moment, density))


def write_binary_stl(path, vertices, faces, header=b"binary corpus", extra=b"", count=None):
    tri = np.asarray(vertices, dtype=np.float32)[np.asarray(faces)]
    rec = np.zeros(len(tri), dtype=[("n", "<f4", (3,)), ("v", "<f4", (3, 3)), ("a", "<u2")])
    rec["v"] = tri
    with open(path, "wb") as fh:
        fh.write(header.ljust(80, b" ")[:80])
        fh.write(struct.pack("<I", len(tri) if count is None else count))
        fh.write(rec.tobytes())
        fh.write(extra)


def ascii_stl_lines(vertices, faces, name=b"corpus", fmt=repr):
    lines = [b"solid " + name]
    for t in np.asarray(vertices, dtype=float)[np.asarray(faces)]:
        lines += [b"  facet normal 0 0 0", b"    outer loop"]
        lines += [("      vertex " + " ".join(fmt(float(x)) for x in p)).encode() for p in t]
        lines += [b"    endloop", b"  endfacet"]
    lines.append(b"endsolid " + name)
    return lines


def write_ascii_stl(path, vertices, faces, newline=b"\n", name=b"corpus", edit=None):
    lines = ascii_stl_lines(vertices, faces, name)
    if edit is not None:
        lines = edit(lines)
    with open(path, "wb") as fh:
        fh.write(newline.join(lines) + newline)


def write_obj(path, vertices, polygons, relative=False):
    with open(path, "w") as fh:
        fh.write("# corpus\n")
        for p in vertices:
            fh.write("v {!r} {!r} {!r}\n".format(*map(float, p)))
        n = len(vertices)
        for poly in polygons:
            idx = [i - n if relative else i + 1 for i in poly]
            fh.write("f " + " ".join(str(i) for i in idx) + "\n")


def write_ply(path, vertices, faces, counts=None):
    nv, nf = counts if counts is not None else (len(vertices), len(faces))
    with open(path, "w") as fh:
        fh.write(f"ply\nformat ascii 1.0\nelement vertex {nv}\nproperty float x\nproperty float y\n"
                 f"property float z\n")
        if nf is not None:
            fh.write(f"element face {nf}\nproperty list uchar int vertex_indices\n")
        fh.write("end_header\n")
        for p in vertices:
            fh.write("{!r} {!r} {!r}\n".format(*map(float, p)))
        for f in faces:
            fh.write("3 " + " ".join(map(str, f)) + "\n")


def f32(vertices):
    """Coordinates as a binary STL stores them (float32), back in float64."""
    return np.asarray(vertices, dtype=np.float32).astype(np.float64)


def _zip(path, members):
    """Write a stored/deflated zip from ``(name, raw_deflate_bytes_or_None, data_or_size, crc)`` by hand."""
    out = bytearray()
    central = bytearray()
    for name, deflated, size, crc in members:
        name_b = name.encode()
        method = 8
        offset = len(out)
        out += struct.pack("<IHHHHHIIIHH", 0x04034B50, 20, 0, method, 0, 0, crc, len(deflated), size,
                           len(name_b), 0) + name_b + deflated
        central += struct.pack("<IHHHHHHIIIHHHHHII", 0x02014B50, 20, 20, 0, method, 0, 0, crc, len(deflated),
                               size, len(name_b), 0, 0, 0, 0, 0, offset) + name_b
    cd_offset = len(out)
    out += central + struct.pack("<IHHHHIIH", 0x06054B50, 0, 0, len(members), len(members), len(central),
                                 cd_offset, 0)
    with open(path, "wb") as fh:
        fh.write(out)


def _deflate(data: bytes) -> bytes:
    c = zlib.compressobj(9, zlib.DEFLATED, -15)
    return c.compress(data) + c.flush()


def _zeros_bomb(total: int, chunk: int = 1 << 20):
    """Raw deflate stream of ``total`` zero bytes, built from one compressed chunk repeated, and its CRC."""
    c = zlib.compressobj(9, zlib.DEFLATED, -15)
    piece = c.compress(b"\0" * chunk) + c.flush(zlib.Z_FULL_FLUSH)
    reps = total // chunk
    crc = 0
    zeros = b"\0" * chunk
    for _ in range(reps):
        crc = zlib.crc32(zeros, crc)
    return piece * reps + b"\x03\x00", crc & 0xFFFFFFFF, reps * chunk


# -- the corpus -----------------------------------------------------------------------------------------

@entry("zero-byte.stl", "zero-byte file", 3, r"empty file \(0 bytes\)")
def _(path):
    open(path, "wb").close()


@entry("a-directory.stl", "a directory", 3, r"is a directory")
def _(path):
    os.mkdir(path)


@entry("picture.stl", "a PNG renamed .stl", 3, r"announces [\d,]+ triangles but the file holds at most",
       shown="binary STL header announces N triangles but the file holds at most M: truncated or not an STL")
def _(path):
    rng = np.random.default_rng(1)
    with open(path, "wb") as fh:
        fh.write(b"\x89PNG\r\n\x1a\n\x00\x00\x00\rIHDR" + rng.integers(0, 256, 600, dtype=np.uint8).tobytes())


@entry("liar-1e9.stl", "binary STL whose header claims 10⁹ triangles", 3, r"announces 1,000,000,000 triangles")
def _(path):
    write_binary_stl(path, *box(), count=10**9)


@entry("truncated.stl", "binary STL cut mid-record", 3, r"announces 12 triangles but the file holds at most 11")
def _(path):
    write_binary_stl(path, *box())
    data = open(path, "rb").read()
    open(path, "wb").write(data[:84 + 50 * 11 + 23])


@entry("trailing.stl", "binary STL with trailing bytes", 0, r"37 bytes after the 12 triangles .* ignored")
def _(path):
    v, f = box()
    write_binary_stl(path, v, f, extra=b"exporter-footer\0" + b"\x7f" * 21)
    return [(f32(v), f)]


@entry("solid-binary.stl", "binary STL whose header starts with \"solid\"", 0, r"^$")
def _(path):
    v, f = box(center=(0.25, 0, 0))
    write_binary_stl(path, v, f, header=b"solid part exported by CAD facet endsolid")
    return [(f32(v), f)]


@entry("solid-binary-trailing.stl", "binary STL starting with \"solid\" and with trailing bytes", 0,
       r"bytes after the 12 triangles")
def _(path):
    v, f = box(center=(0.25, 0, 0))
    write_binary_stl(path, v, f, header=b"solid part facet vertex endsolid", extra=b"solid\n" * 3)
    return [(f32(v), f)]


@entry("garbage-lines.stl", "ASCII STL with garbage lines", 0, r"3 unrecognised lines were ignored")
def _(path):
    v, f = box()
    def edit(lines):
        return lines[:3] + [b"this is not STL"] + lines[3:20] + [b"%%%%", b"12 13 14"] + lines[20:]
    write_ascii_stl(path, v, f, edit=edit)
    return [(v, f)]


@entry("nan.stl", "ASCII STL with a NaN coordinate", 3, r"\d+ triangles have NaN or infinite coordinates")
def _(path):
    v, f = box()
    v[0, 0] = np.nan
    write_ascii_stl(path, v, f)


@entry("inf.stl", "ASCII STL with an infinite coordinate", 3, r"NaN or infinite coordinates")
def _(path):
    v, f = box()
    v[0, 2] = np.inf
    write_ascii_stl(path, v, f)


@entry("huge-1e308.stl", "ASCII STL with 1e308 coordinates", 3, r"coordinates reach 1e\+308 m, beyond",
       shown="coordinates reach 1e+308 m, beyond the ±1e+30 m the volume integrals can hold without overflow")
def _(path):
    v, f = box()
    write_ascii_stl(path, box((2, 2, 2))[0] * 1e308, f)


@entry("no-endloop.stl", "ASCII STL missing 'endloop'", 0, r"12 facets lack 'endloop'")
def _(path):
    v, f = box()
    write_ascii_stl(path, v, f, edit=lambda ls: [x for x in ls if b"endloop" not in x])
    return [(v, f)]


@entry("crlf.stl", "ASCII STL with Windows line endings", 0, r"^$")
def _(path):
    v, f = box()
    write_ascii_stl(path, v, f, newline=b"\r\n")
    return [(v, f)]


@entry("old-mac.stl", "ASCII STL with old-Mac (CR only) line endings", 0, r"^$")
def _(path):
    v, f = box()
    write_ascii_stl(path, v, f, newline=b"\r")
    return [(v, f)]


@entry("latin1-name.stl", "ASCII STL with a non-UTF-8 solid name", 0, r"^$")
def _(path):
    v, f = box()
    write_ascii_stl(path, v, f, name=b"pi\xe8ce \xff\xfe")
    return [(v, f)]


@entry(os.fsdecode(b"caf\xe9-\xff.stl"), "a file name that is not UTF-8", 0, r"^$")
def _(path):
    v, f = box()
    write_binary_stl(path, v, f)
    return [(f32(v), f)]


@entry(os.fsdecode(b"empty-\xff.stl"), "an unreadable file with a non-UTF-8 name", 3, r"empty-\ufffd\.stl: empty",
       shown="the name with undecodable bytes shown as �, e.g. empty-�.stl: empty file (0 bytes)")
def _(path):
    open(path, "wb").close()


@entry("four-vertices.stl", "ASCII STL facet with 4 vertices", 3, r"a facet has 4 vertices instead of 3")
def _(path):
    v, f = box()
    write_ascii_stl(path, v, f, edit=lambda ls: ls[:6] + [ls[5]] + ls[6:])


@entry("cut-ascii.stl", "ASCII STL truncated mid-facet", 3, r"the last facet has 2 vertices instead of 3")
def _(path):
    v, f = box()
    write_ascii_stl(path, v, f, edit=lambda ls: ls[:-4])


@entry("bad-number.stl", "ASCII STL with a non-numeric coordinate", 3, r"line 5: vertex coordinate is not a number")
def _(path):
    v, f = box()
    write_ascii_stl(path, v, f, edit=lambda ls: ls[:4] + [b"      vertex 1 2 x3"] + ls[5:])


@entry("one-long-line.stl", "ASCII STL without line breaks (2 MB)", 3, r"a line is longer than")
def _(path):
    with open(path, "wb") as fh:
        fh.write(b"solid x " + b"facet normal 0 0 0 " * 110_000)


@entry("empty-solid.stl", "ASCII STL with no facets (empty mesh)", 3, r"without any 'vertex' line")
def _(path):
    open(path, "wb").write(b"solid empty\nendsolid empty\n")


@entry("float32-offset.stl", "binary STL (float32) 10 km from the origin", 0,
       r"stores coordinates as float32; at coordinates up to 2e\+04 m each is rounded by up to 0.000977 m",
       shown="warning: FILE: the file stores coordinates as float32; at coordinates up to 2e+04 m each is rounded "
             "by up to 0.000977 m, so the volume (and mass) is known only to ±0.39 relative (the result: the stored "
             "mesh, integrated exactly)")
def _(path):
    v, f = box((0.1, 0.2, 0.3), center=(1e4, -2e4, 5e3))
    write_binary_stl(path, v, f)
    return [(f32(v), f)]


@entry("offset-1e8.stl", "ASCII STL at an offset of 1e8 m", 0, r"^$")
def _(path):
    v, f = box((1.0, 2.0, 3.0), center=(1e8, 1e8, -1e8))
    write_ascii_stl(path, v, f)
    return [(v, f)]


@entry("micrometre.stl", "a 1 µm part, no unit given: warned", 0, r"metres assumed; largest extent 3 µm, below 100 µm")
def _(path):
    v, f = box((1e-6, 2e-6, 3e-6), center=(1e-6, 0, 0))
    write_ascii_stl(path, v, f)
    return [(v, f)]


@entry("kilometre.stl", "a 1 km part, no unit given: warned", 0,
       r"metres assumed; largest extent 1.5e\+03 m, above 20 m")
def _(path):
    v, f = box((1000.0, 1500.0, 800.0), center=(0, 0, 400.0))
    write_ascii_stl(path, v, f)
    return [(v, f)]


@entry("axisymmetric.stl", "an axisymmetric part (two equal moments)", 0, r"principal moments I\d and I\d are equal",
       shown="warning: principal moments I2 and I3 are equal ...; the axes in their plane are an arbitrary choice")
def _(path):
    v, f = prism(n=48, radius=0.5, height=3.0)
    write_ascii_stl(path, v, f)
    return [(v, f)]


@entry("needle.stl", "a needle (one principal moment near zero)", 0, r"smallest principal moment .* needle",
       shown="the smallest principal moment (…) is below 1e-10 of the largest (a needle); it carries only about "
             "N correct digits")
def _(path):
    v, f = prism(n=6, radius=3e-5, height=10.0)
    write_ascii_stl(path, v, f)
    return [(v, f)]


@entry("negative-indices.obj", "OBJ with negative (relative) indices", 0, r"^$")
def _(path):
    v, f = box()
    write_obj(path, v, f, relative=True)
    return [(v, f)]


@entry("quads-ngons.obj", "OBJ with quads and n-gons", 0, r"^$")
def _(path):
    n = 7
    v, f = prism(n=n, radius=1.0, height=0.5)
    rim = list(range(n))
    polys = [rim[::-1], [n + i for i in rim]] + [[i, (i + 1) % n, n + (i + 1) % n, n + i] for i in rim]
    write_obj(path, v[:2 * n], polys)
    # clean copy: the same polygons triangulated independently (caps around their centre)
    return [(v, f)]


@entry("out-of-range.obj", "OBJ with an index past the last vertex", 3, r"face index 9 is past the last vertex")
def _(path):
    v, f = box()
    f = f.copy()
    f[3, 1] = 8
    write_obj(path, v, f)


@entry("index-zero.obj", "OBJ with index 0", 3, r"face index 0 \(OBJ indices start at 1\)")
def _(path):
    v, f = box()
    write_obj(path, v, f - (np.arange(12)[:, None] == 5))


@entry("negative-out-of-range.obj", "OBJ with a relative index before the first vertex", 3,
       r"relative face index -9 points before the first vertex")
def _(path):
    v, f = box()
    write_obj(path, v, f, relative=True)
    text = open(path).read().replace("f -8", "f -9", 1)
    open(path, "w").write(text)


@entry("points.obj", "OBJ point cloud (vertices only)", 3, r"contains no faces \(8 vertices")
def _(path):
    write_obj(path, box()[0], [])


@entry("empty.obj", "OBJ with nothing in it", 3, r"no vertices and no faces")
def _(path):
    open(path, "w").write("# nothing here\n\n")


@entry("liar.ply", "PLY whose header claims more faces than it holds", 3,
       r"PLY header announces 8 vertex, 1,000,000 face .* truncated or lying header",
       shown="PLY header announces 8 vertex, 1,000,000 face (at least N bytes of data) but the file holds only "
             "M: truncated or lying header")
def _(path):
    v, f = box()
    write_ply(path, v, f, counts=(8, 10**6))


@entry("liar-fewer.ply", "PLY whose header claims fewer faces than it holds", 3,
       r"not a closed solid: .*boundary edges")
def _(path):
    v, f = box()
    write_ply(path, v, f, counts=(8, 10))


@entry("points.ply", "PLY point cloud", 3, r"no triangle mesh \(found PointCloud")
def _(path):
    write_ply(path, box()[0], [], counts=(8, None))


@entry("box.ply", "a valid PLY", 0, r"^$")
def _(path):
    v, f = box()
    write_ply(path, v, f)
    return [(v, f)]


@entry("liar.off", "OFF whose header claims 10⁸ faces", 3, r"OFF header announces 8 vertices and 100,000,000 faces")
def _(path):
    v, f = box()
    with open(path, "w") as fh:
        fh.write("OFF\n8 100000000 0\n" + "".join("{} {} {}\n".format(*p) for p in v)
                 + "".join("3 {} {} {}\n".format(*t) for t in f))


@entry("flat.stl", "a flat (zero-volume) mesh", 3, r"encloses no volume")
def _(path):
    v = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0.0]])
    write_binary_stl(path, v, np.array([[0, 1, 2], [0, 2, 1]]))


@entry("degenerate.stl", "all triangles degenerate", 3, r"all 12 triangles are degenerate")
def _(path):
    v, f = box()
    f = f.copy()
    f[:, 2] = f[:, 1]
    write_binary_stl(path, v, f)


@entry("open-box.stl", "an open box (one face missing)", 3,
       r"4 boundary edges \(holes or cracks\).*--repair gives a bounded estimate")
def _(path):
    v, f = box()
    write_binary_stl(path, v, f[2:])


@entry("one-face-flipped.stl", "a box with one face flipped", 0, r"oriented: 2 faces were wound the wrong way")
def _(path):
    v, f = box()
    flipped = f.copy()
    flipped[4:6] = flipped[4:6, ::-1]
    write_binary_stl(path, v, flipped)
    return [(f32(v), f)]


@entry("inside-out.stl", "an inside-out box", 0, r"the mesh is inside out .* flipped")
def _(path):
    v, f = box()
    write_binary_stl(path, v, f[:, ::-1])
    return [(f32(v), f)]


@entry("non-manifold.stl", "a non-manifold edge (three faces on one edge)", 3, r"non-manifold edges")
def _(path):
    v, f = box()
    v = np.r_[v, [[0.0, 0.0, 5.0]]]
    write_binary_stl(path, v, np.r_[f, [[0, 1, 8]]])


@entry("two-bodies-one-inside-out.stl", "two bodies, one inside out", 0, r"1 of 2 shells are inside out")
def _(path):
    v1, f1 = box()
    v2, f2 = box((0.5, 0.5, 0.5), center=(3, 0, 0))
    write_binary_stl(path, np.r_[v1, v2], np.r_[f1, f2[:, ::-1] + 8])
    return [(f32(v1), f1), (f32(v2), f2)]


def box_between(lo, hi):
    """Outward-wound box with the exact corner coordinates ``lo`` and ``hi`` (no arithmetic on them)."""
    v, f = box((1, 1, 1))
    return np.where(v > 0, np.asarray(hi, dtype=float), np.asarray(lo, dtype=float)), f


@entry("overlapping-cubes.stl", "two overlapping cubes (united: the shared volume counted once)", 0,
       r"overlapping bodies united by a boolean")
def _(path):
    v1, f1 = box((1, 1, 1))
    v2, f2 = box((1, 1, 1), center=(0.3, 0.3, 0.3))
    write_binary_stl(path, np.r_[v1, v2], np.r_[f1, f2 + 8])
    a, b = f32(v1), f32(v2)          # the union: cube 1 and three disjoint slabs of cube 2 outside it
    lo, top, hi = b.min(axis=0), a.max(axis=0), b.max(axis=0)
    return [(a, f1), box_between([top[0], lo[1], lo[2]], hi),
            box_between([lo[0], top[1], lo[2]], [top[0], hi[1], hi[2]]),
            box_between([lo[0], lo[1], top[2]], [top[0], top[1], hi[2]])]


@entry("crossed-bars.stl", "two bars crossing like a '+' (no vertex inside the other; united)", 0,
       r"overlapping bodies united")
def _(path):
    v1, f1 = box((3, 1, 1))
    v2, f2 = box((1, 3, 1))
    write_binary_stl(path, np.r_[v1, v2], np.r_[f1, f2 + 8])
    a, b = f32(v1), f32(v2)          # the union: bar 1 and the two arms of bar 2 outside it
    return [(a, f1), box_between([b[:, 0].min(), a[:, 1].max(), b[:, 2].min()], b.max(axis=0)),
            box_between(b.min(axis=0), [b[:, 0].max(), a[:, 1].min(), b[:, 2].max()])]


@entry("hollow.stl", "a box with an inner cavity", 0, r"^$")
def _(path):
    v1, f1 = box((2, 2, 2))
    v2, f2 = box((1, 1, 1))
    write_binary_stl(path, np.r_[v1, v2], np.r_[f1, f2[:, ::-1] + 8])
    return [(v1, f1), (v2, f2[:, ::-1])]


@entry("max-faces.stl", "more triangles than --max-faces", 3,
       r"holds 12 triangles, more than --max-faces \(10\) allows",
       args=("--max-faces", "10"))
def _(path):
    write_binary_stl(path, *box())


@entry("zip-bomb.3mf", "3MF zip bomb (1 MB inflating to 2 GiB)", 3, r"would inflate [\d,]+:1 .* zip bomb",
       shown="3MF member '3D/3dmodel.model' would inflate N:1 (...), over the 100:1 limit: refused as a zip bomb "
             "before inflating")
def _(path):
    deflated, crc, size = _zeros_bomb(2 << 30)
    ct = b'<?xml version="1.0"?><Types xmlns="http://schemas.openxmlformats.org/package/2006/content-types">' \
         b'<Default Extension="model" ContentType="application/vnd.ms-package.3dmanufacturing-3dmodel+xml"/></Types>'
    _zip(path, [("[Content_Types].xml", _deflate(ct), len(ct), zlib.crc32(ct)),
                ("3D/3dmodel.model", deflated, size, crc)])


@entry("not-a-zip.3mf", "a 3MF that is not a zip", 3, r"not a valid 3MF \(zip\) archive")
def _(path):
    open(path, "wb").write(b"<model>not zipped</model>\n")


@entry("bomb.stl.gz", "gzip bomb (2 MB inflating to 2 GiB)", 3, r"refused as a decompression bomb before inflating",
       shown="announces N bytes inflated from N: refused as a decompression bomb before inflating")
def _(path):
    deflated, crc, size = _zeros_bomb(2 << 30)
    header = b"\x1f\x8b\x08\x00\x00\x00\x00\x00\x02\xff"
    open(path, "wb").write(header + deflated + struct.pack("<II", crc, size & 0xFFFFFFFF))


@entry("bomb.stl.bz2", "bzip2 bomb (inflating without limit)", 3, r"inflates beyond [\d,]+ bytes .* decompression bomb",
       shown="inflates beyond N bytes (…): refused as a decompression bomb")
def _(path):
    import bz2
    open(path, "wb").write(bz2.compress(b"\0" * (64 << 20), 9))


@entry("two-meshes.zip", "a zip with two meshes", 3, r"a zip must hold exactly one mesh file")
def _(path):
    data = b"solid a\nendsolid a\n"
    _zip(path, [("a.stl", _deflate(data), len(data), zlib.crc32(data)),
                ("b.stl", _deflate(data), len(data), zlib.crc32(data))])


def make_corpus(directory) -> list[Entry]:
    """Write every corpus file into ``directory``; returns the entries with their clean bodies.

    Each returned entry has ``path`` (the file) and ``reference`` (list of clean ``(vertices, faces)``
    bodies in m for accepted files, else None).
    """
    os.makedirs(directory, exist_ok=True)
    out = []
    for e in ENTRIES:
        path = os.path.join(os.fsdecode(directory), e.name)
        reference = e.build(path)
        done = Entry(e.name, e.kind, e.exit_code, e.says, e.build, e.args, e.shown)
        done.path = path
        done.reference = reference
        out.append(done)
    return out


def _readable(pattern: str) -> str:
    """A regular expression of the table turned into the words a user sees."""
    text = pattern.replace(r"[\d,]+", "N").replace(r"\d+", "N").replace(r"\d", "N").replace(".*", "…")
    text = text.replace("\\ufffd", "\ufffd")
    return re.sub(r"\\(.)", r"\1", text).replace("|", "\\|")


def readme_table() -> str:
    """The README's "Bad input" table: input kind → what the tool says → exit code."""
    rows = ["| input | what `inertia-tool analyze FILE` says | exit |", "|---|---|---|"]
    for e in ENTRIES:
        if e.shown == r"^$":
            said = "the result"
        else:
            said = ("warning: " if e.exit_code == 0 else "error: ") + "FILE: " + _readable(e.shown)
        rows.append(f"| {e.kind} | {said} | {e.exit_code} |")
    return "\n".join(rows)


if __name__ == "__main__":  # pragma: no cover
    if sys.argv[1:] == ["--table"]:
        print(readme_table())
    elif len(sys.argv) == 2:
        for e in make_corpus(sys.argv[1]):
            print(f"{e.exit_code}  {e.path}")
    else:
        sys.exit(__doc__)
