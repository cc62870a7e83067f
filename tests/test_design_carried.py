"""spin-it on a damaged part (review19): the hollowed part is as much an estimate as the repaired part it was cut
from, and its carried bounds (``design.carried``) hold for the true part hollowed by the same cavity.

Before review19 ``spin_it(..., repair=True)`` certified the hollowed part ``exact`` (the exact integral of the
hollowed *repaired* mesh), while the true part so hollowed differs from it as much as the repaired part does from
the true part (the torus below: 6.0e-4 in mass, 1.1e-3 in inertia, labelled ``exact``): its missing surface is as
unknown after the cavity is cut as before.  The truth here: the closed part ``T`` the damaged file was made from,
less the cavity ``C``, whose moments are exactly those of the repaired part less the hollowed one (moments add).
"""

import numpy as np
import pytest

pytest.importorskip("manifold3d")
trimesh = pytest.importorskip("trimesh")

from inertia_tool import mass_properties  # noqa: E402
from inertia_tool.design import spin_it  # noqa: E402
from inertia_tool.tolerances import ROUNDOFF_RTOL  # noqa: E402


def _j(r):
    """``|r|²𝟙 − r rᵀ``: the inertia of a unit point mass at ``r`` about the origin (Eq. 4.16's shift term)."""
    r = np.asarray(r, dtype=float)
    return float(r @ r) * np.eye(3) - np.outer(r, r)


def _about_origin(props):
    """(mass, first moment m·c, inertia about the origin) of a result, additive over solids."""
    c = np.asarray(props.center_of_mass)
    return props.mass, props.mass * c, np.asarray(props.inertia) + props.mass * _j(c)


def _true_hollowed(true_part, before, after):
    """Mass, centre of mass and inertia about it of ``T − C``, with ``C = P − A`` (moments about the origin)."""
    t, p, a = (_about_origin(x) for x in (true_part, before, after))
    mass = t[0] - (p[0] - a[0])
    first = t[1] - (p[1] - a[1])
    inertia_origin = t[2] - (p[2] - a[2])
    com = first / mass
    return mass, com, inertia_origin - mass * _j(com)


def _disc():
    return trimesh.creation.cylinder(radius=0.05, height=0.03, sections=64)


def _torus():
    return trimesh.creation.torus(0.05, 0.02, major_sections=24, minor_sections=12)


def _ball():
    return trimesh.creation.icosphere(subdivisions=2, radius=0.05)


# each loses a few faces whose repair leaves volume in doubt (a cap's fan triangle: ±28 % of the mass; a patch of
# the torus: ±0.5 %; three faces of the ball: ±0.03 %)
@pytest.mark.parametrize("make, lost, resolution",
                         [(_disc, [0], 28), (_torus, [0, 1, 2, 3], 40), (_ball, [0, 1, 2], 28)])
def test_hollowed_repaired_part_is_an_estimate_whose_bounds_hold(make, lost, resolution):
    closed = make()
    keep = np.setdiff1d(np.arange(len(closed.faces)), lost)
    damaged = (np.asarray(closed.vertices), np.asarray(closed.faces)[keep])
    true_part = mass_properties((np.asarray(closed.vertices), np.asarray(closed.faces)), density=1000.0)
    result = spin_it(damaged, axis=(0, 0, 1), wall=0.003, resolution=resolution, repair=True, density=1000.0)
    before, after = result.before, result.after
    assert before.mesh.certificate.kind == "estimate"
    assert result.cavity_volume > 0, "the case must cut a cavity to test anything"
    # the label: the hollowed part is an estimate, with the repaired part's assumptions, never exact
    assert after.mesh.certificate.kind == "estimate"
    assert after.mesh.certificate.assumptions == before.mesh.certificate.assumptions
    assert after.mesh.uncertainty is not None and after.mesh.method == before.mesh.method
    # the bounds hold for the true part hollowed by the same cavity
    mass, com, inertia = _true_hollowed(true_part, before, after)
    unc = after.mesh.uncertainty
    assert abs(mass - after.mass) <= unc.mass * after.mass
    assert np.linalg.norm(com - after.center_of_mass) <= unc.center_of_mass
    assert np.linalg.norm(inertia - after.inertia) <= unc.inertia * np.linalg.norm(after.inertia)
    # and they say something: each within a few times the repaired part's own
    assert unc.mass <= 4 * before.mesh.uncertainty.mass * before.volume / after.volume + 2 * ROUNDOFF_RTOL
    assert unc.volume_in_doubt == before.mesh.uncertainty.volume_in_doubt


def test_closed_part_hollowed_stays_exact():
    closed = _disc()
    result = spin_it((np.asarray(closed.vertices), np.asarray(closed.faces)), axis=(0, 0, 1), wall=0.003,
                     resolution=28, density=1000.0)
    assert result.after.mesh.certificate.kind == "exact" and result.after.mesh.uncertainty is None
