"""inertia_tool: exact mass properties and rotational dynamics of triangle meshes.

Public API (SI units everywhere; conventions in ``docs/conventions.md``)::

    import inertia_tool as it
    props = it.mass_properties("part.stl", units="mm", material="aluminium")
    props.mass, props.volume, props.center_of_mass, props.inertia
    props.inertia_about([0, 0, 0]); props.moment_about_axis([0, 0, 1], point=[0, 0, 0])
    props.principal.moments, props.principal.axes
    traj = it.simulate(props, angular_velocity=[0.1, 1.0, 0.05], t=np.linspace(0, 10, 101))
"""

from .errors import (InertiaToolError, InertiaToolWarning, InvalidMeshError, MeshReadError, PhysicsError,
                     UsageError)
from .dynamics import Trajectory, herpolhode, plot_trajectory, polhode, simulate
from .principal import PrincipalAxes, principal_axes
from .properties import InertiaTensor, MassProperties, combine, point_mass

__version__ = "0.1.0"

__all__ = [
    "__version__",
    "MassProperties",
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
    "InertiaToolError",
    "InertiaToolWarning",
    "InvalidMeshError",
    "MeshReadError",
    "PhysicsError",
    "UsageError",
]
