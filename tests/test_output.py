"""The one output writer (inertia_tool.output) and the commands that write files through it."""

import os
import stat

import numpy as np
import pytest

from inertia_tool.cli import main
from inertia_tool import output
from inertia_tool.output import (OutputFileError, atomic_target, check_targets, write_bytes, write_files,
                                         write_text)

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
WHEEL = os.path.join(ROOT, "meshes", "unbalanced_wheel.stl")
T_HANDLE = os.path.join(ROOT, "meshes", "t_handle.stl")
BALANCE = ["balance", WHEEL, "--units", "mm", "--material", "steel", "--rpm", "3000", "--planes", "-40,40",
           "--radius", "180"]
SPIN = ["spin", T_HANDLE, "--units", "mm", "--density", "7850", "--rate", "300rpm", "--duration", "1s",
        "--samples", "501"]


def _names(folder):
    return sorted(os.listdir(folder))


def test_write_text_replaces_atomically_and_leaves_no_temporary(tmp_path):
    target = tmp_path / "a.md"
    write_text(target, "first\n")
    write_text(target, "second\n")
    assert target.read_text() == "second\n" and _names(tmp_path) == ["a.md"]


def test_a_failure_while_writing_keeps_the_old_file_and_removes_the_temporary(tmp_path):
    target = tmp_path / "traj.csv"
    target.write_text("old\n")
    with pytest.raises(RuntimeError):
        with atomic_target(target) as tmp:
            with open(tmp, "w") as fh:
                fh.write("half a fi")
            raise RuntimeError("the writer died")
    assert target.read_text() == "old\n" and _names(tmp_path) == ["traj.csv"]


def test_an_os_error_on_rename_is_one_line_and_removes_the_temporary(tmp_path, monkeypatch):
    target = tmp_path / "r.html"
    target.write_text("old")

    def full_disk(src, dst, **kw):
        raise OSError(28, "No space left on device")
    monkeypatch.setattr(output.os, "replace", full_disk)     # the rename that replaces (with --force)
    monkeypatch.setattr(output.os, "link", full_disk)        # the rename that never replaces
    with pytest.raises(OutputFileError, match=r"r\.html: cannot write it \(No space left on device\)"):
        write_text(target, "new")
    assert target.read_text() == "old" and _names(tmp_path) == ["r.html"]


def test_check_targets_refuses_before_any_write(tmp_path):
    (tmp_path / "b.svg").write_text("keep")
    files = {str(tmp_path / "a.svg"): "<svg/>", str(tmp_path / "b.svg"): "<svg/>", str(tmp_path / "r.md"): "x"}
    with pytest.raises(OutputFileError,
                       match=r"b\.svg: exists; refusing to overwrite it \(`force=True` overwrites it\)"):
        write_files(files)
    assert _names(tmp_path) == ["b.svg"]                       # a.svg (checked first) was not written either
    with pytest.raises(OutputFileError, match="is a directory"):
        check_targets([str(tmp_path)])
    with pytest.raises(OutputFileError, match="no such directory"):
        check_targets([str(tmp_path / "missing" / "x.csv")])
    with pytest.raises(OutputFileError, match="named twice"):
        check_targets([str(tmp_path / "x.csv"), str(tmp_path / "x.csv")], force=True)
    write_files(files, force=True)
    assert (tmp_path / "b.svg").read_text() == "<svg/>"


def test_written_files_get_the_usual_permissions(tmp_path):
    if os.name != "posix":
        pytest.skip("POSIX modes")
    mask = os.umask(0o022)
    try:
        write_text(tmp_path / "r.md", "x")
    finally:
        os.umask(mask)
    assert (tmp_path / "r.md").stat().st_mode & 0o777 == 0o644


