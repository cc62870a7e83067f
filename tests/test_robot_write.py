"""Corrected descriptions (inertia_tool.robot.write and its tokenizer inertia_tool.robot.xmlspans), checked by
loading them in MuJoCo and Pinocchio, by reading them back, and against the input node by node."""

import os
import re

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from lxml import etree

from inertia_tool.cli import main
from inertia_tool.errors import OutputCheckError, UsageError
from inertia_tool.robot import audit_links, link_inertials, read_robot
from inertia_tool.robot import write as write_module
from inertia_tool.robot.write import corrected_document, write_corrected
from inertia_tool.robot.xmlspans import XMLSpanError, decode_document, element_spans

from conftest import assert_tensor_close
from robot_data import PACKAGES, PANDA, PANDA_MESHES, UR5, UR5_MESHES

ROBOTS = {"ur5": (UR5, UR5_MESHES), "panda": (PANDA, PANDA_MESHES)}


def _corrected(name, tmp_path, **basis):
    path, _ = ROBOTS[name]
    robot = read_robot(path, packages=PACKAGES)
    inertials = link_inertials(robot, **(basis or {"keep_mass": True}))
    out = tmp_path / f"{name}_fixed.urdf"
    write_corrected(robot, inertials, out)
    return robot, {r.name: r.properties for r in inertials if r.properties is not None}, out


def _mujoco_model(urdf, meshes):
    """Load a URDF in MuJoCo: meshes from ``meshes`` (path stripped), no fusing of fixed links, no balancing."""
    mujoco = pytest.importorskip("mujoco")
    text = urdf.read_text()
    compiler = (f'<mujoco><compiler meshdir="{meshes}" strippath="true" fusestatic="false" discardvisual="true" '
                'balanceinertia="false"/></mujoco>')
    text = re.sub(r"(<robot[^>]*>)", lambda m: m.group(1) + compiler, text, count=1)
    return mujoco, mujoco.MjModel.from_xml_string(text)


@pytest.mark.parametrize("name", ["ur5", "panda"])
def test_written_urdf_loads_in_mujoco_with_the_computed_inertias(name, tmp_path):
    robot, ours, out = _corrected(name, tmp_path)
    mujoco, model = _mujoco_model(out, ROBOTS[name][1])
    assert len(ours) >= 7
    for link, props in ours.items():
        i = model.body(link).id
        assert model.body_mass[i] == pytest.approx(props.mass, rel=1e-12)
        np.testing.assert_allclose(model.body_ipos[i], props.center_of_mass, atol=1e-12)
        # MuJoCo diagonalises: principal moments, and the full tensor rebuilt from body_iquat
        np.testing.assert_allclose(np.sort(model.body_inertia[i]), props.principal.moments, rtol=1e-12)
        rot = np.zeros(9)
        mujoco.mju_quat2Mat(rot, model.body_iquat[i])
        rot = rot.reshape(3, 3)
        assert_tensor_close(rot @ np.diag(model.body_inertia[i]) @ rot.T, props.inertia, 1e-12)


def test_written_urdf_gives_pinocchio_the_same_inertias(tmp_path):
    pin = pytest.importorskip("pinocchio", reason="Pinocchio (pip package `pin`) is not installed")
    robot, ours, out = _corrected("ur5", tmp_path)
    model = pin.buildModelFromUrdf(str(out))
    checked = 0
    for link, props in ours.items():
        if not model.existJointName(_joint_of(robot, link)):
            continue
        inertia = model.inertias[model.getJointId(_joint_of(robot, link))]
        assert inertia.mass == pytest.approx(props.mass, rel=1e-12)
        np.testing.assert_allclose(inertia.lever, props.center_of_mass, atol=1e-12)
        assert_tensor_close(inertia.inertia, props.inertia, 1e-12)
        checked += 1
    assert checked == 6          # the six moving links of the UR5 (each the only body of its joint)


def _joint_of(robot, link):
    tree = etree.fromstring(robot.document)
    for joint in tree.findall("joint"):
        if joint.find("child").get("link") == link and joint.get("type") != "fixed":
            return joint.get("name")
    return ""


def _without_inertials(data: bytes) -> bytes:
    tree = etree.fromstring(data)
    for inertial in tree.iter("inertial"):
        inertial.getparent().remove(inertial)
    for comment in tree.xpath("/*/comment()[contains(., 'inertia-tool robot')]"):
        comment.getparent().remove(comment)
    return etree.tostring(tree, method="c14n")


def _outside_inertials(data: bytes) -> bytes:
    """The bytes with every <inertial>…</inertial> and the provenance comment cut out."""
    data = re.sub(rb"[ \t]*<!-- inertia-tool robot:.*?-->\r?\n", b"", data, flags=re.S)
    return re.sub(rb"\r?\n[ \t]*(?:<inertial\b[^>]*/>|<inertial\b.*?</inertial>)", b"", data, flags=re.S)


@pytest.mark.parametrize("name", ["ur5", "panda"])
def test_every_byte_outside_the_inertials_is_kept(name, tmp_path):
    robot, ours, out = _corrected(name, tmp_path)
    original, written = ROBOTS[name][0].read_bytes(), out.read_bytes()
    assert _outside_inertials(original) == _outside_inertials(written)
    assert _without_inertials(original) == _without_inertials(written)        # and as XML, canonically
    assert len(written.splitlines()) == len(original.splitlines()) + 1        # the provenance comment


