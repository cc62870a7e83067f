"""inertia_tool: exact mass properties and rotational dynamics of triangle meshes.

The top level holds the entry points and result classes most users need; everything else is in the layer
that computes it (SI units everywhere; conventions in ``docs/conventions.md``)::

    import inertia_tool as it
    props = it.mass_properties("part.stl", units="mm", material="aluminium")     # or options=it.LoadOptions(...)
    props.mass, props.volume, props.center_of_mass, props.inertia
    props.inertia_about([0, 0, 0]); props.moment_about_axis([0, 0, 1], point=[0, 0, 0])
    props.principal.moments, props.principal.axes
    it.stability(props).kinds
    traj = it.simulate(props, angular_velocity=[0.1, 1.0, 0.05], t=np.linspace(0, 10, 101))
    it.heavy_top(I1, I3, mass, length, theta0=0.3, omega3=300)
    it.balance(props, axis_point=[0, 0, 0], axis_direction=[0, 0, 1], rpm=3000, planes=(-0.04, 0.04),
               radius=0.18, grade="G6.3", bearings=(-0.12, 0.12)).corrections

Layers (each a subpackage): :mod:`inertia_tool.mesh` (reading, welding, checks, preparing) →
:mod:`inertia_tool.mass` (integrals, ``MassProperties``, principal axes, shapes, thin walls) →
:mod:`inertia_tool.dynamics` (stability, free body, heavy top, impulse) and :mod:`inertia_tool.balancing`,
:mod:`inertia_tool.robot` (simulator inertials) → :mod:`inertia_tool.batch`, :mod:`inertia_tool.reports`,
:mod:`inertia_tool.cli`.  Errors and warnings: :mod:`inertia_tool.errors`; tolerances:
:mod:`inertia_tool.tolerances`; units and materials: :mod:`inertia_tool.units`.
"""

import importlib
from typing import TYPE_CHECKING, Any, Callable

from . import errors
from .errors import InertiaToolError

if TYPE_CHECKING:   # what the names below are, for type checkers and the API docs; loaded on first use
    from .balancing.rotor import BalanceReport, balance
    from .dynamics.simulation import simulate
    from .dynamics.spin_stability import StabilityReport, stability
    from .dynamics.top import HeavyTopReport, heavy_top
    from .dynamics.trajectory import Trajectory
    from .mass.pipeline import assembly, mass_properties
    from .mass.principal import PrincipalAxes
    from .mass.properties import MassProperties
    from .mesh.options import LoadOptions

__version__ = "0.1.0"

__all__ = [
    "__version__",
    "mass_properties",
    "assembly",
    "LoadOptions",
    "MassProperties",
    "PrincipalAxes",
    "stability",
    "StabilityReport",
    "simulate",
    "Trajectory",
    "heavy_top",
    "HeavyTopReport",
    "balance",
    "BalanceReport",
    "InertiaToolError",
    "errors",
]

#: The module of each name that loads on first use (PEP 562).  ``import inertia_tool`` (and so every run of
#: the command line) then costs no more than :mod:`.errors`: each command imports only the layers it uses
#: (``inertia-tool analyze`` on a closed STL never imports balancing, the simulation stages, scipy or
#: trimesh; ``tests/test_startup.py`` pins it).
_LAZY = {
    "mass_properties": ".mass.pipeline", "assembly": ".mass.pipeline",
    "LoadOptions": ".mesh.options",
    "MassProperties": ".mass.properties",
    "PrincipalAxes": ".mass.principal",
    "stability": ".dynamics.spin_stability", "StabilityReport": ".dynamics.spin_stability",
    "simulate": ".dynamics.simulation",
    "Trajectory": ".dynamics.trajectory",
    "heavy_top": ".dynamics.top", "HeavyTopReport": ".dynamics.top",
    "balance": ".balancing.rotor", "BalanceReport": ".balancing.rotor",
}


def _lazy_names(package: str, table: dict[str, str], namespace: dict[str, Any]) -> tuple[
        Callable[[str], Any], Callable[[], list[str]]]:
    """The module ``__getattr__`` and ``__dir__`` (PEP 562) of a package whose names load on first use.

    ``table`` maps each name to the module (relative to ``package``) that defines it; a name mapped to the
    module of the same name (``"shapes": ".shapes"``) is that module.  A loaded name is stored in
    ``namespace`` (the package's globals), so it is looked up only once.  Every layer with lazy names uses this.
    """
    def __getattr__(name: str) -> Any:
        if name not in table:
            raise AttributeError(f"module {package!r} has no attribute {name!r}")
        module = importlib.import_module(table[name], package)
        value = module if table[name] == f".{name}" else getattr(module, name)
        namespace[name] = value
        return value

    def __dir__() -> list[str]:
        return sorted(set(namespace) | set(table))

    return __getattr__, __dir__


__getattr__, __dir__ = _lazy_names(__name__, _LAZY, globals())
