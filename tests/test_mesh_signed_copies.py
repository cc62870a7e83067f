"""R0 by signed multiplicity (issue 21; :func:`inertia_tool.mesh.multiplicity.coincident_surfaces`,
:func:`~inertia_tool.mesh.multiplicity.cancel_opposite`, the coplanar overlay's zero chains): a solid with extra copies
of its shells and faces, repeated, reversed, both, several times, with its own vertices or the same ones.

The generator: a box body (or a box body with a box void wound inward inside it), moved by a random rigid motion
1e-3..1e8 m out; each shell listed ``1 + extra`` times, every copy wound either way; side faces written again
forwards and backwards (the same triangles, or the other diagonal's forwards and the file's backwards: R8's
pattern, a zero chain only because the side is exactly planar, so that draw turns by axis permutations only).

The truth knows nothing of the pipeline.  Faces change the winding number only where whole shells repeat (every
added face pair is a zero chain), so with the body listed ``kb`` times net (a copy wound inward counts −1) and the
void ``kv`` times net (outward +1), ``w = kb`` in the body outside the void and ``kb + kv`` in the void.  Two
readings are allowed, each an exact rational integral of the float coordinates
(``review12_generators.rational_moments``):

* ``{w ≥ 1}`` of the file as wound, or of the file turned whole (``{w ≤ −1}``: R4's body written inside out);
* the same after R0 (each shell's copies combined by their net count and a net ±2 counted once: a shell listed
  twice is one solid);
* R0 then R4's nesting by depth (a shell inside a body a cavity, whichever way it is wound; a body wound inside
  out turned).

Where the net counts are ±1 and ∓1 (a body and a void, each left once) every reading is ``body − void``; the
readings part only where a shell is left ±2 or more, or both are wound alike.

An answer labelled ``exact``, ``united`` or ``estimate`` must be one of them (``judge_numbers``' tolerances); a
refusal or an ``unverified``/``summed`` label is allowed; when both readings are empty it must be refused.  On the
code before overlay13 this fails (a void listed twice with its inverted copy answered whole, ``exact``; a body with
a cancelling pair and a repeat answered as the void alone).
"""

from __future__ import annotations

import warnings

import numpy as np
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import review12_generators as G
from adversary_solids import box
from inertia_tool import mass_properties
from inertia_tool.errors import InertiaToolError

#: Box sides as the two triangles ``box`` writes and the other diagonal's two (same winding), by face index pair.
_SIDES = [((0, 1), [[0, 1, 2], [1, 3, 2]]), ((2, 3), [[4, 6, 5], [6, 7, 5]]), ((4, 5), [[0, 4, 1], [4, 5, 1]]),
          ((6, 7), [[2, 3, 6], [3, 7, 6]]), ((8, 9), [[0, 2, 4], [2, 6, 4]]), ((10, 11), [[1, 5, 3], [5, 7, 3]])]


def _motion(rng: np.random.Generator, planar: bool) -> tuple[np.ndarray, np.ndarray]:
    """A rotation (an axis permutation with signs when ``planar``: exact in float64) and an offset 1e-3..1e8 m."""
    if planar:
        q = np.eye(3)[rng.permutation(3)] * rng.choice([-1.0, 1.0], size=3)[:, None]
        if np.linalg.det(q) < 0:
            q[0] *= -1
    else:
        q, _ = np.linalg.qr(rng.normal(size=(3, 3)))
        if np.linalg.det(q) < 0:
            q[:, 0] *= -1
    far = 10.0 ** rng.uniform(-3, 8)
    return q, rng.normal(size=3) / np.sqrt(3) * far


