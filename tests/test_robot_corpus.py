"""`inertia-tool robot` over a folder tree (inertia_tool.robot.corpus): every description audited once, the
likely cause of each bad inertial named, one summary; a model that cannot be read never stops the others."""

import json
import os

import numpy as np
import pytest

from inertia_tool.cli import EXIT_INCOMPLETE, EXIT_OK, main
from inertia_tool.robot.corpus import find_descriptions


def _urdf(path, name, ixx, mass=7.8):
    path.write_text(f'<robot name="{name}"><link name="slab"><inertial><mass value="{mass}"/><inertia ixx="{ixx!r}" '
                    f'iyy="{ixx!r}" izz="{ixx!r}" ixy="0" ixz="0" iyz="0"/></inertial><collision><geometry>'
                    '<box size="0.1 0.2 0.3"/></geometry></collision></link></robot>')


def _corpus(tmp_path):
    root = tmp_path / "corpus"
    (root / "menagerie" / "arm").mkdir(parents=True)
    (root / "ros" / "pkg").mkdir(parents=True)
    (root / "ros" / "pkg" / "package.xml").write_text("<package><name>pkg</name></package>")
    # a box slab, declared as an isotropic placeholder
    _urdf(root / "ros" / "pkg" / "placeholder.urdf", "p", 0.001)
    # the right tensor of the 0.1 x 0.2 x 0.3 box entered in kg·mm² (x1e6)
    moments = 7.8 / 12 * np.array([0.2 ** 2 + 0.3 ** 2, 0.1 ** 2 + 0.3 ** 2, 0.1 ** 2 + 0.2 ** 2])
    truth = [float(v) * 1e6 for v in moments]
    (root / "ros" / "pkg" / "mm.urdf").write_text(
        '<robot name="mm"><link name="slab"><inertial><mass value="7.8"/>'
        f'<inertia ixx="{truth[0]!r}" iyy="{truth[1]!r}" izz="{truth[2]!r}" ixy="0" ixz="0" iyz="0"/></inertial>'
        '<collision><geometry><box size="0.1 0.2 0.3"/></geometry></collision></link></robot>')
    (root / "ros" / "broken.urdf").write_text("<robot name='b'><link name='x'>")
    arm = root / "menagerie" / "arm"
    (arm / "arm.xml").write_text('<mujoco model="arm"><worldbody><body name="b"><inertial pos="0 0 0" mass="1" '
                                 'diaginertia="1 1 1"/><geom type="box" size="0.05 0.1 0.15"/></body></worldbody>'
                                 '</mujoco>')
    (arm / "scene.xml").write_text('<mujoco model="scene"><include file="arm.xml"/></mujoco>')
    return root


def test_find_descriptions_skips_included_mjcf_and_other_xml(tmp_path):
    root = _corpus(tmp_path)
    found = [p.split("corpus/", 1)[1] for p in find_descriptions([root])]
    assert found == ["menagerie/arm/scene.xml", "ros/broken.urdf", "ros/pkg/mm.urdf", "ros/pkg/placeholder.urdf"]


def test_corpus_audit_names_the_causes_and_sums_up(tmp_path, capsys):
    root = _corpus(tmp_path)
    assert main(["robot", str(root), "--keep-mass"]) == EXIT_INCOMPLETE          # broken.urdf is unreadable
    out = capsys.readouterr().out
    assert "unreadable:" in out and "broken.urdf" in out
    assert "mm.urdf: slab: unit slip" in out and "placeholder.urdf: slab: placeholder" in out
    assert "arm/scene.xml: b: placeholder" in out
    # the table only counts: it says where each model's links, issues and reasons are (mujoco18's user trial)
    assert ("\neach model's links, issues and reasons without a result: the same command on one FILE, or --json "
            "here\n") in out
    assert out.rstrip().endswith("4 models (1 unreadable): 3 links, 3 computed, 0 without a result, 3 with issues; "
                                 "likely causes: placeholder 2, unit 1")
    assert main(["robot", str(root / "ros" / "pkg"), str(root / "menagerie"), "--keep-mass", "--json"]) == EXIT_OK
    report = json.loads(capsys.readouterr().out)
    assert len(report["models"]) == 3 and report["likely_causes"] == {"unit": 1, "placeholder": 2}


def test_corpus_refuses_write(tmp_path, capsys):
    root = _corpus(tmp_path)
    assert main(["robot", str(root), "--keep-mass", "--write", str(tmp_path / "x.urdf")]) == 2
    assert "only audited" in capsys.readouterr().err


@pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="named pipes are POSIX")
def test_a_named_pipe_among_the_models_is_unreadable_not_waited_on(tmp_path, capsys):
    # `robot pipe.xml a.urdf` sniffed pipe.xml with open(): it waited for a writer for ever
    _urdf(tmp_path / "a.urdf", "a", 0.001)
    pipe = tmp_path / "pipe.xml"
    os.mkfifo(pipe)
    assert main(["robot", str(pipe), str(tmp_path / "a.urdf"), "--keep-mass"]) == EXIT_INCOMPLETE
    out = capsys.readouterr().out
    assert "pipe.xml: is a FIFO (named pipe), not a regular file" in out
    assert "2 models (1 unreadable)" in out


def test_mjcf_fragments_in_a_folder_are_not_models_but_a_fragment_named_is_read(tmp_path):
    # Menagerie's aloha folder holds actuator and keyframe files meant to be included (no <body>, no
    # <include>; sites in a <worldbody> at most); walked in a folder they are skipped, named on the command
    # line they are read (and refused)
    root = tmp_path / "aloha"
    root.mkdir()
    (root / "robot.xml").write_text('<mujoco><worldbody><body name="b"><geom type="sphere" size="0.1"/></body>'
                                    '</worldbody></mujoco>')
    (root / "keyframe_no_act.xml").write_text('<mujoco><!-- <worldbody> --><keyframe><key name="home" qpos=""/>'
                                              '</keyframe></mujoco>')
    (root / "actuators.xml").write_text('<mujoco><worldbody><site name="centre"/></worldbody><actuator>'
                                        '<position joint="j"/></actuator></mujoco>')
    assert [os.path.basename(p) for p in find_descriptions([root])] == ["robot.xml"]
    assert find_descriptions([root / "actuators.xml"]) == [str(root / "actuators.xml")]


def _box_stl(path, *, inside_out=False, open_=False):
    from conftest import box_arrays, write_binary_stl
    v, f = box_arrays((0.1, 0.2, 0.3))
    f = f[:, ::-1] if inside_out else f
    write_binary_stl(path, v, f[:-1] if open_ else f)


def _mjcf_using(path, mesh, bodies=("left", "right")):
    body = "".join(f'<body name="{b}"><geom type="mesh" mesh="m"/></body>' for b in bodies)
    path.write_text(f'<mujoco><asset><mesh name="m" file="{mesh}"/></asset><worldbody>{body}</worldbody></mujoco>')


def test_a_mesh_shared_by_links_and_models_is_read_once_with_its_warnings_for_each(tmp_path, monkeypatch):
    import inertia_tool.robot.geometry as geometry
    from inertia_tool.robot.corpus import audit_corpus
    calls = []
    real = geometry.mesh_properties
    monkeypatch.setattr(geometry, "mesh_properties", lambda path, **kw: calls.append(path) or real(path, **kw))
    _box_stl(tmp_path / "flipped.stl", inside_out=True)
    _box_stl(tmp_path / "open.stl", open_=True)
    for name in ("scene", "scene_mjx"):                   # two scene variants of one robot
        _mjcf_using(tmp_path / f"{name}.xml", "flipped.stl")
    _mjcf_using(tmp_path / "other.xml", "open.stl")
    with pytest.warns(Warning):
        models = audit_corpus([tmp_path], density=1000)
    assert sorted(os.path.basename(p) for p in calls) == ["flipped.stl", "open.stl"]    # one read each, in all
    for model in models:
        left, right = model.inertials
        if os.path.basename(model.source) == "other.xml":          # refused once, the reason on both links
            assert left.properties is None and left.problem == right.problem and "not a closed" in left.problem
            continue
        volume = 0.1 * 0.2 * 0.3
        assert left.properties.mass == pytest.approx(1000 * volume, rel=1e-6)          # float32 corners
        assert left.properties.mass == right.properties.mass
        # the engine's word on the mesh, with the first link that uses it, in each model as if read there
        assert any("inside out" in w and "flipped" in w for w in left.warnings), left.warnings


def test_the_shared_cache_still_counts_each_robots_face_budget(tmp_path):
    from inertia_tool.robot import link_inertials, read_robot
    from inertia_tool.robot.geometry import MeshCache
    _box_stl(tmp_path / "box.stl")
    _mjcf_using(tmp_path / "a.xml", "box.stl", bodies=("only",))
    shared = MeshCache()
    assert link_inertials(read_robot(tmp_path / "a.xml"), density=1000, mesh_cache=shared)[0].properties is not None
    assert len(shared) == 1
    small = link_inertials(read_robot(tmp_path / "a.xml"), density=1000, mesh_cache=shared, max_faces=5)[0]
    assert small.properties is None and "max_faces" in small.problem and "12 triangles" in small.problem


