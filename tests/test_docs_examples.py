"""Every example in README.md, docs/*.md and meshes/README.md runs as written.

The fenced blocks marked ```bash, ```console or ```python are extracted and run in a temporary directory
holding a copy of ``meshes/`` and a link to ``tests/data/`` (so the examples' relative paths work and the files
they write land there):

* ```bash: every line is a command (``\\`` continues a line, ``#`` starts a comment);
* ```console: the lines starting with ``$ `` are commands (with their ``\\`` continuations), the others are the
  output shown, and every shown line must be printed by the command today (``...`` elides a part of a line, or
  whole lines); a ```text block right after a ```bash block of one command is that command's output, checked
  the same way;
* ```python: run with ``exec``; the snippets of one page share a namespace.

The blocks of a page run in order, so a command may use a file an earlier snippet made (the reference solids
of ``inertia_tool.mass.shapes`` write the parts the examples need, turned and moved with ``transformed``).

``inertia-tool ARGS`` runs in this process through ``inertia_tool.cli.main`` (the console script's entry
point) when the line is a plain command; lines with pipes, redirections or environment assignments run
through ``bash`` with ``inertia-tool`` on the PATH as ``python -m inertia_tool``.  Every command must exit with
0.  A block preceded by ``<!-- no-test -->`` is not run: only where running is impossible here (``pip
install``, a remote Dask scheduler).  ``<!-- slow -->`` marks a block that takes more than a few seconds.
No example may raise a plausibility warning (a part read in the wrong unit, a correction outside the part):
an example that does teaches the mistake, unless it is there to show the warning (``<!-- warns -->``).
``<!-- exits-N -->`` marks a block whose commands exit with the documented code N instead.
"""

from __future__ import annotations

import os
import re
import shlex
import shutil
import stat
import subprocess
import sys
import warnings
from pathlib import Path

import pytest

from inertia_tool.errors import ImplausibleCorrectionWarning, ImplausibleDensityWarning, ImplausibleSizeWarning

ROOT = Path(__file__).resolve().parent.parent
PAGES = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md")), ROOT / "meshes" / "README.md"]
RUN_LANGUAGES = ("bash", "console", "python")
_FENCE = re.compile(r"^```(\w*)\s*$")
_MARK = re.compile(r"<!--\s*(no-test|slow|warns|exits-\d)\s*-->")


def extract_blocks(path: Path) -> list[dict]:
    """The fenced blocks of a Markdown page: language, text, first line number and markers."""
    lines = path.read_text(encoding="utf-8").splitlines()
    blocks, i = [], 0
    while i < len(lines):
        m = _FENCE.match(lines[i])
        if not m:
            i += 1
            continue
        j = i + 1
        while j < len(lines) and not lines[j].startswith("```"):
            j += 1
        k = i - 1
        while k >= 0 and not lines[k].strip():
            k -= 1
        marks = set(_MARK.findall(lines[k])) if k >= 0 else set()
        blocks.append({"language": m.group(1), "text": "\n".join(lines[i + 1:j]), "line": i + 1, "marks": marks,
                       "end": j + 1})
        i = j + 1
    # a ```text block right after a ```bash block of one command (only blank lines between) is its output
    for before, after in zip(blocks, blocks[1:]):
        between = lines[before["end"]:after["line"] - 1]
        if (before["language"] == "bash" and after["language"] == "text" and not any(x.strip() for x in between)
                and len(commands(before)) == 1):
            before["shown"] = after["text"].splitlines()
    return blocks


def commands(block: dict) -> list[str]:
    """The command lines of a bash or console block, continuations joined."""
    out, current = [], None
    for raw in block["text"].splitlines():
        line = raw.rstrip()
        if block["language"] == "console" and current is None:
            if not line.startswith("$ "):
                continue            # output shown in the docs
            line = line[2:]
        if current is not None:
            line = current + " " + line.strip()
        if line.endswith("\\"):
            current = line[:-1].rstrip()
            continue
        current = None
        if line.strip() and not line.lstrip().startswith("#"):
            out.append(line.strip())
    return out


