"""Load every corrected copy in the simulators that read it: ``inertia-tool robot FILE --keep-mass --write``.

For each description under the given folders (MJCF ``*.xml`` with a ``<mujoco>`` root holding a body or an
include, URDF ``*.urdf``, SDFormat ``model.sdf``), the command writes a corrected copy into OUT (the same
relative path) and the copy is loaded beside its original:

* MJCF in MuJoCo (``mujoco.MjModel.from_xml_path``),
* URDF in Pinocchio (``pinocchio.buildModelFromUrdf``; ``--pinocchio-site DIR`` adds a folder where ``pin`` was
  installed with ``pip install --target``), skipped when it cannot be imported;
* SDFormat with ``--sdformat-check PROGRAM``: a program that loads each file given with libsdformat
  (``sdf::Root::Load``) and prints ``PATH<TAB>OK ...`` or ``PATH<TAB>ERROR n: first message`` (no Python binding of
  libsdformat installs here; a 30-line C++ program against Debian's ``libsdformat-dev`` does).

A copy that loads where its original loads, or fails with the same first line as its original (a mesh file
absent from the snapshot), is fine; a copy that fails where its original loads, or fails otherwise, is a
defect of the writer and is printed.  Each load runs in a child process with a time limit (one hang or crash
does not end the run).  Written in robots17 (issue 23) because robots16 stopped after 119 of 192 copies.

    python benchmarks/bench_robot_written_load.py --out /tmp/written /path/to/mujoco_menagerie
"""

from __future__ import annotations

import argparse
import collections
import contextlib
import io
import json
import os
import re
import subprocess
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.dirname(HERE))

_ROOT_TAG = re.compile(rb"<(mujoco|robot|sdf)[\s>/]")
_BODY_OR_INCLUDE = re.compile(rb"<(body|include)[\s>/]")

#: The child process that loads files: for each ``KIND PATH`` line on stdin it prints one JSON line
#: {"path", "ok": bool or None, "error": first line, "bodies", "mass"}.
_LOADER = r"""
import json, site, sys
extra = sys.argv[1]
if extra:
    site.addsitedir(extra)
for line in sys.stdin:
    kind, path = line.rstrip("\n").split("\t", 1)
    try:
        if kind == "mjcf":
            import mujoco
            model = mujoco.MjModel.from_xml_path(path)
            out = {"ok": True, "bodies": int(model.nbody), "mass": float(sum(model.body_mass))}
        else:
            import pinocchio
            model = pinocchio.buildModelFromUrdf(path)
            out = {"ok": True, "bodies": int(model.nbodies), "mass": float(sum(i.mass for i in model.inertias))}
    except ImportError as exc:
        out = {"ok": None, "error": f"not importable: {exc}"}
    except Exception as exc:
        out = {"ok": False, "error": (str(exc).strip().splitlines() or [type(exc).__name__])[0][:300]}
    out["path"] = path
    print(json.dumps(out), flush=True)
"""

#: Files one loader process takes (a crash or time-out retries them one by one).
BATCH = 24


def descriptions(roots: list) -> list:
    """``[(kind, path, root)]``: every MJCF model or scene, URDF and SDFormat model under ``roots``."""
    found = []
    for root in roots:
        for folder, subfolders, files in os.walk(root):
            subfolders.sort()
            for name in sorted(files):
                path = os.path.join(folder, name)
                if name.endswith(".urdf"):
                    found.append(("urdf", path, root))
                elif name.endswith(".sdf"):
                    found.append(("sdf", path, root))
                elif name.endswith(".xml"):
                    with open(path, "rb") as fh:
                        text = re.sub(rb"<!--.*?-->", b"", fh.read(), flags=re.DOTALL)
                    match = _ROOT_TAG.search(text)
                    if match and match.group(1) == b"mujoco" and _BODY_OR_INCLUDE.search(text):
                        found.append(("mjcf", path, root))
                    elif match and match.group(1) == b"robot":
                        found.append(("urdf", path, root))
    return found


def _message(error: str) -> str:
    """An error's first message without the checker's count (``ERROR 7: ...``: the copy may have fewer errors) and
    with quoted paths cut to their file names (the copy names the same file relative to its own folder)."""
    return re.sub(r"'[^']*/([^'/]+)'", r"'\1'", re.sub(r"^ERROR \d+: ", "", error))


def load_sdf(program: str, path: str, timeout: float) -> dict:
    """``{"ok", "error"}`` of the libsdformat checker ``program`` on ``path``."""
    if not program:
        return {"ok": None, "error": "no --sdformat-check program"}
    try:
        done = subprocess.run([program, path], capture_output=True, text=True, timeout=timeout, check=False)
    except subprocess.TimeoutExpired:
        return {"ok": False, "error": f"timeout after {timeout:g} s"}
    _, _, said = done.stdout.strip().partition("\t")
    return {"ok": said.startswith("OK"), "error": "" if said.startswith("OK") else said or done.stderr[-200:]}