def _two_folder_corpus(tmp_path):
    """Two model folders (a shared flipped mesh in one, an open mesh and a fitted capsule in the other) and a
    broken file: warnings, refusals and fitted primitives in both."""
    first, second = tmp_path / "a", tmp_path / "b"
    first.mkdir()
    second.mkdir()
    _box_stl(first / "flipped.stl", inside_out=True)
    for name in ("scene", "scene_mjx"):
        _mjcf_using(first / f"{name}.xml", "flipped.stl")
    _box_stl(second / "open.stl", open_=True)
    _box_stl(second / "box.stl")
    _mjcf_using(second / "other.xml", "open.stl")
    (second / "fit.xml").write_text('<mujoco><asset><mesh name="m" file="box.stl"/></asset><worldbody>'
                                    '<body name="c"><inertial pos="0 0 0" mass="1" diaginertia="1 1 1"/>'
                                    '<geom type="capsule" mesh="m"/></body></worldbody></mujoco>')
    (second / "broken.urdf").write_text("<robot name='b'><link name='x'>")
    return tmp_path


def _summary(models):
    rows = []
    for m in models:
        rows.append((os.path.basename(m.source), m.problem))
        for link, audit in zip(m.inertials, m.audits):
            props = link.properties
            rows.append((link.name, link.problem, link.warnings, audit.issues,
                         None if props is None else (props.mass, tuple(props.center_of_mass),
                                                     tuple(props.inertia.reshape(-1)))))
    return rows


def _serial_and_parallel(root) -> list[tuple[list, list[str]]]:
    """``audit_corpus`` of ``root`` with ``jobs`` 1 and 2: each run's :func:`_summary` and its warnings' texts."""
    import warnings

    from inertia_tool.robot.corpus import audit_corpus
    runs = []
    for jobs in (1, 2):
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            models = audit_corpus([root], density=1000, jobs=jobs)
        runs.append((_summary(models), [str(w.message) for w in caught]))
    return runs


def test_jobs_2_gives_the_serial_results_and_warnings_in_the_serial_order(tmp_path):
    root = _two_folder_corpus(tmp_path)
    (serial, serial_warnings), (parallel, parallel_warnings) = _serial_and_parallel(root)
    assert parallel == serial
    assert parallel_warnings == serial_warnings and any("inside out" in w for w in serial_warnings)
    assert [r[0] for r in serial if r[0].endswith((".xml", ".urdf"))] == \
        ["scene.xml", "scene_mjx.xml", "broken.urdf", "fit.xml", "other.xml"]


@pytest.mark.parametrize("jobs", [0, -1, 1.5, True])
def test_jobs_must_be_a_positive_integer(tmp_path, jobs):
    from inertia_tool.errors import UsageError
    from inertia_tool.robot.corpus import audit_corpus
    with pytest.raises(UsageError, match="jobs"):
        audit_corpus([_two_folder_corpus(tmp_path)], density=1000, jobs=jobs)


def test_cli_jobs_prints_what_one_process_prints(tmp_path, capsys):
    root = _two_folder_corpus(tmp_path)
    outputs = []
    for jobs in ("1", "2"):
        assert main(["robot", str(root), "--density", "1000", "--json", "-j", jobs]) == EXIT_INCOMPLETE
        outputs.append(capsys.readouterr())
    assert outputs[0].out == outputs[1].out and outputs[0].err == outputs[1].err
    assert main(["robot", str(root), "--density", "1000", "--jobs", "0"]) == 2
    assert "--jobs" in capsys.readouterr().err


def test_the_audit_fits_a_primitive_to_a_mesh_once_per_file_content(tmp_path, monkeypatch):
    """The audit's bounding boxes and inside tests fit each fitted geom again; the mesh under it is integrated
    once (issue 23: 22 of 57 s of a Menagerie audit), and again when the file's bytes change."""
    import inertia_tool.robot.geometry as geometry
    from inertia_tool.robot import audit_links, link_inertials, read_robot
    calls = []
    real = geometry.mesh_properties
    monkeypatch.setattr(geometry, "mesh_properties", lambda path, **kw: calls.append(path) or real(path, **kw))
    monkeypatch.setattr(geometry, "_FIT_BODIES", {})
    root = _two_folder_corpus(tmp_path)
    robot = read_robot(root / "b" / "fit.xml")
    audits = audit_links(robot, link_inertials(robot, density=1000))
    assert audits[0].com_in_bounding_box is True and audits[0].com_inside_geometry is True
    before = len(calls)
    for _ in range(3):
        audit_links(robot, link_inertials(robot, density=1000))
    assert len(calls) - before <= 3                      # the link integrals' own fit, once per call
    from conftest import box_arrays, write_binary_stl
    v, f = box_arrays((0.1, 0.2, 0.5))                  # the same file name, other bytes: fitted anew
    write_binary_stl(root / "b" / "box.stl", v, f)
    longer = audit_links(robot, link_inertials(robot, density=1000))[0]
    assert longer.size > audits[0].size


