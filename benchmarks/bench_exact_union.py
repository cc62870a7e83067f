"""Links the tool estimates with ``--repair`` against the solid built by an exact boolean (independent code).

For every link of a robot description that ``link_inertials(..., repair=True)`` answers as an ``estimate``, each
mesh of the link is rebuilt as the solid its surface encloses, {winding number > 0}, by libigl's CGAL boolean
(``igl.copyleft.cgal.mesh_boolean(V, F, [], [], "union")``: exact predicates and constructions, self-crossings
and coplanar overlaps resolved, the result rounded to float64 once), integrated exactly as a closed surface, and
placed and weighted as the tool places and weights the element.  The table says how far the tool's estimate is
from that solid and whether the estimate's stated bounds (its ``uncertainty``) hold.  A mesh with holes has no
such solid (libigl's winding number of an open surface is not an integer): its links are reported as skipped.

Written for issue 23 (scenes19): TALOS's 8 gripper links (``pal_talos`` in Menagerie, ``talos_data`` in
example-robot-data), whose collision meshes hold coplanar overlapping bodies that also cross.

    python benchmarks/bench_exact_union.py DESCRIPTION [--density 1000] [--package NAME=DIR] [--geometry collision]
"""

from __future__ import annotations

import argparse
import os
import sys
import time
import warnings

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.dirname(HERE))
sys.path.insert(0, HERE)

from bench_robot_corpus import _bounds_hold, _difference, _massless  # noqa: E402

from inertia_tool.integrals import second_moment_to_inertia, volume_moments  # noqa: E402
from inertia_tool.mass.properties import MassProperties, combine  # noqa: E402
from inertia_tool.mesh.read import load_mesh  # noqa: E402
from inertia_tool.robot import link_inertials, read_robot  # noqa: E402
from inertia_tool.robot.geometry import _placed, element_mass_properties  # noqa: E402


def exact_union(vertices: np.ndarray, faces: np.ndarray) -> MassProperties:
    """Unit-density mass properties of {winding number > 0} of the surface ``(vertices, faces)``, built by
    libigl's CGAL boolean; raises ValueError where libigl refuses the surface or its result is not closed (an
    open input)."""
    import igl.copyleft.cgal as cgal
    none_v, none_f = np.zeros((0, 3)), np.zeros((0, 3), dtype=np.int64)
    try:
        v, f, _ = cgal.mesh_boolean(np.asarray(vertices, dtype=np.float64), np.asarray(faces, dtype=np.int64),
                                    none_v, none_f, "union")
    except RuntimeError as exc:     # libigl refuses a surface that is not closed ("Mesh boolean failed")
        raise ValueError(f"libigl's boolean refuses the surface, not closed ({exc})") from None
    edges = np.sort(np.concatenate([f[:, [0, 1]], f[:, [1, 2]], f[:, [2, 0]]]), axis=1)
    _, counts = np.unique(edges, axis=0, return_counts=True)
    if len(f) == 0 or np.any(counts % 2):
        raise ValueError("the boolean's surface is not closed (the input has holes)")
    moments = volume_moments(v, f)
    return MassProperties(mass=moments.volume, volume=moments.volume, center_of_mass=moments.centroid,
                          inertia=second_moment_to_inertia(moments.second_moment), density=1.0)


def reference(link, density: float) -> MassProperties:
    """The link rebuilt at ``density`` with every mesh replaced by its exact union (primitives as the tool)."""
    weighted = []
    for element in link.elements:
        if _massless(element):
            continue
        if element.kind == "mesh":
            placed = _placed(load_mesh(element.mesh, units="m"), element)
            unit = exact_union(placed.vertices, placed.faces).transformed(rotation=element.rotation,
                                                                          translation=element.translation)
        else:
            unit = element_mass_properties(element)
        weighted.append(MassProperties(mass=unit.mass * density, volume=unit.volume,
                                       center_of_mass=unit.center_of_mass, inertia=unit.inertia * density,
                                       density=density))
    return weighted[0] if len(weighted) == 1 else combine(weighted)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("description")
    parser.add_argument("--density", type=float, default=1000.0)
    parser.add_argument("--geometry", default="collision")
    parser.add_argument("--package", action="append", default=[], metavar="NAME=DIR")
    args = parser.parse_args(argv)
    packages = dict(p.split("=", 1) for p in args.package)
    warnings.simplefilter("ignore")
    robot = read_robot(args.description, packages=packages, geometry=args.geometry, missing_meshes="per-link")
    start = time.process_time()
    results = link_inertials(robot, density=args.density, repair=True)
    print(f"{args.description}: {len(results)} links, tool --repair {time.process_time() - start:.1f} s CPU")
    held = total = 0
    for link, result in zip(robot.links, results):
        if result.method != "estimate":
            continue
        start = time.process_time()
        try:
            solid = reference(link, args.density)
        except ValueError as exc:
            print(f"  {link.name}: skipped ({exc})")
            continue
        props, bound = result.properties, result.uncertainty
        ok = _bounds_hold(result, solid.mass, solid.center_of_mass, solid.inertia)
        total, held = total + 1, held + ok
        print(f"  {link.name}: mass {abs(props.mass / solid.mass - 1):.2e} (bound {bound.mass:.2e}), centre "
              f"{np.linalg.norm(props.center_of_mass - solid.center_of_mass):.2e} m (bound {bound.center_of_mass:.2e}),"
              f" tensor {np.linalg.norm(props.inertia - solid.inertia) / np.linalg.norm(props.inertia):.2e} (bound "
              f"{bound.inertia if bound.inertia is not None else float('nan'):.2e}); overall "
              f"{_difference(props, solid.mass, solid.center_of_mass, solid.inertia):.2e}; bounds "
              f"{'hold' if ok else 'FAIL'} ({time.process_time() - start:.2f} s CPU)")
    print(f"estimates checked: {total}, bounds hold: {held}")
    return 0 if held == total else 1


if __name__ == "__main__":
    raise SystemExit(main())
