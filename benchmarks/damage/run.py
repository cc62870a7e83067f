"""Damaged real meshes: inertia_tool's repair against trimesh, MeshFix and the convex hull, in one run.

Reads the cases of ``make_cases.py`` (``benchmarks/out/damage/cases.json``) and hands every tool the same
``(vertices, faces)`` arrays (float64):

- ``inertia_tool``: ``mass_properties((vertices, faces), density=1, repair=True)``.  Whatever bounds it states
  are read from ``props.mesh_report`` (or ``props.mesh``): ``method`` and ``uncertainty`` = (relative mass
  bound, centre-of-mass bound in m, relative inertia bound in the Frobenius norm), as a 3-sequence or an object
  with those three fields; absent fields count as "no bounds".
- ``trimesh``: ``Trimesh(vertices, faces)`` (default processing), ``repair.fill_holes``,
  ``repair.fix_normals``, then ``mass_properties``; flagged when the result is not ``is_volume``.
- ``meshfix``: ``pymeshfix.MeshFix(vertices, faces).repair()``, integrated by trimesh's ``mass_properties``;
  flagged when its output is not watertight.
- ``convex_hull``: trimesh's ``convex_hull`` of the input, then ``mass_properties``; never flagged.

A case is *within tolerance* when the volume is within 1 %, the centre of mass within 1 % of the true solid's
bounding-box diagonal and the central inertia tensor within 2 % (relative Frobenius norm).  It is *silently
wrong* when one of the three errors (relative volume, centre-of-mass distance / diagonal, relative inertia)
exceeds 10 % and the tool said nothing: no error, no damage warning, no stated bound above zero.  Each (tool,
case) runs in a worker process with a time limit (``--timeout``, default 60 s); two workers.

Writes ``benchmarks/out/damage.json`` and prints the tables of ``docs/damage-benchmark.md``.

Run: ``python benchmarks/damage/make_cases.py && python benchmarks/damage/run.py``.
"""

from __future__ import annotations

import argparse
import importlib.metadata
import json
import multiprocessing as mp
import os
import platform
import subprocess
import sys
import time
import traceback
import warnings
from multiprocessing.connection import wait
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[2]
OUT = ROOT / "benchmarks" / "out"
TOOLS = ("inertia_tool", "trimesh", "meshfix", "convex_hull")

VOLUME_RTOL = 0.01
COM_DTOL = 0.01         # of the true solid's bounding-box diagonal
INERTIA_RTOL = 0.02
SILENT_THRESHOLD = 0.10
STARTUP_SECONDS = 300  # a worker's imports and warm-up, not timed
BOUND_SLACK = 1e-9      # round-off allowed beyond a stated bound (relative; for the centre, of the diagonal)


# ----------------------------------------------------------------------------------------------- adapters

def _bounds_of(report):
    """(mass, centre-of-mass, inertia) bounds from a report's ``uncertainty``, or None when not stated.

    Mass and inertia bounds are relative to the reported mass and ‖inertia‖ (Frobenius), the centre-of-mass
    bound a distance in m.
    """
    unc = getattr(report, "uncertainty", None)
    if unc is None:
        return None
    if isinstance(unc, (tuple, list, np.ndarray)) and len(unc) == 3:
        values = list(unc)
    else:
        names = (("mass", "relative_mass", "mass_rtol"),
                 ("center_of_mass", "centre_of_mass", "com", "center_of_mass_distance"),
                 ("inertia", "relative_inertia", "inertia_rtol"))
        values = [next((getattr(unc, n) for n in group if hasattr(unc, n)), None) for group in names]
        if any(x is None for x in values):
            return None
    return [float(x) for x in values]


def run_inertia_tool(vertices, faces):
    import inertia_tool as it
    from inertia_tool.errors import ImplausibleSizeWarning, InertiaToolWarning, NearlyEqualMomentsWarning

    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        props = it.mass_properties((vertices, faces), density=1.0, repair=True)
    flags = [f"{w.category.__name__}: {w.message}" for w in caught
             if issubclass(w.category, InertiaToolWarning)
             and not issubclass(w.category, (NearlyEqualMomentsWarning, ImplausibleSizeWarning))]
    report = getattr(props, "mesh_report", None) or getattr(props, "mesh", None)
    method = getattr(report, "method", None)
    return {"volume": props.volume, "center_of_mass": props.center_of_mass, "inertia": props.inertia,
            "flags": flags, "method": None if method is None else str(method), "bounds": _bounds_of(report)}


