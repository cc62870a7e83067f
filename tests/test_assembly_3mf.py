"""Multi-material 3MF files read per part (mesh/threemf.py, mesh/slicers.py, mesh/parts.py, mass/materials.py).

Truths: closed forms of boxes (mass ρabc, inertia ρabc(b² + c²)/12 ..., parallel-axis theorem of Chapter 4
"Rigid Body Motion", Eq. (4.16), written out here independently of the package), and spin-it's own numbers for
the file it writes.

Fixtures modelled on the real formats (documented in inertia_tool/mesh/slicers.py):
* PrusaSlicer 2.x: ``Metadata/Slic3r_PE_model.config`` (``<object id>`` / ``<volume firstid lastid>`` with
  ``<metadata type="volume" key="extruder|volume_type|name">``) and ``Metadata/Slic3r_PE.config``
  (``; filament_type = PLA;PETG``, ``; filament_density = 1.24;1.27``), as PrusaSlicer saves a project;
* Bambu Studio 1.x: geometry in ``3D/Objects/object_1.model`` placed by ``<component p:path objectid>``,
  ``Metadata/model_settings.config`` (``<object id>`` / ``<part id subtype>`` with ``<metadata key="extruder">``)
  and ``Metadata/project_settings.config`` (JSON lists ``filament_type``, ``filament_density``).
"""

from __future__ import annotations

import json
import zipfile

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from inertia_tool import mass_properties
from inertia_tool.cli import main
from inertia_tool.errors import MaterialError, NonMaterialVolumeWarning, OverlapWarning, UsageError

CORE = "http://schemas.microsoft.com/3dmanufacturing/core/2015/02"
PRODUCTION = "http://schemas.microsoft.com/3dmanufacturing/production/2015/06"
CONTENT_TYPES = ('<?xml version="1.0" encoding="UTF-8"?><Types xmlns="http://schemas.openxmlformats.org/package/'
                 '2006/content-types"><Default Extension="rels" ContentType="application/vnd.openxmlformats-package.'
                 'relationships+xml"/><Default Extension="model" ContentType="application/vnd.ms-package.'
                 '3dmanufacturing-3dmodel+xml"/></Types>')
RELS = ('<?xml version="1.0" encoding="UTF-8"?><Relationships xmlns="http://schemas.openxmlformats.org/package/2006/'
        'relationships"><Relationship Target="/3D/3dmodel.model" Id="rel0" Type="http://schemas.microsoft.com/'
        '3dmanufacturing/2013/01/3dmodel"/></Relationships>')


def box(lo, hi):
    """Vertices and outward faces of the box [lo, hi]."""
    lo, hi = np.asarray(lo, float), np.asarray(hi, float)
    v = np.array([[x, y, z] for x in (lo[0], hi[0]) for y in (lo[1], hi[1]) for z in (lo[2], hi[2])])
    f = np.array([[0, 1, 3], [0, 3, 2], [4, 6, 7], [4, 7, 5], [0, 4, 5], [0, 5, 1],
                  [2, 3, 7], [2, 7, 6], [0, 2, 6], [0, 6, 4], [1, 5, 7], [1, 7, 3]])
    return v, f


def box_truth(boxes):
    """Mass, centre of mass and inertia about it of boxes ``(lo, hi, density)`` (SI), by closed form: each box
    ρabc with central moments m(b² + c²)/12 ..., moved to the common centre by I + m(|d|²E − d dᵀ)."""
    masses, centres, tensors = [], [], []
    for lo, hi, rho in boxes:
        size = np.asarray(hi, float) - np.asarray(lo, float)
        m = rho * np.prod(size)
        a2, b2, c2 = size ** 2
        masses.append(m)
        centres.append((np.asarray(hi, float) + np.asarray(lo, float)) / 2)
        tensors.append(np.diag([m * (b2 + c2) / 12, m * (a2 + c2) / 12, m * (a2 + b2) / 12]))
    total = sum(masses)
    com = sum(m * c for m, c in zip(masses, centres)) / total
    inertia = np.zeros((3, 3))
    for m, c, t in zip(masses, centres, tensors):
        d = c - com
        inertia += t + m * (d @ d * np.eye(3) - np.outer(d, d))
    return total, com, inertia


