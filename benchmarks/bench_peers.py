"""inertia_tool against every peer in its fastest correct configuration, 1e4 to 1e7 faces, ratios from one run.

Each size is a closed torus written as binary STL in mm (``bench_scaling.write_torus``, not committed).  Every
peer runs in a fresh process (imports included, as a script that computes a part's mass properties would run;
warm page cache), and reports its wall time, the part of it after its imports, its peak memory (VmHWM) and its
answer (volume, centre of mass, inertia about the centre of mass at density 1), which is checked against ours:

* ``inertia_tool``: ``mass_properties(FILE, density=1, units="mm")`` — full validation (weld, edge census,
  orientation, shells, the exact face-pair check of the certificate) and compensated integrals;
* ``trimesh``: ``trimesh.load(FILE)`` + ``mass_properties`` (its default: ``process=True`` merges vertices);
* ``trimesh process=False``: the same without the vertex merge.  Its integrals are the same sums over the same
  triangles, so it is right wherever the default is (checked below on every size); neither checks that the
  surface is closed or consistently wound (an open or inside-out part gives a number all the same);
* ``numpy-stl``: ``stl.mesh.Mesh.from_file(FILE, calculate_normals=False)`` + ``get_mass_properties()`` (the
  normals are not needed for the integrals).  numpy-stl 4.1 checks that the mesh is closed before integrating
  (a set of every directed edge, in Python; it only logs a warning when it is not), which dominates its time:
  about 50 s of CPU at 1e6 faces, so by default it is not run above 1.1e6 (``--limit``);
* ``MuJoCo``: an ``mujoco.MjSpec`` with one mesh geom of density 1, ``inertia="exact"``, no collisions,
  ``compile()``; the body's mass, ``ipos`` and principal inertia (rotated back by ``iquat``).  MuJoCo's STL
  reader refuses files of more than 200,000 faces; above that the triangles are read with ``numpy.fromfile``
  and given as the mesh's user vertices and faces (its next fastest way).  MuJoCo's default
  mesh inertia (``legacy``) is **not** correct for a non-convex part: on the torus it gives 1.86× the volume
  (the script prints that check too), so the exact mode is its fastest correct configuration.

Answers agree when the volumes differ by less than 1e-6 (relative), the centres by less than 1e-6 of the
diagonal and the inertia tensors by less than 1e-6 (relative, Frobenius norm); every disagreement is printed.

    python benchmarks/bench_peers.py [--sizes 1e4 1e5 1e6 1e7] [--repeat 3] [--plot docs/img/peers.png]

prints a JSON line per run, the answers' checks, then the Markdown table of the README (CPU time of each peer and its
ratio to ours, from this one run) and the tables of the docs (wall and CPU time, whole process and after the
imports, with the load average), and draws the scaling plot.  ``--json FILE`` keeps the rows; ``--from-json FILE``
prints the tables and redraws the plot from them without running anything.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
sys.path.insert(0, HERE)

from bench_scaling import run_caption, write_torus  # noqa: E402

_COMMON = r"""
import json, resource, sys, time
t0 = time.perf_counter()
def cpu():
    r = resource.getrusage(resource.RUSAGE_SELF)
    return r.ru_utime + r.ru_stime
def peak():
    with open("/proc/self/status") as fh:
        for line in fh:
            if line.startswith("VmHWM:"):
                return int(line.split()[1]) * 1024
    return 0
def report(t1, volume, com, inertia):
    import numpy as np
    t2 = time.perf_counter()
    print(json.dumps({"total": t2 - t0, "compute": t2 - t1, "cpu": cpu(), "cpu_compute": cpu() - c1,
                      "peak": peak(), "volume": float(volume),
                      "com": [float(x) for x in np.asarray(com).reshape(3)],
                      "inertia": [float(x) for x in np.asarray(inertia).reshape(9)]}))
"""

# every child answers in mm: volume mm³, centre mm, inertia about the centre mm⁵ (density 1)
PEERS = {
    "inertia_tool": _COMMON + r"""
import warnings
from inertia_tool import mass_properties
t1 = time.perf_counter()
c1 = cpu()
with warnings.catch_warnings():
    warnings.simplefilter("ignore")
    mp = mass_properties(sys.argv[1], density=1.0, units="mm")
report(t1, mp.mass * 1e9, mp.center_of_mass * 1e3, mp.inertia * 1e15)
""",
    "trimesh": _COMMON + r"""
