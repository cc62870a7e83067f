"""Regular files only (inertia_tool.mesh.regular), issue 22 item 5: FIFOs, devices and symbolic links to them
are refused up front — as the mesh, inside glTF references, in compressed files, in a batch — never a hang.
Non-UTF-8 file names keep their bytes, escaped, in batch rows, and a resume matches them.

Every command that could hang runs in a child process with a timeout, so a regression fails the test instead
of hanging the suite.
"""

import json
import os
import subprocess
import sys

import numpy as np
import pytest
import trimesh

from conftest import write_binary_stl
from inertia_tool.batch.rows import open_results
from inertia_tool.batch.runner import row_path
from inertia_tool.errors import MeshReadError
from inertia_tool.mesh.regular import not_regular_reason, open_regular

pytestmark = pytest.mark.skipif(not hasattr(os, "mkfifo") or not os.path.exists("/dev/zero"),
                                reason="needs FIFOs and /dev/zero (POSIX)")

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
ENV = {**os.environ, "PYTHONPATH": ROOT}
TIMEOUT = 120


def _cli(*args, cwd=None):
    return subprocess.run([sys.executable, "-m", "inertia_tool.cli", *[os.fsdecode(a) for a in args]], env=ENV,
                          capture_output=True, text=True, timeout=TIMEOUT, cwd=cwd)


def _box(path, extents=(1.0, 2.0, 3.0)):
    m = trimesh.creation.box(extents)
    write_binary_stl(path, np.asarray(m.vertices), m.faces)
    return path


def _gltf(directory):
    """A box as .gltf with its buffers in separate files; returns the .gltf and the buffer file names."""
    directory.mkdir()
    files = trimesh.creation.box((1.0, 2.0, 3.0)).export(None, file_type="gltf")
    for name, data in files.items():
        (directory / name).write_bytes(data)
    return directory / "model.gltf", [n for n in files if n.endswith(".bin")]


# -- the mesh itself ---------------------------------------------------------------------------------------

@pytest.mark.parametrize("kind", ["fifo", "dev-zero-link", "fifo-link"])
@pytest.mark.parametrize("name", ["part.stl", "part.obj", "part.ply", "part.glb", "part.stl.gz", "part.zip"])
def test_analyze_refuses_fifos_devices_and_links_to_them_at_once(tmp_path, kind, name):
    path = tmp_path / name
    if kind == "fifo":
        os.mkfifo(path)
    elif kind == "dev-zero-link":
        os.symlink("/dev/zero", path)
    else:
        os.mkfifo(tmp_path / "pipe")
        os.symlink(tmp_path / "pipe", path)
    done = _cli("analyze", path)
    assert done.returncode == 3, done.stderr
    err = done.stderr.strip().splitlines()
    what = "a character device" if kind == "dev-zero-link" else "a FIFO (named pipe)"
    link = "a symbolic link to " if kind != "fifo" else ""
    assert err == [f"inertia-tool: error: {path}: is {link}{what}, not a regular file"]


def test_open_regular_refuses_a_fifo_swapped_in_after_the_check(tmp_path, monkeypatch):
    """The time-of-check/time-of-use gap: a FIFO in place of the checked file is opened without blocking
    (O_NONBLOCK) and refused by fstat.  Run in a child so that a regression cannot hang the suite."""
    fifo = tmp_path / "swapped.stl"
    os.mkfifo(fifo)
    script = ("import sys\n"
              "from inertia_tool.mesh import regular\n"
              "regular.check_regular = lambda path: None        # the check saw a regular file\n"
              "try:\n"
              "    regular.open_regular(sys.argv[1])\n"
              "except regular.MeshReadError as exc:\n"
              "    print(exc)\n")
    done = subprocess.run([sys.executable, "-c", script, str(fifo)], env=ENV, capture_output=True, text=True,
                          timeout=TIMEOUT)
    assert done.stdout.strip() == f"{fifo}: is a FIFO (named pipe), not a regular file (it changed while being opened)"


