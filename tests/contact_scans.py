"""Helpers shared by the face-pair check's tests (``test_mesh_intersect_*``): the scan run on either path, the
comparison of two scans' pairs, and the fan-capped cylinder those tests build (``solids.fan_capped_cylinder``, which
the benchmarks build too)."""

from __future__ import annotations

import numpy as np
import pytest

from inertia_tool import _native
from inertia_tool.mesh.intersect import SurfaceContacts, surface_contacts
from solids import fan_capped_cylinder

__all__ = ["FIELDS", "run_scan", "same_pairs", "fan_capped_cylinder"]

#: The pair lists of a :class:`SurfaceContacts` that the paths must agree on.
FIELDS = ("crossing", "coplanar_opposite", "contact")


def run_scan(v, f, accel: bool, **kwargs) -> SurfaceContacts:
    """:func:`surface_contacts` on the C path (``accel``) or the numpy twin."""
    with pytest.MonkeyPatch.context() as mp:
        if accel:
            mp.delenv(_native.NO_ACCEL_ENV, raising=False)
        else:
            mp.setenv(_native.NO_ACCEL_ENV, "1")
        return surface_contacts(v, f, **kwargs)


def same_pairs(a: SurfaceContacts, b: SurfaceContacts) -> None:
    """Both scans complete, with the same pairs in every field."""
    assert a.complete and b.complete
    for name in FIELDS:
        assert np.array_equal(getattr(a, name), getattr(b, name)), name
