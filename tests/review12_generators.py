"""Review 12 (issue 21, "certified answers"): generators written apart from the code they judge, shared by
``tests/test_review12_findings.py`` (a few cases each) and ``benchmarks/bench_review12.py`` (hundreds).

Every case is a set of *files* (OBJ, PLY, OFF, STL, 3MF, or a URDF/MJCF naming them) and the solid it means,
so the reader's quirks are in the path being judged:

* :func:`prism_case` — a star-shaped, usually non-convex polygon extruded along an axis (caps written as one
  polygon, sides as quads), axis-permuted and mirrored exactly, 1e-6..1e2 m across, at the origin or
  1e6..1e9 m off it, as thin plates (height 1e-9..1e-4 of the width) or needles; written as OBJ (1-based or
  negative relative indices, ``v/vt/vn`` corners, ``o``/``g``/``usemtl`` lines splitting the faces), PLY
  (ASCII or binary, polygon faces), OFF (polygons, comments) or STL/3MF (triangles only), in m, mm or inch
  with the matching ``units``.
* :func:`touching_case` — two prisms touching along an edge segment, at one vertex, or over part of a face,
  with their shared corners welded (one vertex index) or written twice; also split over two OBJ objects.
* :func:`duplicate_case` — a prism whose faces are repeated: the same triangle twice (same winding), a triangle
  and its reverse added as a pair, or a pair through the inside of the solid (a two-sided internal membrane).
* :func:`membrane_torus_case` — a polyhedral torus whose hole is closed by a fan (a one-sided membrane, or a
  two-sided one written both ways).

The truth of each is computed without the engine: exact rational integrals (:class:`fractions.Fraction`) of
the polygons as written (every cap is exactly planar: its corners share one coordinate, so any triangulation
of it bounds the same solid; the truth fans each polygon from a rational point of its plane, which gives the
polygon's signed integrals whatever its shape).  Membranes and cancelling pairs enclose no volume and are left
out of the truth: the solid people mean is the prism (or the torus) without them.
"""

from __future__ import annotations

import io
import math
import struct
import zipfile
from dataclasses import dataclass, field
from fractions import Fraction
from pathlib import Path

import numpy as np

FORMATS = ("obj", "ply", "ply_binary", "off", "stl", "3mf")
UNITS = {"m": 1.0, "mm": 1e-3, "in": 0.0254}

Point = tuple[float, float, float]
Polygon = list[int]


# ---------------------------------------------------------------------------------------------- truths
@dataclass(frozen=True)
class RationalTruth:
    """Unit-density moments of the meant solid in metres: volume m³, centroid (3,) m, inertia (3, 3) m⁵ about
    the centroid (tensor convention: off-diagonals −∫xy dV), each the float nearest an exact rational."""

    volume: float
    centroid: np.ndarray
    inertia: np.ndarray


def rational_moments(points: list[Point], polygons: list[Polygon], scale: Fraction = Fraction(1)) -> RationalTruth:
    """Exact integrals of the closed surface ``polygons`` (outward, each exactly planar) over ``points``
    (floats, read as exact rationals, times ``scale``: a unit's metres per file unit as an exact decimal).

    Each polygon is fanned from the mean of its corners (a rational point of its plane): the signed tetrahedra
    ``(0, c, p_i, p_{i+1})`` give the polygon's contribution to ∫dV, ∫x dV, ∫x xᵀ dV for any simple polygon,
    convex or not ("Rigid Body Motion" §4.2, the divergence theorem over a closed surface; det/6, det/24·Σp,
    det/120·(Σ pᵢpᵢᵀ + s sᵀ) of a tetrahedron with one corner at the origin).  The origin is moved to the
    first point first, so far-off parts keep small rationals."""
    origin = [Fraction(x) for x in points[0]]
    fr = [[(Fraction(x) - o) * scale for x, o in zip(p, origin)] for p in points]
    from adversary_solids import fraction_sums

    def fan():
        for poly in polygons:
            corners = [fr[i] for i in poly]
            k = len(corners)
            c = [sum((p[j] for p in corners), Fraction(0)) / k for j in range(3)]
            for i in range(k):
                yield c, corners[i], corners[(i + 1) % k]

    vol, first, second = fraction_sums(fan())
    cen = [first[j] / vol for j in range(3)]
    central = [[second[r][q] - vol * cen[r] * cen[q] for q in range(3)] for r in range(3)]
    tr = central[0][0] + central[1][1] + central[2][2]
    inertia = np.array([[float((tr if r == q else 0) - central[r][q]) for q in range(3)] for r in range(3)])
    centroid = np.array([float(cen[j] + origin[j] * scale) for j in range(3)])
    return RationalTruth(float(vol), centroid, inertia)


