"""Who is right where the tool and MuJoCo disagree on a welded mesh: the exact integrals of the triangles.

For each mesh file: the volume, centre and central inertia (unit density) of

* the file's triangles **as read** (no weld), summed exactly in integers (every float is a dyadic rational;
  ``∫x_i x_j dV`` of the tetrahedron (0, a, b, c) is ``det/120 · (Σ_k v_ki v_kj + S_i S_j)``, Tonon 2004),
  with the coordinates as parsed (float64) and rounded to float32 (MuJoCo stores vertices in float32);
* MuJoCo's compiler (a one-body model, ``inertia="exact"``, density 1);
* the tool (``mass_properties``: the weld, its estimate and its bounds).

It prints each one's relative difference from the exact float32 sum (mass, centre over the radius of gyration,
Frobenius of the tensor) and whether the exact sums lie within the tool's stated bounds.  The surface as read is
not closed where the weld merges vertices (cracks of ~1e-7 m), so its integral is the signed-volume integral
MuJoCo takes, not a solid's; the tool's bound is for the welded solid.

    python benchmarks/bench_mesh_exact_sum.py MESH [MESH ...]
"""

from __future__ import annotations

import argparse
import os
import sys
import tempfile
import warnings
from fractions import Fraction

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


def exact_integrals(vertices: np.ndarray, faces: np.ndarray) -> tuple[Fraction, np.ndarray, np.ndarray]:
    """``(volume, first moments (3,), second moments (3, 3))`` about the origin, exact, of the signed
    tetrahedra (origin, a, b, c) of every triangle: Python integers on the coordinates scaled to integers."""
    coords = np.unique(vertices.ravel())
    scale = max(Fraction(float(c)).denominator for c in coords)
    ints = np.array([[int(Fraction(float(x)) * scale) for x in row] for row in vertices], dtype=object)
    a, b, c = ints[faces[:, 0]], ints[faces[:, 1]], ints[faces[:, 2]]
    det = (a[:, 0] * (b[:, 1] * c[:, 2] - b[:, 2] * c[:, 1]) - a[:, 1] * (b[:, 0] * c[:, 2] - b[:, 2] * c[:, 0])
           + a[:, 2] * (b[:, 0] * c[:, 1] - b[:, 1] * c[:, 0]))
    s = a + b + c
    volume = Fraction(int(det.sum()), 6 * scale ** 3)
    first = np.array([Fraction(int((det * s[:, i]).sum()), 24 * scale ** 4) for i in range(3)], dtype=object)
    second = np.empty((3, 3), dtype=object)
    for i in range(3):
        for j in range(3):
            q = a[:, i] * a[:, j] + b[:, i] * b[:, j] + c[:, i] * c[:, j] + s[:, i] * s[:, j]
            second[i, j] = Fraction(int((det * q).sum()), 120 * scale ** 5)
    return volume, first, second


def central(volume, first, second) -> tuple[float, np.ndarray, np.ndarray]:
    """Volume, centre and the inertia tensor about the centre (tensor convention), exact until the last step."""
    centre = first / volume
    cov = second - np.outer(centre, centre) * volume
    tensor = np.eye(3, dtype=object) * (cov[0, 0] + cov[1, 1] + cov[2, 2]) - cov
    return float(volume), np.array([float(x) for x in centre]), np.array([[float(x) for x in r] for r in tensor])


def mujoco_mesh(path: str) -> tuple[float, np.ndarray, np.ndarray]:
    """MuJoCo's volume, centre and tensor (body axes) of the mesh alone at density 1."""
    import mujoco
    with tempfile.TemporaryDirectory() as folder:
        xml = os.path.join(folder, "m.xml")
        with open(xml, "w") as fh:
            fh.write(f'<mujoco><compiler inertiafromgeom="true"/><asset><mesh name="m" file="{path}" '
                     'inertia="exact"/></asset><worldbody><body name="b"><geom type="mesh" mesh="m" density="1"/>'
                     '</body></worldbody></mujoco>')
        model = mujoco.MjModel.from_xml_path(xml)
    rot = np.zeros(9)
    mujoco.mju_quat2Mat(rot, model.body_iquat[1])
    rot = rot.reshape(3, 3)
    return float(model.body_mass[1]), model.body_ipos[1].copy(), rot @ np.diag(model.body_inertia[1]) @ rot.T


def difference(mass, centre, tensor, ref) -> tuple[float, float, float]:
    m0, c0, t0 = ref
    size = np.sqrt(np.trace(t0) / (2 * m0))
    return (abs(mass - m0) / m0, float(np.linalg.norm(centre - c0)) / size,
            float(np.linalg.norm(tensor - t0) / np.linalg.norm(t0)))


def main(argv=None) -> int:
    from inertia_tool import mass_properties
    from inertia_tool.mesh.read import load_mesh
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("meshes", nargs="+")
    args = parser.parse_args(argv)
    for path in args.meshes:
        raw = load_mesh(path, units="m")
        faces = np.asarray(raw.faces)
        as_read = central(*exact_integrals(np.asarray(raw.vertices, dtype=np.float64), faces))
        rounded = central(*exact_integrals(np.asarray(raw.vertices, dtype=np.float32).astype(np.float64), faces))
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            tool = mass_properties(path, density=1.0)
        theirs = mujoco_mesh(os.path.abspath(path))
        ours = (tool.mass, tool.center_of_mass, tool.inertia)
        u = tool.mesh.uncertainty
        print(f"{path}: {len(faces):,} faces, tool {tool.mesh.certificate.kind}"
              + (f", bounds mass ±{u.mass:.2g}, centre ±{u.center_of_mass:.2g} m, inertia ±{u.inertia:.2g}"
                 if u is not None else ""))
        for label, value in (("exact, float64 as read", as_read), ("MuJoCo", theirs), ("tool", ours)):
            dm, dc, di = difference(*value, rounded)
            print(f"  {label:24s} vs exact float32: mass {dm:.2e}  centre {dc:.2e}  inertia {di:.2e}")
        if u is not None:
            for label, value in (("exact float32", rounded), ("exact float64", as_read)):
                m0, c0, t0 = value
                inside = (abs(tool.mass - m0) <= u.mass * tool.mass
                          and np.linalg.norm(tool.center_of_mass - c0) <= u.center_of_mass
                          and (u.inertia is None or np.linalg.norm(tool.inertia - t0) <= u.inertia
                               * np.linalg.norm(tool.inertia)))
                print(f"  {label} within the tool's bounds: {'yes' if inside else 'NO'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
