"""Write the committed seed corpus of ``fuzz/fuzz_readers.py``: one small valid file (a few KB at most) per
mesh format and robot description format, in ``fuzz/corpus/``.

Run once (the files are committed; re-run only to change them)::

    python fuzz/make_seeds.py

Meshes: a 20 x 10 x 5 box (12 triangles) in every format trimesh writes (STL ASCII and binary, OBJ, PLY ASCII
and binary, OFF, 3MF, glTF with its buffer embedded as a data URI, GLB, COLLADA), plus an OBJ with quads and
negative indices written here.  Robots: a two-link URDF, SDF and MJCF of primitive shapes (box, cylinder,
sphere) with declared inertials, so every parser reaches its inertial and geometry code; no xacro (expanding
xacro runs code from the file).
"""

from __future__ import annotations

import os

import trimesh

HERE = os.path.dirname(os.path.abspath(__file__))
CORPUS = os.path.join(HERE, "corpus")

URDF = """<?xml version="1.0"?>
<robot name="seed">
  <link name="base">
    <inertial><origin xyz="0 0 0.05" rpy="0 0 0"/><mass value="2.0"/>
      <inertia ixx="0.01" ixy="0" ixz="0" iyy="0.02" iyz="0" izz="0.025"/></inertial>
    <collision><origin xyz="0 0 0.05" rpy="0 0 0.3"/><geometry><box size="0.2 0.1 0.1"/></geometry></collision>
  </link>
  <link name="arm">
    <inertial><origin xyz="0 0 0.1"/><mass value="0.5"/>
      <inertia ixx="0.002" ixy="0" ixz="0" iyy="0.002" iyz="0" izz="0.0005"/></inertial>
    <collision><origin xyz="0 0 0.1"/><geometry><cylinder radius="0.02" length="0.2"/></geometry></collision>
    <collision><origin xyz="0 0 0.2"/><geometry><sphere radius="0.03"/></geometry></collision>
  </link>
  <joint name="j" type="revolute"><parent link="base"/><child link="arm"/><origin xyz="0 0 0.1"/>
    <axis xyz="0 1 0"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
</robot>
"""

SDF = """<?xml version="1.0"?>
<sdf version="1.7">
  <model name="seed">
    <link name="base">
      <pose>0 0 0.05 0 0 0</pose>
      <inertial><pose>0 0 0 0 0 0</pose><mass>2.0</mass>
        <inertia><ixx>0.01</ixx><ixy>0</ixy><ixz>0</ixz><iyy>0.02</iyy><iyz>0</iyz><izz>0.025</izz></inertia>
      </inertial>
      <collision name="c"><geometry><box><size>0.2 0.1 0.1</size></box></geometry></collision>
    </link>
    <link name="arm">
      <pose>0 0 0.2 0 0 0</pose>
      <inertial><mass>0.5</mass>
        <inertia><ixx>0.002</ixx><iyy>0.002</iyy><izz>0.0005</izz></inertia></inertial>
      <collision name="c"><pose>0 0 0.1 0 0 0</pose>
        <geometry><cylinder><radius>0.02</radius><length>0.2</length></cylinder></geometry></collision>
      <collision name="s"><geometry><sphere><radius>0.03</radius></sphere></geometry></collision>
    </link>
  </model>
</sdf>
"""

MJCF = """<mujoco model="seed">
  <compiler angle="degree" eulerseq="xyz"/>
  <default><geom density="1000"/></default>
  <worldbody>
    <body name="base" pos="0 0 0.1" euler="0 0 20">
      <inertial pos="0 0 0" mass="2" diaginertia="0.01 0.02 0.025"/>
      <geom type="box" size="0.1 0.05 0.05"/>
      <body name="arm" pos="0 0 0.1" quat="1 0 0 0">
        <joint name="j" type="hinge" axis="0 1 0"/>
        <geom type="capsule" fromto="0 0 0 0 0 0.2" size="0.02"/>
        <geom type="cylinder" size="0.02 0.1" pos="0 0 0.1"/>
        <geom type="sphere" size="0.03" pos="0 0 0.2"/>
        <geom type="ellipsoid" size="0.03 0.02 0.01" pos="0 0 0.25"/>
      </body>
    </body>
  </worldbody>
</mujoco>
"""

OBJ_QUADS = """# a unit cube of quads, negative (relative) indices in the second half
o cube
v 0 0 0
v 1 0 0
v 1 1 0
v 0 1 0
v 0 0 1
v 1 0 1
v 1 1 1
v 0 1 1
f 1 4 3 2
f 5 6 7 8
f 1 2 6 5
f -7 -6 -2 -3
f -6 -5 -1 -2
f -5 -8 -4 -1
"""


def make_seeds(out: str = CORPUS) -> list[str]:
    """Write the seeds into ``out``; returns their paths."""
    os.makedirs(out, exist_ok=True)
    box = trimesh.creation.box((20.0, 10.0, 5.0))
    files = {
        "box-ascii.stl": box.export(file_type="stl_ascii"),
        "box-binary.stl": box.export(file_type="stl"),
        "box.obj": box.export(file_type="obj"),
        "box-ascii.ply": box.export(file_type="ply", encoding="ascii"),
        "box-binary.ply": box.export(file_type="ply"),
        "box.off": box.export(file_type="off"),
        "box.3mf": box.export(file_type="3mf"),
        "box.glb": box.export(file_type="glb"),
        "box.dae": box.export(file_type="dae"),
        "cube-quads.obj": OBJ_QUADS,
        "seed.urdf": URDF,
        "seed.sdf": SDF,
        "seed-mjcf.xml": MJCF,
    }
    from trimesh.exchange.gltf import export_gltf
    gltf = export_gltf(trimesh.Scene(box), embed_buffers=True)
    files["box.gltf"] = gltf["model.gltf"]
    paths = []
    for name, data in files.items():
        path = os.path.join(out, name)
        with open(path, "wb") as fh:
            fh.write(data.encode() if isinstance(data, str) else data)
        paths.append(path)
    return paths


if __name__ == "__main__":
    for p in make_seeds():
        print(f"{os.path.getsize(p):6d} {os.path.relpath(p)}")
