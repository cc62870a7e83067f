"""The mass layer: volume and surface integrals, mass properties and their algebra, principal axes.

Stages: :mod:`.volume` (signed tetrahedra, Tonon 2004) and :mod:`.surface` (thin walls) →
:mod:`.properties` (:class:`~.properties.MassProperties`: parallel-axis theorem, rotations, sums) →
:mod:`.principal` (principal moments and right-handed axes, Eq. 4.25 of Chapter 4).  :mod:`.pipeline` is the
entry from a mesh source; :mod:`.thinwall` the shell and printed-part models; :mod:`.shapes` reference solids
with closed forms; :mod:`.ellipsoid` the equivalent inertia ellipsoid.
"""

from . import shapes
from .ellipsoid import equivalent_ellipsoid_semi_axes
from .pipeline import DEFAULT_DENSITY, assembly, mass_properties, resolve_density
from .principal import PrincipalAxes, principal_axes
from .properties import InertiaTensor, MassProperties, combine, point_mass
from .thinwall import PrintedPart, printed_part, shell_mass_properties

__all__ = ["mass_properties", "assembly", "resolve_density", "DEFAULT_DENSITY", "MassProperties", "InertiaTensor",
           "combine", "point_mass", "PrincipalAxes", "principal_axes", "shell_mass_properties", "printed_part",
           "PrintedPart", "equivalent_ellipsoid_semi_axes", "shapes"]