def test_missing_inertials_are_inserted_in_the_style_of_the_file(tmp_path):
    mujoco = pytest.importorskip("mujoco")
    urdf = tmp_path / "r.urdf"
    urdf.write_text('<?xml version="1.0"?>\n<robot name=\'r\'>\n    <!-- a comment, kept -->\n    <link name=\'a\'>\n'
                    '        <collision>\n            <geometry><box size=\'0.1 0.2 0.3\' /></geometry>\n'
                    '        </collision>\n    </link>\n    <link name="b"/>\n</robot>\n')
    robot = read_robot(urdf)
    inertials = link_inertials(robot, density=1000)
    text = corrected_document(robot, inertials).decode()
    assert "<box size='0.1 0.2 0.3' />" in text and "<!-- a comment, kept -->" in text
    assert "\n        <inertial>\n            <origin" in text
    assert text.endswith("    </link>\n    <link name=\"b\"/>\n</robot>\n")
    declared = read_robot_from_text(tmp_path, text).link("a").declared
    assert declared.mass == pytest.approx(1000 * 0.006)
    mjcf = tmp_path / "m.xml"
    mjcf.write_text('<mujoco>\n  <worldbody>\n    <body name="b">\n      <freejoint/>\n'
                    '      <geom type="sphere" size="0.1"/>\n    </body>\n  </worldbody>\n</mujoco>\n')
    robot = read_robot(mjcf)
    text = corrected_document(robot, link_inertials(robot, density=1000)).decode()
    assert '<body name="b">\n      <inertial pos="0.0 0.0 0.0" mass=' in text
    model = mujoco.MjModel.from_xml_string(text)
    assert model.body_mass[1] == pytest.approx(1000 * 4 / 3 * np.pi * 0.001, rel=1e-14)


def read_robot_from_text(directory, text):
    path = directory / "again.urdf"
    path.write_text(text)
    return read_robot(path)


def test_corrected_values_read_back_as_declared(tmp_path):
    robot, ours, out = _corrected("panda", tmp_path, material="aluminium")
    again = read_robot(out, packages=PACKAGES)
    for link, props in ours.items():
        declared = again.link(link).declared
        assert declared.mass == props.mass
        np.testing.assert_array_equal(declared.rotation, np.eye(3))
        np.testing.assert_allclose(declared.center_of_mass, props.center_of_mass, rtol=0, atol=1e-15)
        assert_tensor_close(declared.inertia, props.inertia, 1e-15)


def test_sdf_and_mjcf_are_corrected_in_their_own_syntax(tmp_path):
    mujoco = pytest.importorskip("mujoco")
    sdf = tmp_path / "m.sdf"
    sdf.write_text('<?xml version="1.0"?>\n<sdf version="1.7"><model name="m"><link name="l">'
                   '<collision name="c"><pose>0.1 0 0 0 0.3 0</pose><geometry><box><size>0.1 0.2 0.3</size></box>'
                   '</geometry></collision></link></model></sdf>\n')
    mjcf = tmp_path / "m.xml"
    mjcf.write_text('<mujoco model="m"><compiler angle="radian"/><worldbody><body name="b"><freejoint/>'
                    '<inertial pos="0 0 0" quat="1 0 0 0" mass="1" diaginertia="1 1 1"/>'
                    '<geom type="box" size="0.05 0.1 0.15" pos="0.1 0 0" euler="0 0.3 0"/></body></worldbody></mujoco>')
    for path in (sdf, mjcf):
        robot = read_robot(path)
        inertials = link_inertials(robot, density=2700)
        out = tmp_path / f"fixed_{path.name}"
        write_corrected(robot, inertials, out)
        props = inertials[0].properties
        declared = read_robot(out).links[0].declared
        assert declared.mass == props.mass
        assert_tensor_close(declared.inertia, props.inertia, 1e-15)
    model = mujoco.MjModel.from_xml_path(str(tmp_path / "fixed_m.xml"))
    assert model.body_mass[1] == pytest.approx(props.mass, rel=1e-14)


def test_never_overwrites_without_force_and_leaves_no_temporary_file(tmp_path):
    robot = read_robot(UR5, packages=PACKAGES)
    inertials = link_inertials(robot, keep_mass=True)
    out = tmp_path / "out.urdf"
    out.write_text("keep me")
    with pytest.raises(UsageError, match="exists"):
        write_corrected(robot, inertials, out)
    assert out.read_text() == "keep me"
    write_corrected(robot, inertials, out, force=True)
    assert out.read_bytes() == corrected_document(robot, inertials)
    assert os.listdir(tmp_path) == ["out.urdf"]
    copy = tmp_path / "copy.urdf"
    copy.write_bytes(UR5.read_bytes())
    robot_copy = read_robot(copy, packages=PACKAGES)
    with pytest.raises(UsageError, match="is the input description"):
        write_corrected(robot_copy, inertials, copy)


def test_real_sdf_is_corrected_in_place(tmp_path):
    from robot_data import CASSIE_SDF
    robot = read_robot(CASSIE_SDF)
    inertials = link_inertials(robot, keep_mass=True)
    out = tmp_path / "cassie_fixed.sdf"
    write_corrected(robot, inertials, out)
    assert _outside_inertials(CASSIE_SDF.read_bytes()) == _outside_inertials(out.read_bytes())
    again = read_robot(out)
    for result in inertials:
        if result.properties is None:
            continue
        declared = again.link(result.name).declared
        assert declared.mass == result.properties.mass
        np.testing.assert_allclose(declared.center_of_mass, result.properties.center_of_mass, rtol=0, atol=1e-15)
        assert_tensor_close(declared.inertia, result.properties.inertia, 1e-15)


