"""Helpers shared by the face-pair check's tests (``test_mesh_intersect_*``): the scan run on either path, the
comparison of two scans' pairs, and the fan-capped cylinder those tests build (as CAD exports tessellate one)."""

from __future__ import annotations

import numpy as np
import pytest

from inertia_tool import _native
from inertia_tool.mesh.intersect import SurfaceContacts, surface_contacts

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


def fan_capped_cylinder(n: int, radius: float = 1.0, height: float = 2.0) -> tuple[np.ndarray, np.ndarray]:
    """A closed cylinder of ``n`` sections with fan caps round a centre vertex at each end, outward."""
    t = 2 * np.pi * np.arange(n) / n
    ring = np.stack([radius * np.cos(t), radius * np.sin(t)], axis=1)
    v = np.concatenate([np.c_[ring, np.zeros(n)], np.c_[ring, np.full(n, height)], [[0, 0, 0], [0, 0, height]]])
    i = np.arange(n)
    j = (i + 1) % n
    bottom, top = np.full(n, 2 * n), np.full(n, 2 * n + 1)
    f = np.concatenate([np.stack([bottom, j, i], 1), np.stack([top, n + i, n + j], 1),
                        np.stack([i, j, n + j], 1), np.stack([i, n + j, n + i], 1)])
    return v, f
