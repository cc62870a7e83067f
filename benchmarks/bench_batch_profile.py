"""Where a small part's CPU goes inside ``inertia-tool batch``'s per-file call, function by function.

Writes the ``small`` catalogue of ``bench_batch.py`` (``--small`` binary STL parts of 12-4,800 triangles) beside
the repository's ``meshes/*.stl``, runs the batch's per-file work (``analyze_chunk``, in this process) over all of
them, and prints:

1. CPU µs per file of the whole (``time.process_time``, the least of ``--repeat`` passes), with the load average;
2. the inclusive CPU µs per file of each stage of the engine (each stage function wrapped by a timer: one clock
   call on entry and exit, whose cost, printed, is in the parents' numbers), the stages that
   :func:`~inertia_tool.mesh.prepare.prepare_mesh` and :func:`~inertia_tool.mass.pipeline.mass_properties`
   call in turn;
3. with ``--profile N``, the ``N`` functions of most own CPU time under ``cProfile`` (clocked by
   ``time.process_time``; the profiler's own cost per Python call inflates functions that make many small
   calls: read section 2 for the sizes, section 3 for the names).

    python benchmarks/bench_batch_profile.py [--small 1000] [--repeat 3] [--profile 40] [--kinds box]
"""

from __future__ import annotations

import argparse
import cProfile
import collections
import functools
import glob
import importlib
import os
import pstats
import sys
import tempfile
import time
import warnings

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
sys.path.insert(0, HERE)
sys.path.insert(1, ROOT)

from bench_batch import SMALL_KINDS, _require_c_kernels, make_small_meshes  # noqa: E402
from inertia_tool.batch.runner import BatchOptions, analyze_chunk, discover_files  # noqa: E402
from inertia_tool.mesh import LoadOptions  # noqa: E402

#: The stage functions timed in section 2, as ``module:function``, in the order the batch calls them.
STAGES = (
    "inertia_tool.batch.runner:_read_once",
    "inertia_tool.mesh.read:load_mesh",
    "inertia_tool.mesh.read_stl:_read_stl",
    "inertia_tool.mesh.weld:_weld_stream_c",
    "inertia_tool.mass.pipeline:mass_properties",
    "inertia_tool.mesh.clean_part:prepare_clean",
    "inertia_tool.integrals:one_shell_moments",
    "inertia_tool.mesh.surface:check_magnitude",
    "inertia_tool.mesh.clean_part:_meet_only_in_contacts",
    "inertia_tool.mesh.precision:conversion_bounds",
    "inertia_tool.mesh.prepare:prepare_mesh",
    "inertia_tool.mesh.surface:close_surface",
    "inertia_tool.mesh.checks:census_and_shells",
    "inertia_tool.mesh.shells:find_shells",
    "inertia_tool.integrals:body_volume_moments",
    "inertia_tool.integrals:accurate_shells",
    "inertia_tool.mesh.welded:settle_welded",
    "inertia_tool.mesh.settle:find_contacts",
    "inertia_tool.mesh.intersect:surface_contacts",
    "inertia_tool.mesh.self_crossing:settle_self_crossing",
    "inertia_tool.mesh.classify:orient_shells",
    "inertia_tool.mesh.unite:unite_overlaps",
    "inertia_tool.mesh.certify:certify",
    "inertia_tool.mass.pipeline:_bodies",
    "inertia_tool.mass.principal:principal_axes",
    "inertia_tool.mass.pipeline:_check_physical",
    "inertia_tool.mass.pipeline:_warn_about_principal",
    "inertia_tool.mesh.precision:warn_storage_precision",
)