def test_real_mjcf_gets_inertials_inserted_and_reads_back(tmp_path):
    # Gymnasium's humanoid has no <inertial> (MuJoCo infers them): each body gets one, first, indented
    from robot_data import GYM
    source = GYM / "humanoid.xml"
    robot = read_robot(source)
    inertials = link_inertials(robot, density=1000)
    out = tmp_path / "humanoid.xml"
    write_corrected(robot, inertials, out)
    assert _outside_inertials(source.read_bytes()) == _outside_inertials(out.read_bytes())
    again = read_robot(out)
    for result in inertials:
        declared = again.link(result.name).declared
        assert declared.mass == result.properties.mass
        assert_tensor_close(declared.inertia, result.properties.inertia, 1e-15)


# -- issue 22: the edit never deletes or garbles anything outside the corrected <inertial> elements ------------

_PARSER = dict(remove_blank_text=False, remove_comments=False, resolve_entities=False, no_network=True)
_OLD_INERTIAL = ('<inertial><mass value="1"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/>'
                 '</inertial{space}>')
_BOX_LINK = ('  <link name="{name}">\n    {inertial}\n'
             '    <collision><geometry><box size="0.1 0.2 0.3"/></geometry></collision>\n  </link>\n')


def _tree(data: bytes):
    return etree.fromstring(data, etree.XMLParser(**_PARSER)).getroottree()


def _structure(tree, fmt: str) -> list:
    """Everything in the document except each link's first <inertial> and the provenance comment, as a list
    of (depth, kind, name, attributes, stripped text, stripped tail) — computed here, independently of
    inertia_tool.robot.write.  A removed node's tail joins the text before it."""
    root = tree.getroot()
    container = "body" if fmt == "mjcf" else "link"
    dropped = [c.find("inertial") for c in root.iter(container) if c.find("inertial") is not None]
    dropped += [c for c in root if isinstance(c, etree._Comment) and "inertia-tool robot:" in (c.text or "")]
    for node in dropped:
        parent, previous = node.getparent(), node.getprevious()
        if previous is not None:
            previous.tail = (previous.tail or "") + (node.tail or "")
        else:
            parent.text = (parent.text or "") + (node.tail or "")
        parent.remove(node)
    rows = []

    def visit(node, depth):
        if isinstance(node, etree._Comment):
            kind, name = "comment", None
        elif isinstance(node, etree._ProcessingInstruction):
            kind, name = "pi", node.target
        elif isinstance(node, etree._Entity):
            kind, name = "entity", node.name
        else:
            kind, name = "element", node.tag
        attrs = tuple(node.attrib.items()) if kind == "element" else ()
        rows.append((depth, kind, name, attrs, (node.text or "").strip(), (node.tail or "").strip()))
        if kind == "element":
            for child in node:
                visit(child, depth + 1)
    visit(root, 0)
    return rows


def _check_copy(source, out, fmt: str, inertials) -> None:
    """``out`` parses, holds everything of ``source`` outside the corrected inertials, and declares the
    computed values exactly."""
    before, after = _tree(source.read_bytes()), _tree(out.read_bytes())
    assert _structure(before, fmt) == _structure(after, fmt)
    assert before.docinfo.doctype == after.docinfo.doctype
    assert before.docinfo.encoding == after.docinfo.encoding
    again = read_robot(out)
    for result in inertials:
        if result.properties is None:
            continue
        declared = again.link(result.name).declared
        assert declared.mass == result.properties.mass
        np.testing.assert_array_equal(declared.rotation, np.eye(3))
        np.testing.assert_allclose(declared.center_of_mass, result.properties.center_of_mass, rtol=0, atol=1e-15)
        assert_tensor_close(declared.inertia, result.properties.inertia, 1e-15)


def test_inertial_end_tag_with_a_space_keeps_the_next_link(tmp_path, capsys):
    """Before: `</inertial >` was not found, the edit ran to the next link's `</inertial>` and deleted link b's
    start and its <collision> (exit 0, "corrected")."""
    urdf = tmp_path / "r.urdf"
    urdf.write_text('<robot name="r">\n' + _BOX_LINK.format(name="a", inertial=_OLD_INERTIAL.format(space=" "))
                    + _BOX_LINK.format(name="b", inertial=_OLD_INERTIAL.format(space="")) + "</robot>\n")
    out = tmp_path / "out.urdf"
    assert main(["robot", str(urdf), "--density", "1000", "--write", str(out)]) == 0
    capsys.readouterr()
    written = out.read_text()
    assert written.count("<collision>") == 2 and written.count("<link ") == 2
    robot = read_robot(urdf)
    _check_copy(urdf, out, "urdf", link_inertials(robot, density=1000))


def test_two_inertial_end_tags_with_spaces_give_well_formed_xml(tmp_path, capsys):
    """Before: two such links gave XML that does not parse."""
    urdf = tmp_path / "r.urdf"
    urdf.write_text('<robot name="r">\n' + "".join(
        _BOX_LINK.format(name=n, inertial=_OLD_INERTIAL.format(space=space)) for n, space in
        (("a", " "), ("b", " \t\n "), ("c", ""))) + "</robot>\n")
    out = tmp_path / "out.urdf"
    assert main(["robot", str(urdf), "--density", "1000", "--write", str(out)]) == 0
    assert "of 3 links corrected" in capsys.readouterr().err
    robot = read_robot(urdf)
    _check_copy(urdf, out, "urdf", link_inertials(robot, density=1000))


def test_notation_and_entities_in_the_doctype_are_kept_byte_for_byte(tmp_path, capsys):
    """Before: a NOTATION (or any '>' inside the internal subset) broke the prolog and the output."""
    prolog = ('<?xml version="1.0"?>\n<!DOCTYPE robot [\n  <!NOTATION png SYSTEM "image/png">\n'
              '  <!ENTITY note "a > b ] c">\n  <!ENTITY unused "</inertial>">\n  <!-- ]> <inertial> -->\n]>\n')
    urdf = tmp_path / "r.urdf"
    urdf.write_text(prolog + '<robot name="r">&note;\n' + _BOX_LINK.format(name="a", inertial="") + "</robot>\n")
    out = tmp_path / "out.urdf"
    assert main(["robot", str(urdf), "--density", "1000", "--write", str(out)]) == 0
    capsys.readouterr()
    assert out.read_text().startswith(prolog + '<robot name="r">')
    assert "&note;" in out.read_text()
    _check_copy(urdf, out, "urdf", link_inertials(read_robot(urdf), density=1000))


