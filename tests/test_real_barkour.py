"""A real self-crossing part answered (issue 23): MuJoCo Menagerie's Barkour v0 ``upper_right_2.stl``.

The file's surface passes through itself (a pleat: a fan of four faces crossing at a tiny angle) and lists four
triangles twice, once each way.  It was refused ("could not be certified") until the arrangement cancelled the
reversed pairs and labelled uncertain patches by exact rays (``mesh/arrange.py``; docs/robots.md, "Barkour v0
``upper_right_2.stl``: answered").  This is its regression test on the file as published.

Independent truth: a Monte Carlo over 600,000 points with libigl's exact winding number (run once, recorded in
docs/robots.md): the solid {w ≥ 1} has volume 6.4071e-5 ± 0.033e-5 m³, and the summed signed volume (which counts
the region of w = 2 twice) exceeds it by 1.68e-7 ± 0.17e-7 m³.  Both are checked within 3 σ; the second is the
sharp one: counting the doubled region twice gives a difference of 0, dropping it twice 3.4e-7.
"""

from __future__ import annotations

import gzip
import shutil
import warnings
from pathlib import Path

import numpy as np
import pytest

from inertia_tool import mass_properties

DATA = Path(__file__).parent / "data"


@pytest.fixture(scope="module")
def barkour_stl(tmp_path_factory: pytest.TempPathFactory) -> Path:
    path = tmp_path_factory.mktemp("barkour") / "upper_right_2.stl"
    with gzip.open(DATA / "menagerie_barkour_v0_upper_right_2.stl.gz", "rb") as src, open(path, "wb") as dst:
        shutil.copyfileobj(src, dst)
    return path


def _summed_signed_volume(path: Path) -> float:
    """Σ det(a, b, c)/6 over the file's triangles as written (binary STL read by hand, no welding)."""
    raw = path.read_bytes()
    n = int(np.frombuffer(raw, dtype="<u4", count=1, offset=80)[0])
    rec = np.dtype([("normal", "<f4", 3), ("v", "<f4", (3, 3)), ("attr", "<u2")])
    tri = np.frombuffer(raw, dtype=rec, count=n, offset=84)["v"].astype(np.float64)
    return float(np.sum(np.einsum("ij,ij->i", tri[:, 0], np.cross(tri[:, 1], tri[:, 2]))) / 6.0)


@pytest.mark.parametrize("repair", [False, True])
def test_barkour_upper_right_2_is_answered_within_the_monte_carlo_truth(barkour_stl: Path, repair: bool) -> None:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        props = mass_properties(str(barkour_stl), density=1.0, repair=repair)
    assert props.mesh.certificate.kind != "exact"
    sigma_v, mc_v = 0.033e-5, 6.4071e-5
    assert abs(props.volume - mc_v) < 3 * sigma_v
    doubled = _summed_signed_volume(barkour_stl) - props.volume
    assert abs(doubled - 1.68e-7) < 3 * 0.17e-7, doubled
