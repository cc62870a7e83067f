"""Review 11 (issue 21, "certified answers"): generators written apart from the code they judge, shared by
``tests/test_review11_findings.py`` (a few hundred cases each) and ``benchmarks/bench_review11.py`` (thousands).

* :func:`face_pair` — two triangles (one face each, sharing a corner by index or not) on a small integer grid,
  scaled by a power of two from 2⁻⁶⁰ to 2⁶⁰, moved far off (1e3..1e8 sizes) or not, rounded to float32 or not,
  some corners copied from the other face, put on its edges or nudged 1-8 ulps: every coplanarity, touching
  corner and crossing at float boundaries the C kernel's float filter (``ct_side_filter``, ``ct_touch_first``)
  must either decide right or hand to the exact stage.  Judged by ``intersect_reference.brute_kind`` (rational
  arithmetic on the same doubles).
* :func:`fitted_truth` — a unit-density tensor and volume (near-degenerate: two equal moments, a flat part with
  ``s_k`` near 0, a needle), bounds ``(ε_m, ε_I)``, and a truth within those bounds chosen to push the fitted
  primitive's volume as far as it can go (principal-axis errors of Frobenius norm ``ε_I ‖Î‖``, volume at its
  limits), for every fit kind.
"""

from __future__ import annotations

import numpy as np

FIT_KINDS = ("box", "ellipsoid", "sphere", "cylinder", "capsule")


# ------------------------------------------------------------------------------------------ face pairs
def _nudge(x: np.ndarray, rng: np.random.Generator, dtype) -> np.ndarray:
    """``x`` with one random coordinate moved 1-8 ulps (of ``dtype``) up or down."""
    y = np.array(x, dtype=dtype)
    c = int(rng.integers(3))
    towards = np.array(np.inf if rng.random() < 0.5 else -np.inf, dtype=dtype)
    for _ in range(int(rng.integers(1, 9))):
        y[c] = np.nextafter(y[c], towards)
    return y.astype(np.float64)


def face_pair(rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray, str]:
    """``(vertices (k, 3), faces (2, 3), recipe)``: two triangles as described in the module docstring.

    A's corners on the grid ``{-3..3}³``; each of B's corners, at random: a copy of a corner of A (by index
    half of the time), the float midpoint of an edge of A, a grid point, a grid point on A's plane (``a0 +
    i (a1 − a0) + j (a2 − a0)`` for small integers), any of these nudged by 1-8 ulps afterwards.
    """
    a = rng.integers(-3, 4, size=(3, 3)).astype(np.float64)
    e1, e2 = a[1] - a[0], a[2] - a[0]
    scale = 2.0 ** int(rng.integers(-60, 61))
    far = float(10.0 ** rng.uniform(3, 8)) * scale if rng.random() < 0.4 else 0.0
    offset = far * rng.normal(size=3)
    single = rng.random() < 0.35
    dtype = np.float32 if single else np.float64
    points = [a[0], a[1], a[2]]
    shared: list[tuple[int, int]] = []
    kinds = []
    for j in range(3):
        pick = rng.choice(["copy", "edge", "grid", "plane", "plane"])
        if pick == "copy":
            i = int(rng.integers(3))
            if rng.random() < 0.5 and i not in {s for s, _ in shared}:
                shared.append((i, j))
            points.append(a[i])
        elif pick == "edge":
            i = int(rng.integers(3))
            points.append(0.5 * (a[i] + a[(i + 1) % 3]))
        elif pick == "grid":
            points.append(rng.integers(-3, 4, size=3).astype(np.float64))
        else:
            i, k = rng.integers(-2, 3, size=2)
            points.append(a[0] + i * e1 + k * e2)
        kinds.append(pick)
    v = (np.array(points) * scale + offset).astype(dtype).astype(np.float64)
    nudged = []
    for j in range(6):
        if rng.random() < 0.2 and not any(j == 3 + jj for _, jj in shared):
            v[j] = _nudge(v[j], rng, dtype)
            nudged.append(j)
    faces = np.array([[0, 1, 2], [3, 4, 5]])
    for i, j in shared:                       # B's corner j is A's corner i by index
        faces[1, j] = i
    if rng.random() < 0.5:
        faces = faces[::-1].copy()            # either face may be the lower index (A in the kernel)
    faces = np.array([np.roll(row, int(rng.integers(3))) if rng.random() < 0.5 else row[::-1] for row in faces])
    recipe = (f"B={kinds} shared={shared} nudged={nudged} scale=2^{int(np.log2(scale))} far={far:.3g} "
              f"{'float32' if single else 'float64'}")
    return v, faces, recipe