def test_latin1_file_stays_latin1(tmp_path, capsys):
    """Before: a Latin-1 file was serialised as UTF-8 bytes under its Latin-1 declaration: `café` became
    `cafÃ©`."""
    urdf = tmp_path / "r.urdf"
    text = ('<?xml version="1.0" encoding="ISO-8859-1"?>\n<!-- café, señor -->\n<robot name="r">\n'
            + _BOX_LINK.format(name="café", inertial="") + "</robot>\n")
    urdf.write_bytes(text.encode("latin-1"))
    out = tmp_path / "out.urdf"
    assert main(["robot", str(urdf), "--density", "1000", "--write", str(out)]) == 0
    capsys.readouterr()
    data = out.read_bytes()
    assert b'<link name="caf\xe9">' in data and b"\xc3" not in data
    assert data.startswith(text.split("<robot")[0].encode("latin-1"))
    assert read_robot(out).links[0].name == "café"
    _check_copy(urdf, out, "urdf", link_inertials(read_robot(urdf), density=1000))


@pytest.mark.parametrize("bom, codec", [(b"\xef\xbb\xbf", "utf-8"), (b"\xff\xfe", "utf-16-le"),
                                        (b"\xfe\xff", "utf-16-be"), (b"", "utf-16-le")])
def test_bom_and_utf16_are_kept(tmp_path, bom, codec):
    urdf = tmp_path / "r.urdf"
    declared = ' encoding="UTF-16"' if "16" in codec else ""
    text = f'<?xml version="1.0"{declared}?>\n<robot name="r">\n' + _BOX_LINK.format(name="ä", inertial="") + \
        "</robot>\n"
    urdf.write_bytes(bom + text.encode(codec))
    robot = read_robot(urdf)
    inertials = link_inertials(robot, density=1000)
    out = tmp_path / "out.urdf"
    write_corrected(robot, inertials, out)
    data = out.read_bytes()
    assert data.startswith(bom + text.split("<robot")[0].encode(codec))
    assert data[len(bom):].decode(codec).count("</inertial>") == 1
    _check_copy(urdf, out, "urdf", inertials)


def test_write_with_an_empty_name_is_a_usage_error(tmp_path, capsys):
    """Before: `--write ''` was silently ignored (exit 0, nothing written)."""
    urdf = tmp_path / "r.urdf"
    urdf.write_text('<robot name="r">\n' + _BOX_LINK.format(name="a", inertial="") + "</robot>\n")
    assert main(["robot", str(urdf), "--density", "1000", "--write", ""]) == 2
    err = capsys.readouterr().err
    assert "--write expects the name of the file" in err and len(err.strip().splitlines()) == 1
    assert sorted(os.listdir(tmp_path)) == ["r.urdf"]
    with pytest.raises(UsageError, match="file name"):
        write_corrected(read_robot(urdf), [], "")


def test_a_copy_that_fails_its_check_is_not_written(tmp_path, monkeypatch, capsys):
    """The check before the rename catches a wrong splice (here: offsets forced one element off) and nothing is
    written; the command exits 1 (an internal error, as docs/usage.md says)."""
    urdf = tmp_path / "r.urdf"
    urdf.write_text('<robot name="r">\n' + _BOX_LINK.format(name="a", inertial=_OLD_INERTIAL.format(space=""))
                    + "</robot>\n")
    real = write_module.element_spans

    def one_off(text):
        spans = real(text)
        k = next(i for i, s in enumerate(spans) if s.tag == "inertial")
        return spans[:k] + [spans[k + 1]] + [spans[k]] + spans[k + 2:]       # <inertial> swapped with <mass>
    monkeypatch.setattr(write_module, "element_spans", one_off)
    out = tmp_path / "out.urdf"
    with pytest.raises(OutputCheckError, match="nothing was written"):
        corrected_document(read_robot(urdf), link_inertials(read_robot(urdf), density=1000))
    monkeypatch.setattr(write_module, "_check_alignment", lambda *a: None)   # the check after the splice
    assert main(["robot", str(urdf), "--density", "1000", "--write", str(out)]) == 1
    err = capsys.readouterr().err
    assert "differs from the input" in err and "nothing was written" in err
    assert sorted(os.listdir(tmp_path)) == ["r.urdf"]


def test_xacro_output_is_the_indented_expansion(tmp_path):
    """xacro's expansion is one line (issue 23); the corrected copy is indented.  The description is built as
    read_robot builds it for a xacro file (format "xacro", document = the expansion), so the test does not
    depend on how, or whether, xacro is run."""
    import dataclasses
    one_line = ('<?xml version="1.0" ?><robot name="r"><link name="a"><collision><geometry><box size="0.1 0.2 0.3"/>'
                '</geometry></collision></link><link name="b"><collision><geometry><sphere radius="0.1"/>'
                '</geometry></collision></link></robot>')
    urdf = tmp_path / "expanded.urdf"
    urdf.write_text(one_line)
    robot = dataclasses.replace(read_robot(urdf), format="xacro", source=str(tmp_path / "r.urdf.xacro"))
    inertials = link_inertials(robot, density=1000)
    out = tmp_path / "out.urdf"
    write_corrected(robot, inertials, out)
    lines = out.read_text().splitlines()
    assert len(lines) > 10 and max(len(line) for line in lines if "<!--" not in line) < 200
    assert any(line.startswith("    <collision>") for line in lines)
    again = read_robot(out)
    assert [link.name for link in again.links] == ["a", "b"]
    assert all(a.ok for a in audit_links(again, link_inertials(again, density=1000)))
    assert _structure(_tree(one_line.encode()), "urdf") == _structure(_tree(out.read_bytes()), "urdf")


