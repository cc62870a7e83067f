"""A printed bound is still a bound (``inertia_tool/rounding.py``: :func:`round_up`), and every report that
prints the bounds of a repaired mesh prints numbers no smaller than the ones it stores."""

import re
from decimal import Decimal

import numpy as np
import pytest
import trimesh
from hypothesis import given, settings
from hypothesis import strategies as st

from inertia_tool import mass_properties
from inertia_tool.errors import InvalidMeshError, MeshRepairedWarning
from inertia_tool.integrals import volume_moments
from inertia_tool.mesh.uncertainty import Uncertainty, check_useful
from inertia_tool.reports.html import html_report
from inertia_tool.reports.text import method_line
from inertia_tool.rounding import round_up

# 0 and normal floats (a subnormal bound has fewer significant bits than the digits asked)
FINITE = st.one_of(st.just(0.0), st.floats(min_value=1e-300, max_value=1e300))


@settings(max_examples=400, deadline=None)
@given(x=FINITE, digits=st.integers(1, 8))
def test_printed_value_is_not_below_the_bound_and_is_the_next_decimal_up(x, digits):
    """Read back, the printed number is at least the bound; one step of the last printed digit lower would be
    below it (so the rounding is the smallest that holds, not a generous one)."""
    up = round_up(x, digits)
    text = f"{up:.{digits}g}"
    assert float(text) >= x * (1 + 1e-12)
    assert float(text) == up                         # the float returned prints as exactly the decimal
    if x > 0:
        exact = Decimal(text)
        step = Decimal(1).scaleb(exact.adjusted() - (digits - 1))
        assert float(exact - step) < x * (1 + 1e-12) or exact - step <= 0
    assert round_up(x, digits, rtol=0.0) >= x


@given(x=st.floats(min_value=1e-12, max_value=1e12), digits=st.integers(1, 6))
def test_decimals_already_short_enough_are_unchanged_without_slack(x, digits):
    short = float(f"{x:.{digits - 1}e}")
    assert round_up(short, digits, rtol=0.0) == short


def test_examples_that_rounding_to_nearest_printed_too_low():
    # the OBJ quad warning's case (hypothesis): 14.29 % was printed as 14 %
    assert f"{round_up(14.2857, 2):.2g}" == "15"
    assert f"{round_up(0.012341, 3):.3g}" == "0.0124"
    assert f"{round_up(99.951, 3):.3g}" == "100"
    assert f"{round_up(0.1, 1, rtol=0.0):.1g}" == "0.1"        # an exact decimal stays as it is without slack
    assert f"{round_up(25.0, 2):.2g}" == "26"                   # and is raised one step with it
    assert round_up(0.0) == 0.0
    assert round_up(float("inf")) == float("inf")
    assert np.isnan(round_up(float("nan")))


@pytest.mark.parametrize("bad", [-1e-300, -2.0, float("-inf")])
def test_a_negative_bound_is_an_error_not_a_number(bad):
    with pytest.raises(ValueError, match="expected a bound of at least 0"):
        round_up(bad)


def test_digits_must_be_positive():
    with pytest.raises(ValueError, match="expected at least 1 significant digit"):
        round_up(1.0, 0)


# ---------------------------------------------------------------------------------- reports of a repair

def _capped_sphere():
    """An icosphere with the cap above z = 0.85 removed: a curved hole whose bound is far above round-off."""
    s = trimesh.creation.icosphere(3)
    v, f = np.asarray(s.vertices), np.asarray(s.faces)
    return v, f[~np.all(v[f][:, :, 2] > 0.85, axis=1)]


@pytest.fixture(scope="module")
def repaired():
    v, f = _capped_sphere()
    with pytest.warns(MeshRepairedWarning):
        return mass_properties((v, f), density=1.0, repair=True)


def _numbers(text, pattern):
    return [float(x) for x in re.findall(pattern, text)]


def test_text_report_prints_the_repair_bounds_rounded_up(repaired):
    u = repaired.mesh.uncertainty
    assert u is not None and u.mass > 1e-4
    line = method_line(repaired.mesh)
    mass, inertia = _numbers(line, r"±([0-9.e+-]+)%")
    com, = _numbers(line, r"centre of mass within ([0-9.e+-]+) m")
    assert mass >= 100 * u.mass and inertia >= 100 * u.inertia and com >= u.center_of_mass
    # three digits, the nearest decimal above: within one unit of the third digit
    assert mass <= 100 * u.mass * (1 + 1e-2)


def test_html_report_prints_the_repair_bounds_rounded_up(repaired):
    u = repaired.mesh.uncertainty
    page = html_report(repaired)
    cell = re.search(r"mass ±([0-9.e+-]+)%, centre of mass ([0-9.e+-]+) m, inertia ±([0-9.e+-]+)%", page)
    assert cell is not None
    mass, com, inertia = (float(x) for x in cell.groups())
    assert mass >= 100 * u.mass and com >= u.center_of_mass and inertia >= 100 * u.inertia


@settings(max_examples=60, deadline=None)
@given(mass=st.floats(0.5000001, 50.0), com=st.floats(1e-9, 1e3))
def test_refusal_message_states_the_bound_rounded_up(mass, com):
    unc = Uncertainty(mass=mass, center_of_mass=com, inertia=1.0, volume_in_doubt=1.0)
    with pytest.raises(InvalidMeshError) as caught:
        check_useful(1.0, unc, source="part.stl", what="the patched surface")
    text = str(caught.value)
    printed_mass, = _numbers(text, r"mass ±([0-9.e+-]+) %")
    printed_com, = _numbers(text, r"centre of mass within ([0-9.e+-]+) m")
    assert printed_mass >= 100 * mass and printed_com >= com


def test_patched_bound_is_not_below_the_truth(repaired):
    """The stored bound itself holds for this hole (the printed one is larger still)."""
    v, f = _capped_sphere()
    s = trimesh.creation.icosphere(3)
    truth = volume_moments(np.asarray(s.vertices), np.asarray(s.faces))
    u = repaired.mesh.uncertainty
    assert abs(repaired.volume - truth.volume) <= u.mass * repaired.volume
    assert len(f) < len(s.faces)


@settings(max_examples=200, deadline=None)
@given(distance=st.floats(1e-300, 1e3), volume=st.floats(1e-300, 1e3))
def test_near_copy_note_states_its_distance_and_volume_rounded_up(distance, volume):
    """R0's note for copies up to rounding prints the corner distance and the Steiner volume bound; with
    ``:.3g`` to nearest, 1.2349e-9 m³ read 1.23e-09 m³, below the bound the note claims."""
    from inertia_tool.mesh.policy import NearCopies, near_copies_message
    note = near_copies_message(NearCopies(drop=np.zeros(0, dtype=bool), copies=1, distance=distance,
                                          volume_bound=volume))
    printed_distance = float(re.search(r"within ([0-9.e+-]+) m ", note).group(1))
    printed_volume = float(re.search(r"at most ([0-9.e+-]+) m³", note).group(1))
    assert printed_distance >= distance
    assert printed_volume >= volume