def _trimesh_answer(mesh, flags):
    mp_ = mesh.mass_properties
    return {"volume": mp_.volume, "center_of_mass": mp_.center_mass, "inertia": mp_.inertia, "flags": flags,
            "method": None, "bounds": None}


def run_trimesh(vertices, faces):
    import trimesh

    mesh = trimesh.Trimesh(vertices=vertices, faces=faces)
    trimesh.repair.fill_holes(mesh)
    trimesh.repair.fix_normals(mesh)
    return _trimesh_answer(mesh, [] if mesh.is_volume else ["not is_volume after repair"])


def run_meshfix(vertices, faces):
    import pymeshfix
    import trimesh

    fixer = pymeshfix.MeshFix(np.asarray(vertices, dtype=np.float64), np.asarray(faces, dtype=np.int32))
    fixer.repair()
    mesh = trimesh.Trimesh(vertices=fixer.points, faces=fixer.faces, process=False)
    if not len(mesh.faces):
        raise ValueError("MeshFix returned an empty mesh")
    return _trimesh_answer(mesh, [] if mesh.is_watertight else ["output not watertight"])


def run_convex_hull(vertices, faces):
    import trimesh

    return _trimesh_answer(trimesh.Trimesh(vertices=vertices, faces=faces).convex_hull, [])


ADAPTERS = {"inertia_tool": run_inertia_tool, "trimesh": run_trimesh, "meshfix": run_meshfix,
            "convex_hull": run_convex_hull}
REQUIRES = {"inertia_tool": "inertia_tool", "trimesh": "trimesh", "meshfix": "pymeshfix", "convex_hull": "scipy"}


def installed(tool) -> str | None:
    """None when the tool's package imports, else the reason it does not."""
    try:
        __import__(REQUIRES[tool])
    except Exception as exc:   # any failure to import is reported, not hidden
        return f"{type(exc).__name__}: {exc}"
    return None


# ------------------------------------------------------------------------------------------------ workers

def _warm_up():
    """Run every adapter once on a cube, untimed, so that no case pays for imports and first-use set-up."""
    corners = np.array([[x, y, z] for x in (0.0, 1.0) for y in (0.0, 1.0) for z in (0.0, 1.0)])
    faces = np.array([[0, 1, 3], [0, 3, 2], [4, 6, 7], [4, 7, 5], [0, 4, 5], [0, 5, 1],
                      [2, 3, 7], [2, 7, 6], [0, 2, 6], [0, 6, 4], [1, 5, 7], [1, 7, 3]])
    for adapter in ADAPTERS.values():
        try:
            adapter(corners, faces)
        except Exception:   # a missing peer is reported by installed(), not here
            pass


def _worker(conn, cases_dir, checkout):
    sys.path.insert(0, checkout)
    os.environ.setdefault("OMP_NUM_THREADS", "1")
    # the peers' round-off RuntimeWarnings would flood the console; inertia_tool's warnings are recorded
    # inside its adapter (catch_warnings there overrides this)
    warnings.simplefilter("ignore")
    _warm_up()
    conn.send("ready")
    while True:
        task = conn.recv()
        if task is None:
            return
        tool, case_id = task
        data = np.load(Path(cases_dir) / f"{case_id}.npz")
        vertices, faces = data["vertices"], data["faces"]
        start = time.perf_counter()
        try:
            answer = ADAPTERS[tool](vertices, faces)
            elapsed = time.perf_counter() - start
            answer = {k: (np.asarray(v, dtype=float).tolist() if k in ("center_of_mass", "inertia") else v)
                      for k, v in answer.items()}
            answer["volume"] = float(answer["volume"])
            conn.send({"status": "answer", "seconds": elapsed, **answer})
        except Exception as exc:   # the tool refused or failed: recorded as "said so"
            elapsed = time.perf_counter() - start
            line = str(exc).splitlines()[0] if str(exc) else ""
            conn.send({"status": "error", "seconds": elapsed, "error": f"{type(exc).__name__}: {line}"[:300],
                       "where": traceback.format_exc(limit=-1).splitlines()[-2:-1]})