def test_the_audit_refuses_a_fit_to_a_mesh_only_a_repair_reads_once_per_file_content(tmp_path, monkeypatch):
    """A primitive fitted to an open mesh: the link's integrals repair the mesh, the audit's bounding box and inside
    test fit the geom again without repair and are refused.  That refusal is kept like a body (issues 23/25,
    corpus15: Piper's ``link3.stl`` took 2.7 s of CPU to be refused on every call) and raised again with the
    warnings of the first attempt; the audit says the same each time."""
    import warnings

    import inertia_tool.robot.geometry as geometry
    from inertia_tool.robot import audit_links, link_inertials, read_robot
    calls = []
    real = geometry.mesh_properties
    monkeypatch.setattr(geometry, "mesh_properties",
                        lambda path, **kw: calls.append(bool(kw.get("repair"))) or real(path, **kw))
    monkeypatch.setattr(geometry, "_FIT_BODIES", {})
    _box_stl(tmp_path / "open.stl", open_=True)
    (tmp_path / "fit.xml").write_text('<mujoco><asset><mesh name="m" file="open.stl"/></asset><worldbody>'
                                      '<body name="c"><inertial pos="0 0 0" mass="1" diaginertia="1 1 1"/>'
                                      '<geom type="capsule" mesh="m"/></body></worldbody></mujoco>')
    robot = read_robot(tmp_path / "fit.xml")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")                  # the repair's warning: the link's, not this test's
        inertials = link_inertials(robot, density=1000, repair=True)
    assert inertials[0].properties is not None and inertials[0].method == "estimate"
    seen = []
    for _ in range(4):
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            audit = audit_links(robot, inertials)[0]
        seen.append((np.isnan(audit.size), audit.com_in_bounding_box, audit.com_inside_geometry, audit.issues,
                     [(w.category, str(w.message)) for w in caught]))
    assert calls.count(False) == 1                       # the fit without repair: refused once, not four times
    assert seen[0][:3] == (True, None, None)             # no box from a mesh read only with repair
    assert all(s == seen[0] for s in seen[1:])


def test_a_byte_identical_copy_in_another_folder_is_integrated_once_with_its_own_warnings(tmp_path, monkeypatch):
    """TIAGo and TIAGo dual ship the same mesh bytes under two paths: a result and a refusal are shared by
    content (issue 25, corpus19: Stretch and Stretch 3 refused 31 copies twice), and each model's warnings,
    result and refusal name its own file, exactly as when its folder is audited alone."""
    import shutil
    import warnings

    import inertia_tool.robot.geometry as geometry
    from inertia_tool.robot.corpus import audit_corpus
    calls = []
    real = geometry.mesh_properties
    monkeypatch.setattr(geometry, "mesh_properties", lambda path, **kw: calls.append(path) or real(path, **kw))
    first, second = tmp_path / "tiago", tmp_path / "tiago_dual"
    first.mkdir()
    second.mkdir()
    _box_stl(first / "flipped.stl", inside_out=True)
    shutil.copyfile(first / "flipped.stl", second / "flipped.stl")
    _box_stl(first / "open.stl", open_=True)
    shutil.copyfile(first / "open.stl", second / "open.stl")
    for folder in (first, second):
        _mjcf_using(folder / "scene.xml", "flipped.stl")
        _mjcf_using(folder / "other.xml", "open.stl")
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        models = audit_corpus([tmp_path], density=1000)
    names = sorted(os.path.relpath(p, tmp_path) for p in calls)
    assert names == ["tiago/flipped.stl", "tiago/open.stl"]      # the result and the refusal once each
    by_model = {os.path.relpath(m.source, tmp_path): m for m in models}
    for folder in ("tiago", "tiago_dual"):
        left = by_model[f"{folder}/scene.xml"].inertials[0]
        assert left.properties.mass == pytest.approx(1000 * 0.1 * 0.2 * 0.3, rel=1e-6)
        own = [w for w in left.warnings if "inside out" in w]
        assert own and all(f"{folder}/flipped.stl" in w for w in own), left.warnings
        refused = by_model[f"{folder}/other.xml"].inertials[0]
        assert refused.properties is None and f"{folder}/open.stl" in refused.problem
    texts = [str(w.message) for w in caught if "inside out" in str(w.message)]
    assert any("tiago_dual/flipped.stl" in t for t in texts) and any("tiago/flipped.stl" in t for t in texts)
    with warnings.catch_warnings(record=True) as caught_alone:
        warnings.simplefilter("always")
        alone = audit_corpus([second], density=1000)        # the copies' folder alone: every mesh its own
    assert _summary(alone) == _summary([m for m in models if os.path.dirname(m.source) == str(second)])
    own = [str(w.message) for w in caught if "tiago_dual" in str(w.message)]
    assert own and own == [str(w.message) for w in caught_alone]