def test_open_regular_reads_a_regular_file_and_a_link_to_one(tmp_path):
    path = _box(tmp_path / "a.stl")
    os.symlink(path, tmp_path / "link.stl")
    for p in (path, tmp_path / "link.stl", os.fsencode(path)):
        with open_regular(p) as fh:
            assert fh.read() == path.read_bytes()
    with pytest.raises(MeshReadError, match="is a directory, not a regular file"):
        open_regular(tmp_path)
    with pytest.raises(FileNotFoundError):
        open_regular(tmp_path / "missing.stl")
    assert not_regular_reason(os.stat(path).st_mode) is None


# -- side files: glTF buffers -------------------------------------------------------------------------------

@pytest.mark.parametrize("kind", ["fifo", "dev-zero-link"])
def test_gltf_buffer_naming_a_fifo_or_device_is_refused_issue22(tmp_path, kind):
    """Issue 22: a glTF buffer naming a FIFO hung `analyze`."""
    gltf, buffers = _gltf(tmp_path / "g")
    target = gltf.parent / buffers[-1]
    target.unlink()
    if kind == "fifo":
        os.mkfifo(target)
    else:
        os.symlink("/dev/zero", target)
    done = _cli("analyze", gltf)
    assert done.returncode == 3, done.stderr
    err = done.stderr.strip().splitlines()
    assert len(err) == 1 and str(gltf) in err[0] and "Traceback" not in done.stderr
    what = "a FIFO (named pipe)" if kind == "fifo" else "a symbolic link to a character device"
    assert err[0] == f"inertia-tool: error: {gltf}: refers to '{buffers[-1]}', which is {what}, not a regular file"


def test_gltf_buffer_outside_the_files_directory_is_refused(tmp_path):
    gltf, buffers = _gltf(tmp_path / "g")
    (tmp_path / "outside.bin").write_bytes((gltf.parent / buffers[-1]).read_bytes())
    data = json.loads(gltf.read_text())
    data["buffers"][-1]["uri"] = "../outside.bin"
    gltf.write_text(json.dumps(data))
    done = _cli("analyze", gltf)
    assert done.returncode == 3, done.stderr
    assert done.stderr.strip() == (f"inertia-tool: error: {gltf}: refers to '../outside.bin', which lies outside "
                                   "the file's directory (refused)")


def test_gltf_with_regular_buffers_still_reads_exactly(tmp_path):
    gltf, _ = _gltf(tmp_path / "g")
    done = _cli("analyze", gltf, "--format", "json")
    assert done.returncode == 0, done.stderr
    assert json.loads(done.stdout)["volume"] == pytest.approx(6.0, rel=1e-12)


def test_obj_naming_a_fifo_material_library_does_not_hang(tmp_path):
    os.mkfifo(tmp_path / "evil.mtl")
    m = trimesh.creation.box((1.0, 2.0, 3.0))
    lines = ["mtllib evil.mtl"] + [f"v {x!r} {y!r} {z!r}" for x, y, z in m.vertices.tolist()]
    lines += [f"f {a + 1} {b + 1} {c + 1}" for a, b, c in m.faces.tolist()]
    (tmp_path / "box.obj").write_text("\n".join(lines) + "\n")
    done = _cli("analyze", tmp_path / "box.obj", "--format", "json")
    assert done.returncode == 0, done.stderr          # geometry only: the material library is never opened
    assert json.loads(done.stdout)["volume"] == pytest.approx(6.0, rel=1e-12)


# -- batch: a failed row, the batch goes on; non-UTF-8 names ---------------------------------------------------