def _mesh_xml(v, f, attrs=""):
    verts = "".join(f'<vertex x="{x!r}" y="{y!r}" z="{z!r}"/>' for x, y, z in v.tolist())
    tris = "".join(f'<triangle v1="{a}" v2="{b}" v3="{c}"{attrs}/>' for a, b, c in f.tolist())
    return f"<mesh><vertices>{verts}</vertices><triangles>{tris}</triangles></mesh>"


def write_package(path, model, extra=()):
    with zipfile.ZipFile(path, "w") as z:
        z.writestr("[Content_Types].xml", CONTENT_TYPES)
        z.writestr("_rels/.rels", RELS)
        z.writestr("3D/3dmodel.model", model)
        for name, data in extra:
            z.writestr(name, data)
    return path


def basematerials_3mf(path, boxes, *, names=None, density_attr=True, unit="millimeter"):
    """Boxes (lo, hi in mm, density kg/m³, material) as one object each, with basematerials (core spec §5)."""
    bases = "".join(f'<base name="{mat}" displaycolor="#808080FF"'
                    + (f' it:density="{rho!r}"' if density_attr and rho is not None else "") + "/>"
                    for _, _, rho, mat in boxes)
    objects = []
    for k, (lo, hi, _, _) in enumerate(boxes):
        name = f' name="{names[k]}"' if names else ""
        objects.append(f'<object id="{k + 2}" type="model"{name} pid="1" pindex="{k}">{_mesh_xml(*box(lo, hi))}'
                       "</object>")
    items = "".join(f'<item objectid="{k + 2}"/>' for k in range(len(boxes)))
    model = (f'<?xml version="1.0" encoding="UTF-8"?><model unit="{unit}" xmlns="{CORE}" '
             f'xmlns:it="http://schemas.inertia-tool.org/3mf/density/2026"><resources><basematerials id="1">{bases}'
             f"</basematerials>{''.join(objects)}</resources><build>{items}</build></model>")
    return write_package(path, model)


def _check(props, truth, rtol=1e-12):
    mass, com, inertia = truth
    assert props.mass == pytest.approx(mass, rel=rtol)
    np.testing.assert_allclose(props.center_of_mass, com, rtol=0, atol=rtol * np.abs(com).max() + 1e-18)
    np.testing.assert_allclose(props.inertia, inertia, rtol=0, atol=rtol * np.abs(inertia).max())


# -- core specification: basematerials --------------------------------------------------------------------------

def test_two_cubes_of_basematerials_against_closed_form(tmp_path):
    """A PLA cube (density from the material table) and a steel cube with the density written on its base."""
    path = basematerials_3mf(tmp_path / "two.3mf", [((0, 0, 0), (10, 10, 10), None, "PLA"),
                                                    ((20, 0, 0), (30, 10, 10), 7850.0, "steel")], density_attr=True)
    props = mass_properties(path)
    mm = 1e-3
    truth = box_truth([((0, 0, 0), (10 * mm, 10 * mm, 10 * mm), 1240.0),
                       ((20 * mm, 0, 0), (30 * mm, 10 * mm, 10 * mm), 7850.0)])
    _check(props, truth)
    assert [(b.name, b.material, b.density) for b in props.parts] == [("object 2", "PLA", 1240.0),
                                                                      ("object 3", "steel", 7850.0)]
    # the same file as one material (the old reading) would be 1.24 g + 1.24 g: the materials matter
    assert props.mass == pytest.approx((1.24 + 7.85) * 1e-3, rel=1e-12)


def test_density_written_in_the_file_wins_over_the_table(tmp_path):
    path = basematerials_3mf(tmp_path / "d.3mf", [((0, 0, 0), (10, 10, 10), 1300.0, "PLA")])
    assert mass_properties(path).mass == pytest.approx(1.3e-3, rel=1e-12)


