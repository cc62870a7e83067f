"""A robot corpus (MuJoCo Menagerie and other MJCF/URDF/SDF trees) through ``inertia-tool robot``, link by link,
and every MJCF body against MuJoCo's own compiler.

For each description that :func:`inertia_tool.robot.corpus.find_descriptions` finds under the folders given:

* read it and compute every link (the settings of ``--geometry``, ``--density``, ``--repair``), with the CPU
  time of each model;
* count links answered by method and links without a result by cause (the first words of their ``problem``);
* for MJCF models, compile the file with MuJoCo (``mujoco.MjSpec``; ``inertiafromgeom="true"``, every mesh's
  ``inertia="exact"``, so that MuJoCo integrates the geometry as this tool does) and compare each body's
  mass, centre of mass and inertia tensor (``body_mass``, ``body_ipos``, ``body_inertia`` in ``body_iquat``)
  with the tool's, computed with ``geometry="all"`` and ``density="model"`` (every geom in
  ``inertiagrouprange`` at its own density, as MuJoCo's inertia from geometry).  The figure is the relative
  difference ``max(|Δm|/m, |Δc|/size, ‖ΔI‖/‖I‖)`` per body, ``size`` the body's radius of gyration.
  Bodies where MuJoCo and the tool disagree by more than ``--rtol`` are listed with both values.

MuJoCo is not the truth for an open or self-overlapping mesh (its exact mode integrates the signed volume of
whatever it is given, or refuses the mesh); the tool's certificate says which bodies were exact.  The table
therefore splits the agreement by the tool's method.

    python benchmarks/bench_robot_corpus.py DIR [DIR ...] [--repair] [--geometry collision] [--no-mujoco]
        [--package NAME=DIR]
"""

from __future__ import annotations

import argparse
import collections
import os
import re
import sys
import time
import warnings

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.dirname(HERE))

from inertia_tool.errors import InertiaToolError  # noqa: E402
from inertia_tool.robot import link_inertials, read_robot  # noqa: E402
from inertia_tool.robot.corpus import find_descriptions  # noqa: E402


def _cause(problem: str) -> str:
    """A short name for a link's problem (the part before the file name or the first colon)."""
    for key in ("mesh needs repair", "every geom is massless", "no collision geometry", "no visual geometry",
                "no all geometry", "cannot be computed", "no declared mass"):
        if problem.startswith(key):
            if key == "mesh needs repair":
                for detail in ("not closed", "open", "inconsistently", "self-intersect", "crossing", "zero volume",
                               "negative volume", "inside out", "no outward", "refused"):
                    if detail in problem:
                        return f"{key} ({detail})"
            return key
    return problem.split(":")[0][:60]


_MESH_NAMED = re.compile(r"mesh '([^']+)'|: (\S+)$")


def mujoco_bodies(path: str, *, max_refusals: int = 200):
    """name → (mass, centre, tensor in body axes) from MuJoCo, inertia from geometry with exact meshes; and
    the bodies left out because MuJoCo refuses the exact inertia of one of their meshes (that mesh is then
    compiled with the model's own mesh inertia, so that the rest of the model can be compared)."""
    import mujoco
    spec = mujoco.MjSpec.from_file(path)
    spec.compiler.inertiafromgeom = mujoco.mjtInertiaFromGeom.mjINERTIAFROMGEOM_TRUE
    for mesh in spec.meshes:
        mesh.inertia = mujoco.mjtMeshInertia.mjMESH_INERTIA_EXACT
    refused: dict = {}
    for _ in range(max_refusals):
        try:
            model = spec.compile()
            break
        except ValueError as exc:
            text = str(exc).splitlines()[0]
            match = _MESH_NAMED.search(text)
            name = match and (match.group(1) or match.group(2))
            mesh = spec.mesh(name) if name else None
            if mesh is None or name in refused:
                raise
            refused[name] = text
            mesh.inertia = mujoco.mjtMeshInertia.mjMESH_INERTIA_CONVEX
    else:
        raise ValueError(f"MuJoCo refused more than {max_refusals} meshes")
    skipped = {}
    for g in range(model.ngeom):
        if model.geom_type[g] == mujoco.mjtGeom.mjGEOM_MESH:
            mesh_name = model.mesh(model.geom_dataid[g]).name
            if mesh_name in refused:
                skipped[int(model.geom_bodyid[g]) - 1] = f"MuJoCo: {refused[mesh_name]}"
    out = []
    for i in range(1, model.nbody):
        rot = np.zeros(9)
        mujoco.mju_quat2Mat(rot, model.body_iquat[i])
        rot = rot.reshape(3, 3)
        out.append((model.body(i).name, float(model.body_mass[i]), model.body_ipos[i].copy(),
                    rot @ np.diag(model.body_inertia[i]) @ rot.T))
    return out, skipped