@pytest.mark.parametrize("name, basis", [("ur5", {"material": "aluminium"}), ("panda", {"density": 2000}),
                                         ("ur5", {"keep_mass": True})])
def test_real_robots_written_then_read_back_have_a_clean_audit(name, basis, tmp_path):
    robot, ours, out = _corrected(name, tmp_path, **basis)
    again = read_robot(out, packages=PACKAGES)
    inertials = link_inertials(again, **basis)
    audits = audit_links(again, inertials, keep_mass=basis.get("keep_mass", False))
    assert len(audits) >= 7
    assert [a.issues for a in audits if a.computed is not None and not a.ok] == []
    before, after = _tree(ROBOTS[name][0].read_bytes()), _tree(out.read_bytes())
    assert _structure(before, "urdf") == _structure(after, "urdf")


# -- the writer: output.py ---------------------------------------------------------------------------

def _simple_robot(tmp_path):
    urdf = tmp_path / "in" / "r.urdf"
    urdf.parent.mkdir()
    urdf.write_text('<robot name="r">\n' + _BOX_LINK.format(name="a", inertial="") + "</robot>\n")
    robot = read_robot(urdf)
    return robot, link_inertials(robot, density=1000)


def test_write_refuses_a_symlink_target_even_with_force(tmp_path, capsys):
    """Before: `os.replace` onto the name was preceded by no check, and the old writer's temporary name was
    predictable; a link planted at the target is now refused and the file it points to is untouched."""
    robot, inertials = _simple_robot(tmp_path)
    victim = tmp_path / "victim.txt"
    victim.write_text("precious")
    link = tmp_path / "out.urdf"
    link.symlink_to(victim)
    for force in (False, True):
        with pytest.raises(UsageError, match="symbolic link"):
            write_corrected(robot, inertials, link, force=force)
    assert main(["robot", robot.source, "--density", "1000", "--write", str(link), "--force"]) == 2
    assert "symbolic link" in capsys.readouterr().err
    assert victim.read_text() == "precious" and link.is_symlink()
    assert sorted(os.listdir(tmp_path)) == ["in", "out.urdf", "victim.txt"]


def test_write_ignores_links_planted_at_the_old_predictable_temporary_names(tmp_path):
    """Before: the temporary file was `.OUT.tmp-PID`, opened with a plain open(): a symbolic link planted there
    sent the corrected document into the file it named."""
    robot, inertials = _simple_robot(tmp_path)
    victim = tmp_path / "victim.txt"
    victim.write_text("precious")
    out = tmp_path / "out.urdf"
    for pid in {os.getpid(), *range(os.getpid() - 3, os.getpid() + 4)}:
        (tmp_path / f".out.urdf.tmp-{pid}").symlink_to(victim)
    write_corrected(robot, inertials, out)
    assert victim.read_text() == "precious"
    assert read_robot(out).links[0].declared.mass == inertials[0].properties.mass
    leftovers = [p for p in os.listdir(tmp_path) if p.startswith(".") and not os.path.islink(tmp_path / p)]
    assert leftovers == []


# -- the tokenizer -------------------------------------------------------------------------------------------

def test_tokenizer_finds_exact_element_offsets():
    text = ('<?xml version="1.0"?>\n<!DOCTYPE r [<!ENTITY e "<x>"><!NOTATION n PUBLIC "a>]" "b">]>\n'
            '<r a=\'x>"y\'><!-- <inertial> --><![CDATA[</r><inertial>]]><i  b="&gt;>" /><j>t</j\n ></r >\n')
    spans = element_spans(text)
    assert [(s.tag, s.depth) for s in spans] == [("r", 0), ("i", 1), ("j", 1)]
    assert text[spans[0].start:spans[0].end].endswith("</r >") and text[spans[0].end:] == "\n"
    assert text[spans[1].start:spans[1].end] == '<i  b="&gt;>" />' and spans[1].empty
    assert text[spans[2].start:spans[2].end] == "<j>t</j\n >"
    assert text[spans[2].start_end:spans[2].close] == "t"


def test_tokenizer_uses_xml_whitespace_not_unicode_whitespace():
    """U+1680 (Ogham space mark) is a name character in XML 1.0 and whitespace to Python's ``\\s``."""
    text = '<r><x\u1680y a="1"/><link\u1680 name="a"></link\u1680></r>'
    assert [s.tag for s in element_spans(text)] == ["r", "x\u1680y", "link\u1680"]
    assert [e.tag for e in _tree(text.encode()).getroot().iter()] == ["r", "x\u1680y", "link\u1680"]


@pytest.mark.parametrize("bad", ["<r><a></b></r>", "<r>", "<r a='1></r>", "<!DOCTYPE r [<!ENTITY e 'x'>",
                                 "<r><!-- open</r>"])
def test_tokenizer_refuses_what_it_cannot_follow(bad):
    with pytest.raises(XMLSpanError):
        element_spans(bad)


def test_decode_document_follows_bom_then_declaration():
    assert decode_document(b'\xef\xbb\xbf<?xml version="1.0" encoding="latin-1"?><a/>').codec == "utf-8"
    assert decode_document('<?xml version="1.0" encoding="ISO-8859-1"?><a>é</a>'.encode("latin-1")).text.endswith(
        "é</a>")
    assert decode_document("<?xml version='1.0'?><a/>".encode("utf-16-be")).codec == "utf-16-be"
    with pytest.raises(XMLSpanError, match="not one Python"):
        decode_document(b'<?xml version="1.0" encoding="no-such-codec"?><a/>')


