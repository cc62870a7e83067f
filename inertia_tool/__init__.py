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

from . import errors
from .balancing.rotor import BalanceReport, balance
from .dynamics.spin_stability import StabilityReport, stability
from .dynamics.top import HeavyTopReport, heavy_top
from .dynamics.trajectory import Trajectory
from .errors import InertiaToolError
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


def __getattr__(name):
    # `simulate` loads on first use: its stages import scipy.special and scipy.integrate (about 0.2 s), which
    # `inertia-tool analyze` never needs (measured with `python -X importtime -c "import inertia_tool"`).
    if name == "simulate":
        from .dynamics.simulation import simulate
        globals()["simulate"] = simulate
        return simulate
    raise AttributeError(f"module 'inertia_tool' has no attribute {name!r}")


def __dir__():
    return sorted(set(globals()) | {"simulate"})
