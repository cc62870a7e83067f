"""Generate ``unbalanced_wheel.stl`` (millimetres): a steel-sized wheel with an off-centre lump and a tilt.

The wheel is a revolved profile about the mesh z axis (bore 20 mm, hub to 45 mm, web 12 mm thick, rim
160–185 mm wide 70 mm), one closed shell.  A lump (a 17 × 14 × 20 mm block, like a clip-on weight left on
the inside of the rim) sits at about 150 mm radius on +x, 8–28 mm above the mid-plane; it is a second,
disjoint closed shell.  Everything is then tilted by 0.2° about the mesh x axis, so that about the mesh z
axis the wheel has both static unbalance (the lump) and couple unbalance (the lump's axial offset and the
tilt): an ISO 21940-2 "dynamic" unbalance.

Run ``python meshes/make_wheel.py`` from the repository root to rewrite the file (deterministic).
"""

from __future__ import annotations

import math
import os

import numpy as np
import trimesh

#: (r, z) outline of the wheel's cross-section in mm, counter-clockwise, closed.
PROFILE = [(20, -30), (45, -30), (45, -6), (160, -6), (160, -35), (185, -35), (185, 35), (160, 35),
           (160, 6), (45, 6), (45, 30), (20, 30), (20, -30)]
SECTIONS = 180
LUMP_CENTER = (150.5, 0.0, 18.0)   # mm
LUMP_SIZE = (17.0, 14.0, 20.0)     # mm: radial, tangential, axial
TILT_DEG = 0.2                     # about the mesh x axis


def make_wheel() -> trimesh.Trimesh:
    """The unbalanced wheel as one mesh with two shells, mm."""
    wheel = trimesh.creation.revolve(np.array(PROFILE, dtype=float), sections=SECTIONS)
    if wheel.volume < 0:
        wheel.invert()
    lump = trimesh.creation.box(extents=LUMP_SIZE,
                                transform=trimesh.transformations.translation_matrix(LUMP_CENTER))
    both = trimesh.util.concatenate([wheel, lump])
    both.apply_transform(trimesh.transformations.rotation_matrix(math.radians(TILT_DEG), [1, 0, 0]))
    return both


if __name__ == "__main__":
    mesh = make_wheel()
    out = os.path.join(os.path.dirname(os.path.abspath(__file__)), "unbalanced_wheel.stl")
    mesh.export(out)
    print(f"wrote {out}: {len(mesh.faces)} triangles, watertight={mesh.is_watertight}, "
          f"volume={mesh.volume:.1f} mm³")
