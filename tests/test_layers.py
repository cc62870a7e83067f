"""The layers of docs/architecture.md: the engine imports only downward, never from reports/ or cli/."""

import ast
from pathlib import Path

import pytest

PACKAGE = Path(__file__).resolve().parent.parent / "inertia_tool"

#: Engine packages: pure functions and result objects; formatting and the command line sit above them.
ENGINE = ("mass", "dynamics", "mesh", "balancing", "design")
#: The layers no engine module may import.
ABOVE = ("reports", "cli")


def _imported_packages(path: Path) -> set[str]:
    """First package component (below inertia_tool) of every relative or absolute import in ``path``."""
    tree = ast.parse(path.read_text(encoding="utf-8"))
    depth = len(path.relative_to(PACKAGE).parts) - 1       # folders between inertia_tool/ and the module
    found = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom):
            if node.level == 0:
                parts = (node.module or "").split(".")
                if parts[0] == "inertia_tool" and len(parts) > 1:
                    found.add(parts[1])
            elif node.level == depth + 1 and node.module:      # from ..X import: X is a top-level package
                found.add(node.module.split(".")[0])
            elif node.level == depth + 1:                       # from .. import X
                found.update(alias.name for alias in node.names)
        elif isinstance(node, ast.Import):
            for alias in node.names:
                parts = alias.name.split(".")
                if parts[0] == "inertia_tool" and len(parts) > 1:
                    found.add(parts[1])
    return found


@pytest.mark.parametrize("package", ENGINE)
def test_engine_never_imports_reports_or_cli(package):
    offenders = {str(p.relative_to(PACKAGE)): sorted(_imported_packages(p) & set(ABOVE))
                 for p in sorted((PACKAGE / package).rglob("*.py"))}
    offenders = {k: v for k, v in offenders.items() if v}
    assert offenders == {}


def test_the_mesh_layer_never_imports_the_mass_layer():
    """mesh/ sits below mass/ (the volume integrals both need live in the base module inertia_tool.integrals)."""
    offenders = [str(p.relative_to(PACKAGE)) for p in sorted((PACKAGE / "mesh").rglob("*.py"))
                 if "mass" in _imported_packages(p)]
    assert offenders == []


def test_the_checker_sees_an_upward_import(tmp_path, monkeypatch):
    """The AST walk finds ``from ..reports.x import y`` in a module one folder down (so the test above can fail)."""
    module = PACKAGE / "mass" / "_probe_for_layers_test.py"
    text = "from ..reports.output import write_bytes\nfrom inertia_tool.cli import main\n"
    monkeypatch.setattr(Path, "read_text", lambda self, encoding=None: text)
    assert _imported_packages(module) == {"reports", "cli"}
