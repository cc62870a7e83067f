"""Shell labels as int32 (issue 25 item 1: the labels live through the face-pair check, 4 bytes a face instead of
8): the dtype on both engine paths, no widening copy at the C boundary, and every result of ``prepare_mesh``
(labels, faces, shells' moments bit for bit, owners, the report with its certificate, the warnings) identical
to the same analysis run with int64 labels, on scenes of boxes that lie apart, nest, touch and overlap."""

from __future__ import annotations

import warnings
from unittest import mock

import numpy as np
import pytest
from hypothesis import HealthCheck, example, given, settings
from hypothesis import strategies as st

from adversary_solids import box
from inertia_tool import _native
from inertia_tool.errors import InertiaToolError
from inertia_tool.mesh import checks, nonmanifold
from inertia_tool.mesh.checks import census_and_shells, shell_labels
from inertia_tool.mesh.prepare import prepare_mesh
from inertia_tool.mesh.read import RawMesh

pytestmark = pytest.mark.usefixtures("engine_path")


def _scene(boxes):
    """One mesh of axis-aligned boxes ``(lower corner, size, inverted)`` in quarter units."""
    vs, fs, n = [], [], 0
    for lower, size, inverted in boxes:
        lo, ext = 0.25 * np.asarray(lower, float), 0.25 * np.asarray(size, float)
        v, f = box(extents=ext, center=lo + ext / 2)
        vs.append(v)
        fs.append((f[:, ::-1] if inverted else f) + n)
        n += len(v)
    return np.vstack(vs), np.vstack(fs)


def _outcome(v, f):
    """Everything ``prepare_mesh`` says about the mesh, in comparable form."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            p = prepare_mesh(RawMesh(vertices=v, faces=f, source="scene.stl", file_faces=len(f)),
                             repair=False)
        except InertiaToolError as exc:
            return ("refused", type(exc).__name__, str(exc), [str(w.message) for w in caught]), None
    moments = [(s.volume, s.centroid.tobytes(), s.second_moment.tobytes(), s.area, s.zero_area_faces)
               for s in p.shells]
    return (p.labels.tolist(), p.faces.tobytes(), p.vertices.tobytes(), moments, p.owner.tolist(), repr(p.report),
            [str(w.message) for w in caught]), p.labels.dtype


def _as_int64():
    """Patch the label type back to int64, as before issue 25 item 1."""
    wide = mock.patch.object(checks, "label_dtype", lambda n: np.dtype(np.int64))
    wide_welded = mock.patch.object(nonmanifold, "label_dtype", lambda n: np.dtype(np.int64))
    return wide, wide_welded


corner = st.tuples(*[st.integers(0, 6)] * 3)
size = st.tuples(*[st.integers(1, 6)] * 3)
scenes = st.lists(st.tuples(corner, size, st.just(False)), min_size=1, max_size=4)
NESTED = [((0, 0, 0), (6, 6, 6), False), ((2, 2, 2), (2, 2, 2), True), ((2, 2, 2), (1, 1, 1), False)]
TOUCHING = [((0, 0, 0), (2, 2, 2), False), ((2, 0, 0), (2, 2, 2), False), ((4, 2, 2), (1, 1, 1), False)]
CORNER_ONLY = [((0, 0, 0), (2, 2, 2), False), ((2, 2, 2), (2, 2, 2), False)]
OVERLAPPING = [((0, 0, 0), (3, 3, 3), False), ((1, 1, 1), (3, 3, 3), False), ((8, 0, 0), (1, 1, 1), False)]
FLUSH = [((0, 0, 0), (1, 1, 1), False), ((0, 0, 0), (1, 1, 2), False)]     # flush on five faces: one left out (R4)


@settings(max_examples=15, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(boxes=scenes, inverted=st.lists(st.booleans(), min_size=4, max_size=4))
@example(boxes=NESTED, inverted=[False] * 4)
@example(boxes=TOUCHING, inverted=[False] * 4)
@example(boxes=CORNER_ONLY, inverted=[False] * 4)
@example(boxes=OVERLAPPING, inverted=[False] * 4)
@example(boxes=NESTED[:2], inverted=[False, True, False, False])
@example(boxes=[((0, 0, 0), (1, 2, 3), False)], inverted=[False] * 4)
@example(boxes=FLUSH, inverted=[False] * 4)
def test_int32_labels_give_the_int64_results(boxes, inverted):
    boxes = [(lo, sz, inv or flip) for (lo, sz, inv), flip in zip(boxes, inverted)]
    v, f = _scene(boxes)
    narrow = _outcome(v, f)
    wide, wide_welded = _as_int64()
    with wide, wide_welded:
        broad = _outcome(v, f)
    assert broad[0] == narrow[0]
    if narrow[1] is not None:           # not refused: the labels had the type asked for
        assert narrow[1] == np.int32 and broad[1] == np.int64


def test_labels_are_int32_and_reach_c_uncopied():
    v, f = _scene(NESTED + [((9, 0, 0), (1, 2, 3), False)])
    labels, count = shell_labels(f, len(v))
    assert labels.dtype == np.int32 and count == 4
    _, census_labels, census_count = census_and_shells(f, len(v))
    assert census_labels.dtype == np.int32 and census_count == 4
    assert np.array_equal(census_labels, labels)
    assert _native.labels_for_c(labels) is labels
    assert _native.labels_for_c(labels.astype(np.int64)).dtype == np.int64
    assert _native.labels_for_c(labels.astype(np.uint8)).dtype == np.int64      # other types widened, as before
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")         # the small box touches the cavity's wall: said, and not the point
        prepared = prepare_mesh(RawMesh(vertices=v, faces=f, source="scene.stl", file_faces=len(f)))
    assert prepared.labels.dtype == np.int32


def test_label_type_widens_where_int32_ends():
    assert _native.label_dtype(2**31 - 1) == np.int32
    assert _native.label_dtype(2**31) == np.int64


def test_one_shell_holds_no_label_array():
    """One shell: the census's labels are a read-only view of one int32 zero (its buffer goes back to the
    kernels' pool before the check), and the analysis reads them as it read an array of zeros."""
    v, f = box(extents=(1.0, 2.0, 3.0))
    topology, labels, count = census_and_shells(f, len(v))
    assert count == 1 and labels.dtype == np.int32 and labels.shape == (len(f),)
    if _native.accel() is not None:
        assert labels.strides == (0,) and not labels.flags.writeable
    assert np.array_equal(labels, np.zeros(len(f)))
    prepared = prepare_mesh(RawMesh(vertices=v, faces=f, source="box.stl", file_faces=len(f)))
    assert prepared.labels.dtype == np.int32 and prepared.report.certificate.kind == "exact"
    assert prepared.shells[0].volume == pytest.approx(6.0, rel=1e-15)