# -- property: random formatting, random encodings ----------------------------------------------------------

_WS = st.sampled_from(["", " ", "  ", "\t", "\n", "\n  ", " \r\n "])
_SIZES = st.tuples(*[st.sampled_from([0.05, 0.1, 0.2, 0.37]) for _ in range(3)])
_DECOYS = st.sampled_from([
    "<!-- <inertial><mass value='9'/></inertial> -->",
    "<![CDATA[ <inertial> </link> ]]>",
    "<?pi <inertial> ?>",
    "<!-- </link> -->",
    "",
])
_ENCODINGS = st.sampled_from([("utf-8", b""), ("utf-8", b"\xef\xbb\xbf"), ("latin-1", b""),
                              ("utf-16-le", b"\xff\xfe"), ("utf-16-be", b"\xfe\xff"), ("utf-16-le", b"")])
_DOCTYPES = st.sampled_from([
    "",
    '<!DOCTYPE {root} [\n  <!NOTATION gif SYSTEM "viewer > gif">\n  <!ENTITY who "a ]> b">\n]>\n',
    "<!DOCTYPE {root} [ <!-- ]> --> <!ELEMENT link ANY> <!ATTLIST link name CDATA #IMPLIED> ]>\n",
])


@st.composite
def _documents(draw):
    fmt = draw(st.sampled_from(["urdf", "sdf", "mjcf"]))
    links = []
    for k in range(draw(st.integers(1, 3))):
        name = draw(st.sampled_from(["l", "é", "a>b", "q\"x"])) + str(k)
        links.append((name, draw(_SIZES), draw(st.booleans()), draw(_WS), draw(_DECOYS), draw(_WS)))
    quote = draw(st.sampled_from(['"', "'"]))
    return fmt, links, quote, draw(_ENCODINGS), draw(_DOCTYPES), draw(_WS), draw(st.sampled_from(["\n", "\r\n"]))


def _attr(value: str, quote: str) -> str:
    value = value.replace("&", "&amp;").replace("<", "&lt;").replace(quote, "&quot;" if quote == '"' else "&apos;")
    return f"{quote}{value}{quote}"


def _render(fmt, links, quote, ws_tail) -> tuple[str, str]:
    """(root tag, body text) of a description with one box per link, formatted as drawn."""
    parts = []
    for name, (a, b, c), has, ws, decoy, ws2 in links:
        n = _attr(name, quote)
        if fmt == "urdf":
            old = (f"<inertial {' ' if ws else ''}><mass value={quote}2{quote}/><inertia ixx='1' ixy='0' ixz='0' "
                   f"iyy='1' iyz='0' izz='1'/></inertial{ws}>") if has else ""
            parts.append(f"<link name={n}{ws}>{decoy}{old}{ws2}<collision note={quote}x > y{quote}><geometry>"
                         f"<box size='{a} {b} {c}'{ws}/></geometry></collision{ws}>{decoy}</link{ws}>")
        elif fmt == "sdf":
            old = (f"<inertial><mass>2</mass><inertia><ixx>1</ixx><iyy>1</iyy><izz>1</izz></inertia>"
                   f"</inertial{ws}>") if has else ""
            parts.append(f"<link name={n}>{ws2}{decoy}<collision name='c'><pose>0.1 0 0 0 0 0</pose><geometry><box>"
                         f"<size>{a} {b} {c}</size></box></geometry></collision{ws}>{old}{decoy}</link{ws}>")
        else:
            old = (f"<inertial pos='0 0 0' mass='2' diaginertia='1 1 1'{ws}/>" if ws else
                   "<inertial pos='0 0 0' mass='2' diaginertia='1 1 1'></inertial >") if has else ""
            parts.append(f"<body name={n}>{ws2}{old}{decoy}<geom type='box' size='{a / 2} {b / 2} {c / 2}' "
                         f"pos='0 0.1 0'{ws}/>{decoy}</body{ws}>")
    sep = "\n  " if ws_tail else ""
    body = sep + sep.join(parts) + ("\n" if ws_tail else "")
    if fmt == "urdf":
        return "robot", f"<robot name='r'>{body}</robot>"
    if fmt == "sdf":
        return "sdf", f"<sdf version='1.7'><model name='m'>{body}</model></sdf>"
    return "mujoco", f"<mujoco model='m'><worldbody>{body}</worldbody></mujoco>"


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(document=_documents())
def test_random_formatting_and_encodings_round_trip(document, tmp_path_factory):
    fmt, links, quote, (codec, bom), doctype, ws_tail, newline = document
    root, body = _render(fmt, links, quote, ws_tail)
    label = {"utf-8": "UTF-8", "latin-1": "ISO-8859-1"}.get(codec, "UTF-16")
    prolog = f"<?xml version={quote}1.0{quote} encoding={quote}{label}{quote}?>\n" + doctype.format(root=root)
    text = prolog + "<!-- before the root: <inertial> -->\n" + body + "\n<!-- after -->\n"
    text, prolog = text.replace("\r\n", "\n").replace("\n", newline), prolog.replace("\n", newline)
    directory = tmp_path_factory.mktemp("doc")
    source = directory / ("r.urdf" if fmt == "urdf" else "r.sdf" if fmt == "sdf" else "r.xml")
    source.write_bytes(bom + text.encode(codec))
    robot = read_robot(source)
    inertials = link_inertials(robot, density=1000)
    out = directory / ("out" + source.suffix)
    write_corrected(robot, inertials, out)
    data = out.read_bytes()
    assert data.startswith(bom + prolog.encode(codec))                       # declaration, DOCTYPE, BOM kept
    assert data.endswith(f"{newline}<!-- after -->{newline}".encode(codec))
    if newline == "\r\n":                                   # no bare line feed added by the edit
        assert data.decode(codec).count("\n") == data.decode(codec).count("\r\n")
    _check_copy(source, out, fmt, inertials)


