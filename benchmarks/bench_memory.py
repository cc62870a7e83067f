"""Peak memory of ``inertia-tool analyze`` as a function of the number of triangles: the bound the face limit
(``--max-faces``) puts on the memory of a run.

Writes icospheres of 82k to 5.2M triangles as binary STL (and, smaller, as 3MF), runs
``inertia-tool analyze FILE --json`` on each in a fresh process (the child's own VmHWM, as in
``bench_engine.py``), on the C extension and on the numpy path, and fits ``peak = a + b × faces`` by least
squares per path.  Since a file is refused above ``--max-faces``, ``a + b × max_faces`` bounds the peak of any
accepted file of that format.

With ``--formats`` it measures instead the peak resident memory of one ``inertia-tool`` run per file format and
per hostile file of issue 22 (scaled down), as the child's ``ru_maxrss`` through
``resource.getrusage(RUSAGE_CHILDREN)`` in a fresh wrapper process, and prints it against the file size and
the number of triangles: the multiple of the file size (and of the faces) that each reader costs, and the
cost of a refusal (which must stay at the interpreter's baseline: the counts are checked before allocating).

With ``--stages FILE ...`` it runs ``analyze FILE --json --units mm`` in a fresh process with each stage of
``prepare_mesh`` (and ``load_mesh``, the weld and the census) wrapped: the peak resident memory within each
stage (VmHWM, reset through ``/proc/self/clear_refs`` at every stage boundary and folded into the stages still
open), the memory on entry and on exit and the stage's CPU time (Linux only).  Generate the files outside the
repository (e.g. the tori of ``bench_scaling.py`` under /tmp).

Usage::

    python benchmarks/bench_memory.py [--largest 9]      # icosphere subdivisions 6..largest
    python benchmarks/bench_memory.py --formats [--subdivisions 7]
    python benchmarks/bench_memory.py --stages /tmp/torus_9999392.stl
"""

from __future__ import annotations

import argparse
import os
import sys

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)

from bench_engine import CHILD_OURS, OUT, run_child, write_icosphere  # noqa: E402

_MIB = 1 << 20


def write_3mf(subdivisions: int) -> str:
    import trimesh
    path = os.path.join(OUT, f"icosphere_{subdivisions}.3mf")
    if not os.path.exists(path):
        os.makedirs(OUT, exist_ok=True)
        trimesh.creation.icosphere(subdivisions=subdivisions, radius=50.0).export(path)
    return path


def fit(points):
    """Least-squares ``peak = a + b × faces``; returns ``(a bytes, b bytes per face)``."""
    f = np.array([p[0] for p in points], dtype=float)
    m = np.array([p[1] for p in points], dtype=float)
    b, a = np.polyfit(f, m, 1)
    return a, b


# -- per format: peak RSS of a child against the file size ------------------------------------------------------

_WRAPPER = r"""
import resource, subprocess, sys
code = subprocess.run(sys.argv[1:], stdout=subprocess.DEVNULL, stderr=subprocess.PIPE).returncode
print(code, resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss * 1024)
"""


def peak_of(argv: list) -> tuple[int, int]:
    """``(exit code, peak RSS in bytes)`` of ``inertia-tool argv`` run as the only child of a fresh process."""
    import subprocess
    root = os.path.dirname(HERE)
    env = {**os.environ, "PYTHONPATH": root}
    cmd = [sys.executable, "-c", _WRAPPER, sys.executable, "-m", "inertia_tool", *argv]
    out = subprocess.run(cmd, capture_output=True, text=True, env=env, check=True, cwd=root).stdout.split()
    return int(out[0]), int(out[1])


def _format_files(directory: str, subdivisions: int) -> list:
    """``(label, path, faces)`` of one icosphere (radius 50 mm) in every format the readers take."""
    import trimesh
    sphere = trimesh.creation.icosphere(subdivisions=subdivisions, radius=0.05)
    files = []
    for suffix in ("stl", "obj", "ply", "off", "3mf", "glb", "dae"):
        path = os.path.join(directory, f"sphere_{subdivisions}.{suffix}")
        if not os.path.exists(path):
            sphere.export(path)
        files.append((suffix.upper(), path, len(sphere.faces)))
    return files