def test_balance_markdown_checks_every_file_before_printing_or_writing(tmp_path, capsys):
    """Before: the report was printed and plane 1's SVG written, then the existing plane 2 SVG refused."""
    report = tmp_path / "wheel.md"
    (tmp_path / "wheel-plane2.svg").write_text("keep")
    assert main(BALANCE + ["--report", str(report)]) == 2
    captured = capsys.readouterr()
    assert captured.out == "" and len(captured.err.strip().splitlines()) == 1
    assert "wheel-plane2.svg: exists" in captured.err
    assert _names(tmp_path) == ["wheel-plane2.svg"] and (tmp_path / "wheel-plane2.svg").read_text() == "keep"
    assert main(BALANCE + ["--report", str(report), "--force"]) == 0
    assert _names(tmp_path) == ["wheel-plane1.svg", "wheel-plane2.svg", "wheel.md"]


def test_balance_write_failure_prints_nothing_and_leaves_no_partial_file(tmp_path, monkeypatch, capsys):
    report = tmp_path / "wheel.html"

    def full_disk(src, dst, **kw):
        raise OSError(28, "No space left on device")
    monkeypatch.setattr(output.os, "replace", full_disk)     # the rename that replaces (with --force)
    monkeypatch.setattr(output.os, "link", full_disk)        # the rename that never replaces
    assert main(BALANCE + ["--report", str(report)]) == 2
    captured = capsys.readouterr()
    assert captured.out == "" and "No space left on device" in captured.err
    assert _names(tmp_path) == []