@settings(max_examples=80, deadline=None)
@given(document=_documents())
def test_tokenizer_agrees_with_lxml_on_every_element(document):
    """Independent truth: lxml's element order, names and lines (libxml2's ``sourceline`` is the line where the
    start tag ends) against the spans."""
    fmt, links, quote, (codec, bom), doctype, ws_tail, newline = document
    root, body = _render(fmt, links, quote, ws_tail)
    text = (doctype.format(root=root) + "<!-- <inertial> -->" + body).replace("\r\n", "\n").replace("\n", newline)
    spans = element_spans(text)
    elements = list(_tree(text.encode("utf-8")).getroot().iter(tag=etree.Element))
    assert [s.tag for s in spans] == [e.tag for e in elements]
    assert [text.count("\n", 0, s.start_end - 1) + 1 for s in spans] == [e.sourceline for e in elements]
    for span, element in zip(spans, elements):
        written = text[span.start:span.end]
        assert written.startswith(f"<{span.tag}") and written.endswith("/>" if span.empty else ">")
        if not span.empty:
            assert re.fullmatch(rf"</{re.escape(span.tag)}\s*>", text[span.close:span.end])
            assert text[span.start_end:span.close].count("<") >= len(element)


def test_force_corrects_the_input_in_place_and_a_second_run_changes_nothing(tmp_path, capsys):
    urdf = tmp_path / "r.urdf"
    urdf.write_text('<robot name="r">\n' + _BOX_LINK.format(name="a", inertial=_OLD_INERTIAL.format(space=" ")) +
                    "</robot>\n")
    original = urdf.read_bytes()
    assert main(["robot", str(urdf), "--density", "1000", "--write", str(urdf)]) == 2
    assert "is the input description" in capsys.readouterr().err and urdf.read_bytes() == original
    assert main(["robot", str(urdf), "--density", "1000", "--write", str(urdf), "--force"]) == 0
    once = urdf.read_bytes()
    assert once != original and os.listdir(tmp_path) == ["r.urdf"]
    robot = read_robot(urdf)
    assert all(a.ok for a in audit_links(robot, link_inertials(robot, density=1000)))
    assert main(["robot", str(urdf), "--density", "1000", "--write", str(urdf), "--force"]) == 0
    assert urdf.read_bytes() == once            # the provenance comment of the first run is replaced, not added
    assert main(["robot", str(urdf), "--density", "2000", "--write", str(urdf), "--force"]) == 0
    twice = urdf.read_bytes()
    assert twice.count(b"<!-- inertia-tool robot:") == 1 and b"density 2000 kg/m^3" in twice
    assert len(twice.splitlines()) == len(once.splitlines())


def test_sdf_values_written_over_entities_and_comments_hold_only_the_new_number(tmp_path):
    sdf = tmp_path / "m.sdf"
    sdf.write_text('<?xml version="1.0"?>\n<!DOCTYPE sdf [<!ENTITY kg "">]>\n<sdf version="1.7"><model name="m">'
                   '<link name="l"><inertial><mass>2<!-- kg -->&kg;</mass><inertia><ixx>1&kg;</ixx><iyy>1</iyy>'
                   '<izz><![CDATA[1]]></izz></inertia></inertial><collision name="c"><geometry><box>'
                   '<size>0.1 0.2 0.3</size></box></geometry></collision></link></model></sdf>\n')
    robot = read_robot(sdf)
    inertials = link_inertials(robot, density=1000)
    out = tmp_path / "out.sdf"
    write_corrected(robot, inertials, out)
    tree = _tree(out.read_bytes())
    for tag in ("mass", "ixx", "izz"):
        element = tree.find(f".//inertial//{tag}")
        assert len(element) == 0 and float(element.text) == pytest.approx(
            inertials[0].properties.mass if tag == "mass" else np.diag(inertials[0].properties.inertia)[
                {"ixx": 0, "izz": 2}[tag]], rel=1e-15)
    _check_copy(sdf, out, "sdf", inertials)


# -- a copy written to another folder loads there (issue 23 item 3) ---------------------------------------

def test_mjcf_written_to_another_folder_loads_in_mujoco(tmp_path):
    # go1, 2f85, ur5e, g1: a relative meshdir was copied as it was, so the copy found no meshes
    mujoco = pytest.importorskip("mujoco")
    from inertia_tool.mass import shapes
    src = tmp_path / "robot"
    (src / "assets").mkdir(parents=True)
    (src / "textures").mkdir()
    shapes.write_stl(shapes.cone(0.02, 0.05, segments=24), src / "assets" / "cone.stl")
    shapes.write_stl(shapes.box(0.01, 0.02, 0.03), src / "plain.stl")
    (src / "parts.xml").write_text('<mujoco><default><geom density="900"/></default></mujoco>')
    model = src / "m.xml"
    model.write_text('<mujoco model="m">\n  <compiler angle="radian" meshdir="assets/"/>\n'
                     '  <include file="parts.xml"/>\n'
                     '  <asset>\n    <mesh name="cone" file="cone.stl"/>\n  </asset>\n'
                     '  <worldbody>\n    <body name="b">\n      <freejoint/>\n'
                     '      <geom type="mesh" mesh="cone"/>\n    </body>\n  </worldbody>\n</mujoco>\n')
    out_dir = tmp_path / "elsewhere" / "deeper"
    out_dir.mkdir(parents=True)
    out = out_dir / "m_fixed.xml"
    robot = read_robot(model)
    results = link_inertials(robot, density=900)
    write_corrected(robot, results, out)
    text = out.read_text()
    assert 'meshdir="../../robot/assets/"' in text and 'file="../../robot/parts.xml"' in text
    compiled = mujoco.MjModel.from_xml_path(str(out))             # loads where it was written
    assert compiled.body("b").mass[0] == pytest.approx(results[0].properties.mass, rel=1e-12)
    # the same folder: no path changes at all
    same = src / "m_same.xml"
    write_corrected(robot, link_inertials(robot, density=900), same)
    assert 'meshdir="assets/"' in same.read_text()
    # no meshdir: each asset file is re-expressed instead
    model.write_text(model.read_text().replace(' meshdir="assets/"', "").replace('file="cone.stl"',
                                                                                'file="assets/cone.stl"'))
    robot = read_robot(model)
    out2 = out_dir / "m2.xml"
    write_corrected(robot, link_inertials(robot, density=900), out2)
    assert 'file="../../robot/assets/cone.stl"' in out2.read_text()
    mujoco.MjModel.from_xml_path(str(out2))