def _hostile_files(directory: str) -> list:
    """The issue's hostile files, scaled down ~10x: ``(label, argv, faces claimed)``."""
    import struct
    import zipfile
    files = []
    # 3MF of 500,000 vertices and no triangles (the issue: 5M vertices, 34 MB, 4.9 GB)
    path = os.path.join(directory, "vertices.3mf")
    if not os.path.exists(path):
        ns = "http://schemas.microsoft.com/3dmanufacturing/core/2015/02"
        vertex = '<vertex x="1.5" y="2.5" z="3.5"/>'
        with zipfile.ZipFile(path, "w", zipfile.ZIP_DEFLATED) as zf:
            zf.writestr("3D/3dmodel.model", f'<model unit="millimeter" xmlns="{ns}"><resources><object id="1"><mesh>'
                        f"<vertices>{vertex * 500_000}</vertices><triangles/></mesh></object></resources><build>"
                        '<item objectid="1"/></build></model>')
    files.append(("3MF, 500k vertices, no triangles", ["analyze", path, "--max-faces", "100000"], 0))
    # PLY of 255-corner polygons (the issue: 204 MB, 4.6 GB)
    path = os.path.join(directory, "polygons.ply")
    polygons = 20_000
    if not os.path.exists(path):
        import numpy as np
        header = (b"ply\nformat binary_little_endian 1.0\nelement vertex 255\nproperty float x\nproperty float y\n"
                  b"property float z\nelement face %d\nproperty list uchar int vertex_indices\nend_header\n" % polygons)
        angle = np.linspace(0, 2 * np.pi, 255, endpoint=False)
        body = np.c_[np.cos(angle), np.sin(angle), np.zeros(255)].astype("<f4").tobytes()
        with open(path, "wb") as fh:
            fh.write(header + body + (bytes([255]) + np.arange(255, dtype="<i4").tobytes()) * polygons)
    files.append(("PLY, 255-corner polygons", ["analyze", path, "--max-faces", "1000000"], 253 * polygons))
    # GLB of 20,000 instances of a box (the issue: 200k instances, 10 MB, 1.7 GB)
    path = os.path.join(directory, "instances.glb")
    if not os.path.exists(path):
        import json

        import numpy as np
        import trimesh
        box = trimesh.creation.box()
        v, f = box.vertices.astype("<f4"), box.faces.astype("<u4")
        binary = v.tobytes() + f.tobytes()
        doc = {"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": list(range(20_000))}],
               "nodes": [{"mesh": 0, "translation": [2.0 * k, 0, 0]} for k in range(20_000)],
               "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1}]}],
               "buffers": [{"byteLength": len(binary)}],
               "bufferViews": [{"buffer": 0, "byteLength": v.nbytes},
                               {"buffer": 0, "byteOffset": v.nbytes, "byteLength": f.nbytes}],
               "accessors": [{"bufferView": 0, "componentType": 5126, "count": len(v), "type": "VEC3",
                              "min": v.min(axis=0).tolist(), "max": v.max(axis=0).tolist()},
                             {"bufferView": 1, "componentType": 5125, "count": f.size, "type": "SCALAR"}]}
        text = json.dumps(doc).encode()
        text += b" " * (-len(text) % 4)
        chunks = struct.pack("<I4s", len(text), b"JSON") + text + struct.pack("<I4s", len(binary), b"BIN\0") + binary
        with open(path, "wb") as fh:
            fh.write(struct.pack("<4sII", b"glTF", 2, 12 + len(chunks)) + chunks)
    files.append(("GLB, 20k box instances", ["analyze", path, "--max-faces", "1000000"], 12 * 20_000))
    # URDF of 30,000 links (the issue: 300k links, 30 MB, 4.0 GB)
    path = os.path.join(directory, "links.urdf")
    if not os.path.exists(path):
        link = '<link name="l{}"><collision><geometry><box size="1 1 1"/></geometry></collision></link>'
        with open(path, "w") as fh:
            fh.write('<robot name="r">' + "".join(link.format(k) for k in range(30_000)) + "</robot>")
    files.append(("URDF, 30k links", ["robot", path, "--density", "1000"], 0))
    return files


def formats(subdivisions: int) -> None:
    """Peak RSS per format and per hostile file against its size (``--formats``)."""
    directory = os.path.join(OUT, "memory")
    os.makedirs(directory, exist_ok=True)
    _, baseline = peak_of(["analyze", os.path.join(directory, "missing.stl")])
    print(f"baseline (interpreter, a refused missing file): {baseline / _MIB:.0f} MiB")
    print()
    print("| input | file MiB | triangles | exit | peak MiB | (peak − baseline) / file size | bytes per triangle |")
    print("|---|---|---|---|---|---|---|")
    rows = [(label, ["analyze", path, "--json"], faces)
            for label, path, faces in _format_files(directory, subdivisions)]
    rows += _hostile_files(directory)
    for label, argv, faces in rows:
        size = os.path.getsize(argv[1])
        code, peak = peak_of(argv)
        extra = max(peak - baseline, 0)
        per_face = f"{extra / faces:,.0f}" if faces and code == 0 else "-"
        print(f"| {label} | {size / _MIB:.1f} | {faces:,} | {code} | {peak / _MIB:.0f} | {extra / size:.1f} | "
              f"{per_face} |", flush=True)


# -- per stage: peak RSS within each stage of one analysis --------------------------------------------------------

