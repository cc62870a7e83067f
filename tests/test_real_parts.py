"""Issue 24 tried on real prints and CAD parts (provenance: tests/data/README.md, "Real prints and CAD parts").

Each test names the symptom the issue reported on that file and checks it against an independent truth where
one exists (trimesh's inertia of the hollowed mesh, numpy's eigenvectors)."""
import json
import warnings
from pathlib import Path

import numpy as np
import pytest
import trimesh

from inertia_tool import mass_properties
from inertia_tool.cli import main
from inertia_tool.design.verify import spin_it_verified
from inertia_tool.errors import DesignRejectedError, PivotOffPartWarning
from inertia_tool.reports.text import face_count_text

DATA = Path(__file__).parent / "data" / "real_parts"
QUADKNOT = DATA / "quadknot.obj"
FIXED_TOP = DATA / "fixed_top.ply"
REAR_CASE = DATA / "rear_case.stl"


def _degrees_to_nearest_principal(inertia: np.ndarray, axis: np.ndarray) -> float:
    """Angle (degrees) between ``axis`` and the nearest eigenvector of ``inertia`` (numpy, not the package)."""
    _, vectors = np.linalg.eigh(inertia)
    cosines = np.abs(vectors.T @ (axis / np.linalg.norm(axis)))
    return float(np.degrees(np.arccos(min(1.0, cosines.max()))))


@pytest.mark.slow
def test_quadknot_yoyo_does_not_end_off_principal():
    """Issue 24: "on quadknot.obj the yo-yo's spin axis ends 10° off every principal axis" with exit 0.  The
    input's axis (1, 0, 0) lies in its plane of two equal moments (I1 = I2 < I3), so it is not the major axis
    a yo-yo needs.  Read as the file's non-planar quads are split now (shorter diagonal, as MuJoCo does), every
    design's simulated spin wobbles more than the input's: spin-it must refuse, name the major axis, hand
    nothing back and say nothing about "<arrays>" (with the first-corner split a design passed its checks; a
    design handed back must in any case put the axis within 1° of a principal axis: the check below)."""
    axis = np.array([1.0, 0.0, 0.0])
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            result, verdicts = spin_it_verified(str(QUADKNOT), axis=tuple(axis), mode="yoyo", wall=0.002,
                                                units="mm", material="pla", resolution=48)
        except DesignRejectedError as exc:
            message = str(exc)
            assert "major axis" in message and "nothing was written" in message, message
            assert "intermediate" in message or "minor" in message, message
            result = None
    if result is not None:       # a design that passed every check: it must end on a principal axis
        assert verdicts[-1].ok
        hollowed = trimesh.Trimesh(result.vertices, result.faces, process=False)
        assert hollowed.is_watertight and hollowed.volume > 0
        assert _degrees_to_nearest_principal(hollowed.moment_inertia, axis) < 1.0
        np.testing.assert_allclose(result.after.inertia / result.after.density, hollowed.moment_inertia,
                                   rtol=1e-6, atol=1e-9 * np.abs(hollowed.moment_inertia).max())
    texts = [str(w.message) for w in caught]
    assert not any("<arrays>" in t for t in texts), texts
    assert sum("quadrilaterals are not planar" in t for t in texts) >= 1


def test_fixed_top_pivot_warning_said_once_when_a_finer_design_is_rejected():
    """fixed_top.ply is a ring: a pivot at its centre lies in empty space and is warned about, once, although
    resolution 128 designs twice (the first attempt is rejected, 1.19° off the pivot→COM line)."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        result, verdicts = spin_it_verified(str(FIXED_TOP), axis=(0, 1, 0), mode="top", pivot=(0, 0, 0),
                                            wall=0.001, units="mm", material="pla", resolution=128)
    assert len(verdicts) >= 2 and not verdicts[0].ok
    assert sum(issubclass(w.category, PivotOffPartWarning) for w in caught) == 1
    assert not any("<arrays>" in str(w.message) for w in caught)
    # nothing that helps: the part is handed back unchanged
    assert result.after.mass == pytest.approx(result.before.mass, rel=1e-12)


def test_quadknot_face_count_says_the_quads_were_split_not_repaired():
    """quadknot.obj holds 1,440 quads: 2,880 triangles integrated, nothing repaired."""
    props = mass_properties(str(QUADKNOT), density=1240.0, units="mm")
    mesh = props.mesh
    assert mesh is not None and (mesh.file_faces, mesh.faces) == (1440, 2880) and not mesh.repaired
    text = face_count_text(mesh)
    assert "split into triangles" in text and "repair" not in text


def test_html_mesh_table_wraps_its_text_column(tmp_path, capsys):
    """The mesh table's values (certificate, notes) are text: left-aligned and wrapping, so that a long
    certificate is not clipped at 1280 px (seen on rear_case.stl's report)."""
    out = tmp_path / "quadknot.html"
    assert main(["analyze", str(QUADKNOT), "--units", "mm", "--material", "pla", "--report", str(out)]) == 0
    capsys.readouterr()
    html = out.read_text(encoding="utf-8")
    mesh_table = html[html.index("coordinates, converted to m"):]
    assert '<td class="l">exact (edge-balanced' in mesh_table
    assert '<td class="l">2,880 triangles' in mesh_table


@pytest.mark.slow
def test_rear_case_printed_error_estimate_is_finite_and_small(capsys):
    """Issue 24: on rear_case.stl (23 self-crossing face pairs) --shell 1.2mm --infill 20% gave an error
    estimate of "5.88e+12 %".  Now every bound is finite and the mass bound below 10 %; the volumes add up
    (envelope = skin + core; volume = skin + 20 % of the core) and the envelope is the union's volume."""
    code = main(["analyze", str(REAR_CASE), "--units", "mm", "--shell", "1.2mm", "--infill", "20%",
                 "--material", "pla", "--json"])
    assert code == 0
    data = json.loads(capsys.readouterr().out)
    model = data["model"]
    bounds = [model["mass_error_bound"], model["center_of_mass_error_bound"], model["inertia_error_bound"],
              *data["uncertainty"].values()]
    assert all(np.isfinite(b) and b >= 0 for b in bounds)
    assert model["mass_error_bound"] < 0.10 and data["uncertainty"]["mass"] < 0.10
    assert model["envelope_volume"] == pytest.approx(model["skin_volume"] + model["core_volume"], rel=1e-9)
    assert data["volume"] == pytest.approx(model["skin_volume"] + 0.2 * model["core_volume"], rel=1e-9)
    solid = mass_properties(str(REAR_CASE), density=1240.0, units="mm")
    assert model["envelope_volume"] == pytest.approx(solid.volume, rel=1e-9)
    # trimesh sums the crossing shells (counts the doubly enclosed region twice): the union is not larger
    assert solid.volume <= trimesh.load(str(REAR_CASE)).volume * (1 + 1e-9)
