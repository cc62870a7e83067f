"""The clean-part fast path (``mesh/clean_part.py``, issue 25 item 6) against the full checks it stands in for.

On every generated mesh, clean or adversarial (touching itself, passing through itself, open, inward, with repeated
or reversed faces, non-manifold, two shells, flat, far from the origin), ``mass_properties(..., fast_path=True)``
must give what ``fast_path=False`` gives: the same exception and message, the same warnings in the same order, and
the same numbers to the bit (on the parts it takes, the fast path runs the same functions on the same arrays), and
``prepare_clean`` must either decline without a word or return the full path's ``PreparedMesh`` field for field.
"""

from __future__ import annotations

import dataclasses
import struct
import warnings

import numpy as np
import pytest
from hypothesis import HealthCheck, example, given, settings
from hypothesis import strategies as st

from adversary_solids import box, cylinder, icosphere, torus
from inertia_tool.errors import InertiaToolError
from inertia_tool.mass.pipeline import mass_properties
from inertia_tool.mesh.clean_part import CLEAN_CHECKS, prepare_clean
from inertia_tool.mesh.prepare import prepare_mesh
from inertia_tool.mesh.read import load_mesh


# ------------------------------------------------------------------------------------------------- comparing
def _bits(x, path="value"):
    """A hashable picture of ``x`` to the bit: floats by their IEEE bytes, arrays by dtype, shape and bytes,
    dataclasses field by field (so that +0.0 and -0.0, or two NaNs of different payloads, differ)."""
    if isinstance(x, float):
        return ("f", struct.pack("<d", x))
    if isinstance(x, np.ndarray):
        return ("a", x.dtype.str, x.shape, np.ascontiguousarray(x).tobytes())
    if isinstance(x, np.generic):
        return ("g", x.dtype.str, x.tobytes())
    if dataclasses.is_dataclass(x) and not isinstance(x, type):
        return (type(x).__name__,) + tuple((f.name, _bits(getattr(x, f.name))) for f in dataclasses.fields(x))
    if isinstance(x, (tuple, list)):
        return (type(x).__name__,) + tuple(_bits(y) for y in x)
    return (type(x).__name__, x)


def _run(raw, fast):
    """``(outcome, warnings)`` of ``mass_properties(raw)`` with or without the fast path: the result's bits
    (principal axes included) or the exception's type and message; each warning's category and message."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            props = mass_properties(raw, density=1240.0, fast_path=fast)
            outcome = ("ok", _bits(props), _bits(props.principal))
        except InertiaToolError as exc:
            outcome = ("error", type(exc).__name__, str(exc))
    return outcome, [(w.category.__name__, str(w.message)) for w in caught]


def _check_both_ways(v, f):
    """The fast path against the full one on the mesh ``(v, f)``; returns whether the fast path took it."""
    raw = load_mesh((np.asarray(v, dtype=np.float64), np.asarray(f, dtype=np.int64)))
    assert _run(raw, True) == _run(raw, False)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        quick = prepare_clean(raw)
    assert caught == []                                   # declining or not, the fast path says nothing
    if quick is None:
        return False
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        full = prepare_mesh(raw)
    assert caught == []                                   # a part it takes is one the full path has nothing to say of
    assert _bits(quick) == _bits(full)
    assert quick.report.certificate.kind == "exact" and quick.report.certificate.checks == CLEAN_CHECKS
    return True


# -------------------------------------------------------------------------------------------------- meshes
def _welded(v, f):
    """Vertices at the same coordinates merged (bit for bit), as a file's reader welds them."""
    uniq, inverse = np.unique(v, axis=0, return_inverse=True)
    return uniq, inverse.reshape(-1)[f]


def _piece(kind, size):
    if kind == "box":
        return box((1.0, 0.5 + 0.25 * size, 0.75), subdivide=size % 2)
    if kind == "icosphere":
        return icosphere(0.7, size % 2)
    if kind == "cylinder":
        return cylinder(0.4, 1.0, 5 + 3 * size)
    return torus(0.6, 0.2, 8 + 2 * size, 5 + size)


MUTATIONS = ("none", "inward", "open", "repeated_face", "reversed_face", "twice", "degenerate", "vertex_anywhere",
             "vertex_on_vertex", "vertex_on_face", "vertex_through", "two_apart", "two_sharing_a_corner", "flat",
             "far", "tiny", "sliver")


