"""Meta-tests of the public API (STYLE.md §10): the surface is pinned, and every exported callable documents every
parameter as a numpydoc entry of its "Parameters" (or, for classes, "Attributes") section."""

import importlib
import inspect
import pkgutil
import re

import pytest

import inertia_tool as it

#: The top level, pinned: adding or removing a name is an API decision, made here on purpose.
TOP_LEVEL = {
    "__version__", "mass_properties", "assembly", "LoadOptions", "MassProperties", "PrincipalAxes", "stability",
    "StabilityReport", "simulate", "Trajectory", "heavy_top", "HeavyTopReport", "balance", "BalanceReport",
    "InertiaToolError", "errors",
}

#: The subpackages whose ``__all__`` is public API (documented parameter by parameter below).
SUBPACKAGES = ["inertia_tool.mesh", "inertia_tool.mass", "inertia_tool.dynamics", "inertia_tool.balancing",
               "inertia_tool.robot", "inertia_tool.batch", "inertia_tool.design"]


def test_top_level_surface_is_pinned():
    assert set(it.__all__) == TOP_LEVEL
    assert len(it.__all__) == len(set(it.__all__))
    for name in it.__all__:
        assert hasattr(it, name), name


def _public_callables():
    seen = {}
    for package in ["inertia_tool"] + SUBPACKAGES:
        module = importlib.import_module(package)
        for name in module.__all__:
            obj = getattr(module, name)
            if callable(obj) and not inspect.ismodule(obj) and not name.startswith("_"):
                seen.setdefault(f"{obj.__module__}.{obj.__qualname__}", obj)
    return sorted(seen.items())


_SECTION = re.compile(r"^(Parameters|Attributes|Other Parameters)\n-+\n(.*?)(?=^\S[^\n]*\n-+\n|\Z)", re.M | re.S)
_ENTRY = re.compile(r"^(\*{0,2}[A-Za-z_][\w, *]*?)\s*(?::|$)", re.M)


def documented_names(doc: str) -> set[str]:
    """Names that head an entry ("name : type", "a, b, c", "**kwargs") in the numpydoc parameter sections."""
    names = set()
    for match in _SECTION.finditer(doc):
        for line in match.group(2).splitlines():
            if not line or line[0].isspace():
                continue                     # a description line, not an entry
            entry = _ENTRY.match(line)
            if entry:
                names.update(n.strip().lstrip("*") for n in entry.group(1).split(","))
    return names


def test_documented_names_reads_numpydoc_entries_not_substrings():
    doc = ("Parameters\n----------\nalpha : float\n    uses beta in the text.\ngamma, delta\n    two.\n**extra\n"
           "    more.\n")
    assert documented_names(doc) == {"alpha", "gamma", "delta", "extra"}


@pytest.mark.parametrize("qualname, obj", _public_callables(), ids=[q for q, _ in _public_callables()])
def test_every_public_parameter_is_documented(qualname, obj):
    doc = inspect.getdoc(obj) or ""
    assert doc.strip(), f"{qualname} has no docstring"
    try:
        sig = inspect.signature(obj)
    except (TypeError, ValueError):   # builtins without a signature
        return
    params = [p.name for p in sig.parameters.values() if p.name not in ("self", "cls")]
    if not params:
        return
    documented = documented_names(doc)
    missing = [p for p in params if p not in documented]
    assert not missing, f"{qualname}: parameters without a numpydoc entry: {missing}"


def test_public_names_stay_what_they_are_after_every_submodule_is_imported():
    # importing a submodule rebinds the package attribute of the same name; no public name may be shadowed
    for info in pkgutil.walk_packages(it.__path__, "inertia_tool."):
        if info.name.endswith("__main__"):
            continue
        importlib.import_module(info.name)
    assert [n for n in it.__all__ if inspect.ismodule(getattr(it, n))] == ["errors"]
    for package in SUBPACKAGES:
        module = importlib.import_module(package)
        shadowed = [n for n in module.__all__ if inspect.ismodule(getattr(module, n)) and n != "shapes"]
        assert not shadowed, f"{package}: {shadowed} are modules, expected functions or classes"
