"""Benchmark of ``spin-it`` (inertia_tool.design) on the shapes of the Spin-It papers, in one run.

    python benchmarks/bench_spin_it.py [--resolutions 32,48,64]

Shapes (built with manifold3d, metres):
* lopsided yo-yo — a 60 mm disc, 12 mm thick, with an 18 mm ball fused off-centre on one face; axis z through
  the origin, wall 2 mm;
* asymmetric top — an ellipsoid (50 × 36 × 24 mm) tilted 20° on a conical tip, with an off-axis handle; pivot
  at the tip, axis z, wall 1.5 mm.

For each resolution: the full pipeline (grid, optimisation, cavity mesh, boolean, exact re-analysis), its time
and the before/after numbers of the re-analysed part.

Then, at the middle resolution, the same with a steel insert allowed (``insert_density=7850``, a second
quadric region, 20 unknowns).

Peer, side by side on the same cells and the same objective: the Spin-It (2014) relaxation — one fill
fraction per cell in [0, 1], L-BFGS-B with the exact gradient through the moments, then thresholded at 1/2 —
against the quadric cavity (Hafner et al. 2024, 10 unknowns).  Reported: the objective of each sharp cavity on
the cells, and the optimisation times with their ratio.

    python benchmarks/bench_spin_it.py --parts 48,128

Per part (the bundled ``meshes/`` parts, the two shapes above and a thin finely tessellated top like trimesh's
``fixed_top.ply``), each in a fresh process: ``spin_it_verified`` (what the command runs) at each resolution,
its CPU time and peak resident memory (``ru_maxrss``, interpreter and imports included), and the load average.
"""

import argparse
import math
import sys
import time
from pathlib import Path

import manifold3d
import numpy as np
from scipy.optimize import minimize

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from inertia_tool.design import spin_it  # noqa: E402
from inertia_tool.design.grid import interior_grid  # noqa: E402
from inertia_tool.design.hollow import DEPTH_MARGIN, _exact_near_wall, design_frame  # noqa: E402
from inertia_tool.design.moments import (cell_moment_rows, moment_vector,  # noqa: E402
                                         top_objective, top_threshold_measure, yoyo_objective)
from inertia_tool.design.optimize import _gradient_in_moments, _moment_scales, optimize_quadric_cavity  # noqa: E402
from inertia_tool.mass.pipeline import mass_properties  # noqa: E402


def _arrays(solid):
    mesh = solid.to_mesh64()
    return np.asarray(mesh.vert_properties)[:, :3].copy(), np.asarray(mesh.tri_verts).astype(np.int64)


def lopsided_yoyo():
    disc = manifold3d.Manifold.cylinder(0.012, 0.03, 0.03, 96).translate([0, 0, -0.006])
    bump = manifold3d.Manifold.sphere(0.009, 48).translate([0.016, 0.004, 0.006])
    return _arrays(disc + bump)


def asymmetric_top():
    body = manifold3d.Manifold.sphere(1.0, 64).scale([0.025, 0.018, 0.012]).rotate([20, 0, 0]).translate(
        [0.002, 0, 0.016])
    tip = manifold3d.Manifold.cylinder(0.008, 0.0005, 0.007, 48)
    handle = manifold3d.Manifold.cylinder(0.02, 0.003, 0.003, 32).translate([0.004, 0.002, 0.022])
    return _arrays(body + tip + handle)


CASES = [
    ("lopsided yo-yo", lopsided_yoyo, dict(mode="yoyo", axis=[0, 0, 1], through=[0, 0, 0], wall=0.002)),
    ("asymmetric top", asymmetric_top, dict(mode="top", axis=[0, 0, 1], pivot=[0, 0, 0], wall=0.0015)),
]


def _cells_problem(vertices, faces, spec, resolution):
    """The cells, unit-density part moments and objective exactly as spin_it sets them up."""
    props = mass_properties((vertices, faces), material="PLA")
    extent = float(np.max(vertices.max(axis=0) - vertices.min(axis=0)))
    size = float(np.linalg.norm(vertices.max(axis=0) - vertices.min(axis=0)))
    h = extent / resolution
    wall = spec["wall"]
    grid = _exact_near_wall(interior_grid(vertices, faces, spacing=h), vertices, faces, wall)
    deep = grid.inside & (grid.signed_distance >= wall + DEPTH_MARGIN * h)
    origin = np.asarray(spec.get("through", spec.get("pivot")), dtype=float)
    frame = design_frame(np.asarray(spec["axis"], float))
    points = (grid.centers(np.nonzero(deep)) - origin) @ frame
    mu_part = moment_vector(props, origin, frame) / props.density
    if spec["mode"] == "yoyo":
        def objective(mu):
            return yoyo_objective(mu, size=size, center_weight=1e4, product_weight=1e4, axis_through_origin=True)
    else:
        reference = top_threshold_measure(mu_part)

        def objective(mu):
            return top_objective(mu, size=size, center_weight=1e4, product_weight=1e4,
                                 reference_threshold=reference)
    return mu_part, points, h, size, objective