_STAGES_CHILD = r"""
import contextlib, functools, importlib, io, os, sys, time
MIB = 1 << 20
stack, rows = [], []          # open stages: [label, rss on entry, peak]; closed: (depth, label, in, peak, out, cpu)


def status():
    d = {}
    with open("/proc/self/status") as fh:
        for line in fh:
            if line.startswith(("VmHWM", "VmRSS")):
                key, value = line.split(":")
                d[key] = int(value.split()[0]) * 1024
    return d


def checkpoint():
    s = status()
    for frame in stack:
        frame[2] = max(frame[2], s["VmHWM"])
    with open("/proc/self/clear_refs", "w") as fh:
        fh.write("5")                               # reset VmHWM to the current RSS
    return s["VmRSS"]


def wrap(modname, name):
    mod = importlib.import_module(modname)
    inner = getattr(mod, name)

    @functools.wraps(inner)
    def outer(*args, **kwargs):
        rss = checkpoint()
        depth = len(stack)
        stack.append([name, rss, rss])
        cpu = time.process_time()
        try:
            return inner(*args, **kwargs)
        finally:
            out = checkpoint()
            frame = stack.pop()
            rows.append((depth, name, frame[1], frame[2], out, time.process_time() - cpu))
    setattr(mod, name, outer)


for stage in ("close_surface", "find_shells", "settle_welded", "find_contacts", "settle_self_crossing",
              "orient_shells", "unite_overlaps", "certify"):
    wrap("inertia_tool.mesh.prepare", stage)
for stage in ("load_mesh", "prepare_mesh", "_bodies"):
    wrap("inertia_tool.mass.pipeline", stage)
wrap("inertia_tool.mesh.read_stl", "weld_exact_stream")        # the weld inside load_mesh (issue 25)
wrap("inertia_tool.mesh.surface", "census_and_shells")     # the census inside close_surface
from inertia_tool.cli import main
rss0 = checkpoint()
stack.append(["analyze", rss0, rss0])
with contextlib.redirect_stdout(io.StringIO()):
    rc = main(["analyze", sys.argv[1], "--json", "--units", "mm"])
checkpoint()
whole = stack.pop()
size = os.path.getsize(sys.argv[1])
print(f"{sys.argv[1]}: exit {rc}, file {size / MIB:,.1f} MiB, "
      f"peak {whole[2] / MIB:,.0f} MiB = {whole[2] / size:.2f}x the file")
print(f"{'stage':26s} {'in':>8s} {'peak':>8s} {'+':>7s} {'out':>8s} {'CPU s':>7s}  (MiB)")
for depth, name, rss_in, peak, out, cpu in rows:
    print(f"{'  ' * depth + name:26s} {rss_in / MIB:8.0f} {peak / MIB:8.0f} {(peak - rss_in) / MIB:7.0f} "
          f"{out / MIB:8.0f} {cpu:7.2f}")
"""


def stages(paths: list) -> None:
    """Print the peak memory within each stage of ``analyze`` on each file (a fresh process per file)."""
    import subprocess
    env = {**os.environ, "PYTHONPATH": os.path.dirname(HERE)}
    for path in paths:
        # cwd: a ``-c`` child puts its working directory first on sys.path, which would shadow PYTHONPATH
        r = subprocess.run([sys.executable, "-c", _STAGES_CHILD, path], capture_output=True, text=True, env=env,
                           cwd=os.path.dirname(HERE))
        if r.returncode:
            raise RuntimeError(f"the stage child failed on {path}: {r.stderr[-2000:]}")
        print(r.stdout)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--largest", type=int, default=9, help="largest icosphere subdivision (9: 5.2M faces)")
    ap.add_argument("--largest-3mf", type=int, default=7, help="largest 3MF subdivision (7: 328k faces)")
    ap.add_argument("--formats", action="store_true", help="peak per file format and per hostile file instead")
    ap.add_argument("--subdivisions", type=int, default=7, help="--formats: icosphere subdivision (7: 328k faces)")
    ap.add_argument("--stages", nargs="+", metavar="FILE", help="peak memory within each stage of analyze instead")
    args = ap.parse_args()
    if args.stages:
        stages(args.stages)
        return
    if args.formats:
        formats(args.subdivisions)
        return
    runs = {}
    for label, env, writer, largest in (("STL, C extension", "", write_icosphere, args.largest),
                                        ("STL, numpy path", "1", write_icosphere, args.largest),
                                        ("3MF (streaming reader), C extension", "", write_3mf, args.largest_3mf)):
        os.environ["INERTIA_TOOL_NO_ACCEL"] = env
        points = []
        for sub in range(5, largest + 1):
            path = writer(sub)
            faces = 20 * 4 ** sub
            seconds, peak = run_child(CHILD_OURS, path)
            points.append((faces, peak))
            print(f"{label:36s} {faces:>10,} faces  {os.path.getsize(path) / _MIB:8.1f} MiB file  "
                  f"{seconds:6.2f} s  peak {peak / _MIB:8.1f} MiB", flush=True)
        runs[label] = points
    os.environ.pop("INERTIA_TOOL_NO_ACCEL", None)
    print()
    print("| path | peak memory ≈ a + b × faces | at 1M faces | at the default --max-faces (50M) |")
    print("|---|---|---|---|")
    for label, points in runs.items():
        a, b = fit(points)
        print(f"| {label} | {a / _MIB:.0f} MiB + {b:.0f} B × faces | {(a + b * 1e6) / _MIB:,.0f} MiB | "
              f"{(a + b * 5e7) / (1 << 30):,.1f} GiB |")


if __name__ == "__main__":
    main()