@st.composite
def meshes(draw):
    """A small piece moved rigidly, then one mutation (``MUTATIONS``)."""
    kind = draw(st.sampled_from(("box", "icosphere", "cylinder", "torus")))
    v, f = _piece(kind, draw(st.integers(0, 2)))
    seed = draw(st.integers(0, 2**32 - 1))
    mutation = draw(st.sampled_from(MUTATIONS))
    rng = np.random.default_rng(seed)
    if rng.random() < 0.5:                                           # a random rotation (coordinates rounded)
        q = rng.normal(size=4)
        w, x, y, z = q / np.linalg.norm(q)
        rot = np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
                        [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
                        [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]])
        v = v @ rot.T
    v = v + rng.integers(-8, 9, size=3) * 0.125
    f = f.copy()
    k = int(rng.integers(len(f)))
    a = int(rng.integers(len(v)))
    if mutation == "inward":
        f = f[:, ::-1].copy()
    elif mutation == "open":
        f = np.delete(f, k, axis=0)
    elif mutation == "repeated_face":
        f = np.vstack([f, f[k:k + 1]])
    elif mutation == "reversed_face":
        f = np.vstack([f, f[k:k + 1, ::-1]])
    elif mutation == "twice":
        f = np.vstack([f, f])
    elif mutation == "degenerate":
        f = np.vstack([f, [[f[k, 0], f[k, 0], f[k, 1]]]])
    elif mutation == "vertex_anywhere":
        v = v.copy()
        v[a] = v.min(0) + rng.random(3) * (v.max(0) - v.min(0))
    elif mutation == "vertex_on_vertex":                             # two corners at one point, not welded
        v = v.copy()
        v[a] = v[int(rng.integers(len(v)))]
    elif mutation == "vertex_on_face":                               # a corner moved onto a face's centroid
        v = v.copy()
        v[a] = v[f[k]].mean(axis=0)
    elif mutation == "vertex_through":                               # a corner pushed through the opposite side
        v = v.copy()
        centre = v.mean(axis=0)
        v[a] = centre + (centre - v[a]) * float(rng.uniform(0.5, 1.5))
    elif mutation == "two_apart":
        span = v.max(0) - v.min(0)
        v, f = np.vstack([v, v + span * 2]), np.vstack([f, f + len(v)])
    elif mutation == "two_sharing_a_corner":                         # welded at one corner: a non-manifold vertex
        top = v[np.argmax(v[:, 2])]
        other = v - v[np.argmin(v[:, 2])] + top
        v, f = _welded(np.vstack([v, other]), np.vstack([f, f + len(v)]))
    elif mutation == "flat":
        v = v.copy()
        v[:, 2] = 0.0
    elif mutation == "far":
        v = v + 1e7
    elif mutation == "tiny":
        v = v * 1e-9
    elif mutation == "sliver":                                       # thin enough for R7 to integrate it again
        v = v * np.array([1.0, 1.0, 10.0 ** -float(rng.uniform(3, 12))]) + 10.0 ** float(rng.uniform(0, 6))
    return v, f


# ---------------------------------------------------------------------------------------------------- tests
@settings(max_examples=50, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(meshes())
@example((box((1.0, 2.0, 3.0))))
@example((torus(0.6, 0.2, 10, 6)))
def test_fast_path_agrees_with_the_full_checks(mesh):
    _check_both_ways(*mesh)


def _tiny_coordinate():
    """A box with a corner coordinate of 1e-300 m (nonzero, below the C face-pair filters' safe range): the fast
    path asks ``surface_contacts`` itself, which scales the coordinates first."""
    v, f = box((1.0, 1.0, 1.0), center=(0.5, 0.5, 0.5))
    v = v.copy()
    v[0, 0] = 1e-300
    return v, f


@pytest.mark.parametrize("piece", [box((1.0, 2.0, 3.0)), box((1.0, 1.0, 1.0), subdivide=1), icosphere(0.5, 1),
                                   cylinder(0.3, 2.0, 24), torus(0.6, 0.2, 12, 6), _tiny_coordinate()])
def test_clean_parts_take_the_fast_path(piece):
    """The parts of a catalogue (closed, outward, one shell, nothing meeting) are the fast path's: not vacuous."""
    assert _check_both_ways(*piece)


def test_a_shell_touching_itself_takes_the_fast_path():
    """A corner of a dented box resting on the opposite face: a contact of the shell with itself (no crossing),
    which no stage of the full path acts on; the fast path takes it and gives the same answer."""
    v, f = box((1.0, 1.0, 1.0), subdivide=1)
    top = int(np.flatnonzero((np.abs(v[:, 0]) < 1e-12) & (np.abs(v[:, 1]) < 1e-12) & (v[:, 2] > 0))[0])
    v = v.copy()
    v[top, 2] = -0.5                                      # the top face's centre pushed down onto the bottom face
    raw = load_mesh((v, f))
    from inertia_tool.mesh.intersect import surface_contacts
    contacts = surface_contacts(raw.vertices, raw.faces)
    assert len(contacts.contact) and not len(contacts.crossing) and not len(contacts.coplanar_opposite)
    assert _check_both_ways(v, f)


@pytest.mark.parametrize("mutation", ["inward", "open", "twice", "vertex_through", "two_apart", "flat"])
def test_other_meshes_go_to_the_full_checks(mutation):
    """Each adversarial kind is declined by the fast path (and answered by the full path, the same either way)."""
    v, f = box((1.0, 1.0, 1.0), subdivide=1)
    if mutation == "inward":
        f = f[:, ::-1].copy()
    elif mutation == "open":
        f = f[1:]
    elif mutation == "twice":
        f = np.vstack([f, f])
    elif mutation == "vertex_through":
        v = v.copy()
        top = int(np.flatnonzero((np.abs(v[:, 0]) < 1e-12) & (np.abs(v[:, 1]) < 1e-12) & (v[:, 2] > 0))[0])
        v[top, 2] = -0.75
    elif mutation == "two_apart":
        v, f = np.vstack([v, v + 3.0]), np.vstack([f, f + len(v)])
    elif mutation == "flat":
        v = v.copy()
        v[:, 2] = 0.0
    assert not _check_both_ways(v, f)