class _Slot:
    """One worker process and the (tool, case) task it runs, if any."""

    def __init__(self, ctx, cases_dir, checkout):
        self.ctx, self.cases_dir, self.checkout = ctx, str(cases_dir), str(checkout)
        self.task = None
        self.deadline = None
        self._start()

    def _start(self):
        self.parent, child = self.ctx.Pipe()
        self.process = self.ctx.Process(target=_worker, args=(child, self.cases_dir, self.checkout), daemon=True)
        self.process.start()
        child.close()
        if not self.parent.poll(STARTUP_SECONDS) or self.parent.recv() != "ready":
            self.process.kill()
            raise RuntimeError(f"a benchmark worker did not start within {STARTUP_SECONDS} s")

    def restart(self):
        """Kill this slot's own worker (stuck or dead) and start a fresh one."""
        self.process.kill()
        self.process.join()
        self._start()

    def close(self):
        self.parent.send(None)
        self.process.join(timeout=10)


def run_all(tasks, cases_dir, timeout, workers=2, progress=None, checkout=ROOT):
    """Run (tool, case_id) tasks on ``workers`` processes; a task past ``timeout`` s kills its worker.

    The workers import ``inertia_tool`` from ``checkout`` (a repository's root).
    """
    ctx = mp.get_context("spawn")
    slots = [_Slot(ctx, cases_dir, checkout) for _ in range(workers)]
    pending = list(tasks)
    results = {}
    late = {"status": "timeout", "seconds": timeout, "error": f"over {timeout:g} s"}
    while pending or any(s.task for s in slots):
        for s in slots:
            if s.task is None and pending:
                s.task = pending.pop(0)
                s.deadline = time.monotonic() + timeout
                s.parent.send(s.task)
        busy = [s for s in slots if s.task]
        ready = wait([s.parent for s in busy], timeout=max(0.0, min(s.deadline for s in busy) - time.monotonic()))
        now = time.monotonic()
        for s in busy:
            if s.parent in ready:
                try:
                    result = s.parent.recv()
                    if result["seconds"] > timeout:    # finished, but late: the limit decides
                        result = late
                except EOFError:                       # the worker died (e.g. a crash in native code)
                    result = {"status": "error", "seconds": float("nan"),
                              "error": f"worker died (exit code {s.process.exitcode})"}
                    s.restart()
            elif now >= s.deadline:
                result = late
                s.restart()
            else:
                continue
            results[s.task] = result
            if progress:
                progress(s.task, result)
            s.task = None
    for s in slots:
        s.close()
    return results


# ------------------------------------------------------------------------------------------------ scoring