def voxel_relaxation(objective, mu_part, points, h, size, max_iterations=500):
    """Spin-It (2014) style: fill fraction per cell, L-BFGS-B in [0, 1]^n, gradient through the moments."""
    psi = cell_moment_rows(points, h)
    scales = _moment_scales(mu_part, size)
    started = time.perf_counter()

    def f(fill):
        mu = mu_part - np.einsum("ij,i->j", psi, 1.0 - fill)
        value = objective(mu)
        g_mu = _gradient_in_moments(objective, mu, scales, value)
        return value, np.einsum("ij,j->i", psi, g_mu)

    result = minimize(f, np.ones(len(points)), jac=True, method="L-BFGS-B", bounds=[(0.0, 1.0)] * len(points),
                      options={"maxiter": max_iterations})
    removed = result.x < 0.5
    sharp = objective(mu_part - psi[removed].sum(axis=0))
    return sharp, time.perf_counter() - started, int(result.nit)


def _row(name, m, mode):
    if mode == "yoyo":
        return (f"{name}: I_axis/I_next {m.moment_ratio:.4f}, tilt {math.degrees(m.axis_tilt):.3f}°, "
                f"COM offset {m.axis_offset * 1e3:.3f} mm, c = {m.epsilon_coefficient:.4f}, mass {m.mass * 1e3:.2f} g")
    return (f"{name}: sleeping threshold {m.sleeping_threshold:.2f} rad/s "
            f"({m.sleeping_threshold * 60 / (2 * math.pi):.0f} rpm), asymmetry {m.transverse_asymmetry:.4f}, "
            f"COM offset {m.axis_offset * 1e3:.3f} mm, tilt {math.degrees(m.axis_tilt):.3f}°, "
            f"l {m.height * 1e3:.2f} mm, mass {m.mass * 1e3:.2f} g")


PARTS = [
    ("washer", "meshes/washer.stl", dict(mode="yoyo", axis=[0, 0, 1], wall=1.5e-3)),
    ("torus", "meshes/torus.stl", dict(mode="yoyo", axis=[0, 0, 1], wall=2e-3)),
    ("spinning_top", "meshes/spinning_top.stl", dict(mode="top", axis=[0, 0, 1], pivot=[0, 0, 0], wall=2e-3)),
    ("t_handle", "meshes/t_handle.stl", dict(mode="yoyo", axis=[0, 0, 1], wall=2e-3)),
    ("cone", "meshes/cone.stl", dict(mode="yoyo", axis=[0, 0, 1], wall=2e-3)),
    ("box", "meshes/box.stl", dict(mode="yoyo", axis=[0, 0, 1], wall=2e-3)),
    ("octahedron", "meshes/octahedron.stl", dict(mode="yoyo", axis=[0, 0, 1], wall=2e-3)),
    ("hollow_sphere", "meshes/hollow_sphere.stl", dict(mode="yoyo", axis=[0, 0, 1], wall=1e-3)),
    ("unbalanced_wheel", "meshes/unbalanced_wheel.stl", dict(mode="yoyo", axis=[0, 0, 1], wall=3e-3)),
    ("lopsided_yoyo", "@lopsided_yoyo", dict(mode="yoyo", axis=[0, 0, 1], through=[0, 0, 0], wall=2e-3)),
    ("asymmetric_top", "@asymmetric_top", dict(mode="top", axis=[0, 0, 1], pivot=[0, 0, 0], wall=1.5e-3)),
    ("thin_top", "@thin_top", dict(mode="top", axis=[0, 0, 1], pivot=[0, 0, 0], wall=1e-3)),
]


def thin_top():
    """Like trimesh's fixed_top.ply: a thin disc (r 30 mm, 4 mm) on a cone tip with a stem, 3,580 triangles."""
    disc = manifold3d.Manifold.cylinder(0.004, 0.030, 0.030, 512).translate([0, 0, 0.008])
    tip = manifold3d.Manifold.cylinder(0.008, 0.0004, 0.010, 256)
    stem = manifold3d.Manifold.cylinder(0.020, 0.003, 0.003, 128).translate([0, 0, 0.010])
    return _arrays(disc + tip + stem)


