"""mesh/intersect.py, the numpy twin's grid (``_raw_pairs``) when a certified star's vertex index exceeds the face
count.

The twin leaves out the pairs within a certified star by grouping the faces round each certified vertex (the
group is the vertex's index) and keying each grid entry by (cell rank, group + shift).  With ``shift = m + 1``
(m faces) the keys of one cell ran into the next cell's as soon as a vertex index passed m — an unwelded file,
or vertices no face uses — and a small face querying a larger level's grid got a wrong range of partners: pairs
were missed (a crossing among them) or the count went negative (``ValueError: repeats may not contain negative
values``).  Found on Menagerie's meshes (``agilex_piper/assets/link5_5.obj``: 3 contact pairs missed;
``link2_4.obj``, ``anybotics_anymal_c/assets/thigh.obj``, ``arx_l5/assets/link7.obj``: the error) by
``benchmarks/bench_patches_agree.py``.

The meshes here: large fans of 8 faces round a centre (certified stars, a high level of the grid) on a lattice,
with many small chips (the lowest level) scattered through them, and up to 60,000 unused vertices listed before
them (so every centre's index is far above the face count).  The numpy twin must give the C scan's candidate
count (without patches: the twin's counting) and pairs.
"""

import numpy as np
import pytest
from hypothesis import HealthCheck, example, given, settings
from hypothesis import strategies as st

from conftest import HAVE_ACCEL
from contact_scans import run_scan, same_pairs

pytestmark = pytest.mark.skipif(not HAVE_ACCEL, reason="inertia_tool._accel is not built")


def fans_and_chips(k: int, pad: int, seed: int, sections: int = 8) -> tuple[np.ndarray, np.ndarray]:
    """k x k fans of radius 10, 30 apart in the plane z = 0, and 40·k² chips (triangles 0.1 across, tilted
    through z = 0 or beside it) at random; ``pad`` unused vertices listed first."""
    rng = np.random.default_rng(seed)
    v: list[list[float]] = []
    f: list[list[int]] = []
    t = 2 * np.pi * np.arange(sections) / sections
    for i in range(k):
        for j in range(k):
            c = len(v)
            v.append([30.0 * i, 30.0 * j, 0.0])
            v += [[30.0 * i + 10 * np.cos(a), 30.0 * j + 10 * np.sin(a), 0.0] for a in t]
            f += [[c, c + 1 + x, c + 1 + (x + 1) % sections] for x in range(sections)]
    for _ in range(40 * k * k):
        p = rng.uniform(-10, 30 * k, 2)
        z = rng.uniform(-0.05, 0.05)
        c = len(v)
        v += [[p[0], p[1], z - 0.05], [p[0] + 0.1, p[1], z + 0.05], [p[0], p[1] + 0.1, z + 0.05]]
        f.append([c, c + 1, c + 2])
    pts = np.r_[rng.normal(size=(pad, 3)) * 100, np.array(v)]
    return pts, np.array(f, dtype=np.int64) + pad


@settings(max_examples=12, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.integers(3, 5), st.sampled_from([0, 5, 2000, 60000]), st.integers(0, 2**16))
@example(5, 2000, 1)            # the old grid: negative counts (ValueError)
@example(5, 50000, 0)           # the old grid: one crossing pair of 262 missed
def test_numpy_twin_finds_the_c_pairs_whatever_the_vertex_indices(k, pad, seed):
    v, f = fans_and_chips(k, pad, seed)
    fast = run_scan(v, f, accel=True, _patches=False)
    twin = run_scan(v, f, accel=False)
    same_pairs(fast, twin)
    assert twin.candidate_pairs == fast.candidate_pairs