@pytest.mark.skipif(sys.platform == "darwin", reason="macOS file systems refuse non-UTF-8 names")
@pytest.mark.parametrize("fmt", ["csv", "jsonl"])
def test_batch_with_fifo_device_link_and_non_utf8_name_issue22(tmp_path, fmt):
    """Issue 22: a FIFO or a /dev/zero link with a mesh suffix hung batch forever (lock held, every resume hung),
    and one non-UTF-8 file name ended a batch with an internal error."""
    d = tmp_path / "parts"
    d.mkdir()
    _box(d / "ok.stl")
    odd = os.path.join(os.fsencode(d), b"caf\xe9-\xff.stl")        # Latin-1 bytes: not UTF-8
    _box(odd, (2.0, 2.0, 2.0))
    os.mkfifo(d / "pipe.stl")
    os.symlink("/dev/zero", d / "zero.stl")
    out = tmp_path / f"r.{fmt}"
    done = _cli("batch", d, "--out", out)
    assert done.returncode == 3, done.stderr                        # two failed rows; not a hang, not exit 1
    assert "internal error" not in done.stderr and "2 ok, 2 failed" in done.stderr
    with open_results(out) as r:
        rows = {row["path"]: row for row in r.previous_rows}
    escaped = os.path.join(str(d), "caf\\xe9-\\xff.stl")            # backslash, x, e, 9: the bytes, readable
    assert set(rows) == {str(d / "ok.stl"), escaped, str(d / "pipe.stl"), str(d / "zero.stl")}
    assert rows[escaped]["status"] == "ok" and rows[escaped]["volume"] == pytest.approx(8.0, rel=1e-12)
    assert rows[str(d / "pipe.stl")]["status"] == "error"
    assert "FIFO (named pipe), not a regular file" in rows[str(d / "pipe.stl")]["error"]
    assert "symbolic link to a character device" in rows[str(d / "zero.stl")]["error"]
    assert out.read_bytes().decode("utf-8")                         # the results file stays UTF-8
    again = _cli("batch", d, "--out", out)                          # resume: the odd name is matched, skipped
    assert again.returncode == 3 and "0 ok, 2 failed in this run; 2 done before" in again.stderr


def test_batch_names_a_single_fifo_as_a_failed_row(tmp_path):
    os.mkfifo(tmp_path / "only.stl")
    done = _cli("batch", tmp_path / "only.stl", "--out", tmp_path / "r.jsonl")
    assert done.returncode == 3 and "is a FIFO (named pipe), not a regular file" in done.stderr


def test_row_path_escapes_undecodable_bytes_only():
    assert row_path("/a/b c,\"d\"\n.stl") == "/a/b c,\"d\"\n.stl"
    assert row_path(os.fsdecode(b"/a/caf\xc3\xa9.stl")) == "/a/café.stl"
    assert row_path(os.fsdecode(b"/a/\xff\xfe.stl")) == "/a/\\xff\\xfe.stl"
    assert row_path("lone \ud800 surrogate") == "lone \\ud800 surrogate"


# -- robot descriptions: mesh references --------------------------------------------------------------------

@pytest.mark.parametrize("kind", ["fifo", "dev-zero-link"])
def test_robot_mesh_reference_to_a_fifo_or_device_is_refused(tmp_path, kind):
    if kind == "fifo":
        os.mkfifo(tmp_path / "part.stl")
    else:
        os.symlink("/dev/zero", tmp_path / "part.stl")
    geometry = '<geometry><mesh filename="part.stl"/></geometry>'
    (tmp_path / "r.urdf").write_text(f'<robot name="r"><link name="a"><visual>{geometry}</visual>'
                                     f'<collision>{geometry}</collision></link></robot>')
    done = _cli("robot", tmp_path / "r.urdf", "--material", "steel")
    assert done.returncode == 3, done.stderr
    what = "a FIFO (named pipe)" if kind == "fifo" else "a symbolic link to a character device"
    assert done.stderr.strip().splitlines() == [
        f"inertia-tool: error: {tmp_path / 'r.urdf'}: link 'a': mesh 'part.stl': resolves to "
        f"{tmp_path / 'part.stl'}, which is {what}, not a regular file"]