def score(case, result):
    """Errors of an answer against the case's truth, and whether the tool said something was off."""
    truth = case["truth"]
    out = {"status": result["status"], "seconds": result["seconds"], "error": result.get("error")}
    if result["status"] != "answer":
        return {**out, "said_so": True}
    volume_err = abs(result["volume"] - truth["volume"]) / abs(truth["volume"])
    com_err = float(np.linalg.norm(np.subtract(result["center_of_mass"], truth["center_of_mass"]))) / truth["diagonal"]
    true_inertia = np.asarray(truth["inertia"])
    inertia_err = float(np.linalg.norm(np.asarray(result["inertia"]) - true_inertia) / np.linalg.norm(true_inertia))
    errors = [volume_err, com_err, inertia_err]
    if not np.all(np.isfinite(errors)):
        errors = [float("inf")] * 3
    bounds = result.get("bounds")
    stated = bounds is not None and any(b > 0 for b in bounds)
    contains = None
    if bounds is not None:
        # the bounds are relative to the reported values: |m − m_true| ≤ b_m·m, ‖I − I_true‖ ≤ b_I·‖I‖
        diag = truth["diagonal"]
        volume_gap = abs(result["volume"] - truth["volume"])
        inertia_gap = float(np.linalg.norm(np.asarray(result["inertia"]) - true_inertia))
        contains = bool(volume_gap <= (bounds[0] + BOUND_SLACK) * abs(result["volume"])
                        and com_err * diag <= bounds[1] + BOUND_SLACK * diag
                        and inertia_gap <= (bounds[2] + BOUND_SLACK) * float(np.linalg.norm(result["inertia"])))
    within = volume_err <= VOLUME_RTOL and com_err <= COM_DTOL and inertia_err <= INERTIA_RTOL
    return {**out, "volume_error": volume_err, "com_error": com_err, "inertia_error": inertia_err,
            "within": {"volume": volume_err <= VOLUME_RTOL, "com": com_err <= COM_DTOL,
                       "inertia": inertia_err <= INERTIA_RTOL, "all": within},
            "flags": result.get("flags", []), "method": result.get("method"), "bounds": bounds,
            "bounds_contain": contains, "said_so": bool(result.get("flags")) or stated}


def summarise(cases, scored, tool):
    rows = [scored[(tool, c["id"])] for c in cases]
    n = len(rows)
    answered = [r for r in rows if r["status"] == "answer"]
    bounded = [r for r in answered if r["bounds"] is not None]
    silent = [r for r in answered if max(r["volume_error"], r["com_error"], r["inertia_error"]) > SILENT_THRESHOLD
              and not r["said_so"]]
    seconds = np.array([r["seconds"] for r in rows if np.isfinite(r["seconds"])])
    return {"cases": n, "answered": len(answered),
            "errors": sum(r["status"] == "error" for r in rows),
            "timeouts": sum(r["status"] == "timeout" for r in rows),
            "within_volume": sum(r["within"]["volume"] for r in answered),
            "within_com": sum(r["within"]["com"] for r in answered),
            "within_inertia": sum(r["within"]["inertia"] for r in answered),
            "within_all": sum(r["within"]["all"] for r in answered),
            "flagged_answers": sum(r["said_so"] for r in answered),
            "bounds_stated": len(bounded), "bounds_contain": sum(bool(r["bounds_contain"]) for r in bounded),
            "silent_over_10pct": len(silent),
            "median_seconds": float(np.median(seconds)) if len(seconds) else None,
            "mean_seconds": float(np.mean(seconds)) if len(seconds) else None,
            "max_seconds": float(np.max(seconds)) if len(seconds) else None}


def _pct(k, n):
    return f"{100 * k / n:.0f} %" if n else "–"


