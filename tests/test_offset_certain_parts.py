"""``offset._certain_parts`` (the sub-cells of a band cell certainly in or out of the core) against a direct
evaluation of its two Lipschitz tests over every sub-cell and sample at once, on random cells, margins and closest
points; the kernel loops over the samples for speed (a 12-face box's core 8.2 -> 5.6 s CPU) and must decide every
sub-cell the same way."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from inertia_tool.mass import offset

pytestmark = pytest.mark.usefixtures("engine_path")   # the C kernel (_accel.c section 12) and the numpy loop


def _direct(centres, size, depth, margins, closest):
    sub_n = offset._SUB
    rho = 0.5 * np.sqrt(3.0) * size / sub_n
    samples = np.concatenate([np.zeros((1, 3)), offset._CORNER_OFFSETS]) * size                # (9, 3)
    y = centres[:, None, :] + size * offset._SUB_OFFSETS[None]                                  # (k, 64, 3)
    x = centres[:, None, :] + samples[None]                                                     # (k, 9, 3)
    gap = np.linalg.norm(y[:, :, None, :] - x[:, None, :, :], axis=-1)                         # (k, 64, 9)
    core = np.any(margins[:, None, :] - gap >= rho, axis=2)
    out = np.any(-margins[:, None, :] - gap >= rho, axis=2)
    if depth > rho:
        reach = np.linalg.norm(y[:, :, None, :] - closest[:, None, :, :], axis=-1)             # (k, 64, 9)
        out |= np.any(reach + rho <= depth, axis=2)
    return core, out & ~core


@settings(max_examples=40, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), size=st.floats(1e-4, 1e-1), depth_cells=st.floats(0.05, 4.0))
def test_certain_parts_match_the_direct_tests(seed, size, depth_cells):
    rng = np.random.default_rng(seed)
    k = int(rng.integers(1, 300))
    depth = depth_cells * size
    centres = rng.normal(scale=10 * size, size=(k, 3))
    margins = rng.normal(scale=size, size=(k, 9))
    closest = centres[:, None, :] + rng.normal(scale=2 * size, size=(k, 9, 3))
    core, outside = offset._certain_parts(centres, size, depth, None, margins, closest)
    want_core, want_out = _direct(centres, size, depth, margins, closest)
    # the two forms round differently only for a sub-cell whose test lands within a few ulp of its threshold
    assert np.count_nonzero(core != want_core) <= 1e-3 * core.size
    assert np.count_nonzero(outside != want_out) <= 1e-3 * outside.size
    assert not (core & outside).any()