def _cases():
    """One case per page, its blocks in order (a command may use a file an earlier snippet wrote); a page
    with ``<!-- slow -->`` blocks has a second case, marked slow, that runs them too."""
    cases = []
    for page in PAGES:
        rel = page.relative_to(ROOT).as_posix()
        blocks = [b for b in extract_blocks(page)
                  if b["language"] in RUN_LANGUAGES and "no-test" not in b["marks"]]
        fast = [b for b in blocks if "slow" not in b["marks"]]
        if fast:
            cases.append(pytest.param(rel, fast, id=rel))
        if len(fast) < len(blocks):
            cases.append(pytest.param(rel, blocks, id=f"{rel}:slow", marks=[pytest.mark.slow]))
    return cases


@pytest.fixture
def sandbox(tmp_path, monkeypatch):
    """A temporary working directory with ``meshes/`` and a PATH where ``inertia-tool`` and ``python`` are
    this interpreter with this checkout's package."""
    shutil.copytree(ROOT / "meshes", tmp_path / "meshes", ignore=shutil.ignore_patterns("*.py", "__pycache__"))
    (tmp_path / "tests").mkdir()
    (tmp_path / "tests" / "data").symlink_to(ROOT / "tests" / "data", target_is_directory=True)   # read only
    bin_dir = tmp_path / ".bin"
    bin_dir.mkdir()
    for name, target in (("inertia-tool", f'"{sys.executable}" -m inertia_tool "$@"'),
                         ("python", f'"{sys.executable}" "$@"')):
        script = bin_dir / name
        script.write_text(f"#!/bin/sh\nexec {target}\n")
        script.chmod(script.stat().st_mode | stat.S_IEXEC)
    monkeypatch.chdir(tmp_path)
    env = dict(os.environ, PATH=f"{bin_dir}{os.pathsep}{os.environ.get('PATH', '')}",
               PYTHONPATH=str(ROOT), MPLBACKEND="Agg")
    return tmp_path, env


_SHELL = re.compile(r"[|<>;&`$]|^\w+=")

#: Words of the plausibility warnings (inertia_tool.mesh.plausibility, balancing.rotor): an example that
#: raises one teaches a mistake (a part read in the wrong unit, a correction outside the part).
_IMPLAUSIBLE = ("metres assumed", "every solid material", "outside the part", "a sizeable change of the part")


def _check_plausible(line: str, stderr: str) -> None:
    found = [w for w in _IMPLAUSIBLE if w in stderr]
    assert not found, f"`{line}` printed a plausibility warning:\n{stderr[-2000:]}"


def _expected_code(marks: set) -> int:
    return next((int(m.split("-")[1]) for m in marks if m.startswith("exits-")), 0)


def _run_command(line: str, env: dict, cwd: Path, capsys, *, warns: bool = False, expect: int = 0) -> str:
    """Run one command line; it must exit with ``expect`` (0).  Returns what it printed (stdout, then stderr)."""
    words = shlex.split(line, comments=True)
    if words and words[0] == "inertia-tool" and not _SHELL.search(line.split("#")[0]):
        from inertia_tool.cli import main
        code = main(words[1:])
        captured = capsys.readouterr()
        assert code == expect, f"`{line}` exited with {code}:\n{captured.err[-2000:]}"
        if not warns:
            _check_plausible(line, captured.err)
        return captured.out + captured.err
    result = subprocess.run(["bash", "-o", "pipefail", "-c", line], cwd=cwd, env=env, capture_output=True,
                            text=True, timeout=300)
    assert result.returncode == expect, f"`{line}` exited with {result.returncode}:\n{result.stderr[-2000:]}"
    if not warns:
        _check_plausible(line, result.stderr)
    return result.stdout + result.stderr


def console_pairs(block: dict) -> list[tuple[str, list[str]]]:
    """``(command, shown output lines)`` of a console block: the lines after each ``$`` command."""
    pairs, lines = [], block["text"].splitlines()
    commands_ = commands(block)
    k = -1
    continuing = False
    for raw in lines:
        if raw.startswith("$ ") and not continuing:
            k += 1
            pairs.append((commands_[k], []))
            continuing = raw.rstrip().endswith("\\")
            continue
        if continuing:
            continuing = raw.rstrip().endswith("\\")
            continue
        if pairs:
            pairs[-1][1].append(raw)
    return pairs