# ---------------------------------------------------------------------------------------------- shapes
def star_polygon(rng: np.random.Generator, convex: bool = False) -> np.ndarray:
    """``(k, 2)``: a star-shaped polygon about the origin, counter-clockwise, radius ≤ 1, 3..9 corners whose
    angles are at least 0.2 rad apart (so no rounding makes it self-crossing)."""
    k = int(rng.integers(3, 10))
    while True:
        angles = np.sort(rng.uniform(0, 2 * np.pi, size=k))
        gaps = np.diff(np.concatenate([angles, [angles[0] + 2 * np.pi]]))
        if gaps.min() > 0.2 and gaps.max() < np.pi - 0.05:
            break
    radius = np.ones(k) if convex else rng.uniform(0.3, 1.0, size=k)
    return np.column_stack([radius * np.cos(angles), radius * np.sin(angles)])


@dataclass
class Solid:
    """Points (floats, file units) and outward polygons; ``truth_polygons`` the polygons of the meant solid
    (``polygons`` minus membranes and cancelling pairs); ``objects[i]`` the object each polygon belongs to."""

    points: list[Point]
    polygons: list[Polygon]
    truth_polygons: list[Polygon]
    objects: list[int] = field(default_factory=list)
    recipe: str = ""
    #: a point each non-convex polygon is star-shaped about (by its corners' tuple), for triangle-only formats
    centres: dict[tuple[int, ...], Point] = field(default_factory=dict)


def _placed(rng: np.random.Generator, xy: np.ndarray, z0: float, z1: float, width: float,
            offset: np.ndarray, perm: np.ndarray, signs: np.ndarray
            ) -> tuple[list[Point], list[Polygon], dict[tuple[int, ...], Point]]:
    """The prism over ``xy`` (scaled by ``width``) from ``z0`` to ``z1`` moved by ``offset`` with its axes
    permuted/mirrored (exact in float: only the addition of the offset rounds, once per coordinate)."""
    k = len(xy)
    raw = [(x * width, y * width, z) for z in (z0, z1) for x, y in xy]
    pts = []
    for p in raw:
        q = np.array(p)[perm] * signs
        pts.append(tuple(float(q[j] + offset[j]) for j in range(3)))
    bottom = list(range(k))[::-1]
    top = list(range(k, 2 * k))
    sides = [[i, (i + 1) % k, k + (i + 1) % k, k + i] for i in range(k)]
    polys = [bottom, top] + sides
    if np.prod(signs) * np.linalg.det(np.eye(3)[perm]) < 0:       # a mirror turns the surface inside out
        polys = [p[::-1] for p in polys]
    centres = {}
    for cap, z in ((polys[0], z0), (polys[1], z1)):    # each cap is star-shaped about its axis point
        q = np.array([0.0, 0.0, z])[perm] * signs
        centre = tuple(float(q[j] + offset[j]) for j in range(3))
        # the shared coordinate exactly as the corners have it (so the centre lies on the cap's plane)
        corners = np.array([pts[i] for i in cap])
        same = np.all(corners == corners[0], axis=0)
        centres[tuple(cap)] = tuple(float(corners[0][j]) if same[j] else centre[j] for j in range(3))
    return pts, polys, centres


def prism_case(rng: np.random.Generator) -> Solid:
    """One prism (see the module docstring): shape ``plain | plate | needle``, size, offset."""
    shape = str(rng.choice(["plain", "plain", "plate", "needle"]))
    width = float(10.0 ** rng.uniform(-6, 2))
    height = width * float(rng.uniform(0.3, 3))
    if shape == "plate":
        height = width * float(10.0 ** rng.uniform(-9, -4))
    elif shape == "needle":
        height = width * float(10.0 ** rng.uniform(4, 8))
        width = height / float(10.0 ** rng.uniform(4, 8))
    far = min(float(10.0 ** rng.uniform(6, 9)), width * 1e11) if rng.random() < 0.35 else 0.0
    offset = rng.normal(size=3) * far        # at most 1e11 widths out: the polygon keeps ≥ 1e5 ulps across
    perm = rng.permutation(3)
    signs = rng.choice([-1.0, 1.0], size=3)
    xy = star_polygon(rng, convex=rng.random() < 0.3)
    pts, polys, centres = _placed(rng, xy, 0.0, height, width, offset, perm, signs)
    recipe = f"prism {shape} k={len(xy)} width={width:.3g} height={height:.3g} far={far:.3g} perm={perm} signs={signs}"
    return Solid(pts, polys, list(polys), [0] * len(polys), recipe, centres)