def test_triangle_materials_without_an_object_material(tmp_path):
    """pid/p1 on the triangles only: one material for all of them is the object's; two is refused."""
    v, f = box((0, 0, 0), (10, 10, 10))
    head = (f'<?xml version="1.0" encoding="UTF-8"?><model unit="millimeter" xmlns="{CORE}"><resources>'
            '<basematerials id="5"><base name="abs" displaycolor="#FFFFFF"/><base name="steel" displaycolor="#000"/>'
            '</basematerials><object id="1" type="model">')
    tail = '</object></resources><build><item objectid="1"/></build></model>'
    one = write_package(tmp_path / "one.3mf", head + _mesh_xml(v, f, ' pid="5" p1="0"') + tail)
    assert mass_properties(one).mass == pytest.approx(1.04e-3, rel=1e-12)
    tris = "".join(f'<triangle v1="{a}" v2="{b}" v3="{c}" pid="5" p1="{k % 2}"/>' for k, (a, b, c) in enumerate(f))
    verts = "".join(f'<vertex x="{x}" y="{y}" z="{z}"/>' for x, y, z in v.tolist())
    mixed = write_package(tmp_path / "mixed.3mf", head + f"<mesh><vertices>{verts}</vertices><triangles>{tris}"
                          "</triangles></mesh>" + tail)
    with pytest.raises(Exception, match="several materials on its triangles"):
        mass_properties(mixed)


def test_a_3mf_without_materials_reads_as_before(tmp_path):
    """No material anywhere: one solid of the given density (no parts table), as before."""
    v, f = box((0, 0, 0), (10, 10, 10))
    model = (f'<?xml version="1.0" encoding="UTF-8"?><model unit="millimeter" xmlns="{CORE}"><resources>'
             f'<object id="1" type="model">{_mesh_xml(v, f)}</object></resources>'
             '<build><item objectid="1"/></build></model>')
    path = write_package(tmp_path / "plain.3mf", model)
    props = mass_properties(path, material="steel")
    assert props.mass == pytest.approx(7.85e-3, rel=1e-12) and props.mesh is not None


# -- the material rule and its errors ---------------------------------------------------------------------------

