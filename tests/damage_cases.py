"""Cases of the damage benchmark (``benchmarks/damage/coverage.py``) made again in the tests, by their id.

A case id ``SEED-NN-KIND`` names the seed, the source and the damage; :func:`case_row` draws the same random
numbers as the benchmark's run of it (``np.random.default_rng([seed, index, kind, 0])``: quantised a third of the
time, then damaged) and gives the benchmark's verdict on it (``coverage.evaluate``).
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

DAMAGE = Path(__file__).resolve().parents[1] / "benchmarks" / "damage"


def coverage_module():
    """``benchmarks/damage/coverage.py``, imported from its folder (put first on ``sys.path`` for the import)."""
    sys.path.insert(0, str(DAMAGE))
    try:
        import coverage
    finally:
        sys.path.remove(str(DAMAGE))
    return coverage


def damaged(cov, kind, v, f, truth, rng):
    """The benchmark's damage ``kind`` done to ``(v, f)`` with ``rng``, after quantising the coordinates with
    probability ``cov.QUANTISE_SHARE`` (then the truth is the quantised surface's, where it has one): the damaged
    vertices, faces and the truth to judge them by."""
    if rng.random() < cov.QUANTISE_SHARE:
        qv, qf, _ = cov._quantised(v, f, rng, truth["diagonal"])
        qt = cov.truth_of(qv, qf)
        if qt is not None:
            v, f, truth = qv, qf, qt
    dv, df, _ = cov.make_case(kind, v, f, rng, truth["diagonal"])
    return dv, df, truth


def case_row(cov, case, index, v, f):
    """The benchmark's row (``cov.evaluate``) of case ``case`` (``"SEED-NN-KIND"``) made from source number
    ``index`` (its place in the benchmark's list of sources), whose surface is ``(v, f)``."""
    seed, kind = int(case.split("-")[0]), case.split("-", 2)[2]
    truth = cov.truth_of(v, f)
    rng = np.random.default_rng([seed, index, cov.KINDS.index(kind), 0])
    dv, df, truth = damaged(cov, kind, v, f, truth, rng)
    return cov.evaluate(dv, df, truth)
