"""inertia_tool: exact mass properties and rotational dynamics of triangle meshes.

Public API (SI units everywhere; conventions in ``docs/conventions.md``)::

    import inertia_tool as it
    props = it.mass_properties("part.stl", units="mm", material="aluminium")
    props.mass, props.volume, props.center_of_mass, props.inertia
    props.inertia_about([0, 0, 0]); props.moment_about_axis([0, 0, 1], point=[0, 0, 0])
    props.principal.moments, props.principal.axes
    it.balance(props, axis_point=[0, 0, 0], axis_direction=[0, 0, 1], rpm=3000, planes=(-0.04, 0.04),
               radius=0.18, grade="G6.3", bearings=(-0.12, 0.12)).corrections
    traj = it.simulate(props, angular_velocity=[0.1, 1.0, 0.05], t=np.linspace(0, 10, 101))
    it.stability(props).kinds; it.heavy_top_from_mesh(props, pivot=[0, 0, 0], theta0=0.3, omega3=300)
    it.inertial_frame(props, "principal")          # for URDF / SDF / MJCF, checked like Gazebo and MuJoCo
    it.shell_mass_properties("casing.stl", thickness=0.002, units="mm", material="steel")
    it.printed_part("bracket.stl", skin=0.0012, infill=0.2, units="mm", material="PLA").properties
"""

from .errors import (InertiaToolError, InertiaToolWarning, InvalidMeshError, MeshReadError, PhysicsError,
                     UsageError)
from .principal import PrincipalAxes, principal_axes
from .properties import InertiaTensor, MassProperties, combine, point_mass
from .pipeline import assembly, mass_properties
from .checks import MeshReport
# names that are also submodules must be bound eagerly (importing a submodule rebinds the package attribute)
from .balance import BalanceReport, Correction, balance
from .stability import AxisStability, StabilityReport, polhode_period, stability
from .heavy_top import HeavyTopReport, heavy_top, heavy_top_from_mesh

# The rest of the public API is imported on first use (PEP 562), so `inertia-tool analyze` does not pay for
# scipy.integrate, scipy.special and the dynamics when it never calls them.
_LAZY = {
    "shapes": (".shapes", None),
    "simulate": (".dynamics", "simulate"), "Trajectory": (".dynamics", "Trajectory"),
    "polhode": (".dynamics", "polhode"), "herpolhode": (".dynamics", "herpolhode"),
    "plot_trajectory": (".dynamics", "plot_trajectory"),
    "apply_impulse": (".impulse", "apply_impulse"), "ImpulseResult": (".impulse", "ImpulseResult"),
    "spin_experiment": (".spin", "spin_experiment"), "SpinExperiment": (".spin", "SpinExperiment"),
    "inertial_frame": (".inertial", "inertial_frame"), "InertialFrame": (".inertial", "InertialFrame"),
    "check_moments": (".inertial", "check_moments"), "MomentCheck": (".inertial", "MomentCheck"),
    "printed_part": (".thinwall", "printed_part"), "PrintedPart": (".thinwall", "PrintedPart"),
    "shell_mass_properties": (".thinwall", "shell_mass_properties"),
    "BatchOptions": (".batch", "BatchOptions"), "BatchSummary": (".batch", "BatchSummary"),
    "analyze_file": (".batch", "analyze_file"), "run_batch": (".batch", "run_batch"),
    "equivalent_ellipsoid_semi_axes": (".ellipsoid", "equivalent_ellipsoid_semi_axes"),
}


def __getattr__(name):
    if name not in _LAZY:
        raise AttributeError(f"module 'inertia_tool' has no attribute {name!r}")
    import importlib
    module_name, attribute = _LAZY[name]
    module = importlib.import_module(module_name, __name__)
    value = module if attribute is None else getattr(module, attribute)
    globals()[name] = value
    return value


def __dir__():
    return sorted(set(globals()) | set(_LAZY))


__version__ = "0.1.0"

__all__ = [
    "__version__",
    "mass_properties",
    "assembly",
    "MassProperties",
    "MeshReport",
    "balance",
    "BalanceReport",
    "Correction",
    "InertiaTensor",
    "PrincipalAxes",
    "principal_axes",
    "combine",
    "point_mass",
    "simulate",
    "Trajectory",
    "polhode",
    "herpolhode",
    "plot_trajectory",
    "stability",
    "StabilityReport",
    "AxisStability",
    "polhode_period",
    "heavy_top",
    "heavy_top_from_mesh",
    "HeavyTopReport",
    "apply_impulse",
    "ImpulseResult",
    "spin_experiment",
    "SpinExperiment",
    "shell_mass_properties",
    "printed_part",
    "PrintedPart",
    "inertial_frame",
    "InertialFrame",
    "check_moments",
    "MomentCheck",
    "InertiaToolError",
    "InertiaToolWarning",
    "InvalidMeshError",
    "MeshReadError",
    "PhysicsError",
    "UsageError",
    "shapes",
    "BatchOptions",
    "BatchSummary",
    "analyze_file",
    "run_batch",
    "equivalent_ellipsoid_semi_axes",
]