def shared_corners(faces: np.ndarray) -> list[tuple[int, int]]:
    """``[(i, j)]``: corner ``i`` of face 0 is corner ``j`` of face 1 by index."""
    return [(i, j) for i in range(3) for j in range(3) if faces[0, i] == faces[1, j]]


# ------------------------------------------------------------------------------------------ fitted primitives
def _tensor(rng: np.random.Generator) -> tuple[np.ndarray, float, str]:
    """``(unit-density tensor about the centre (3, 3), volume, shape)``: the tensor of a box of random
    half-sizes turned at random, with half-sizes that make it near-degenerate half of the time."""
    shape = str(rng.choice(["random", "two_equal", "flat", "needle", "cube", "flat_equal"]))
    h = np.exp(rng.uniform(-3, 3, size=3))
    if shape == "two_equal":
        h[1] = h[0] * (1 + rng.choice([0.0, 1e-15, 1e-9, 1e-4]))
    elif shape == "flat":
        h[2] = h[0] * 10.0 ** rng.uniform(-9, -2)
    elif shape == "needle":
        h[0] = h[1] = h[2] * 10.0 ** rng.uniform(-9, -2)
    elif shape == "cube":
        h[:] = h[0]
    elif shape == "flat_equal":
        h[1] = h[0]
        h[2] = h[0] * 10.0 ** rng.uniform(-9, -2)
    units = 10.0 ** float(rng.choice([-3.0, 0.0, 3.0]))        # mm, m, km parts
    h = h * units
    volume = 8 * float(np.prod(h))
    moments = volume / 3 * np.array([h[1] ** 2 + h[2] ** 2, h[0] ** 2 + h[2] ** 2, h[0] ** 2 + h[1] ** 2])
    q, r = np.linalg.qr(rng.normal(size=(3, 3)))
    q = q * np.sign(np.diag(r))
    return q @ np.diag(moments) @ q.T, volume, shape


def fitted_truth(rng: np.random.Generator) -> tuple[np.ndarray, float, float, float, np.ndarray, float]:
    """``(estimated tensor, estimated volume, ε_m, ε_I, true tensor, true volume)``: the truth within the bounds
    (``|V − V̂| ≤ ε_m V̂``, ``‖I − Î‖_F ≤ ε_I ‖Î‖_F``), on its boundary: an error along ``Î``'s principal axes of
    the full Frobenius norm, its direction one of the worst for some ``s_k`` (``±(1, 1, −1)/√3`` permuted) or
    random, or a random symmetric error; the volume at ``V̂ (1 ± ε_m)``."""
    tensor, volume, _ = _tensor(rng)
    eps_m = float(10.0 ** rng.uniform(-8, -0.5))
    eps_i = float(10.0 ** rng.uniform(-8, -0.5))
    delta = eps_i * float(np.linalg.norm(tensor))
    moments, axes = np.linalg.eigh(tensor)
    how = rng.random()
    if how < 0.6:
        d = np.array([1.0, 1.0, -1.0]) * rng.choice([-1.0, 1.0])
        d = rng.permutation(d) / np.sqrt(3.0) if how < 0.45 else rng.normal(size=3)
        d = d / np.linalg.norm(d) * delta
        error = axes @ np.diag(d) @ axes.T
    else:
        m = rng.normal(size=(3, 3))
        m = m + m.T
        error = m / np.linalg.norm(m) * delta
    error *= 1 - 1e-12                                          # strictly inside the bound, after rounding
    truth = tensor + error
    true_volume = volume * (1 + eps_m * (1 - 1e-12) * rng.choice([-1.0, 1.0, rng.uniform(-1, 1)]))
    return tensor, volume, eps_m, eps_i, truth, true_volume