def test_folders_sharing_mesh_files_are_one_group_and_a_nested_model_folder_is_its_own(tmp_path):
    """Issue 25: Stretch and Stretch 3 ship 65 byte-identical meshes; in one worker each is integrated (or
    refused) once.  Folders are grouped by mesh files of the same name and size; a sub-folder holding its own
    descriptions counts for itself, not for the folder above it; other files do not group."""
    from inertia_tool.robot.corpus import _shared_groups
    a, nested, b, c, d = (tmp_path / "a", tmp_path / "a" / "sub", tmp_path / "b", tmp_path / "c", tmp_path / "d")
    for folder in (a, nested, b, c, d):
        folder.mkdir()
    _box_stl(a / "link.stl")
    _box_stl(b / "LINK.STL")                           # the same name (case aside) and size: grouped
    _box_stl(c / "link.stl", open_=True)               # the same name, another size: not grouped by it
    _box_stl(nested / "open.stl", open_=True)
    _box_stl(c / "open.stl", open_=True)               # c shares with a's sub-folder, not with a
    (a / "notes.txt").write_text("x")
    (d / "notes.txt").write_text("x")                  # not a mesh: not grouped
    folders = [str(a), str(nested), str(b), str(c), str(d)]
    assert _shared_groups(folders) == [[str(a), str(b)], [str(nested), str(c)], [str(d)]]


def test_jobs_2_with_copies_across_folders_gives_the_serial_results_and_warnings(tmp_path):
    import shutil
    for name in ("tiago", "tiago_dual", "other"):
        (tmp_path / name).mkdir()
    _box_stl(tmp_path / "tiago" / "flipped.stl", inside_out=True)
    _box_stl(tmp_path / "tiago" / "open.stl", open_=True)
    for name in ("flipped.stl", "open.stl"):
        shutil.copyfile(tmp_path / "tiago" / name, tmp_path / "tiago_dual" / name)
    _box_stl(tmp_path / "other" / "box.stl")
    for folder in ("tiago", "tiago_dual"):
        _mjcf_using(tmp_path / folder / "scene.xml", "flipped.stl")
        _mjcf_using(tmp_path / folder / "more.xml", "open.stl")
    _mjcf_using(tmp_path / "other" / "scene.xml", "box.stl")
    runs = _serial_and_parallel(tmp_path)
    assert runs[1] == runs[0]
    assert any("tiago_dual/flipped.stl" in w for w in runs[0][1])


def test_a_copy_is_readdressed_only_where_every_mention_of_the_file_is_its_whole_path():
    """A kept warning or refusal is re-addressed to a copy by replacing whole paths, in one pass (a new path that
    contains an old one is not replaced again); a text that names the file by its base name alone is not
    re-addressed (None: the copy is integrated by itself), unless the two base names are the same."""
    from inertia_tool.errors import InvalidMeshError
    from inertia_tool.robot.geometry import _moved_error, _readdressed
    pairs = [("/m/a/x.stl", "/m/b/x.stl"), ("/m/a/y.stl", "/m/a/x.stl.y.stl")]
    assert _readdressed("/m/a/x.stl + /m/a/y.stl: open", pairs) == "/m/b/x.stl + /m/a/x.stl.y.stl: open"
    assert _readdressed("x.stl: open (/m/a/x.stl)", pairs[:1]) == "x.stl: open (/m/b/x.stl)"     # same base name
    assert _readdressed("y.stl: open (/m/a/y.stl)", pairs[1:]) is None                       # base name alone
    error = InvalidMeshError("/m/a/x.stl: not closed", details={"boundary_edges": 3})
    moved = _moved_error(error, pairs[:1])
    assert type(moved) is InvalidMeshError and str(moved) == "/m/b/x.stl: not closed"
    assert moved.details == {"boundary_edges": 3} and str(error) == "/m/a/x.stl: not closed"
    assert _moved_error(InvalidMeshError("/m/a/y.stl: y.stl is open"), pairs[1:]) is None