def compare(path: str, rtol: float, repair: bool) -> tuple[list, list, str | None]:
    """[(body, method, difference)], [disagreement lines], problem of the MuJoCo compile (or None)."""
    try:
        reference, skipped = mujoco_bodies(path)
    except Exception as exc:   # noqa: BLE001 -- MuJoCo's own refusal is a finding, reported as such
        return [], [], f"MuJoCo refuses it: {str(exc).splitlines()[0][:160]}"
    robot = read_robot(path, geometry="all")
    ours = link_inertials(robot, density="model", repair=repair)
    rows, lines = [], []
    if len(ours) != len(reference):
        return [], [f"  {len(ours)} links against MuJoCo's {len(reference)} bodies"], None
    for index, (mine, (name, mass, com, tensor)) in enumerate(zip(ours, reference)):
        if name and mine.name != name:
            lines.append(f"  body {name!r} of MuJoCo is the tool's {mine.name!r}")
            continue
        if index in skipped:
            rows.append((name, "mujoco refused", float("nan")))
            continue
        if mine.properties is None:
            rows.append((name, "none", float("nan")))
            continue
        props = mine.properties
        if mass == 0:
            diff = 0.0 if props.mass == 0 else float("inf")
        else:
            size = max(np.sqrt(np.trace(tensor) / (2 * mass)), 1e-12)
            diff = max(abs(props.mass - mass) / mass, float(np.linalg.norm(props.center_of_mass - com)) / size,
                       float(np.linalg.norm(props.inertia - tensor) / max(np.linalg.norm(tensor), 1e-300)))
        rows.append((name, mine.method or "?", diff))
        if not diff <= rtol:
            lines.append(f"  {name} [{mine.method}]: {diff:.2e}  mass {props.mass:.6g} vs MuJoCo {mass:.6g}, "
                         f"com {np.array2string(props.center_of_mass, precision=5)} vs "
                         f"{np.array2string(com, precision=5)}")
    return rows, lines, None


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("folders", nargs="+")
    parser.add_argument("--geometry", default="collision")
    parser.add_argument("--density", default="1000")
    parser.add_argument("--repair", action="store_true")
    parser.add_argument("--no-mujoco", action="store_true")
    parser.add_argument("--rtol", type=float, default=1e-6)
    parser.add_argument("--package", action="append", default=[], metavar="NAME=DIR")
    parser.add_argument("--verbose", action="store_true", help="print every link without a result")
    args = parser.parse_args(argv)
    density = args.density if args.density == "model" else float(args.density)
    packages = dict(item.split("=", 1) for item in args.package)
    models = find_descriptions(args.folders)
    answered: collections.Counter = collections.Counter()
    causes: collections.Counter = collections.Counter()
    unreadable: list = []
    agreement: dict = collections.defaultdict(list)
    disagreements: list = []
    mujoco_refusals: list = []
    cpu_total = 0.0
    links_total = 0
    for path in models:
        start = time.process_time()
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            try:
                robot = read_robot(path, geometry=args.geometry, packages=packages)
                results = link_inertials(robot, density=density, repair=args.repair)
            except InertiaToolError as exc:
                unreadable.append(f"{path}: {exc}")
                cpu_total += time.process_time() - start
                continue
            except Exception as exc:   # noqa: BLE001 -- a crash is the finding
                unreadable.append(f"{path}: CRASH {type(exc).__name__}: {exc}")
                cpu_total += time.process_time() - start
                continue
            cpu = time.process_time() - start
            cpu_total += cpu
            links_total += len(results)
            for r in results:
                if r.properties is not None:
                    answered[r.method] += 1
                else:
                    causes[_cause(r.problem)] += 1
                    if args.verbose:
                        print(f"  {os.path.relpath(path)}: {r.name}: {r.problem[:300]}")
            if robot.format == "mjcf" and not args.no_mujoco:
                try:
                    rows, lines, refused = compare(path, args.rtol, args.repair)
                except Exception as exc:   # noqa: BLE001
                    rows, lines, refused = [], [], f"comparison crashed: {type(exc).__name__}: {exc}"
                if refused:
                    mujoco_refusals.append(f"{path}: {refused}")
                for _, method, diff in rows:
                    agreement[method].append(diff)
                if lines:
                    disagreements.append(f"{path}:")
                    disagreements.extend(lines)
        print(f"{cpu:7.2f} s  {len(results):3d} links  {path}", flush=True)
    print(f"\n{len(models)} descriptions, {len(unreadable)} unreadable, {links_total} links: "
          f"{sum(answered.values())} answered ({dict(answered)}), {sum(causes.values())} without a result; "
          f"CPU {cpu_total:.1f} s")
    for cause, n in causes.most_common():
        print(f"  {n:4d}  {cause}")
    for line in unreadable:
        print(f"unreadable: {line[:400]}")
    if agreement:
        print("\nagainst MuJoCo (geometry all, the model's densities, exact mesh inertia), per body:")
        for method, diffs in sorted(agreement.items()):
            d = np.array(diffs)
            finite = d[np.isfinite(d)]
            within = int(np.sum(finite <= args.rtol))
            print(f"  {method:10s} {len(d):4d} bodies, {within} within {args.rtol:g}"
                  + (f", median {np.median(finite):.1e}, max {finite.max():.1e}" if finite.size else ""))
        for line in mujoco_refusals:
            print(f"  {line}")
        for line in disagreements:
            print(line[:400])
    return 0


if __name__ == "__main__":
    sys.exit(main())