def _wrap_stages(totals: collections.Counter, calls: collections.Counter) -> list[str]:
    """Replace each stage function, in every module that imported it, by a timed wrapper; the names not found."""
    missing = []
    clock = time.process_time
    for spec in STAGES:
        module_name, name = spec.split(":")
        try:
            fn = getattr(importlib.import_module(module_name), name)
        except (ImportError, AttributeError):
            missing.append(spec)
            continue

        def timed(*args, __fn=fn, __name=name, **kwargs):
            start = clock()
            try:
                return __fn(*args, **kwargs)
            finally:
                totals[__name] += clock() - start
                calls[__name] += 1

        functools.update_wrapper(timed, fn)
        for module in list(sys.modules.values()):
            if module is not None and module.__dict__.get(name) is fn:
                setattr(module, name, timed)
    return missing


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--small", type=int, default=1000, help="generated parts (besides meshes/*.stl)")
    ap.add_argument("--repeat", type=int, default=3, help="passes of the whole (the least CPU time is kept)")
    ap.add_argument("--profile", type=int, default=0, metavar="N", help="also print cProfile's top N functions")
    ap.add_argument("--kinds", default=",".join(SMALL_KINDS), help="kinds of generated part, comma-separated")
    args = ap.parse_args()
    kinds = tuple(k.strip() for k in args.kinds.split(",") if k.strip())
    _require_c_kernels()
    warnings.simplefilter("ignore")
    options = BatchOptions(load=LoadOptions(units="mm"), density=1240.0)
    with tempfile.TemporaryDirectory() as tmp:
        faces = make_small_meshes(tmp, args.small, kinds=kinds) if args.small else []
        files = discover_files(tmp) if args.small else []
        files += sorted(glob.glob(os.path.join(ROOT, "meshes", "*.stl")))
        chunk = [(path, None) for path in files]
        analyze_chunk(chunk[:20], options)                        # imports and first-call caches
        best = float("inf")
        for _ in range(args.repeat):
            start = time.process_time()
            analyze_chunk(chunk, options)
            best = min(best, time.process_time() - start)
        n = len(files)
        span = f"{min(faces):,}-{max(faces):,} triangles, " if faces else ""
        print(f"{n} files ({args.small} generated, {span}{n - args.small} from meshes/); load average "
              f"{', '.join(f'{x:.1f}' for x in os.getloadavg())}")
        print(f"whole per-file call (analyze_chunk): {best / n * 1e6:,.0f} µs of CPU per file (least of "
              f"{args.repeat})")

        profiler = None
        if args.profile:                            # before the stages are wrapped
            profiler = cProfile.Profile(time.process_time)
            profiler.enable()
            analyze_chunk(chunk, options)
            profiler.disable()

        totals: collections.Counter = collections.Counter()
        calls: collections.Counter = collections.Counter()
        missing = _wrap_stages(totals, calls)
        wrapped = float("inf")
        for _ in range(args.repeat):                # the pass of least CPU time, its stages
            totals.clear()
            calls.clear()
            start = time.process_time()
            analyze_chunk(chunk, options)
            seconds = time.process_time() - start
            if seconds < wrapped:
                wrapped, kept, kept_calls = seconds, dict(totals), dict(calls)
        t0 = time.process_time()
        for _ in range(10_000):
            time.process_time()
        clock_cost = (time.process_time() - t0) / 10_000
        print(f"\nstages, inclusive CPU µs per file (the least of {args.repeat} passes with the stages wrapped: "
              f"{wrapped / n * 1e6:,.0f} µs per file; a clock call costs {clock_cost * 1e6:.2f} µs)")
        for spec in STAGES:
            name = spec.split(":")[1]
            if kept_calls.get(name):
                print(f"  {spec:58s} {kept[name] / n * 1e6:8,.0f}   calls per file {kept_calls[name] / n:.2f}")
        for spec in missing:
            print(f"  {spec:58s} (not found in this checkout)")

        if profiler is not None:
            print(f"\ncProfile, {args.profile} functions of most own time (profiled, so inflated):")
            pstats.Stats(profiler, stream=sys.stdout).sort_stats("tottime").print_stats(args.profile)


if __name__ == "__main__":
    main()