def fit_volume(kind: str, tensor: np.ndarray, volume: float, fit_scale: float = 1.0) -> float:
    """Volume of MuJoCo's inertia-box fit of ``kind`` to a unit-density ``tensor`` and ``volume``, written here
    from MuJoCo's rules (not the tool's helpers): half-sizes ``h = √(3 (I_i + I_j − I_k) / (2 V))`` from the
    moments sorted largest first, times ``fit_scale``; a box ``8 h_x h_y h_z``, an ellipsoid ``4/3 π h_x h_y
    h_z``, a sphere of radius ``mean(h)``, a cylinder of radius ``r = (h_x + h_y)/2`` and half-length ``h_z``, a
    capsule of that radius and half-length ``max(0, h_z − r/2)``."""
    m = np.sort(np.linalg.eigvalsh(0.5 * (tensor + tensor.T)))[::-1]
    s = np.array([m[1] + m[2] - m[0], m[0] + m[2] - m[1], m[0] + m[1] - m[2]])
    h = np.sqrt(np.clip(1.5 * s / volume, 0, None)) * fit_scale
    r = 0.5 * (h[0] + h[1])
    if kind == "box":
        return float(8 * h[0] * h[1] * h[2])
    if kind == "ellipsoid":
        return float(4 / 3 * np.pi * h[0] * h[1] * h[2])
    if kind == "sphere":
        return float(4 / 3 * np.pi * np.mean(h) ** 3)
    if kind == "cylinder":
        return float(np.pi * r * r * 2 * h[2])
    half = max(0.0, float(h[2]) - 0.5 * r)
    return float(np.pi * r * r * 2 * half + 4 / 3 * np.pi * r ** 3)


# ------------------------------------------------------------------------------------------ round-off of estimates
def far_part_with_a_hole(rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray, np.ndarray, str]:
    """``(vertices, closed faces, faces with a hole, recipe)``: a finely divided box or icosphere (so that the
    hole, its smallest face or that face and a neighbour, is small and the patch's bound is near the round-off),
    0.1 µm..10 m across, turned, near the origin or 1e3..1e8 of its size away, float32-quantised a third of the
    time (near placements only: float32 carries ~7 digits), wound outward by its exact rational volume."""
    from adversary_solids import _outward_exactly, box, icosphere, random_rotation
    kind = int(rng.integers(2))
    v, f = box(rng.uniform(0.2, 2.0, size=3), subdivide=int(rng.integers(1, 3))) if kind == 0 else \
        icosphere(float(rng.uniform(0.3, 1.0)), int(rng.integers(2, 4)))
    size = float(10.0 ** rng.uniform(-7, 1))
    single = rng.random() < 0.33
    far = 0.0 if single or rng.random() < 0.3 else float(10.0 ** rng.uniform(3, 8))
    v = (v * size) @ random_rotation(rng).T + rng.normal(size=3) * far * size
    if single:
        v = v.astype(np.float32).astype(np.float64)
    f = _outward_exactly(v, f)
    area = np.linalg.norm(np.cross(v[f[:, 1]] - v[f[:, 0]], v[f[:, 2]] - v[f[:, 0]]), axis=1)
    lost = [int(np.argmin(area))]
    if rng.random() < 0.5:                       # and a face beside it (sharing an edge)
        edges = {frozenset(e) for e in ((f[lost[0], 0], f[lost[0], 1]), (f[lost[0], 1], f[lost[0], 2]),
                                        (f[lost[0], 2], f[lost[0], 0]))}
        for j, row in enumerate(f):
            if j != lost[0] and any(frozenset(e) in edges for e in ((row[0], row[1]), (row[1], row[2]),
                                                                   (row[2], row[0]))):
                lost.append(j)
                break
    holed = np.delete(f, lost, axis=0)
    recipe = (f"{'box' if kind == 0 else 'icosphere'} {len(f)} faces, size {size:.2g} m, far {far:.2g} sizes, "
              f"{'float32' if single else 'float64'}, {len(lost)} face(s) lost")
    return v, f, holed, recipe
