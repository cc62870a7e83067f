"""The corpus benchmark's MuJoCo reference (benchmarks/bench_robot_corpus.py): a file MuJoCo's exact mode
refuses is compiled with the model's own mesh inertia instead, mesh by mesh."""

import os
import sys

import numpy as np
import pytest

mujoco = pytest.importorskip("mujoco")
sys.path.insert(0, os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "benchmarks"))

from bench_robot_corpus import mujoco_reference  # noqa: E402

CORNERS = [(x, y, z) for x in (0, 1) for y in (0, 1) for z in (0, 1)]
TRIANGLES = [(0, 1, 3), (0, 3, 2), (4, 6, 7), (4, 7, 5), (0, 4, 5), (0, 5, 1), (2, 3, 7), (2, 7, 6),
             (0, 2, 6), (0, 6, 4), (1, 5, 7), (1, 7, 3)]


def test_two_meshes_on_one_refused_file_are_both_retried(tmp_path):
    # Talos, TIAGo, Lite 6 and Cassie name one file from a left and a right mesh; MuJoCo's exact mode refuses
    # the file's inconsistent orientation once per mesh.  The reference retried by file, so the second
    # refusal of the same file ended the comparison of the whole model ("not compared").
    flipped = TRIANGLES[:-1] + [TRIANGLES[-1][::-1]]
    with open(tmp_path / "part.obj", "w") as fh:
        fh.writelines(f"v {x} {y} {z}\n" for x, y, z in CORNERS)
        fh.writelines(f"f {a + 1} {b + 1} {c + 1}\n" for a, b, c in flipped)
    path = tmp_path / "robot.xml"
    path.write_text("""<mujoco>
  <asset><mesh name="left" file="part.obj"/><mesh name="right" file="part.obj"/></asset>
  <worldbody>
    <body name="l"><geom type="mesh" mesh="left"/></body>
    <body name="r" pos="2 0 0"><geom type="mesh" mesh="right"/></body>
  </worldbody>
</mujoco>
""")
    bodies, refused, missing, _ = mujoco_reference(str(path))
    assert [b[0] for b in bodies] == ["l", "r"] and not missing
    assert list(refused) == ["part.obj"] and "inconsistent orientation" in refused["part.obj"]
    assert bodies[0][1] == pytest.approx(bodies[1][1]) and np.isfinite(bodies[0][1])