def _draw(seed: int):
    """(vertices, faces, readings, recipe): the file and its allowed readings ([] when it encloses nothing)."""
    rng = np.random.default_rng(seed)
    ext = rng.integers(4, 17, size=3) / 16.0
    body = box(ext)
    shells = [body]
    if rng.random() < 0.6:                                    # a void inside, a quarter of the body's extents
        inner = rng.integers(1, 4, size=3) / 16.0
        centre = (rng.integers(-1, 2, size=3) / 32.0) * (ext - inner)
        shells.append(box(inner, centre))
    pattern = rng.random() < 0.4                              # R8's other-diagonal pair on a side
    q, offset = _motion(rng, planar=pattern)
    placed = [(v @ q.T + offset, f) for v, f in shells]
    counts = []
    pieces: list[tuple[np.ndarray, bool]] = []                # (faces on the base vertices, with own vertices)
    base_vertices = np.vstack([v for v, _ in placed])
    for k, (_, f) in enumerate(placed):
        ways = [1 if k == 0 else -1] + [int(rng.choice([-1, 1])) for _ in range(int(rng.integers(0, 4)))]
        counts.append(sum(ways))                              # net count, a copy wound outward +1
        for w in ways:
            pieces.append(((f if w > 0 else f[:, ::-1]) + 8 * k, bool(rng.random() < 0.5)))
    for _ in range(int(rng.integers(0, 3))):                  # side faces forwards and backwards: zero chains
        which, other = _SIDES[int(rng.integers(6))]
        side = placed[0][1][list(which)]
        if pattern and rng.random() < 0.7:                    # the other diagonal forwards, the file's backwards
            pieces += [(np.array(other), False), (side[:, ::-1], False)]
        else:
            r = int(rng.integers(1, 3))
            pieces += [(side, False)] * r + [(side[:, ::-1], False)] * r
    vs, fs = [base_vertices], []
    n = len(base_vertices)
    for faces, own in pieces:
        if own:
            used = np.unique(faces)
            remap = np.full(n, -1)
            remap[used] = sum(len(v) for v in vs) + np.arange(len(used))
            vs.append(base_vertices[used])
            fs.append(remap[faces])
        else:
            fs.append(faces)
    faces = np.vstack(fs)
    faces = faces[rng.permutation(len(faces))]
    vertices = np.vstack(vs)
    return vertices, faces, _readings(placed, counts), (ext.tolist(), counts, pattern, float(np.abs(offset).max()))


def _readings(placed, counts) -> list[G.RationalTruth]:
    """The readings of the module docstring, as exact rational moments of the solids they name."""
    pts = [tuple(p) for v, _ in placed for p in v]
    body = [list(map(int, t)) for t in placed[0][1]]
    void = [list(map(int, t + 8)) for t in placed[1][1]] if len(placed) > 1 else []
    kb, kv = counts[0], counts[1] if void else 0
    parts = {(True, True): body, (True, False): body + [t[::-1] for t in void], (False, True): void}
    named: set[tuple[bool, bool]] = set()
    for b, c in ((kb, kv), (int(np.sign(kb)), int(np.sign(kv)))):      # as wound; R0's net counted once
        for turn in (1, -1):                                            # the file as wound; turned whole (R4)
            where = (turn * b >= 1, bool(void) and turn * (b + c) >= 1)  # outside the void, inside it
            if any(where):
                named.add(where if void else (where[0], where[0]))
    if kb != 0:                                                         # R4: nesting by depth
        named.add((True, not (void and kv != 0)))
    elif void and kv != 0:
        named.add((False, True))
    return [G.rational_moments(pts, parts[k]) for k in sorted(named)]


def _judge(vertices, faces, readings, diag) -> str | None:
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            props = mass_properties((vertices, faces), density=1.0)
    except InertiaToolError:
        return None
    label = props.mesh.certificate.kind if props.mesh.certificate is not None else props.mesh.method
    if label not in G.PROVEN + ("estimate",):
        return None
    if not readings:
        return f"{label} {props.mass!r} m³ where the file encloses nothing"
    verdicts = [G.judge_numbers(label, props.mass, props.center_of_mass, props.inertia, props.mesh.uncertainty,
                                truth, diag) for truth in readings]
    if any(v.wrong is None for v in verdicts):
        return None
    return f"{label}: " + " | ".join(str(v.wrong) for v in verdicts)


@settings(max_examples=40, derandomize=True, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(seed=st.integers(0, 2 ** 32 - 1))
def test_copies_combine_by_their_windings(seed):
    vertices, faces, readings, recipe = _draw(seed)
    diag = float(np.linalg.norm(np.ptp(vertices, axis=0)))
    wrong = _judge(vertices, faces, readings, diag)
    assert wrong is None, (wrong, recipe)
