"""Identity check of the weld and the census between two builds (issue 25): every case written as a binary STL
(float32 corners, so that the file reader's weld runs), then read, censused and analysed; a digest of every
output is printed per case, and ``--compare`` lists the cases whose digests differ between two runs.

Cases: ``--cases N`` generated compositions of ``tests/adversary_solids.py`` (case ``i`` from
``numpy.random.default_rng([seed, i])``, as ``bench_adversarial.py``: nested, touching, overlapping,
duplicated, inside-out, sliver ... solids), and every ``.npz`` of ``--damage DIR`` (the damaged robot parts of
``benchmarks/damage/make_cases.py``: holes, flips, soups, cracks, overlaps, duplicates, touching mirrors,
fragments), each analysed plain and with ``repair=True``.  Per case it digests (SHA-256 of the exact bytes):

* ``weld``: the vertices (float64 bits) and faces the reader's weld gives;
* ``census``: ``census_and_shells`` of those faces (every EdgeTopology field, the sample edges' coordinates, the
  shell labels and their count);
* ``report``: every field of the ``MeshReport`` of ``mass_properties`` (arrays by their bytes, the
  certificate, notes, uncertainty) and the mass, centre of mass and inertia; or the refusal's class and message.

``--partition`` welds every stream on the radix partition (``PARTITION_MIN_POINTS = 1``), which otherwise takes
only streams of 4M corners and more.  Run it with each build's package first on ``PYTHONPATH``::

    PYTHONPATH=/work/main python benchmarks/bench_weld_identity.py --cases 1000 --damage DIR --partition --json old.json
    PYTHONPATH=.          python benchmarks/bench_weld_identity.py --cases 1000 --damage DIR --partition --json new.json
    python benchmarks/bench_weld_identity.py --compare old.json new.json
"""

from __future__ import annotations

import argparse
import dataclasses
import hashlib
import json
import os
import sys
import tempfile
import warnings
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "tests"))

_RECORD = np.dtype([("n", "<f4", (3,)), ("v", "<f4", (3, 3)), ("a", "<u2")])
#: The temporary folder of this run, replaced by ``<tmp>`` in everything digested (messages name the file).
_SCRUB: list[str] = []


def _digest(*parts: object) -> str:
    h = hashlib.sha256()
    for p in parts:
        if isinstance(p, np.ndarray):
            h.update(str((p.dtype.str, p.shape)).encode())
            h.update(np.ascontiguousarray(p).tobytes())
        elif dataclasses.is_dataclass(p) and not isinstance(p, type):
            for f in dataclasses.fields(p):
                h.update(f.name.encode())
                h.update(_digest(getattr(p, f.name)).encode())
        elif isinstance(p, (tuple, list)):
            h.update(b"(")
            for q in p:
                h.update(_digest(q).encode())
            h.update(b")")
        else:
            text = repr(p)
            for folder in _SCRUB:
                text = text.replace(folder, "<tmp>")
            h.update(text.encode())
    return h.hexdigest()[:16]


def _write_stl(path: str, vertices: np.ndarray, faces: np.ndarray) -> None:
    rec = np.zeros(len(faces), dtype=_RECORD)
    rec["v"] = vertices.astype(np.float32)[faces]
    with open(path, "wb") as fh:
        fh.write(b"weld identity".ljust(80))
        fh.write(np.uint32(len(rec)).tobytes())
        rec.tofile(fh)


def analyse(path: str, repairs: tuple[bool, ...]) -> dict[str, str]:
    from inertia_tool import mass_properties
    from inertia_tool.mesh.checks import census_and_shells
    from inertia_tool.mesh.read import load_mesh

    out: dict[str, str] = {}
    raw = load_mesh(path)
    out["weld"] = _digest(raw.vertices, raw.faces)
    f = raw.faces[~((raw.faces[:, 0] == raw.faces[:, 1]) | (raw.faces[:, 1] == raw.faces[:, 2])
                    | (raw.faces[:, 2] == raw.faces[:, 0]))]
    if len(f):
        topo, labels, count = census_and_shells(f, len(raw.vertices), raw.vertices)
        out["census"] = _digest(topo, labels.astype(np.int64), count)
    for repair in repairs:
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                props = mass_properties(path, density=1.0, repair=repair)
            out[f"report{'+repair' if repair else ''}"] = _digest(props.mesh, props.mass, props.center_of_mass,
                                                                  props.inertia)
        except Exception as exc:        # a refusal (or a crash) is an output too: its class and message
            out[f"report{'+repair' if repair else ''}"] = _digest(type(exc).__name__, str(exc))
    return out


def run(args: argparse.Namespace) -> dict[str, dict[str, str]]:
    import adversary_solids as S

    if args.partition:
        import inertia_tool.mesh.weld as weld
        weld.PARTITION_MIN_POINTS = 1
    results: dict[str, dict[str, str]] = {}
    with tempfile.TemporaryDirectory() as tmp:
        _SCRUB.append(tmp)
        path = os.path.join(tmp, "case.stl")
        for i in range(args.cases):
            case = S.make_case(S.KINDS[i % len(S.KINDS)], np.random.default_rng([args.seed, i]))
            _write_stl(path, case.vertices, case.faces)
            results[f"adversary/{i}"] = analyse(path, (False,))
        for npz in sorted(Path(args.damage).glob("*.npz")) if args.damage else ():
            with np.load(npz) as data:
                _write_stl(path, data["vertices"], data["faces"])
            results[f"damage/{npz.stem}"] = analyse(path, (False, True))
    return results


def compare(old: dict, new: dict) -> int:
    differ = [k for k in old if old[k] != new.get(k)]
    missing = sorted(set(old) ^ set(new))
    print(f"{len(old)} cases: {len(old) - len(differ)} identical, {len(differ)} differ, {len(missing)} in one run only")
    for k in differ[:20]:
        print(f"  {k}: " + ", ".join(s for s in old[k] if old[k][s] != new[k].get(s)))
    return 1 if differ or missing else 0


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--cases", type=int, default=1000)
    ap.add_argument("--seed", type=int, default=21)
    ap.add_argument("--damage", help="a folder of damage cases (.npz) from benchmarks/damage/make_cases.py")
    ap.add_argument("--partition", action="store_true", help="weld every stream on the radix partition")
    ap.add_argument("--json", help="write the digests here")
    ap.add_argument("--compare", nargs=2, metavar=("OLD", "NEW"), help="compare two runs' digests")
    args = ap.parse_args(argv)
    if args.compare:
        old, new = (json.loads(Path(p).read_text()) for p in args.compare)
        return compare(old, new)
    import inertia_tool
    from inertia_tool._native import accel
    print(f"inertia_tool from {os.path.dirname(inertia_tool.__file__)}; C extension "
          f"{'on' if accel() is not None else 'off'}", file=sys.stderr)
    results = run(args)
    if args.json:
        Path(args.json).write_text(json.dumps(results, indent=0, sort_keys=True))
    print(f"{len(results)} cases digested", file=sys.stderr)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
