"""STEP assemblies read per part through OpenCASCADE's XCAF document (mesh/cad.py ``step_parts``, read in the
isolated child), against the closed form of boxes (tests/test_assembly_3mf.py ``box_truth``: ρabc, central
moments m(b² + c²)/12, parallel-axis theorem of Chapter 4 "Rigid Body Motion", Eq. (4.16)).

The files are written here with OCP's own XCAF writer (``STEPCAFControl_Writer``, names and materials on), so
the test needs no fixture file; OpenCASCADE writes a material's density in g/cm³.
"""

from __future__ import annotations

import json

import numpy as np
import pytest

pytest.importorskip("OCP")

from inertia_tool import mass_properties  # noqa: E402
from inertia_tool.cli import main  # noqa: E402
from test_assembly_3mf import _check, box_truth  # noqa: E402


def write_step_assembly(path, parts):
    """``parts``: (name, lo mm, hi mm, material or None, density g/cm³ or None), as components of one assembly
    (each box placed by a component location, so the placements are composed by the reader)."""
    from OCP.BRepPrimAPI import BRepPrimAPI_MakeBox
    from OCP.gp import gp_Pnt, gp_Trsf, gp_Vec
    from OCP.Interface import Interface_Static
    from OCP.STEPCAFControl import STEPCAFControl_Writer
    from OCP.STEPControl import STEPControl_AsIs
    from OCP.TCollection import TCollection_ExtendedString, TCollection_HAsciiString
    from OCP.TDataStd import TDataStd_Name
    from OCP.TDocStd import TDocStd_Document
    from OCP.TopLoc import TopLoc_Location
    from OCP.XCAFDoc import XCAFDoc_DocumentTool

    from inertia_tool.mesh.cad import _quiet
    doc = TDocStd_Document(TCollection_ExtendedString("XmlOcaf"))
    shapes = XCAFDoc_DocumentTool.ShapeTool_s(doc.Main())
    materials = XCAFDoc_DocumentTool.MaterialTool_s(doc.Main())
    top = shapes.NewShape()
    TDataStd_Name.Set_s(top, TCollection_ExtendedString("assembly"))
    for name, lo, hi, material, density in parts:
        size = np.subtract(hi, lo)
        label = shapes.AddShape(BRepPrimAPI_MakeBox(gp_Pnt(0, 0, 0), gp_Pnt(*size)).Shape(), False)
        TDataStd_Name.Set_s(label, TCollection_ExtendedString(name))
        if material is not None:
            mat = materials.AddMaterial(TCollection_HAsciiString(material), TCollection_HAsciiString(""),
                                        float(density), TCollection_HAsciiString("density"),
                                        TCollection_HAsciiString("POSITIVE_RATIO_MEASURE"))
            materials.SetMaterial(label, mat)
        move = gp_Trsf()
        move.SetTranslation(gp_Vec(*map(float, lo)))
        shapes.AddComponent(top, label, TopLoc_Location(move))
    shapes.UpdateAssemblies()
    Interface_Static.SetCVal_s("write.step.unit", "MM")
    writer = STEPCAFControl_Writer()
    writer.SetMaterialMode(True)
    writer.SetNameMode(True)
    with _quiet():
        writer.Transfer(doc, STEPControl_AsIs)
        writer.Write(str(path))
    return path


MM = 1e-3


@pytest.mark.slow
def test_two_named_boxes_of_two_materials_against_closed_form(tmp_path, capsys):
    path = write_step_assembly(tmp_path / "pair.step", [("alpha", (0, 0, 0), (10, 10, 10), "steel", 7.85),
                                                        ("beta", (20, 0, 5), (30, 20, 15), "aluminium", 2.7)])
    props = mass_properties(path)
    truth = box_truth([((0, 0, 0), (10 * MM, 10 * MM, 10 * MM), 7850.0),
                       ((20 * MM, 0, 5 * MM), (30 * MM, 20 * MM, 15 * MM), 2700.0)])
    _check(props, truth, rtol=1e-9)
    assert [(b.name, b.material, b.density) for b in props.parts] == [("alpha", "steel", pytest.approx(7850.0)),
                                                                      ("beta", "aluminium", pytest.approx(2700.0))]
    assert main(["analyze", str(path), "--json", "--material-map", "beta=copper"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert [b["name"] for b in data["bodies"]] == ["alpha", "beta"]
    assert data["mass"] == pytest.approx(7.85e-3 + 8.96e-3 * 2, rel=1e-9)


@pytest.mark.slow
def test_parts_with_and_without_materials(tmp_path, capsys):
    """One part without a material takes the default; with none anywhere the solids are one part (fused, the
    exact B-rep), and --material-map has nothing to address."""
    path = write_step_assembly(tmp_path / "half.step", [("left", (0, 0, 0), (10, 10, 10), None, None),
                                                        ("right", (20, 0, 0), (30, 10, 10), "steel", 7.85)])
    assert main(["analyze", str(path)]) == 2
    assert "'left' has no material" in capsys.readouterr().err
    assert main(["analyze", str(path), "--json", "--material", "pla"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert [(b["name"], b["density"]) for b in data["bodies"]] == [("left", 1240.0), ("right", pytest.approx(7850.0))]
    plain = write_step_assembly(tmp_path / "plain.step", [("left", (0, 0, 0), (10, 10, 10), None, None),
                                                          ("right", (20, 0, 0), (30, 10, 10), None, None)])
    assert main(["analyze", str(plain), "--json", "--material", "pla"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["mass"] == pytest.approx(2 * 1.24e-3, rel=1e-9) and "brep" in data
    assert main(["analyze", str(plain), "--material-map", "left=steel"]) == 2
