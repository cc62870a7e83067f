"""robot: a primitive fitted to a mesh that only ``--repair`` integrates is an estimate with the mass bound that
follows from the mesh's bounds (:func:`fitted_mass_bound`), or ``unverified`` with no uncertainty where that bound
is past ±50 %, and the text table and ``--json`` say the same (robots10; robots7 saw arx_l5's ``link2``
"repaired (patched, an estimate)" in the warnings beside ``unverified`` and no bound)."""

import json
import re

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from inertia_tool.cli import main
from inertia_tool.mass.properties import MassProperties
from inertia_tool.mesh.uncertainty import Uncertainty
from inertia_tool.robot.description import GeometryElement
from inertia_tool.robot.geometry import element_mass_properties, fitted_mass_bound


def _holed_box(path):
    """A 0.1 m box, each side split 8 × 8, one of its 768 triangles missing: a bounded patched estimate."""
    import trimesh
    from conftest import write_binary_stl
    box = trimesh.creation.box(extents=(0.1, 0.1, 0.1)).subdivide().subdivide().subdivide()
    write_binary_stl(path, np.asarray(box.vertices), np.asarray(box.faces)[:-1])


def _table_methods(text):
    """link name → the method column of the text table."""
    rows = text.split("\n---")[1].split("\n\n")[0].strip().splitlines()[1:] if "\n---" in text else []
    head = text.split("\n---")[0].splitlines()[-1]
    assert head.startswith("link")
    return {row.split()[0]: row.split()[1] for row in rows if row.strip()}


def test_fitted_primitive_on_an_estimate_says_the_same_in_table_and_json(tmp_path, capsys):
    _holed_box(tmp_path / "open.stl")
    import trimesh
    from conftest import write_binary_stl
    box = trimesh.creation.box(extents=(0.1, 0.1, 0.1))
    write_binary_stl(tmp_path / "whole.stl", np.asarray(box.vertices), np.asarray(box.faces))
    xml = tmp_path / "robot.xml"
    xml.write_text('<mujoco><asset><mesh name="m" file="open.stl"/><mesh name="w" file="whole.stl"/></asset>'
                   '<worldbody><body name="fitted"><geom type="capsule" mesh="m"/></body>'
                   '<body name="truth"><geom type="capsule" mesh="w"/></body>'
                   '<body name="plain"><geom type="mesh" mesh="m"/></body></worldbody></mujoco>')
    argv = ["robot", str(xml), "--density", "model", "--repair"]
    assert main(argv) == 0
    text = capsys.readouterr().out
    assert main([*argv, "--json"]) == 0
    links = {link["name"]: link for link in json.loads(capsys.readouterr().out)["links"]}
    table = _table_methods(text)
    assert table == {name: link["method"] for name, link in links.items()}
    assert links["plain"]["method"] == "estimate" and links["plain"]["uncertainty"]["mass"] > 0
    fitted, truth = links["fitted"], links["truth"]
    assert fitted["method"] == "estimate" and truth["method"] == "exact"
    bound = fitted["uncertainty"]
    assert bound["inertia"] is None and abs(fitted["mass"] - truth["mass"]) <= bound["mass"] * fitted["mass"]
    shift = np.linalg.norm(np.subtract(fitted["center_of_mass"], truth["center_of_mass"]))
    assert shift <= bound["center_of_mass"] + 1e-15           # (round-off of two integrations of a 0.1 m box)
    notes = [w for w in fitted["warnings"] if "is fitted to open.stl" in w]
    assert len(notes) == 1 and "mass follows within" in notes[0]
    assert re.search(r"volume ±[0-9.e+-]+ %, inertia ±[0-9.e+-]+ %", notes[0])
    assert f"fitted: {notes[0]}" in " ".join(text.split())      # the same sentence in the text warnings
    assert not any("is fitted to" in w for w in links["plain"]["warnings"])


def _fit_volume(kind, tensor, volume, fit_scale):
    """MuJoCo's inertia-box fit (half-sizes from the sorted principal moments) and the fitted primitive's volume
    from the closed forms of ``element_mass_properties`` (an independent path for the volume)."""
    m = np.linalg.eigvalsh(0.5 * (tensor + tensor.T))[::-1]
    half = np.sqrt(np.maximum(0.0, 3.0 * np.array([m[1] + m[2] - m[0], m[0] + m[2] - m[1], m[0] + m[1] - m[2]])
                              / (2.0 * volume))) * fit_scale
    if kind == "sphere":
        size = (float(np.mean(half)),)
    elif kind in ("cylinder", "capsule"):
        r = 0.5 * (half[0] + half[1])
        size = (r, 2.0 * (half[2] if kind == "cylinder" else max(0.0, half[2] - 0.5 * r)))
    else:
        size = tuple(2.0 * half) if kind == "box" else tuple(half)
    if min(size) <= 0:
        return 0.0 if kind != "capsule" or size[0] <= 0 else 4.0 / 3.0 * np.pi * size[0] ** 3
    return element_mass_properties(GeometryElement(kind, np.eye(3), np.zeros(3), size=size)).volume