def tables(cases, scored, available, missing):
    """The summary table (one row per tool, missing ones named) and the per-class table, as Markdown."""
    lines = ["| tool | answered | volume ≤ 1 % | COM ≤ 1 % diag | inertia ≤ 2 % | all three | bounds stated | "
             "bounds hold | > 10 % off, silent | refused / failed | timeouts | median s/case | mean s/case |",
             "|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
    summaries = {}
    for tool in [t for t in TOOLS if t in available or t in missing]:
        if tool in missing:
            lines.append(f"| {tool} | not installed: {missing[tool]} |" + " |" * 11)
            continue
        s = summaries[tool] = summarise(cases, scored, tool)
        n = s["cases"]
        lines.append(f"| {tool} | {_pct(s['answered'], n)} | {_pct(s['within_volume'], n)} | "
                     f"{_pct(s['within_com'], n)} | "
                     f"{_pct(s['within_inertia'], n)} | **{_pct(s['within_all'], n)}** | {s['bounds_stated']} | "
                     f"{_pct(s['bounds_contain'], s['bounds_stated'])} | {s['silent_over_10pct']} | {s['errors']} | "
                     f"{s['timeouts']} | {s['median_seconds']:.3f} | {s['mean_seconds']:.3f} |")
    classes = list(dict.fromkeys(c["class"] for c in cases))
    lines += ["", "Per damage class: cases within all three tolerances / answers more than 10 % off without a flag "
              "/ refused or failed (of the cases in the class).", "",
              "| class | cases | " + " | ".join(available) + " |", "|---|---|" + "---|" * len(available)]
    for cls in classes:
        members = [c for c in cases if c["class"] == cls]
        cells = []
        for tool in available:
            rows = [scored[(tool, c["id"])] for c in members]
            ok = sum(r["status"] == "answer" and r["within"]["all"] for r in rows)
            silent = sum(r["status"] == "answer" and not r["said_so"]
                         and max(r["volume_error"], r["com_error"], r["inertia_error"]) > SILENT_THRESHOLD
                         for r in rows)
            failed = sum(r["status"] != "answer" for r in rows)
            cells.append(f"{ok} / {silent} / {failed}")
        variants = ", ".join(sorted({c["damage"] for c in members}))
        lines.append(f"| {cls} ({variants}) | {len(members)} | " + " | ".join(cells) + " |")
    return "\n".join(lines), summaries


def _git_commit(checkout) -> str:
    try:
        return subprocess.run(["git", "-C", str(checkout), "rev-parse", "--short", "HEAD"], capture_output=True,
                              text=True, check=True).stdout.strip()
    except (OSError, subprocess.CalledProcessError):
        return "unknown"


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--cases", type=Path, default=OUT / "damage" / "cases.json")
    parser.add_argument("--out", type=Path, default=OUT / "damage.json")
    parser.add_argument("--timeout", type=float, default=60.0, help="seconds per (tool, case)")
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--tools", default=",".join(TOOLS))
    parser.add_argument("--limit", type=int, help="first N cases only (a quick look)")
    parser.add_argument("--inertia-tool", type=Path, default=ROOT, metavar="CHECKOUT",
                        help="root of the checkout whose inertia_tool to measure (default: this one)")
    args = parser.parse_args(argv)
    checkout = args.inertia_tool.resolve()
    sys.path.insert(0, str(checkout))
    manifest = json.loads(args.cases.read_text())
    cases = manifest["cases"][:args.limit]
    wanted = [t for t in TOOLS if t in args.tools.split(",")]
    missing = {t: reason for t in wanted if (reason := installed(t))}
    available = [t for t in wanted if t not in missing]
    tasks = [(tool, c["id"]) for c in cases for tool in available]
    done = [0]

    def progress(task, result):
        done[0] += 1
        if done[0] % 50 == 0 or done[0] == len(tasks):
            print(f"  {done[0]}/{len(tasks)}", flush=True)

    started = time.time()
    raw = run_all(tasks, args.cases.parent / "cases", args.timeout, args.workers, progress, checkout)
    by_id = {c["id"]: c for c in cases}
    scored = {task: score(by_id[task[1]], result) for task, result in raw.items()}
    table, summaries = tables(cases, scored, available, missing)
    import inertia_tool
    versions = {"python": platform.python_version(), "inertia_tool": inertia_tool.__version__,
                "inertia_tool_file": inertia_tool.__file__, "inertia_tool_commit": _git_commit(checkout)}
    for distribution in ("trimesh", "pymeshfix", "manifold3d", "numpy", "scipy"):
        try:
            versions[distribution] = importlib.metadata.version(distribution)
        except importlib.metadata.PackageNotFoundError:
            versions[distribution] = "not installed"
    report = {"source": {k: manifest[k] for k in ("package", "version", "seed")}, "versions": versions,
              "timeout_seconds": args.timeout, "workers": args.workers, "wall_seconds": time.time() - started,
              "missing": missing, "summary": summaries,
              "cases": [{"id": c["id"], "class": c["class"], "damage": c["damage"], "mesh": c["mesh"],
                         "faces": c["faces"], "results": {t: scored[(t, c["id"])] for t in available}} for c in cases]}
    args.out.parent.mkdir(parents=True, exist_ok=True)
    args.out.write_text(json.dumps(report, indent=1, default=float))
    print(table)
    print(f"\n{len(cases)} cases, {time.time() - started:.0f} s wall; versions {versions}; -> {args.out}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
