"""The modules the fuzzers instrument: every module of inertia_tool a file can reach (its readers, mesh checks
and robot parsers, lazy imports included) and the third-party readers it hands formats to.

Import them inside ``atheris.instrument_imports(include=INCLUDE)`` with :func:`import_readers`: a module
imported before that block, or lazily on first use after it, is not instrumented, and libFuzzer then sees no
coverage of it (``fuzz_analyze.py`` saw 58 edges when its block imported only the command line).
"""

from __future__ import annotations

import importlib
import pkgutil

#: Packages instrumented: inertia_tool and the third-party parsers of 3MF, glTF/GLB, PLY/OFF and COLLADA.
INCLUDE = ("inertia_tool", "trimesh.exchange", "collada")

#: inertia_tool modules no file reaches (the command line is imported by the fuzzer that needs it).
_SKIP = ("inertia_tool.cli", "inertia_tool.reports.html", "inertia_tool.dynamics.plot", "inertia_tool.design")

_THIRD_PARTY = ("trimesh.exchange.load", "trimesh.exchange.stl", "trimesh.exchange.obj", "trimesh.exchange.ply",
                "trimesh.exchange.off", "trimesh.exchange.threemf", "trimesh.exchange.gltf", "trimesh.exchange.dae",
                "collada")


def import_readers() -> list[str]:
    """Import the modules of :data:`INCLUDE` that reading a file can reach; returns their names (an optional
    dependency that is missing, such as OCP for STEP, is left out)."""
    import inertia_tool
    names = []
    for info in pkgutil.walk_packages(inertia_tool.__path__, "inertia_tool."):
        if info.name.startswith(_SKIP) or info.name.endswith("__main__"):
            continue
        try:
            importlib.import_module(info.name)
        except ImportError:
            continue
        names.append(info.name)
    for name in _THIRD_PARTY:
        try:
            importlib.import_module(name)
        except ImportError:
            continue
        names.append(name)
    return names