@settings(max_examples=150, deadline=None)
@given(kind=st.sampled_from(["box", "sphere", "cylinder", "capsule", "ellipsoid"]),
       extents=st.lists(st.floats(0.02, 0.5), min_size=3, max_size=3),
       mass_rtol=st.floats(0.0, 0.3), inertia_rtol=st.floats(0.0, 0.3), fit_scale=st.floats(0.5, 2.0),
       seed=st.integers(0, 2 ** 32 - 1), extreme=st.booleans(),
       signs=st.tuples(*[st.sampled_from([-1.0, 1.0])] * 3) | st.none())
def test_fitted_mass_bound_holds_for_every_truth_within_the_mesh_bounds(kind, extents, mass_rtol, inertia_rtol,
                                                                        fit_scale, seed, extreme, signs):
    # the estimated mesh: a box's unit-density integrals (nearly equal moments allowed: any extents); the truth:
    # any volume and tensor the estimate's bounds allow — random in the ball, or on its surface (``extreme``)
    # along a random direction, or along the principal axes with moments moved by ±δ/√3 each (``signs``: the
    # errors that move some s_k = I_i + I_j − I_k by the most, √3 δ), where a wrong derivation fails first
    rng = np.random.default_rng(seed)
    a, b, c = extents
    volume = a * b * c
    tensor = volume / 12.0 * np.diag([b * b + c * c, a * a + c * c, a * a + b * b])
    rotation = np.linalg.qr(rng.normal(size=(3, 3)))[0]
    tensor = rotation @ tensor @ rotation.T
    mesh = MassProperties(mass=volume, volume=volume, center_of_mass=np.zeros(3), inertia=tensor,
                          surface_area=1.0, density=1.0)
    bounds = Uncertainty(mass=mass_rtol, center_of_mass=0.0, inertia=inertia_rtol, volume_in_doubt=mass_rtol * volume)
    element = GeometryElement(kind, np.eye(3), np.zeros(3), mesh="m.stl", fit_scale=fit_scale)
    bound = fitted_mass_bound(element, mesh, bounds)
    assert bound is not None
    estimate = _fit_volume(kind, tensor, volume, fit_scale)
    if signs is None:
        direction = rng.normal(size=(3, 3))
        direction = 0.5 * (direction + direction.T)
    else:
        _, axes = np.linalg.eigh(tensor)
        direction = axes @ np.diag(signs) @ axes.T
    direction /= np.linalg.norm(direction)
    scale = 1.0 if extreme else rng.uniform()
    true_tensor = tensor + scale * inertia_rtol * np.linalg.norm(tensor) * direction
    true_volume = volume * (1.0 + (rng.choice([-1.0, 1.0]) if extreme else rng.uniform(-1, 1)) * mass_rtol)
    truth = _fit_volume(kind, true_tensor, true_volume, fit_scale)
    assert abs(truth - estimate) <= bound * estimate * (1 + 1e-9) + 1e-15


def test_a_fit_to_a_loosely_bounded_mesh_stays_unverified_and_says_why():
    from inertia_tool.robot.geometry import _fitted_estimate_note
    tensor = np.diag([2.0, 2.0, 1.0]) * 1e-3
    mesh = MassProperties(mass=1.0, volume=1.0, center_of_mass=np.zeros(3), inertia=tensor, surface_area=1.0,
                          density=1.0)
    element = GeometryElement("capsule", np.eye(3), np.zeros(3), mesh="m.stl", fit_scale=1.0, name="c")
    loose = Uncertainty(mass=0.25, center_of_mass=0.1, inertia=1.0, volume_in_doubt=0.25)
    bound = fitted_mass_bound(element, mesh, loose)
    assert bound is not None and bound > 0.5
    note = _fitted_estimate_note(element, loose, bound)
    assert "past the ±50 % at which an estimate is given, hence 'unverified'" in note
    assert fitted_mass_bound(element, mesh, Uncertainty(mass=1.0, center_of_mass=0.1, inertia=0.1,
                                                        volume_in_doubt=1.0)) is None
    with pytest.raises(AssertionError):      # the bound is not vacuous: a tensor far outside it breaks it
        _check_outside(element, mesh)


def _check_outside(element, mesh):
    tight = Uncertainty(mass=0.0, center_of_mass=0.0, inertia=0.01, volume_in_doubt=0.0)
    bound = fitted_mass_bound(element, mesh, tight)
    estimate = _fit_volume("capsule", mesh.inertia, mesh.volume, 1.0)
    truth = _fit_volume("capsule", mesh.inertia * 1.5, mesh.volume, 1.0)
    assert abs(truth - estimate) <= bound * estimate
