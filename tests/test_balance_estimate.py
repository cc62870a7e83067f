"""balance on a repaired part (review19): the report says the part is an estimate and by how much its static
unbalance is uncertain, and that bound holds for the closed part the damaged file was made from.

Before review19 the text report verified the corrected repaired surface ("kind balanced, meets G 0.4") with no
word that the part's centre of mass was known to 0.36 mm only: the steel torus below with four faces lost is
left with a true residual static unbalance of 108 g·mm after the correction (181 g·mm with six other faces lost),
where the report said 1e-12 g·mm and G 0.4.
"""

import warnings

import numpy as np
import pytest

trimesh = pytest.importorskip("trimesh")

from inertia_tool import mass_properties  # noqa: E402
from inertia_tool.balancing.rotor import balance, shaft_frame, unbalance_state  # noqa: E402
from inertia_tool.mass.properties import combine, point_mass  # noqa: E402
from inertia_tool.reports.balance import format_balance_text  # noqa: E402


def _torus(offset):
    t = trimesh.creation.torus(0.05, 0.02, major_sections=24, minor_sections=12)
    t.apply_translation(offset)
    return np.asarray(t.vertices), np.asarray(t.faces)


@pytest.mark.parametrize("offset, lost", [((0.002, 0.001, 0.0), [0, 1, 2, 3]),
                                          ((-0.001, 0.003, 0.002), [30, 31]),
                                          ((0.0, 0.0, 0.0), [100, 101, 102, 103, 104, 105])])
def test_repaired_part_states_a_static_unbalance_bound_that_holds(offset, lost):
    v, f = _torus(offset)
    keep = np.setdiff1d(np.arange(len(f)), lost)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        repaired = mass_properties((v, f[keep]), density=7850.0, repair=True)
        true_part = mass_properties((v, f), density=7850.0)
        report = balance(repaired, axis_point=(0, 0, 0), axis_direction=(0, 0, 1), rpm=3000, planes=(-0.01, 0.01),
                         radius=0.04)
    assert repaired.mesh.uncertainty is not None
    bound = report.residual_bound
    assert bound is not None and bound > 0
    frame = shaft_frame((0, 0, 0), (0, 0, 1))
    # before: the true part's static unbalance is within the bound of the one reported
    true_before = unbalance_state(true_part, frame)
    assert np.linalg.norm(true_before.static_unbalance - report.initial.static_unbalance) <= bound
    # after: the true part with the same correction masses
    masses = [point_mass(c.mass, c.position, name="correction") for c in report.corrections]
    true_after = unbalance_state(combine([true_part] + masses), frame)
    assert np.linalg.norm(true_after.static_unbalance) <= bound + 1e-12
    # and the text says so, beside the verification
    text = format_balance_text(report)
    assert "for the repaired surface" in text and "the part is an estimate" in text


def test_exact_part_has_no_bound():
    v, f = _torus((0.002, 0.0, 0.0))
    report = balance(mass_properties((v, f), density=7850.0), axis_point=(0, 0, 0), axis_direction=(0, 0, 1),
                     rpm=3000, planes=(-0.01, 0.01), radius=0.04)
    assert report.residual_bound is None
    assert "repaired surface" not in format_balance_text(report)