import trimesh
t1 = time.perf_counter()
c1 = cpu()
m = trimesh.load(sys.argv[1])
p = m.mass_properties
report(t1, p["volume"], p["center_mass"], p["inertia"])
""",
    "trimesh process=False": _COMMON + r"""
import trimesh
t1 = time.perf_counter()
c1 = cpu()
m = trimesh.load(sys.argv[1], process=False)
p = m.mass_properties
report(t1, p["volume"], p["center_mass"], p["inertia"])
""",
    "numpy-stl": _COMMON + r"""
from stl import mesh
t1 = time.perf_counter()
c1 = cpu()
m = mesh.Mesh.from_file(sys.argv[1], calculate_normals=False)
volume, cog, inertia = m.get_mass_properties()
report(t1, volume, cog, inertia)
""",
    "MuJoCo MjSpec": _COMMON + r"""
import mujoco
import numpy as np
t1 = time.perf_counter()
c1 = cpu()
spec = mujoco.MjSpec()
part = spec.add_mesh()
part.name = "part"
with open(sys.argv[1], "rb") as fh:
    fh.seek(80)
    n_faces = int.from_bytes(fh.read(4), "little")
if n_faces <= 200000:           # MuJoCo's STL reader refuses more faces
    part.file = sys.argv[1]
else:                           # its next fastest way: the triangles as user vertices and faces
    rec = np.fromfile(sys.argv[1], dtype=[("n", "<f4", (3,)), ("v", "<f4", (3, 3)), ("a", "<u2")], offset=84)
    part.uservert = rec["v"].reshape(-1).astype(np.float64)
    part.userface = np.arange(3 * len(rec), dtype=np.int32)
    del rec