def touching_case(rng: np.random.Generator) -> Solid:
    """Two boxes (prisms over a square) touching along part of an edge, at one vertex, or over part of a face;
    corners shared by index (welded) or written twice.  The truth is the sum (the interiors are disjoint)."""
    how = str(rng.choice(["edge", "vertex", "face"]))
    welded = bool(rng.random() < 0.5)
    size = float(10.0 ** rng.uniform(-5, 1))
    far = min(float(10.0 ** rng.uniform(6, 9)), size * 1e11) if rng.random() < 0.3 else 0.0
    offset = rng.normal(size=3) * far
    a = np.array([1.0, 1.0, 1.0]) * size
    b = rng.uniform(0.4, 1.5, size=3) * size
    if how == "vertex":
        lo_b = a.copy()
    elif how == "edge":
        lo_b = np.array([a[0], a[1], float(rng.uniform(-0.5, 0.5)) * size])
    else:
        lo_b = np.array([a[0], float(rng.uniform(-0.5, 0.5)) * size, float(rng.uniform(-0.5, 0.5)) * size])
    pts: list[Point] = []
    index: dict[Point, int] = {}
    polys: list[Polygon] = []
    objects: list[int] = []

    def vid(p):
        p = tuple(float(x) for x in p)
        if welded and p in index:
            return index[p]
        pts.append(p)
        index[p] = len(pts) - 1
        return len(pts) - 1

    for obj, (lo, hi) in enumerate([(np.zeros(3), a), (lo_b, lo_b + b)]):
        corners = [np.array([hi[0] if i & 1 else lo[0], hi[1] if i & 2 else lo[1], hi[2] if i & 4 else lo[2]])
                   + offset for i in range(8)]
        ids = [vid(c) for c in corners]
        for quad in ([0, 2, 3, 1], [4, 5, 7, 6], [0, 1, 5, 4], [2, 6, 7, 3], [0, 4, 6, 2], [1, 3, 7, 5]):
            polys.append([ids[q] for q in quad])
            objects.append(obj)
    return Solid(pts, polys, list(polys), objects,
                 f"touching {how} welded={welded} size={size:.3g} far={far:.3g} b={b / size}")


