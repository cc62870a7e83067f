"""The batch's per-file path after batch6's cuts gives the rows it gave before (issue 25 item 6).

What changed, and what each test checks it against:

- a chunk shares one warnings context, one empty row and one density description (``runner._chunk_context``):
  each row of a chunk equals that file's row analysed alone (``analyze_file``, its own context), warnings
  included, with files that warn and fail in between;
- a row's numbers are taken from Python lists: checked against ``mass_properties`` of the file, entry by entry
  (the tensor's entries, the axes as columns);
- ``policy.shell_contacts`` of a part whose faces meet nowhere: equal, field by field and in dtype and shape, to
  the general path's summary of contacts that meet only within one shell;
- a one-shell part's ``MassProperties`` made once with its report: equal to the body made from its shell and
  copied with the report, as ``_part`` made it before;
- a batch in one process writes each row as its file is done, and what the writer warns is shown.
"""

import warnings

import numpy as np
import pytest
import trimesh

from conftest import write_binary_stl
from inertia_tool import mass_properties
from inertia_tool.batch.runner import BatchOptions, ROW_FIELDS, analyze_chunk, analyze_file, run_batch
from inertia_tool.mass import pipeline
from inertia_tool.mass.properties import MassProperties
from inertia_tool.mesh import LoadOptions
from inertia_tool.mesh.intersect import SurfaceContacts
from inertia_tool.mesh.policy import shell_contacts
from inertia_tool.mesh.prepare import prepare_mesh
from inertia_tool.mesh.read import load_mesh

OPTIONS = BatchOptions(load=LoadOptions(units="mm"), density=1240.0)


@pytest.fixture
def files(tmp_path):
    """A box, a box with a degenerate triangle (warns), a sphere (equal moments: warns), a file that is not a
    mesh (fails), a squashed torus; each written as binary STL."""
    out = []
    box = trimesh.creation.box((10.0, 20.0, 30.0))
    out.append(tmp_path / "a_box.stl")
    write_binary_stl(out[-1], box.vertices, box.faces)
    faces = np.vstack([box.faces, [[0, 0, 1]]])
    out.append(tmp_path / "b_degenerate.stl")
    write_binary_stl(out[-1], box.vertices, faces)
    sphere = trimesh.creation.icosphere(1, radius=15.0)
    out.append(tmp_path / "c_sphere.stl")
    write_binary_stl(out[-1], sphere.vertices, sphere.faces)
    out.append(tmp_path / "d_text.stl")
    out[-1].write_bytes(b"solid nothing here\n")
    torus = trimesh.creation.torus(30.0, 8.0, major_sections=24, minor_sections=10)
    torus.apply_transform(np.diag([1.0, 1.3, 0.8, 1.0]))          # squashed: distinct moments, no warning
    torus.apply_translation((100.0, -40.0, 7.0))
    out.append(tmp_path / "e_torus.stl")
    write_binary_stl(out[-1], torus.vertices, torus.faces)
    return [str(p) for p in out]


def _without_time(row: dict) -> dict:
    return {k: v for k, v in row.items() if k != "seconds"}


def test_each_row_of_a_chunk_is_the_files_row_alone(files):
    together = analyze_chunk([(f, None) for f in files] * 2, OPTIONS)
    alone = [analyze_file(f, OPTIONS) for f in files] * 2
    assert [r["status"] for r in together] == ["ok", "ok", "ok", "error", "ok"] * 2
    assert [tuple(r) for r in together] == [ROW_FIELDS] * len(together)        # the columns, in order
    for a, b in zip(together, alone):
        assert _without_time(a) == _without_time(b)
    warned = [r["warnings"] for r in together]
    assert warned[0] is None and warned[4] is None                             # nothing leaks from a neighbour
    assert "degenerate" in warned[1] and "equal" in warned[2] and warned[3] is None


def test_a_rows_numbers_are_the_engines_entry_by_entry(files):
    row = analyze_file(files[4], OPTIONS)
    props = mass_properties(files[4], units="mm", density=1240.0)
    inertia, axes = np.asarray(props.inertia), np.asarray(props.principal.axes)
    expected = {"density": props.density, "mass": props.mass, "volume": props.volume,
                "surface_area": props.surface_area,
                **{f"com_{c}": props.center_of_mass[i] for i, c in enumerate("xyz")},
                "ixx": inertia[0, 0], "iyy": inertia[1, 1], "izz": inertia[2, 2], "ixy": inertia[0, 1],
                "ixz": inertia[0, 2], "iyz": inertia[1, 2],
                **{f"i{k + 1}": props.principal.moments[k] for k in range(3)},
                **{f"axis{k + 1}_{c}": axes[i, k] for k in range(3) for i, c in enumerate("xyz")}}
    for name, value in expected.items():
        assert type(row[name]) is float and row[name] == float(value), name


def test_shell_contacts_of_faces_meeting_nowhere_is_the_general_summary():
    """The shortcut for no contacts at all against the general path on contacts that meet only within one shell
    (which the general path summarises as nothing between shells)."""
    labels = np.array([0, 0, 0, 1, 1, 1, 2, 2])
    empty = np.zeros((0, 2), dtype=np.int64)
    for complete in (True, False):
        none = shell_contacts(SurfaceContacts(empty, empty, empty, complete), labels, 3)
        within = shell_contacts(SurfaceContacts(empty, empty, np.array([[0, 1], [3, 4]]), complete), labels, 3)
        for name in ("self_crossing", "crossing", "crossing_with", "touching"):
            a, b = getattr(none, name), getattr(within, name)
            assert a.dtype == b.dtype and a.shape == b.shape and np.array_equal(a, b), name
        assert none == within
        assert none.self_crossing_pairs == 0 and none.complete is complete


def test_a_one_shell_part_is_the_body_of_its_shell_with_its_report(files):
    raw = load_mesh(files[4], units="mm")
    prepared = prepare_mesh(raw)
    assert len(prepared.shells) == 1
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        props = mass_properties(raw, density=1240.0)
    (body,) = pipeline._bodies(prepared, 1240.0, raw.source)
    before = MassProperties(mass=body.mass, volume=body.volume, center_of_mass=body.center_of_mass,
                            inertia=body.inertia, surface_area=body.surface_area, density=1240.0, name=raw.source,
                            mesh=prepared.report, parts=())
    assert props == before
    assert props.mesh == prepared.report and props.parts == () and props.material == ""


def test_one_process_writes_each_row_when_its_file_is_done_and_shows_the_writers_warnings(files, monkeypatch):
    import inertia_tool.batch.runner as runner

    seen: list[int] = []
    calls: list[int] = []
    real = runner.mass_properties

    def counting(*args, **kwargs):
        calls.append(len(seen))             # rows written before this file's analysis
        return real(*args, **kwargs)

    def write_row(row):
        seen.append(len(row))
        warnings.warn(UserWarning(f"written {row['path']}"), stacklevel=1)

    monkeypatch.setattr(runner, "mass_properties", counting)
    with pytest.warns(UserWarning, match="written") as shown:
        run_batch(files, OPTIONS, write_row, jobs=1)
    assert len([w for w in shown if "written" in str(w.message)]) == len(files)
    assert calls == [0, 1, 2, 4]            # the text file fails in reading: no analysis, its row still written