part.inertia = getattr(mujoco.mjtMeshInertia, "mjMESH_INERTIA_" + (sys.argv[2] if len(sys.argv) > 2 else "EXACT"))
body = spec.worldbody.add_body()
geom = body.add_geom()
geom.type = mujoco.mjtGeom.mjGEOM_MESH
geom.meshname = "part"
geom.density = 1.0
geom.contype = 0
geom.conaffinity = 0
model = spec.compile()
rot = np.zeros(9)
mujoco.mju_quat2Mat(rot, model.body_iquat[1])
rot = rot.reshape(3, 3)
report(t1, model.body_mass[1], model.body_ipos[1], rot @ np.diag(model.body_inertia[1]) @ rot.T)
""",
}

AGREE = 1e-6


def run(peer: str, path: str, repeat: int, timeout: float, extra: tuple[str, ...] = ()) -> dict | None:
    env = {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}
    env["PYTHONPATH"] = ROOT
    best = None
    for _ in range(repeat):
        try:
            r = subprocess.run([sys.executable, "-c", PEERS[peer], path, *extra], capture_output=True, text=True,
                               env=env, timeout=timeout)
        except subprocess.TimeoutExpired:
            return {"error": f"timeout after {timeout:.0f} s"}
        if r.returncode != 0:
            return {"error": r.stderr.strip().splitlines()[-1][:200] if r.stderr.strip() else f"exit {r.returncode}"}
        got = json.loads(r.stdout.strip().splitlines()[-1])
        if best is None or got["total"] < best["total"]:
            best = got
    return best


def disagreement(ours: dict, theirs: dict, diag: float) -> tuple[float, float, float]:
    """(relative volume, centre distance / diagonal, relative inertia in the Frobenius norm)."""
    iv, tv = ours["volume"], theirs["volume"]
    ic, tc = np.array(ours["com"]), np.array(theirs["com"])
    ii, ti = np.array(ours["inertia"]), np.array(theirs["inertia"])
    return (abs(tv - iv) / abs(iv), float(np.linalg.norm(tc - ic)) / diag,
            float(np.linalg.norm(ti - ii) / np.linalg.norm(ii)))


def plot(rows: list[dict], out: str, load: tuple[float, float], caption: str = "") -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, (ax_t, ax_c) = plt.subplots(1, 2, figsize=(11, 4.4))
    styles = {"inertia_tool": ("C0", "o-"), "trimesh": ("C3", "s-"), "trimesh process=False": ("C1", "s--"),
              "numpy-stl": ("C2", "^-"), "MuJoCo MjSpec": ("C4", "D-")}
    for peer, (colour, style) in styles.items():
        pts = [(r["faces"], r["peers"][peer]["total"]) for r in rows if "total" in r["peers"].get(peer, {})]
        if pts:
            ax_t.loglog(*zip(*pts), style, color=colour, label=peer)
        pts = [(r["faces"], r["peers"][peer]["cpu"]) for r in rows if "cpu" in r["peers"].get(peer, {})]
        if pts:
            ax_c.loglog(*zip(*pts), style, color=colour, label=peer)
    ax_t.set(xlabel="triangles", ylabel="wall time, s (fresh process, imports included)", title="Wall time")
    ax_c.set(xlabel="triangles", ylabel="CPU time, s (user + system, all threads)", title="CPU time")
    for ax in (ax_t, ax_c):
        ax.grid(True, which="both", lw=0.3)
        ax.legend(fontsize=8)
    fig.suptitle(f"Binary STL tori, one run, load average {load[0]:.1f} before, {load[1]:.1f} after on "
                 f"{os.cpu_count()} CPUs\ninertia_tool runs every check of its "
                 "certificate, numpy-stl a closedness check, trimesh and MuJoCo none"
                 + (f"\n{caption}" if caption else ""), fontsize=9)
    fig.tight_layout()
    fig.savefig(out, dpi=110)


def table(rows: list[dict], load: tuple[float, float], key: str = "total") -> str:
    """The README table: each peer's time (``key``: "total" or "compute" wall time, "cpu" or "cpu_compute" CPU
    time of the process) and its ratio to ours."""
    peers = [p for p in PEERS if p != "inertia_tool"]
    head = "| faces | STL | inertia_tool | " + " | ".join(peers) + " |"
    lines = [head, "|---:|---:|---:|" + "---:|" * len(peers)]
    for r in rows:
        ours = r["peers"]["inertia_tool"]
        cells = [f"{r['faces']:,}", f"{r['file_mb']:.1f} MB", f"{ours[key]:.2f} s" if key in ours else "—"]
        for p in peers:
            got = r["peers"].get(p, {})
            if key not in got:
                cells.append(got.get("error", "—"))
            elif key in ours:
                flag = "" if got.get("agrees", True) else " (disagrees)"
                cells.append(f"{got[key]:.2f} s ({got[key] / ours[key]:.1f}×){flag}")
            else:
                cells.append(f"{got[key]:.2f} s")
        lines.append("| " + " | ".join(cells) + " |")
    lines.append("")
    what = {"total": "wall time, imports included", "compute": "wall time after the imports (read + mass properties)",
            "cpu": "CPU time of the whole process (user + system, all threads), imports included",
            "cpu_compute": "CPU time after the imports"}[key]
    lines.append(f"Fresh process per run, {what}, best of the repeats; (n×) = the peer's time / "
                 f"inertia_tool's, from this one run. Load average {load[0]:.2f} before, {load[1]:.2f} after, "
                 f"{os.cpu_count()} CPUs.")
    return "\n".join(lines)


def readme_table(rows: list[dict]) -> str:
    """The README's table: CPU time of the whole process (imports included) and each peer's ratio to ours."""
    peers = [p for p in PEERS if p != "inertia_tool"]
    names = {"trimesh process=False": "trimesh `process=False`", "MuJoCo MjSpec": "MuJoCo `MjSpec` (exact inertia)"}
    lines = ["| faces | inertia_tool | " + " | ".join(names.get(p, p) for p in peers) + " |",
             "|---:|---:|" + "---:|" * len(peers)]
    for r in rows:
        ours = r["peers"]["inertia_tool"]
        cells = [f"{r['faces']:,}", f"{ours['cpu']:.2f} s" if "cpu" in ours else "—"]
        for p in peers:
            got = r["peers"].get(p, {})
            if "cpu" not in got:
                cells.append("not run" if "not run" in got.get("error", "") else got.get("error", "—"))
            else:
                flag = "" if got.get("agrees", True) else " (disagrees)"
                ratio = f" ({got['cpu'] / ours['cpu']:.1f}×)" if "cpu" in ours else ""
                cells.append(f"{got['cpu']:.2f} s{ratio}{flag}")
        lines.append("| " + " | ".join(cells) + " |")
    return "\n".join(lines)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--sizes", type=float, nargs="+", default=[1e4, 1e5, 1e6, 1e7])
    ap.add_argument("--repeat", type=int, default=3, help="runs per peer below 2e6 faces (one above)")
    ap.add_argument("--timeout", type=float, default=600.0, help="seconds per child")
    ap.add_argument("--peers", nargs="+", default=list(PEERS), choices=list(PEERS))
    ap.add_argument("--plot", default=os.path.join(ROOT, "docs", "img", "peers.png"))
    ap.add_argument("--json", help="write the rows here (after every size)")
    ap.add_argument("--from-json", help="print the tables and draw the plot from rows written by --json (no runs)")
    ap.add_argument("--limit", nargs="*", default=["numpy-stl=1.1e6"],
                    help="PEER=FACES: do not run PEER above FACES faces (default: numpy-stl=1.1e6)")
    args = ap.parse_args()
    if "inertia_tool" not in args.peers:
        args.peers.insert(0, "inertia_tool")
    if args.from_json:
        with open(args.from_json) as fh:
            saved = json.load(fh)
        print(saved.get("caption", ""))
        print(readme_table(saved["rows"]), end="\n\n")
        for key in ("total", "cpu", "compute", "cpu_compute"):
            print(table(saved["rows"], tuple(saved["load"]), key=key), end="\n\n")
        if args.plot:
            plot(saved["rows"], args.plot, tuple(saved["load"]), saved.get("caption", ""))
        return
    limits = {k: float(v) for k, v in (item.rsplit("=", 1) for item in args.limit)}
    load_before = os.getloadavg()[0]
    caption = run_caption("bench_peers.py", sys.argv[1:])
    rows = []
    for target in args.sizes:
        path, m = write_torus(int(target))
        with open(path, "rb") as fh:      # warm the page cache
            while fh.read(1 << 24):
                pass
        diag = float(np.sqrt(100.0 ** 2 + 100.0 ** 2 + 20.0 ** 2))     # bounding box 100 × 100 × 20 mm
        row: dict = {"faces": m, "file_mb": os.path.getsize(path) / (1 << 20), "peers": {}}
        repeat = args.repeat if m < 2e6 else 1
        for peer in args.peers:
            if m > limits.get(peer, float("inf")):
                row["peers"][peer] = {"error": f"not run above {limits[peer]:,.0f} faces"}
                continue
            t = time.perf_counter()
            got = run(peer, path, repeat, args.timeout) or {"error": "no output"}
            row["peers"][peer] = got
            shown = {k: got[k] for k in ("total", "compute", "cpu", "cpu_compute", "peak", "error") if k in got}
            print(json.dumps({"faces": m, "peer": peer, "elapsed": round(time.perf_counter() - t, 2), **shown}),
                  flush=True)
        ours = row["peers"]["inertia_tool"]
        for peer, got in row["peers"].items():
            if peer == "inertia_tool" or "volume" not in got or "volume" not in ours:
                continue
            dv, dc, di = disagreement(ours, got, diag)
            got["difference"] = [dv, dc, di]
            got["agrees"] = max(dv, dc, di) < AGREE
            if not got["agrees"]:
                print(f"DISAGREEMENT at {m:,} faces: {peer} volume {dv:.2e}, centre {dc:.2e} of the diagonal, "
                      f"inertia {di:.2e}", flush=True)
        if m <= 2e5 and "MuJoCo MjSpec" in args.peers and "volume" in ours:
            legacy = run("MuJoCo MjSpec", path, 1, args.timeout, ("LEGACY",))
            if legacy and "volume" in legacy:
                dv, dc, di = disagreement(ours, legacy, diag)
                row["mujoco_default"] = [dv, dc, di]
                print(f"MuJoCo's default mesh inertia (legacy) at {m:,} faces: volume "
                      f"{legacy['volume'] / ours['volume']:.3f}× ours, inertia off by {di:.2e} (relative): not a "
                      "correct configuration", flush=True)
        rows.append(row)
        if args.json:
            with open(args.json, "w") as fh:
                json.dump({"rows": rows, "load": [load_before, os.getloadavg()[0]], "caption": caption}, fh,
                          indent=1)
    load_after = os.getloadavg()[0]
    for r in rows:
        for peer, got in r["peers"].items():
            if "difference" in got:
                dv, dc, di = got["difference"]
                print(f"check {r['faces']:>10,} {peer:<22} volume {dv:.1e}  centre {dc:.1e}  inertia {di:.1e}  "
                      f"{'agrees' if got['agrees'] else 'DISAGREES'}")
    print(f"\nREADME table (CPU time, imports included; {caption}):\n")
    print(readme_table(rows))
    print()
    print(table(rows, (load_before, load_after)))
    for key in ("cpu", "compute", "cpu_compute"):
        print()
        print(table(rows, (load_before, load_after), key=key))
    if args.json:
        with open(args.json, "w") as fh:
            json.dump({"rows": rows, "load": [load_before, load_after], "caption": caption}, fh, indent=1)
    if args.plot:
        plot(rows, args.plot, (load_before, load_after), caption)
        print(f"\nwrote {args.plot}")


if __name__ == "__main__":
    main()