@pytest.mark.parametrize("command", ["spin", "top"])
def test_trajectory_csv_is_atomic(tmp_path, monkeypatch, capsys, command):
    """Before: np.savetxt wrote straight onto the target, so a failure left half a CSV over the old one."""
    target = tmp_path / "traj.csv"
    target.write_text("old\n")
    real = np.savetxt

    def dies_half_way(path, data, **kw):
        real(path, data[: len(data) // 2], **kw)
        raise OSError(28, "No space left on device")
    monkeypatch.setattr(np, "savetxt", dies_half_way)
    argv = SPIN if command == "spin" else ["top", os.path.join(ROOT, "meshes", "spinning_top.stl"), "--units",
                                           "mm", "--pivot", "0,0,0", "--spin", "50rev/s", "--tilt", "20deg"]
    assert main(argv + ["--csv", str(target), "--force"]) == 2
    assert "No space left on device" in capsys.readouterr().err
    assert target.read_text() == "old\n" and _names(tmp_path) == ["traj.csv"]


def test_spin_plot_goes_through_the_atomic_writer(tmp_path, capsys):
    pytest.importorskip("matplotlib")
    png = tmp_path / "spin.png"
    assert main(SPIN + ["--plot", str(png)]) == 0
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and _names(tmp_path) == ["spin.png"]
    capsys.readouterr()
    assert main(SPIN + ["--plot", str(png), "--csv", str(png), "--force"]) == 2       # one file named twice
    assert "named twice" in capsys.readouterr().err


# -- issue 22: temporary files that cannot be predicted, followed or swapped; targets never clobbered ---------

def test_temporary_names_are_unpredictable_and_fsynced(tmp_path, monkeypatch):
    names, synced = [], []
    real_replace, real_link, real_fsync = os.replace, os.link, os.fsync

    def record_link(src, dst, **kw):
        names.append(os.path.basename(src))
        return real_link(src, dst, **kw)

    def record_replace(src, dst):
        names.append(os.path.basename(src))
        return real_replace(src, dst)

    def record_fsync(fd):
        synced.append(os.fstat(fd).st_size)
        return real_fsync(fd)
    monkeypatch.setattr(output.os, "link", record_link)
    monkeypatch.setattr(output.os, "replace", record_replace)
    monkeypatch.setattr(output.os, "fsync", record_fsync)
    write_bytes(tmp_path / "a.urdf", b"<a/>", replace=False)
    write_bytes(tmp_path / "a.urdf", b"<b/>", replace=True)
    assert len(names) == 2 and names[0] != names[1]
    assert all(n.startswith(".a.") and n.endswith(".tmp.urdf") and len(n) > len(".a..tmp.urdf") + 5 for n in names)
    assert 4 in synced                                         # the file itself, with its bytes, before the rename
    assert (tmp_path / "a.urdf").read_bytes() == b"<b/>" and os.listdir(tmp_path) == ["a.urdf"]


def test_never_clobbers_a_file_that_appears_after_the_check(tmp_path):
    target = tmp_path / "out.urdf"
    with pytest.raises(OutputFileError, match="exists"):
        with atomic_target(target, replace=False) as tmp:
            with open(tmp, "wb") as fh:
                fh.write(b"new")
            target.write_bytes(b"someone else's")              # created between the check and the rename
    assert target.read_bytes() == b"someone else's" and os.listdir(tmp_path) == ["out.urdf"]


def test_a_temporary_file_swapped_for_a_link_is_refused(tmp_path):
    victim = tmp_path / "victim.txt"
    victim.write_text("precious")
    target = tmp_path / "out.svg"
    with pytest.raises(OutputFileError, match="replaced or removed"):
        with atomic_target(target) as tmp:
            os.remove(tmp)
            os.symlink(victim, tmp)
            with open(tmp, "w") as fh:                         # a third-party writer follows the planted link
                fh.write("x")
    assert not target.exists()
    assert victim.read_text() == "x"          # what the third-party writer did cannot be undone, but...
    assert sorted(os.listdir(tmp_path)) == sorted(["victim.txt", os.path.basename(tmp)])   # ...nothing renamed


def test_a_symlink_target_is_refused_even_with_force(tmp_path):
    victim = tmp_path / "victim.txt"
    victim.write_text("precious")
    link = tmp_path / "out.md"
    link.symlink_to(victim)
    dangling = tmp_path / "dangling.md"
    dangling.symlink_to(tmp_path / "nowhere")
    for target in (link, dangling):
        for force in (False, True):
            with pytest.raises(OutputFileError, match="symbolic link"):
                check_targets([str(target)], force=force)
    with pytest.raises(OutputFileError, match="exists"):       # even without the check, the rename refuses it
        write_bytes(dangling, b"x", replace=False)
    assert victim.read_text() == "precious" and not (tmp_path / "nowhere").exists()
    assert _names(tmp_path) == ["dangling.md", "out.md", "victim.txt"]


@pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="named pipes are POSIX")
def test_a_named_pipe_is_not_replaced_even_with_force(tmp_path, capsys):
    # `robot --write /dev/null --force` (as root) renamed a regular file over /dev/null; a named pipe stands in
    # for the device here.  Refused at the check and again at the rename (a pipe made after the check)
    pipe = tmp_path / "out.urdf"
    os.mkfifo(pipe)
    for force in (False, True):
        with pytest.raises(OutputFileError, match="named pipe, not a regular file"):
            check_targets([str(pipe)], force=force)
    with pytest.raises(OutputFileError, match="named pipe"):
        write_bytes(pipe, b"x", replace=True)
    robot = tmp_path / "r.urdf"
    robot.write_text('<robot name="r"><link name="l"><inertial><mass value="1"/><inertia ixx="1" ixy="0" ixz="0" '
                     'iyy="1" iyz="0" izz="1"/></inertial><collision><geometry><box size="0.1 0.2 0.3"/>'
                     '</geometry></collision></link></robot>')
    assert main(["robot", str(robot), "--keep-mass", "--write", str(pipe), "--force"]) == 2
    assert "named pipe" in capsys.readouterr().err
    assert stat.S_ISFIFO(os.lstat(pipe).st_mode)
    assert _names(tmp_path) == ["out.urdf", "r.urdf"]


def test_no_hard_links_falls_back_to_a_checked_replace(tmp_path, monkeypatch):
    def no_links(src, dst, **kw):
        raise OSError(1, "Operation not permitted")                 # EPERM: what FAT and some FUSE mounts say
    monkeypatch.setattr(output.os, "link", no_links)
    target = tmp_path / "a.md"
    write_bytes(target, b"one", replace=False)
    assert target.read_bytes() == b"one" and _names(tmp_path) == ["a.md"]
    with pytest.raises(OutputFileError, match="exists"):
        write_bytes(target, b"two", replace=False)
    assert target.read_bytes() == b"one" and _names(tmp_path) == ["a.md"]