def load(items: list, extra: str, timeout: float) -> dict:
    """``{path: {"ok", "error", ...}}`` for ``items`` [(kind, path)] (MJCF and URDF) in one child process;
    after a crash or time-out the files without an answer are loaded one by one."""
    text = "".join(f"{kind}\t{path}\n" for kind, path in items)
    try:
        done = subprocess.run([sys.executable, "-c", _LOADER, extra], input=text, capture_output=True, text=True,
                              timeout=timeout * len(items), check=False)
        out = done.stdout
    except subprocess.TimeoutExpired as exc:
        out = exc.stdout.decode() if isinstance(exc.stdout, bytes) else (exc.stdout or "")
    answers = {}
    for line in out.splitlines():
        with contextlib.suppress(ValueError):
            answer = json.loads(line)
            answers[answer["path"]] = answer
    left = [(k, p) for k, p in items if p not in answers]
    if left and len(items) == 1:
        return {items[0][1]: {"ok": False, "error": "the loader crashed or timed out"}}
    for item in left:
        answers.update(load([item], extra, timeout))
    return answers


def write_copy(path: str, out: str) -> tuple[int, str]:
    """Exit code and what ``inertia-tool robot PATH --keep-mass --write OUT --force`` said it wrote (or its
    error), run in this process."""
    from inertia_tool.cli import main
    err = io.StringIO()
    with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(err):
        try:
            code = main(["robot", path, "--keep-mass", "--write", out, "--force"])
        except SystemExit as exc:            # argparse
            code = int(exc.code or 0)
    lines = [line for line in err.getvalue().splitlines() if line.strip()]
    said = [line for line in lines if line.startswith(("wrote ", "inertia-tool: error"))]
    return code, (said or lines or [""])[-1]


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("roots", nargs="+")
    parser.add_argument("--out", required=True)
    parser.add_argument("--pinocchio-site", default="")
    parser.add_argument("--load-only", action="store_true",
                        help="write nothing: load the copies already in OUT beside their originals")
    parser.add_argument("--sdformat-check", default="", metavar="PROGRAM")
    parser.add_argument("--timeout", type=float, default=120.0)
    parser.add_argument("--only", default="", help="a regular expression the description path must match")
    args = parser.parse_args(argv)
    import warnings
    warnings.simplefilter("ignore")
    counts: collections.Counter = collections.Counter()
    problems = []
    start = time.process_time()
    pairs = []
    for kind, path, root in descriptions(args.roots):
        if args.only and not re.search(args.only, path):
            continue
        target = os.path.join(args.out, os.path.basename(os.path.normpath(root)), os.path.relpath(path, root))
        if args.load_only:
            if os.path.exists(target):
                pairs.append((kind, path, target))
            continue
        os.makedirs(os.path.dirname(target), exist_ok=True)
        code, said = write_copy(path, target)
        counts[f"{kind} written exit {code}"] += 1
        if not os.path.exists(target):
            counts[f"{kind} no copy"] += 1
            problems.append(f"no copy (exit {code}): {path}: {said}")
            continue
        pairs.append((kind, path, target))
    print(f"written: {len(pairs)} copies, CPU {time.process_time() - start:.1f} s", flush=True)
    results = {}
    python = [(k, p) for kind, path, target in pairs if kind != "sdf" for k, p in ((kind, path), (kind, target))]
    for first in range(0, len(python), BATCH):
        results.update(load(python[first:first + BATCH], args.pinocchio_site, args.timeout))
    for kind, path, target in pairs:
        if kind == "sdf":
            results[path] = load_sdf(args.sdformat_check, path, args.timeout)
            results[target] = load_sdf(args.sdformat_check, target, args.timeout)
        original, copy = results[path], results[target]
        if copy["ok"] is None:
            counts[f"{kind} loader not available"] += 1
        elif copy["ok"] and original["ok"]:
            counts[f"{kind} loads, as its original"] += 1
        elif copy["ok"]:
            counts[f"{kind} loads (its original does not)"] += 1
        elif not original["ok"] and _message(copy["error"].replace(target, path)) == _message(original["error"]):
            counts[f"{kind} fails as its original"] += 1
        else:
            counts[f"{kind} FAILS"] += 1
            problems.append(f"{path}: copy: {copy['error']} | original: {original.get('error', 'loads')}")
    for key in sorted(counts):
        print(f"{counts[key]:5d}  {key}")
    for line in problems:
        print(line)
    print(f"CPU {time.process_time() - start:.1f} s in this process (the loads are children)")
    return 1 if any("FAILS" in k for k in counts) else 0


if __name__ == "__main__":
    sys.exit(main())