def _one_part(name, resolution):
    """Child process: run one part, print one JSON line."""
    import json
    import resource
    import warnings

    from inertia_tool.design.verify import spin_it_verified
    warnings.simplefilter("ignore")
    _, path, spec = next(p for p in PARTS if p[0] == name)
    root = Path(__file__).resolve().parents[1]
    source, units = (globals()[path[1:]](), None) if path.startswith("@") else (str(root / path), "mm")
    cpu = time.process_time()
    try:
        result, verdicts = spin_it_verified(source, units=units, material="PLA", resolution=resolution, **spec)
        out = dict(ok=True, resolution=verdicts[-1].resolution, removed=result.removed_cells)
    except Exception as exc:                  # a rejected design is a result here, not a failure
        out = dict(ok=False, error=type(exc).__name__)
    out.update(cpu=time.process_time() - cpu, peak_mb=resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024)
    print(json.dumps(out))


def parts(resolutions):
    import json
    import os
    import subprocess
    for resolution in resolutions:
        print(f"== resolution {resolution}; load average {os.getloadavg()[0]:.1f}")
        cpus = []
        for name, _, _ in PARTS:
            run = subprocess.run([sys.executable, __file__, "--one", name, str(resolution)], capture_output=True,
                                 text=True, env=dict(os.environ, OPENBLAS_NUM_THREADS="1"))
            row = json.loads(run.stdout.strip().splitlines()[-1])
            cpus.append(row["cpu"])
            what = f"resolution {row['resolution']}" if row["ok"] else row["error"]
            print(f"  {name:18s} CPU {row['cpu']:6.2f} s  peak {row['peak_mb']:6.0f} MB  ({what})")
        print(f"  median CPU {float(np.median(cpus)):.2f} s; load average {os.getloadavg()[0]:.1f}")


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--resolutions", default="32,48,64")
    parser.add_argument("--parts", help="resolutions for the per-part CPU time and memory table, e.g. 48,128")
    parser.add_argument("--one", nargs=2, help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.one:
        return _one_part(args.one[0], int(args.one[1]))
    if args.parts:
        return parts([int(r) for r in args.parts.split(",")])
    resolutions = [int(r) for r in args.resolutions.split(",")]
    for name, build, spec in CASES:
        vertices, faces = build()
        print(f"== {name} ({len(faces)} triangles)")
        for resolution in resolutions:
            started = time.perf_counter()
            result = spin_it((vertices, faces), material="PLA", resolution=resolution, **spec)
            total = time.perf_counter() - started
            print(f"  resolution {resolution}: {total:.2f} s in all (optimisation {result.optimisation_seconds:.2f} s, "
                  f"{result.allowed_cells} cells, {result.removed_cells} removed), "
                  f"wall {result.measured_wall * 1e3:.3f} mm ≥ {result.wall * 1e3:.1f} mm; "
                  f"objective {result.objective_before:.4g} → "
                  f"{result.objective_after:.4g} (exact)")
            if resolution == resolutions[0]:
                print("    " + _row("before", result.metrics_before, spec["mode"]))
            print("    " + _row("after ", result.metrics_after, spec["mode"]))
        resolution = resolutions[len(resolutions) // 2]
        started = time.perf_counter()
        result = spin_it((vertices, faces), material="PLA", resolution=resolution, insert_density=7850.0, **spec)
        total = time.perf_counter() - started
        grams = 0.0 if result.insert is None else result.insert.mass * 1e3
        print(f"  resolution {resolution} with a steel insert ({grams:.2f} g): {total:.2f} s in all (optimisation "
              f"{result.optimisation_seconds:.2f} s); objective {result.objective_before:.4g} → "
              f"{result.objective_after:.4g} (exact)")
        print("    " + _row("after ", result.metrics_after, spec["mode"]))
        mu_part, points, h, size, objective = _cells_problem(vertices, faces, spec, resolution)
        quadric = optimize_quadric_cavity(objective, mu_part, points, h, size=size)
        relaxed, relaxed_seconds, iterations = voxel_relaxation(objective, mu_part, points, h, size)
        print(f"  cells at resolution {resolution} ({len(points)} cells), "
              f"objective {quadric.objective_solid:.4g} solid:")
        print(f"    quadric (10 unknowns):       objective {quadric.objective:.4g} in {quadric.seconds:.2f} s")
        print(f"    voxel relaxation ({len(points)} unknowns, {iterations} L-BFGS-B iterations): objective "
              f"{relaxed:.4g} in {relaxed_seconds:.2f} s")
        print(f"    time ratio relaxation / quadric: {relaxed_seconds / quadric.seconds:.1f}×; objective ratio "
              f"quadric / relaxation: {quadric.objective / relaxed:.3f}")


if __name__ == "__main__":
    main()