def test_unknown_material_is_exit_2_naming_it_and_the_option(tmp_path, capsys):
    path = basematerials_3mf(tmp_path / "u.3mf", [((0, 0, 0), (10, 10, 10), None, "Unobtainium X")])
    with pytest.raises(MaterialError, match="Unobtainium X"):
        mass_properties(path)
    assert main(["analyze", str(path)]) == 2
    err = capsys.readouterr().err
    assert "Unobtainium X" in err and "--material-map" in err and err.count("\n") == 1
    # mapped: by the material's name, or by the object
    assert main(["analyze", str(path), "--material-map", "unobtainium x=2.5g/cm3", "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["mass"] == pytest.approx(2.5e-3, rel=1e-12)
    assert main(["analyze", str(path), "--material-map", "object 2=steel", "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["mass"] == pytest.approx(7.85e-3, rel=1e-12) and data["bodies"][0]["material"] == "steel"


def test_material_map_by_object_name_overrides_the_file(tmp_path, capsys):
    path = basematerials_3mf(tmp_path / "n.3mf", [((0, 0, 0), (10, 10, 10), 1240.0, "PLA"),
                                                  ((20, 0, 0), (30, 10, 10), 1240.0, "PLA")],
                             names=["body", "weight"])
    assert main(["analyze", str(path), "--material-map", "weight=tungsten", "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert [b["density"] for b in data["bodies"]] == [1240.0, 19300.0]
    assert data["mass"] == pytest.approx(1.24e-3 + 19.3e-3, rel=1e-12)


def test_material_map_entry_matching_nothing_is_refused(tmp_path, capsys):
    path = basematerials_3mf(tmp_path / "t.3mf", [((0, 0, 0), (10, 10, 10), None, "PLA")])
    assert main(["analyze", str(path), "--material-map", "PLAA=steel"]) == 2
    err = capsys.readouterr().err
    assert "PLAA" in err and "PLA" in err
    with pytest.raises(UsageError):
        mass_properties(path, material_map={"nothing": 1000.0})


def test_a_default_that_applies_to_no_part_is_refused(tmp_path, capsys):
    path = basematerials_3mf(tmp_path / "m.3mf", [((0, 0, 0), (10, 10, 10), None, "PLA"),
                                                  ((20, 0, 0), (30, 10, 10), None, "steel")])
    assert main(["analyze", str(path), "--material", "steel"]) == 2
    assert "--material" in capsys.readouterr().err


def test_a_file_of_one_material_takes_the_given_one(tmp_path, capsys):
    """A slicer project in one filament: --material and --density apply to all of it, as to any file."""
    path = basematerials_3mf(tmp_path / "one.3mf", [((0, 0, 0), (10, 10, 10), 1240.0, "PLA"),
                                                    ((20, 0, 0), (30, 10, 10), 1240.0, "PLA")])
    assert mass_properties(path).mass == pytest.approx(2 * 1.24e-3, rel=1e-12)
    assert mass_properties(path, material="steel").mass == pytest.approx(2 * 7.85e-3, rel=1e-12)
    assert main(["analyze", str(path), "--density", "1.1g/cm3", "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["mass"] == pytest.approx(2 * 1.1e-3, rel=1e-12)
    unknown = basematerials_3mf(tmp_path / "unknown.3mf", [((0, 0, 0), (10, 10, 10), None, "Generic Filament")])
    assert mass_properties(unknown, material="petg").mass == pytest.approx(1.27e-3, rel=1e-12)


def test_overlapping_parts_of_different_materials_are_warned_with_the_shared_volume(tmp_path):
    path = basematerials_3mf(tmp_path / "o.3mf", [((0, 0, 0), (10, 10, 10), None, "PLA"),
                                                  ((5, 0, 0), (15, 10, 10), None, "steel")])
    with pytest.warns(OverlapWarning, match=r"share 5e-07 m³ \(50% of the smaller\)"):
        props = mass_properties(path)
    assert props.mass == pytest.approx((1.24 + 7.85) * 1e-3, rel=1e-12)      # summed, as the warning says


def test_touching_parts_are_not_an_overlap(tmp_path, recwarn):
    path = basematerials_3mf(tmp_path / "t.3mf", [((0, 0, 0), (10, 10, 10), None, "PLA"),
                                                  ((10, 0, 0), (20, 10, 10), None, "steel")])
    mass_properties(path)
    assert not [w for w in recwarn if issubclass(w.category, OverlapWarning)]


# -- slicers ----------------------------------------------------------------------------------------------------

def test_prusaslicer_volumes_and_filaments(tmp_path, capsys):
    """One object of three volumes (triangle ranges): a PLA body (extruder 1), a PETG weight (extruder 2) and a
    modifier (not material, left out with a warning)."""
    parts = [box((0, 0, 0), (20, 10, 10)), box((30, 0, 0), (40, 10, 10)), box((0, 0, 0), (5, 5, 5))]
    v = np.vstack([p[0] for p in parts])
    f = np.vstack([p[1] + 8 * k for k, p in enumerate(parts)])
    model = (f'<?xml version="1.0" encoding="UTF-8"?><model unit="millimeter" xml:lang="en-US" xmlns="{CORE}" '
             'xmlns:slic3rpe="http://schemas.slic3r.org/3mf/2017/06"><metadata name="slic3rpe:Version3mf">1'
             f'</metadata><resources><object id="1" type="model">{_mesh_xml(v, f)}</object></resources>'
             '<build><item objectid="1" transform="1 0 0 0 1 0 0 0 1 100 100 0" printable="1"/></build></model>')
    config = ('<?xml version="1.0" encoding="UTF-8"?>\n<config>\n <object id="1" instances_count="1">\n'
              '  <metadata type="object" key="name" value="weighted.stl"/>\n'
              '  <metadata type="object" key="extruder" value="1"/>\n'
              '  <volume firstid="0" lastid="11">\n   <metadata type="volume" key="name" value="body"/>\n'
              '   <metadata type="volume" key="volume_type" value="ModelPart"/>\n'
              '   <metadata type="volume" key="extruder" value="0"/>\n  </volume>\n'
              '  <volume firstid="12" lastid="23">\n   <metadata type="volume" key="name" value="weight"/>\n'
              '   <metadata type="volume" key="volume_type" value="ModelPart"/>\n'
              '   <metadata type="volume" key="extruder" value="2"/>\n  </volume>\n'
              '  <volume firstid="24" lastid="35">\n   <metadata type="volume" key="name" value="denser infill"/>\n'
              '   <metadata type="volume" key="volume_type" value="ParameterModifier"/>\n  </volume>\n'
              ' </object>\n</config>\n')
    settings_ini = ("; generated by PrusaSlicer 2.7.1\n; extruder_colour = #FF8000;#000000\n"
                    "; filament_density = 1.24;1.27\n; filament_type = PLA;PETG\n; layer_height = 0.2\n")
    path = write_package(tmp_path / "prusa.3mf", model, [("Metadata/Slic3r_PE_model.config", config),
                                                          ("Metadata/Slic3r_PE.config", settings_ini)])
    with pytest.warns(NonMaterialVolumeWarning, match="denser infill"):
        props = mass_properties(path)
    mm = 1e-3
    truth = box_truth([((100 * mm, 100 * mm, 0), (120 * mm, 110 * mm, 10 * mm), 1240.0),
                       ((130 * mm, 100 * mm, 0), (140 * mm, 110 * mm, 10 * mm), 1270.0)])
    _check(props, truth)
    assert [(b.name, b.material) for b in props.parts] == [("body", "PLA"), ("weight", "PETG")]
    assert main(["analyze", str(path)]) == 0
    rows = [line.split() for line in capsys.readouterr().out.splitlines()]
    assert ["weight", "PETG", "1270"] in [r[:3] for r in rows] and ["body", "PLA", "1240"] in [r[:3] for r in rows]


def test_bambu_studio_parts_and_filaments(tmp_path):
    """An object of two components in 3D/Objects/object_1.model, parts on extruders 1 and 2."""
    a, b = box((0, 0, 0), (10, 10, 10)), box((0, 0, 20), (10, 10, 30))
    sub = (f'<?xml version="1.0" encoding="UTF-8"?><model unit="millimeter" xmlns="{CORE}"><resources>'
           f'<object id="1" type="model">{_mesh_xml(*a)}</object><object id="2" type="model">{_mesh_xml(*b)}'
           '</object></resources><build/></model>')
    root = (f'<?xml version="1.0" encoding="UTF-8"?><model unit="millimeter" xml:lang="en-US" xmlns="{CORE}" '
            f'xmlns:p="{PRODUCTION}" requiredextensions="p"><resources><object id="3" type="model"><components>'
            '<component p:path="/3D/Objects/object_1.model" objectid="1" transform="1 0 0 0 1 0 0 0 1 0 0 0"/>'
            '<component p:path="/3D/Objects/object_1.model" objectid="2" transform="1 0 0 0 1 0 0 0 1 0 0 0"/>'
            '</components></object></resources><build><item objectid="3" transform="1 0 0 0 1 0 0 0 1 50 50 0"/>'
            '</build></model>')
    settings_xml = ('<?xml version="1.0" encoding="UTF-8"?>\n<config>\n  <object id="3">\n'
                    '    <metadata key="name" value="stack"/>\n    <metadata key="extruder" value="1"/>\n'
                    '    <part id="1" subtype="normal_part">\n      <metadata key="name" value="base"/>\n'
                    '    </part>\n    <part id="2" subtype="normal_part">\n'
                    '      <metadata key="name" value="cap"/>\n      <metadata key="extruder" value="2"/>\n'
                    '    </part>\n  </object>\n</config>\n')
    project = json.dumps({"filament_type": ["PLA", "TPU"], "filament_density": ["1.26", "1.22"],
                          "filament_colour": ["#FFFFFF", "#000000"]})
    path = write_package(tmp_path / "bambu.3mf", root, [("3D/Objects/object_1.model", sub),
                                                        ("Metadata/model_settings.config", settings_xml),
                                                        ("Metadata/project_settings.config", project)])
    props = mass_properties(path)
    mm = 1e-3
    truth = box_truth([((50 * mm, 50 * mm, 0), (60 * mm, 60 * mm, 10 * mm), 1260.0),
                       ((50 * mm, 50 * mm, 20 * mm), (60 * mm, 60 * mm, 30 * mm), 1220.0)])
    _check(props, truth)
    assert [(b.name, b.material, b.density) for b in props.parts] == [("base", "PLA", 1260.0),
                                                                      ("cap", "TPU", 1220.0)]


# -- spin-it's own file -----------------------------------------------------------------------------------------

@pytest.mark.slow
def test_spin_it_two_material_3mf_reads_back_with_its_mass(tmp_path, capsys):
    """Issue 24: spin-it reported 17.08 g and analyze of its file 5.81 g (one density for both objects)."""
    import trimesh
    from test_design_spin_it import asymmetric_top
    v, f = asymmetric_top()
    src = tmp_path / "top.stl"
    trimesh.Trimesh(v * 1000, f, process=False).export(src)
    out = tmp_path / "top.3mf"
    assert main(["spin-it", str(src), "--units", "mm", "--material", "PLA", "--axis", "0,0,1", "--mode", "top",
                 "--pivot", "0,0,0", "--wall", "1.5mm", "--resolution", "24", "--insert", "steel", "--out", str(out),
                 "--json"]) == 0
    after = json.loads(capsys.readouterr().out)["after"]["mass_properties"]
    assert main(["analyze", str(out), "--json"]) == 0
    captured = capsys.readouterr()
    data = json.loads(captured.out)
    assert data["mass"] == pytest.approx(after["mass"], rel=1e-9)
    np.testing.assert_allclose(data["center_of_mass"], after["center_of_mass"], rtol=0, atol=1e-9 * 0.05)
    np.testing.assert_allclose(data["inertia"], after["inertia"], rtol=0, atol=1e-9 * np.abs(after["inertia"]).max())
    assert [(b["material"], b["density"]) for b in data["bodies"]] == [("PLA", 1240.0), ("steel", 7850.0)]
    assert data["warnings"] == []            # the insert touches its pocket: no overlap


@pytest.mark.slow
@pytest.mark.parametrize("insert", [False, True])
def test_spin_it_one_material_3mf_reads_back_with_its_mass(tmp_path, capsys, insert):
    """A 3MF of one material (no --insert, or an insert that did not help: spin-it then keeps the cavity alone)
    carries the material and its density: analyze gave the mass at water's density (21.8 g for 27.0 g of PLA)."""
    out = tmp_path / "top.3mf"
    extra = ["--insert", "steel"] if insert else []
    assert main(["spin-it", "meshes/spinning_top.stl", "--units", "mm", "--material", "PLA", "--axis", "0,0,1",
                 "--mode", "top", "--pivot", "0,0,0", "--wall", "2mm", "--resolution", "24", "--out", str(out),
                 "--json", *extra]) == 0
    body = json.loads(capsys.readouterr().out)
    after = body["after"]["mass_properties"]
    assert main(["analyze", str(out), "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["mass"] == pytest.approx(after["mass"], rel=1e-9)
    expected = [("PLA", 1240.0)] + ([] if body["insert"] is None else [("steel", 7850.0)])
    assert [(b["material"], b["density"]) for b in data["bodies"]] == expected


# -- property: totals of random parts against an independent sum ------------------------------------------------

@settings(max_examples=15, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(st.lists(st.tuples(st.floats(1, 20), st.floats(1, 20), st.floats(1, 20), st.floats(-50, 50),
                          st.floats(-50, 50), st.floats(300, 20000)), min_size=1, max_size=5))
def test_random_parts_total_is_the_independent_sum(tmp_path, boxes):
    """Parts of random sizes, placements and densities, laid apart along x so that none overlap."""
    specs, x = [], 0.0
    for a, b, c, y, z, rho in boxes:
        specs.append(((x, y, z), (x + a, y + b, z + c), rho, f"m{len(specs)}"))
        x += a + 1.0
    path = basematerials_3mf(tmp_path / "r.3mf", specs)
    props = mass_properties(path)
    mm = 1e-3
    truth = box_truth([(np.multiply(lo, mm), np.multiply(hi, mm), rho) for lo, hi, rho, _ in specs])
    _check(props, truth, rtol=1e-10)
    assert len(props.parts) == len(specs)


def test_parts_json_validates_and_declares_every_field(tmp_path, capsys):
    """The parts of a multi-material file in --json: material, density and certificate per body, in the schema."""
    import jsonschema
    from test_json_schema import _errors, _undeclared

    import inertia_tool
    with open(f"{inertia_tool.__path__[0]}/schema/output-v1.json", encoding="utf-8") as fh:
        schema = json.load(fh)
    path = basematerials_3mf(tmp_path / "s.3mf", [((0, 0, 0), (10, 10, 10), None, "PLA"),
                                                  ((20, 0, 0), (30, 10, 10), 7850.0, "steel")], names=["a", "b"])
    assert main(["analyze", str(path), "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert _errors(jsonschema.Draft202012Validator(schema), data) == []
    assert _undeclared(schema, schema["$defs"]["analyze"], data) == []
    assert [(b["name"], b["material"], b["density"], b["certificate"]["kind"]) for b in data["bodies"]] == [
        ("a", "PLA", 1240.0, "exact"), ("b", "steel", 7850.0, "exact")]


def test_prusaslicer_volumes_that_leave_triangles_out_are_refused(tmp_path):
    """Triangles no volume claims would be dropped silently: the file is refused instead."""
    parts = [box((0, 0, 0), (10, 10, 10)), box((20, 0, 0), (30, 10, 10))]
    v = np.vstack([p[0] for p in parts])
    f = np.vstack([p[1] + 8 * k for k, p in enumerate(parts)])
    model = (f'<?xml version="1.0" encoding="UTF-8"?><model unit="millimeter" xmlns="{CORE}"><resources>'
             f'<object id="1" type="model">{_mesh_xml(v, f)}</object></resources>'
             '<build><item objectid="1"/></build></model>')
    config = ('<?xml version="1.0" encoding="UTF-8"?>\n<config>\n <object id="1" instances_count="1">\n'
              '  <volume firstid="0" lastid="11">\n   <metadata type="volume" key="extruder" value="1"/>\n'
              '  </volume>\n </object>\n</config>\n')
    path = write_package(tmp_path / "gap.3mf", model, [("Metadata/Slic3r_PE_model.config", config)])
    with pytest.raises(Exception, match="do not cover its 24 triangles exactly once"):
        mass_properties(path)


def test_a_flood_of_base_materials_is_refused_while_reading(tmp_path):
    bases = '<base name="m" displaycolor="#000"/>' * 200
    v, f = box((0, 0, 0), (10, 10, 10))
    model = (f'<?xml version="1.0" encoding="UTF-8"?><model unit="millimeter" xmlns="{CORE}"><resources>'
             f'<basematerials id="1">{bases}</basematerials><object id="2" type="model" pid="1" pindex="0">'
             f'{_mesh_xml(v, f)}</object></resources><build><item objectid="2"/></build></model>')
    path = write_package(tmp_path / "flood.3mf", model)
    with pytest.raises(Exception, match="base materials"):
        mass_properties(path, max_faces=40)
    assert mass_properties(path, max_faces=100, material_map={"m": 1000.0}).mass == pytest.approx(1e-3)


def test_html_report_lists_the_parts(tmp_path, capsys):
    path = basematerials_3mf(tmp_path / "h.3mf", [((0, 0, 0), (10, 10, 10), None, "PLA"),
                                                  ((20, 0, 0), (30, 10, 10), None, "steel")], names=["a", "b"])
    report = tmp_path / "r.html"
    assert main(["analyze", str(path), "--report", str(report)]) == 0
    html = report.read_text(encoding="utf-8")
    assert "Parts (2)" in html and "<td>steel</td>" in html and "<td>PLA</td>" in html


def test_a_raw_mesh_is_one_solid_of_the_given_density(tmp_path):
    """Robot geometry passes meshes read before at unit density: their parts do not decide."""
    from inertia_tool.mesh.read import load_mesh
    path = basematerials_3mf(tmp_path / "r.3mf", [((0, 0, 0), (10, 10, 10), None, "steel")])
    raw = load_mesh(path)
    assert raw.parts and mass_properties(raw, density=1.0).mass == pytest.approx(1e-6, rel=1e-12)
    with pytest.raises(UsageError, match="material_map"):
        mass_properties(raw, material_map={"steel": 1.0})


def test_batch_row_of_a_multi_material_file(tmp_path, capsys):
    """A batch row of a file integrated part by part: its total, counts added, the parts' certificate."""
    import csv
    folder = tmp_path / "in"
    folder.mkdir()
    basematerials_3mf(folder / "two.3mf", [((0, 0, 0), (10, 10, 10), None, "PLA"),
                                           ((20, 0, 0), (30, 10, 10), None, "steel")])
    out = tmp_path / "rows.csv"
    assert main(["batch", str(folder), "--out", str(out)]) == 0
    with open(out, newline="", encoding="utf-8") as fh:
        (row,) = list(csv.DictReader(fh))
    assert row["status"] == "ok" and float(row["mass"]) == pytest.approx((1.24 + 7.85) * 1e-3, rel=1e-12)
    assert row["certificate"] == "exact" and row["faces"] == "24" and row["bodies"] == "2"
    assert row["density_source"] == "per part (the file's materials)"


def test_overlapping_parts_of_one_material_are_united(tmp_path, recwarn):
    """Two overlapping PLA cubes: their union (15 × 10 × 10 mm), as when the file was read as one solid; a third
    part of another material stays apart."""
    path = basematerials_3mf(tmp_path / "u.3mf", [((0, 0, 0), (10, 10, 10), None, "PLA"),
                                                  ((5, 0, 0), (15, 10, 10), None, "PLA"),
                                                  ((30, 0, 0), (40, 10, 10), None, "steel")], names=["a", "b", "c"])
    props = mass_properties(path)
    mm = 1e-3
    _check(props, box_truth([((0, 0, 0), (15 * mm, 10 * mm, 10 * mm), 1240.0),
                             ((30 * mm, 0, 0), (40 * mm, 10 * mm, 10 * mm), 7850.0)]), rtol=1e-9)
    assert [b.name for b in props.parts] == ["a + b", "c"]
    assert not [w for w in recwarn if issubclass(w.category, OverlapWarning) and "parts overlap" in str(w.message)]


def test_spin_it_refuses_a_file_of_several_materials(tmp_path, capsys):
    """spin-it hollows one material: a multi-material input would be designed as one density, silently."""
    path = basematerials_3mf(tmp_path / "two.3mf", [((0, 0, 0), (10, 10, 10), None, "PLA"),
                                                    ((20, 0, 0), (30, 10, 10), None, "steel")])
    assert main(["spin-it", str(path), "--material", "pla", "--axis", "0,0,1", "--wall", "1mm"]) == 2
    assert "several" in capsys.readouterr().err