def check_shown_output(command: str, shown: list[str], printed: str) -> None:
    """Every line the docs show must be printed by the command today: the same words after whitespace is
    normalised, ``...`` standing for an elided part (a shown line of only ``...`` elides whole lines)."""
    actual = [" ".join(line.split()) for line in printed.splitlines()]
    for raw in shown:
        line = " ".join(raw.split())
        if not line or line.strip(".") == "":
            continue
        pieces = [p.strip() for p in line.split("...") if p.strip()]

        def matches(candidate):
            at = 0
            for piece in pieces:
                at = candidate.find(piece, at)
                if at < 0:
                    return False
                at += len(piece)
            return True
        assert any(matches(a) for a in actual), (
            f"the docs show a line that `{command}` does not print today:\n  {raw.strip()}\n"
            f"it printed:\n" + "\n".join(printed.splitlines()[:60]))


@pytest.mark.parametrize("page, blocks", _cases())
def test_docs_example_runs(page, blocks, sandbox, capsys, core_moments_memo):
    cwd, env = sandbox
    namespace = {"__name__": "__docs__"}
    for b in blocks:
        if b["language"] == "python":
            with warnings.catch_warnings():
                for category in (ImplausibleSizeWarning, ImplausibleDensityWarning, ImplausibleCorrectionWarning):
                    warnings.simplefilter("ignore" if "warns" in b["marks"] else "error", category)
                exec(compile(b["text"], f"{page}:{b['line']}", "exec"), namespace)   # noqa: S102 - the docs' own
        else:
            if b["language"] == "console":
                for line, shown in console_pairs(b):
                    printed = _run_command(line, env, cwd, capsys, warns="warns" in b["marks"],
                                           expect=_expected_code(b["marks"]))
                    check_shown_output(line, shown, printed)
            else:
                for line in commands(b):
                    printed = _run_command(line, env, cwd, capsys, warns="warns" in b["marks"],
                                           expect=_expected_code(b["marks"]))
                    if "shown" in b:
                        check_shown_output(line, b["shown"], printed)


def test_extraction_finds_the_examples():
    """The extractor sees the README's examples (a renamed fence would silently skip them)."""
    blocks = [b for c in _cases() for b in c.values[1]]
    assert any(b["language"] == "python" for b in blocks)
    assert sum(len(commands(b)) for b in blocks if b["language"] in ("bash", "console")) >= 20
    block = {"language": "console", "text": "$ inertia-tool a \\\n    --b 1   # note\nout\n$ x", "line": 1}
    assert commands(block) == ["inertia-tool a --b 1   # note", "x"]
    assert console_pairs(block) == [("inertia-tool a --b 1   # note", ["out"]), ("x", [])]
    check_shown_output("c", ["  mass:   2.5 kg ... steel)", "..."], "x\n  mass: 2.5 kg (from steel)\n")
    with pytest.raises(AssertionError, match="does not print today"):
        check_shown_output("c", ["  mass: 2.6 kg"], "  mass: 2.5 kg\n")


def _help_examples():
    from inertia_tool.cli import build_parser
    parser = build_parser()
    commands = next(a for a in parser._actions if a.dest == "command").choices
    cases = []
    for name, sub in commands.items():
        epilog = sub.epilog or ""
        lines = [line.strip() for line in epilog.splitlines()[1:] if line.strip()]
        cases.append(pytest.param(name, lines, id=f"{name} --help"))
    return cases


@pytest.mark.parametrize("command, examples", _help_examples())
def test_help_examples_run(command, examples, sandbox, capsys, core_moments_memo):
    """The examples at the end of every ``--help`` run as printed, from the repository root."""
    cwd, env = sandbox
    assert examples, f"inertia-tool {command} --help shows no examples"
    for line in examples:
        _run_command(line, env, cwd, capsys)
