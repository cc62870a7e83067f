"""The links of a MuJoCo Menagerie checkout still refused with ``--repair``, by model, mesh file and cause.

Every model file and ``scene*.xml`` of the checkout (as ``bench_robot_corpus.py --menagerie`` finds them) is read
with ``--geometry collision --density 1000 --repair`` in one process (meshes shared, so each mesh file placed the
same way is integrated once); each link without a result is listed with its model folder, the mesh file the
problem names, and a cause bucket, and the mass bound the refusal quotes (``±79.7 %``) when it quotes one.
The totals (links computed by method, links refused, CPU seconds, load average) are printed first, then a
Markdown table (``--markdown``: one row per model folder and mesh file, the links refused counted over every
file that uses them, so a model's links count once per scene that includes it).

    python benchmarks/bench_robot_refusals.py ROOT [--markdown] [--only FOLDER ...] [--slowest N] [--rows FILE]
"""

from __future__ import annotations

import argparse
import collections
import os
import re
import sys
import time
import warnings

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.dirname(HERE))
sys.path.insert(0, HERE)

from bench_robot_corpus import menagerie_files  # noqa: E402

from inertia_tool.errors import InertiaToolError  # noqa: E402
from inertia_tool.robot import link_inertials, read_robot  # noqa: E402
from inertia_tool.robot.geometry import MeshCache  # noqa: E402

_FILE = re.compile(r"(/[^:]+\.(?:stl|obj|ply|dae|msh|STL|OBJ))")
_BOUND = re.compile(r"mass ±([0-9.]+) %")


def cause_of(problem: str) -> str:
    """A cause bucket for a refused link's ``problem``."""
    if "a shell wound outward lies inside another" in problem:
        return "R4: a shell wound outward inside another (body or cavity undecided) widens the bound"
    if "encloses a volume of" in problem:
        return "self-crossing: the winding estimate encloses no volume"
    if "cannot be bounded usefully" in problem and "winding-number" in problem:
        return "self-crossing: the winding estimate is too loose"
    if "cannot be bounded usefully" in problem:
        return "holes too large for a bounded patch"
    if "is an island in a flat face" in problem or "are islands in a flat face" in problem:
        return "holes: an island in a flat face (nothing bounds the feature's height)"
    if "mesh file missing" in problem or "which does not exist" in problem:
        return "mesh file missing"
    if "encloses no volume" in problem:
        return "encloses no volume (a sheet)"
    return problem.split(":")[0][:60]


#: (CPU seconds, mesh file) of every mesh integrated by :func:`refused_links` (``--slowest``).
MESH_TIMES: list = []


def _timed_mesh_properties():
    """Wrap ``geometry.mesh_properties`` to record the CPU time of each mesh integrated (each mesh once: the run
    shares its meshes)."""
    import inertia_tool.robot.geometry as geometry
    real = geometry.mesh_properties

    def timed(path, **kw):
        start = time.process_time()
        try:
            return real(path, **kw)
        finally:
            MESH_TIMES.append((time.process_time() - start, str(path)))
    geometry.mesh_properties = timed


def refused_links(root: str, only: tuple = ()) -> tuple[list, collections.Counter, float, float]:
    """[(folder, xml, link, mesh file, cause, mass bound % or None, problem)], methods of the links computed,
    CPU seconds and wall seconds."""
    models, scenes = menagerie_files(root)
    cache = MeshCache()
    MESH_TIMES.clear()
    rows: list = []
    methods: collections.Counter = collections.Counter()
    cpu0, wall0 = time.process_time(), time.perf_counter()
    for path in models + scenes:
        rel = os.path.relpath(path, root)
        folder = rel.split(os.sep)[0]
        if only and folder not in only:
            continue
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            try:
                robot = read_robot(path)
                results = link_inertials(robot, density=1000.0, repair=True, mesh_cache=cache)
            except InertiaToolError:
                continue            # files refused whole are bench_robot_corpus.py's table
        for r in results:
            if r.properties is not None:
                methods[r.method] += 1
                continue
            problem = r.problem or ""
            if problem.startswith(("no collision geometry", "every geom is massless")):
                continue
            named = _FILE.search(problem)
            bound = _BOUND.search(problem)
            rows.append((folder, rel, r.name, os.path.basename(named.group(1)) if named else "",
                         cause_of(problem), float(bound.group(1)) if bound else None, problem))
    return rows, methods, time.process_time() - cpu0, time.perf_counter() - wall0


def markdown(rows: list) -> str:
    """One row per (model folder, mesh file, cause): links refused, the files they are in, the mass bound."""
    group: dict = collections.defaultdict(list)
    for folder, rel, link, mesh, cause, bound, _ in rows:
        group[(folder, mesh, cause)].append((rel, link, bound))
    lines = ["| model | mesh file | cause | links refused | mass bound |", "|---|---|---|---|---|"]
    for (folder, mesh, cause), items in sorted(group.items(), key=lambda kv: (-len(kv[1]), kv[0])):
        bounds = sorted({b for _, _, b in items if b is not None})
        said = (f"±{bounds[0]:g} %" if len(bounds) == 1 else f"±{bounds[0]:g}…{bounds[-1]:g} %") if bounds else "—"
        lines.append(f"| {folder} | `{mesh}` | {cause} | {len(items)} | {said} |")
    return "\n".join(lines)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("root")
    parser.add_argument("--markdown", action="store_true")
    parser.add_argument("--only", nargs="*", default=[], help="model folders to run (default: all)")
    parser.add_argument("--slowest", type=int, default=0, metavar="N",
                        help="print the N meshes whose integration took the most CPU time")
    parser.add_argument("--rows", metavar="FILE", help="also write every refused link (with its problem) as JSON")
    args = parser.parse_args(argv)
    if args.slowest:
        _timed_mesh_properties()
    load = os.getloadavg()[0]
    rows, methods, cpu, wall = refused_links(args.root, tuple(args.only))
    print(f"links computed {sum(methods.values())} ({', '.join(f'{k} {v}' for k, v in methods.most_common())}); "
          f"refused {len(rows)}; CPU {cpu:.1f} s, wall {wall:.1f} s, load average {load:.1f} at start")
    for cause, n in collections.Counter(r[4] for r in rows).most_common():
        print(f"  {n:5d}  {cause}")
    if args.slowest:
        total = sum(t for t, _ in MESH_TIMES)
        print(f"  meshes integrated {len(MESH_TIMES)}, {total:.1f} s CPU; the slowest:")
        for seconds, path in sorted(MESH_TIMES, reverse=True)[:args.slowest]:
            print(f"    {seconds:7.2f} s  {os.path.relpath(path, args.root)}")
    if args.rows:
        import json
        with open(args.rows, "w") as sink:
            keys = ("folder", "file", "link", "mesh", "cause", "mass_bound", "problem")
            json.dump([dict(zip(keys, r)) for r in rows], sink, indent=1)
    by_model = collections.Counter(r[0] for r in rows)
    print("  by model: " + ", ".join(f"{k} {v}" for k, v in by_model.most_common()))
    if args.markdown:
        print()
        print(markdown(rows))
    else:
        for _folder, rel, link, mesh, cause, bound, _problem in rows:
            print(f"  {rel}: {link}: {mesh}: {cause}" + (f" (±{bound:g} %)" if bound is not None else ""))
    return 0


if __name__ == "__main__":
    sys.exit(main())