def duplicate_case(rng: np.random.Generator) -> Solid:
    """A prism (triangulated caps) with faces repeated: ``same`` (a triangle twice, same winding), ``pair`` (a
    side quad and its reverse added), ``inner`` (a triangle through the inside written both ways)."""
    base = prism_case(rng)
    how = str(rng.choice(["same", "pair", "inner"]))
    pts, polys = list(base.points), [list(p) for p in base.polygons]
    extra: list[Polygon] = []
    count = int(rng.integers(1, 4))
    for _ in range(count):
        if how == "same":
            extra.append(list(polys[int(rng.integers(len(polys)))]))
        elif how == "pair":
            p = list(polys[int(rng.integers(2, len(polys)))])
            extra += [p, p[::-1]]
        else:
            k = (len(pts)) // 2           # bottom ring 0..k-1, top ring k..2k-1: a triangle across the inside
            i = int(rng.integers(k))
            tri = [i, k + (i + 1) % k, (i + k // 2) % k] if k > 3 else [0, k + 1, 2]
            extra += [tri, tri[::-1]]
    order = rng.permutation(len(polys) + len(extra))
    every = polys + extra
    return Solid(pts, [every[i] for i in order], polys, [0] * len(every),
                 f"duplicate {how} x{count} of ({base.recipe})", base.centres)


def membrane_torus_case(rng: np.random.Generator) -> Solid:
    """A torus of triangles (major R, minor r, n × m sections) whose hole is closed by a fan from the axis to
    the innermost ring, one-sided (either winding) or two-sided."""
    n, m = int(rng.integers(8, 24)), int(rng.integers(4, 10))
    if m % 2:
        m += 1                                   # so the innermost ring is a ring of vertices (phi = pi)
    big = float(rng.uniform(1.0, 3.0))
    small = big * float(rng.uniform(0.1, 0.6))
    scale = float(10.0 ** rng.uniform(-4, 1))
    far = float(10.0 ** rng.uniform(6, 8)) if rng.random() < 0.3 else 0.0
    offset = rng.normal(size=3) * far
    pts: list[Point] = []
    for i in range(n):
        t = 2 * math.pi * i / n
        for j in range(m):
            p = 2 * math.pi * j / m
            x = (big + small * math.cos(p)) * math.cos(t)
            y = (big + small * math.cos(p)) * math.sin(t)
            z = small * math.sin(p)
            pts.append((float(x * scale + offset[0]), float(y * scale + offset[1]), float(z * scale + offset[2])))

    def v(i, j):
        return (i % n) * m + (j % m)

    tris: list[Polygon] = []
    for i in range(n):
        for j in range(m):
            tris += [[v(i, j), v(i + 1, j), v(i + 1, j + 1)], [v(i, j), v(i + 1, j + 1), v(i, j + 1)]]
    pts.append((float(offset[0]), float(offset[1]), float(offset[2])))
    centre = len(pts) - 1
    ring = [v(i, m // 2) for i in range(n)]
    fan = [[centre, ring[i], ring[(i + 1) % n]] for i in range(n)]
    how = str(rng.choice(["up", "down", "both"]))
    membrane = fan if how == "up" else [f[::-1] for f in fan] if how == "down" else fan + [f[::-1] for f in fan]
    return Solid(pts, tris + membrane, tris, [0] * (len(tris) + len(membrane)),
                 f"membrane torus {how} n={n} m={m} R={big:.3g} r={small:.3g} scale={scale:.3g} far={far:.3g}")


GENERATORS = {"prism": prism_case, "touching": touching_case, "duplicate": duplicate_case,
              "membrane_torus": membrane_torus_case}


# ---------------------------------------------------------------------------------------------- writers
def _num(x: float) -> str:
    return repr(float(x))


def _triangles(polys: list[Polygon]) -> list[Polygon]:
    """Fans from the first corner (for convex polygons; planar to the bit here)."""
    return [[p[0], p[i], p[i + 1]] for p in polys for i in range(1, len(p) - 1)]


def triangulated(solid: Solid) -> Solid:
    """``solid`` with every polygon cut into triangles that do not overlap: a polygon with a centre
    (``solid.centres``, a star's kernel point on its plane) fanned from it as a new vertex, others (convex)
    from their first corner.  The meant solid is unchanged (the same planar polygons)."""
    pts = list(solid.points)
    added: dict[tuple[int, ...], int] = {}
    polys: list[Polygon] = []
    objects: list[int] = []
    for p, o in zip(solid.polygons, solid.objects or [0] * len(solid.polygons)):
        key = tuple(p)
        centre = solid.centres.get(key)
        if centre is None and tuple(p[::-1]) in solid.centres:
            key = tuple(p[::-1])
            centre = solid.centres[key]
        if centre is None or len(p) == 3:
            tris = _triangles([p])
        else:
            if key not in added:
                pts.append(centre)
                added[key] = len(pts) - 1
            c = added[key]
            tris = [[c, p[i], p[(i + 1) % len(p)]] for i in range(len(p))]
        polys += tris
        objects += [o] * len(tris)
    truth = _triangles(solid.truth_polygons)
    return Solid(pts, polys, truth, objects, solid.recipe)


def write_obj(solid: Solid, rng: np.random.Generator, unit: float = 1.0) -> bytes:
    """OBJ with quirks: negative relative indices (after each object's vertices), ``v/vt/vn`` corners,
    ``o``/``g``/``usemtl`` lines, vertices interleaved with faces per object, comments, blank lines."""
    negative = bool(rng.random() < 0.5)
    corner_kind = int(rng.integers(4))
    out = io.StringIO()
    out.write("# review12 generated\nmtllib none.mtl\n")
    objs = sorted(set(solid.objects)) or [0]
    written: dict[int, int] = {}              # point -> 1-based index in the file
    for obj in objs:
        out.write(f"o part{obj}\ng group{obj}\nusemtl m{obj}\n")
        polys = [p for p, o in zip(solid.polygons, solid.objects) if o == obj]
        for p in polys:
            for i in p:
                if i not in written:
                    x, y, z = (c / unit for c in solid.points[i])
                    out.write(f"v {_num(x)} {_num(y)} {_num(z)}\n")
                    written[i] = len(written) + 1
        out.write("vt 0.5 0.5\nvn 0 0 1\n\n")
        total = len(written)
        for p in polys:
            idx = [written[i] - total - 1 if negative else written[i] for i in p]
            if corner_kind == 0:
                cs = [str(i) for i in idx]
            elif corner_kind == 1:
                cs = [f"{i}//{-1 if negative else len(objs[:obj + 1])}" for i in idx]
            elif corner_kind == 2:
                cs = [f"{i}/-1/-1" for i in idx]
            else:
                cs = [f"{i}/-1" for i in idx]
            out.write("f " + " ".join(cs) + "\n")
    return out.getvalue().encode()


def _indexed(solid: Solid, unit: float) -> tuple[np.ndarray, list[Polygon]]:
    return np.array(solid.points) / unit, solid.polygons


def write_ply(solid: Solid, binary: bool, unit: float = 1.0) -> bytes:
    v, polys = _indexed(solid, unit)
    head = (f"ply\nformat {'binary_little_endian' if binary else 'ascii'} 1.0\ncomment review12\n"
            f"element vertex {len(v)}\nproperty double x\nproperty double y\nproperty double z\n"
            f"element face {len(polys)}\nproperty list uchar int vertex_indices\nend_header\n").encode()
    if binary:
        body = b"".join(struct.pack("<3d", *p) for p in v)
        body += b"".join(struct.pack(f"<B{len(p)}i", len(p), *p) for p in polys)
        return head + body
    lines = [" ".join(_num(x) for x in p) for p in v] + [f"{len(p)} " + " ".join(map(str, p)) for p in polys]
    return head + ("\n".join(lines) + "\n").encode()


def write_off(solid: Solid, unit: float = 1.0) -> bytes:
    v, polys = _indexed(solid, unit)
    out = [f"OFF\n# review12\n{len(v)} {len(polys)} 0"]
    out += [" ".join(_num(x) for x in p) for p in v]
    out += [f"{len(p)} " + " ".join(map(str, p)) for p in polys]
    return ("\n".join(out) + "\n").encode()


def write_stl(solid: Solid, unit: float = 1.0) -> bytes:
    v, polys = _indexed(solid, unit)
    tris = _triangles(polys)
    # binary STL is float32: write the corners as float32 and let the caller's truth use those values
    body = b"".join(struct.pack("<12fH", 0.0, 0.0, 0.0, *v[t[0]], *v[t[1]], *v[t[2]], 0) for t in tris)
    return b"review12".ljust(80, b" ") + struct.pack("<I", len(tris)) + body


def write_3mf(solid: Solid, unit_name: str, unit: float = 1.0) -> bytes:
    """A 3MF package, one ``<object>`` per object of ``solid`` (triangles), all placed by the build."""
    v, polys = _indexed(solid, unit)
    objs = sorted(set(solid.objects)) or [0]
    unit_word = {"m": "meter", "mm": "millimeter", "in": "inch"}[unit_name]
    parts = []
    items = []
    for k, obj in enumerate(objs):
        mine = [p for p, o in zip(polys, solid.objects) if o == obj]
        used = sorted({i for p in mine for i in p})
        local = {i: n for n, i in enumerate(used)}
        verts = "".join(f'<vertex x="{_num(v[i][0])}" y="{_num(v[i][1])}" z="{_num(v[i][2])}"/>' for i in used)
        tris = "".join(f'<triangle v1="{local[t[0]]}" v2="{local[t[1]]}" v3="{local[t[2]]}"/>'
                       for t in _triangles(mine))
        parts.append(f'<object id="{k + 1}" type="model"><mesh><vertices>{verts}</vertices>'
                     f'<triangles>{tris}</triangles></mesh></object>')
        items.append(f'<item objectid="{k + 1}"/>')
    model = ('<?xml version="1.0" encoding="UTF-8"?>'
             f'<model unit="{unit_word}" xml:lang="en-US" '
             'xmlns="http://schemas.microsoft.com/3dmanufacturing/core/2015/02">'
             f'<resources>{"".join(parts)}</resources><build>{"".join(items)}</build></model>')
    buf = io.BytesIO()
    with zipfile.ZipFile(buf, "w") as zf:
        zf.writestr("[Content_Types].xml",
                    '<?xml version="1.0" encoding="UTF-8"?><Types xmlns="http://schemas.openxmlformats.org/'
                    'package/2006/content-types"><Default Extension="rels" ContentType="application/'
                    'vnd.openxmlformats-package.relationships+xml"/><Default Extension="model" ContentType='
                    '"application/vnd.ms-package.3dmanufacturing-3dmodel+xml"/></Types>')
        zf.writestr("_rels/.rels",
                    '<?xml version="1.0" encoding="UTF-8"?><Relationships xmlns="http://schemas.openxmlformats.'
                    'org/package/2006/relationships"><Relationship Target="/3D/3dmodel.model" Id="rel0" '
                    'Type="http://schemas.microsoft.com/3dmanufacturing/2013/01/3dmodel"/></Relationships>')
        zf.writestr("3D/3dmodel.model", model)
    return buf.getvalue()


def write(solid: Solid, fmt: str, unit_name: str, rng: np.random.Generator, folder: Path,
          stem: str = "part") -> tuple[Path, RationalTruth]:
    """Write ``solid`` (metres) in ``fmt`` with coordinates in ``unit_name``; returns the path and the truth of
    what was written, in metres (the coordinates as the file holds them, times the unit's exact metres)."""
    unit = UNITS[unit_name]
    exact_unit = {"m": Fraction(1), "mm": Fraction(1, 1000), "in": Fraction(254, 10000)}[unit_name]
    suffix = {"ply_binary": "ply"}.get(fmt, fmt)
    path = folder / f"{stem}.{suffix}"
    if fmt in ("stl", "3mf"):
        solid = triangulated(solid)
    if fmt == "obj":
        data = write_obj(solid, rng, unit)
    elif fmt in ("ply", "ply_binary"):
        data = write_ply(solid, fmt == "ply_binary", unit)
    elif fmt == "off":
        data = write_off(solid, unit)
    elif fmt == "stl":
        data = write_stl(solid, unit)
    else:
        data = write_3mf(solid, unit_name, unit)
    path.write_bytes(data)
    # the file's numbers, read back as the writer wrote them (float32 for STL, repr-exact otherwise)
    file_points = np.array(solid.points) / unit
    if fmt == "stl":
        file_points = file_points.astype(np.float32).astype(np.float64)
    polys = solid.truth_polygons
    return path, rational_moments([tuple(p) for p in file_points], polys, exact_unit)


# ---------------------------------------------------------------------------------------------- judging
#: A proven answer (``exact``/``united``) must match the truth to these (volume and inertia relative; centre of
#: mass relative to the diagonal, plus 4 ulps of the centre's own coordinates, which a far part cannot beat).
VOLUME_RTOL, COM_RTOL, INERTIA_RTOL = 1e-9, 1e-9, 1e-8
PROVEN = ("exact", "united")


@dataclass(frozen=True)
class Verdict:
    """``label`` the certificate's kind, ``refused`` or ``crashed``; ``wrong`` why the numbers miss the truth
    (None when they hold); ``message`` the refusal's first line."""

    label: str
    wrong: str | None = None
    message: str = ""
    method: str = ""            # the mesh report's method (``welded``, ``union``, ...) when there is an answer

    @property
    def silent(self) -> bool:
        """A wrong number under a label that claims proof, or an estimate whose bounds miss the truth."""
        return self.wrong is not None and self.label in PROVEN + ("estimate",)


def judge_numbers(label: str, mass: float, com, inertia, uncertainty, truth: RationalTruth, diag: float,
                  density: float = 1.0) -> Verdict:
    """Whether ``(mass, com, inertia)`` (kg, m, kg·m² about the centre of mass) labelled ``label`` is honest
    against ``truth`` at ``density``: proven labels to the tolerances above, an estimate within its bounds."""
    com, inertia = np.asarray(com, dtype=float), np.asarray(inertia, dtype=float)
    if not (np.isfinite(mass) and np.all(np.isfinite(com)) and np.all(np.isfinite(inertia))):
        return Verdict(label, wrong=f"non-finite result (mass {mass}, com {com})")
    vol = mass / density
    dvol = abs(vol - truth.volume) / abs(truth.volume)
    dcom = float(np.linalg.norm(com - truth.centroid))
    din = float(np.linalg.norm(inertia / density - truth.inertia) / np.linalg.norm(truth.inertia))
    ulps = 4 * float(np.linalg.norm(np.spacing(np.abs(truth.centroid))))
    numbers = (f"volume {vol:.12g} vs {truth.volume:.12g}: rel {dvol:.2e}, com off {dcom:.3g} m "
               f"({dcom / diag:.2e}·diag), inertia rel {din:.2e}")
    if label == "estimate":
        if uncertainty is None:
            return Verdict(label, wrong="an estimate without bounds; " + numbers)
        u = uncertainty
        slack = 1e-9
        if not (dvol <= u.mass + slack and dcom <= u.center_of_mass + slack * diag + ulps
                and din <= u.inertia + slack):
            return Verdict(label, wrong=f"outside its bounds (±{u.mass:.3g} mass, ±{u.center_of_mass:.3g} m com, "
                                        f"±{u.inertia:.3g} inertia); " + numbers)
        return Verdict(label)
    if dvol > VOLUME_RTOL or dcom > COM_RTOL * diag + ulps or din > INERTIA_RTOL:
        return Verdict(label, wrong=numbers)
    return Verdict(label)


def judge_file(path, unit_name: str, truth: RationalTruth, diag: float, repair: bool = False) -> Verdict:
    """Run :func:`inertia_tool.mass_properties` on the file (a path, or a ``(vertices, faces)`` pair) at density 1
    and judge it (see :func:`judge_numbers`); a named :class:`~inertia_tool.errors.InertiaToolError` is a
    refusal, anything else a crash."""
    import warnings

    from inertia_tool import mass_properties
    from inertia_tool.errors import InertiaToolError
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            props = mass_properties(str(path) if isinstance(path, (str, Path)) else path, density=1.0, units=unit_name,
                                    repair=repair)
    except InertiaToolError as exc:
        return Verdict("refused", message=str(exc).splitlines()[0] if str(exc) else type(exc).__name__)
    except Exception as exc:           # a traceback on input is a defect: counted, never hidden
        return Verdict("crashed", wrong=f"{type(exc).__name__}: {exc}"[:300])
    cert = props.mesh.certificate
    label = cert.kind if cert is not None else props.mesh.method
    verdict = judge_numbers(label, props.mass, props.center_of_mass, props.inertia, props.mesh.uncertainty, truth,
                            diag)
    return Verdict(verdict.label, verdict.wrong, verdict.message, props.mesh.method)


def silent_reason(vertices, faces, truth: RationalTruth, units: str = "m", repair: bool = False) -> str | None:
    """None when the arrays' answer is a refusal, an unproven label, or honest against ``truth``; else why (a
    crash counts: a traceback on input is a defect)."""
    diag = float(np.linalg.norm(vertices.max(0) - vertices.min(0))) * UNITS[units]      # in metres
    verdict = judge_file((vertices, faces), units, truth, diag, repair=repair)
    return f"{verdict.label} {verdict.method}: {verdict.wrong}" if verdict.silent or verdict.label == "crashed" \
        else None


def diagonal(solid: Solid) -> float:
    """The bounding-box diagonal of the meant solid's points (m)."""
    used = sorted({i for p in solid.truth_polygons for i in p})
    pts = np.array([solid.points[i] for i in used])
    return float(np.linalg.norm(pts.max(0) - pts.min(0)))


def draw(kind: str, rng: np.random.Generator, folder: Path,
         unit: str | None = None) -> tuple[Solid, str, str, Path, RationalTruth]:
    """One case of generator ``kind`` written to ``folder``: ``(solid, format, unit, path, truth)``; STL
    (float32) only for parts near the origin; ``unit`` forces the file's unit (else m, mm or inch at random)."""
    for _ in range(100):                  # bounded: a draw whose written coordinates enclose nothing is drawn again
        solid = GENERATORS[kind](rng)
        far = float(np.abs(np.array(solid.points)).max()) > 1e5
        choices = [f for f in FORMATS if not (f == "stl" and far)]
        fmt = str(rng.choice(choices))
        unit_name = str(rng.choice(list(UNITS)))
        unit_name = unit or unit_name
        try:
            path, truth = write(solid, fmt, unit_name, rng, folder)
        except ZeroDivisionError:
            continue
        return solid, fmt, unit_name, path, truth
    raise RuntimeError(f"no {kind} case with volume in 100 draws")