def test_urdf_and_sdf_written_to_another_folder_read_back_with_their_meshes(tmp_path):
    from inertia_tool.mass import shapes
    src = tmp_path / "src"
    (src / "meshes").mkdir(parents=True)
    shapes.write_stl(shapes.box(0.1, 0.2, 0.3), src / "meshes" / "b.stl")
    urdf = src / "r.urdf"
    urdf.write_text('<robot name="r">\n  <link name="a">\n    <collision><geometry><mesh filename="meshes/b.stl"/>'
                    '</geometry></collision>\n  </link>\n  <link name="c">\n    <collision><geometry>'
                    '<mesh filename="file://meshes/b.stl" scale="1 1 1"/></geometry></collision>\n  </link>\n'
                    '  <link name="p">\n    <collision><geometry><mesh filename="package://pkg/b.stl"/></geometry>'
                    '</collision>\n  </link>\n</robot>\n')
    sdf = src / "m.sdf"
    sdf.write_text('<sdf version="1.7">\n  <model name="m">\n    <link name="a">\n      <collision name="c">\n'
                   '        <geometry><mesh><uri>meshes/b.stl</uri></mesh></geometry>\n      </collision>\n'
                   '    </link>\n  </model>\n</sdf>\n')
    out = tmp_path / "out"
    out.mkdir()
    packages = {"pkg": src / "meshes"}
    for path in (urdf, sdf):
        robot = read_robot(path, packages=packages)
        target = out / path.name
        write_corrected(robot, link_inertials(robot, density=1000), target)
        again = read_robot(target, packages=packages)
        assert all(e.mesh == str(src / "meshes" / "b.stl") for link in again.links for e in link.elements)
    text = (out / "r.urdf").read_text()
    assert 'filename="../src/meshes/b.stl"' in text and 'filename="file://../src/meshes/b.stl" scale="1 1 1"' in text
    assert 'filename="package://pkg/b.stl"' in text
    assert "<uri>../src/meshes/b.stl</uri>" in (out / "m.sdf").read_text()


def test_mjcf_scene_written_elsewhere_restates_the_meshdir_of_the_included_robot(tmp_path):
    # Menagerie: scene.xml includes robot.xml, whose <compiler meshdir="assets"/> MuJoCo takes relative to the
    # *main* file's folder; a scene written to another folder must say where the meshes are
    mujoco = pytest.importorskip("mujoco")
    from inertia_tool.mass import shapes
    src = tmp_path / "robot"
    (src / "assets").mkdir(parents=True)
    shapes.write_stl(shapes.cone(0.02, 0.05, segments=24), src / "assets" / "cone.stl")
    (src / "robot.xml").write_text('<mujoco model="r">\n  <compiler angle="radian" meshdir="assets"/>\n'
                                   '  <asset>\n    <mesh name="cone" file="cone.stl"/>\n  </asset>\n'
                                   '  <worldbody>\n    <body name="b">\n      <freejoint/>\n'
                                   '      <geom type="mesh" mesh="cone"/>\n    </body>\n  </worldbody>\n</mujoco>\n')
    scene = src / "scene.xml"
    scene.write_text('<mujoco model="scene">\n  <include file="robot.xml"/>\n  <worldbody>\n'
                     '    <geom name="floor" type="plane" size="1 1 0.1"/>\n  </worldbody>\n</mujoco>\n')
    out = tmp_path / "elsewhere" / "scene_fixed.xml"
    out.parent.mkdir()
    robot = read_robot(scene)
    results = link_inertials(robot, density=1000)
    write_corrected(robot, results, out)
    text = out.read_text()
    assert '<include file="../robot/robot.xml"/>\n  <compiler meshdir="../robot/assets"/>\n  <worldbody>' in text
    compiled = mujoco.MjModel.from_xml_path(str(out))                        # loads where it was written
    assert compiled.body("b").mass[0] == pytest.approx(results[0].properties.mass, rel=1e-12)
    again = read_robot(out)
    assert again.links[0].elements[0].mesh == str(src / "assets" / "cone.stl")
    # a compiler of the main file after the include still has the last word (left as it was, moved)
    scene.write_text(scene.read_text().replace('  <worldbody>', '  <compiler meshdir="assets/"/>\n  <worldbody>'))
    robot = read_robot(scene)
    write_corrected(robot, link_inertials(robot, density=1000), out, force=True)
    assert text.count("<compiler") + 1 == out.read_text().count("<compiler")
    mujoco.MjModel.from_xml_path(str(out))
