"""Meta-tests of the public API (STYLE.md §10): every exported callable is documented, parameter by parameter."""

import inspect

import pytest

import inertia_tool as it

_CALLABLES = [name for name in it.__all__ if callable(getattr(it, name)) and not inspect.ismodule(getattr(it, name))]


@pytest.mark.parametrize("name", _CALLABLES)
def test_every_public_parameter_is_documented(name):
    obj = getattr(it, name)
    doc = inspect.getdoc(obj) or ""
    assert doc.strip(), f"{name} has no docstring"
    try:
        sig = inspect.signature(obj)
    except (TypeError, ValueError):   # builtins without a signature
        return
    missing = [p.name for p in sig.parameters.values()
               if p.kind not in (p.VAR_POSITIONAL, p.VAR_KEYWORD) and p.name not in doc]
    assert not missing, f"{name}: parameters not in the docstring: {missing}"


def test_all_names_exist_and_are_unique():
    assert len(set(it.__all__)) == len(it.__all__)
    for name in it.__all__:
        assert hasattr(it, name), name


def test_public_names_stay_functions_after_every_submodule_is_imported():
    # importing a submodule rebinds the package attribute of the same name (balance, stability, heavy_top)
    import importlib
    import pkgutil
    for info in pkgutil.walk_packages(it.__path__, "inertia_tool."):
        if info.name.endswith("__main__"):
            continue
        importlib.import_module(info.name)
    modules = [name for name in it.__all__ if inspect.ismodule(getattr(it, name))]
    assert modules == ["shapes"]
