"""The mass layer: volume and surface integrals, mass properties and their algebra, principal axes.

Stages: the volume integrals (signed tetrahedra, Tonon 2004) live below both this layer and the mesh layer, in
:mod:`inertia_tool.integrals`, since shell classification reads them too; :mod:`.surface` (thin walls) →
:mod:`.properties` (:class:`~.properties.MassProperties`: parallel-axis theorem, rotations, sums) →
:mod:`.principal` (principal moments and right-handed axes, Eq. 4.25 of Chapter 4).  :mod:`.pipeline` is the
entry from a mesh source; :mod:`.thinwall` the shell and printed-part models; :mod:`.shapes` reference solids
with closed forms; :mod:`.ellipsoid` the equivalent inertia ellipsoid.
"""

from .. import _lazy_names
from typing import TYPE_CHECKING

if TYPE_CHECKING:   # what the names below are, for type checkers and the API docs; loaded on first use
    from . import shapes
    from .ellipsoid import equivalent_ellipsoid_semi_axes
    from .pipeline import DEFAULT_DENSITY, assembly, mass_properties, resolve_density
    from .principal import PrincipalAxes, principal_axes
    from .properties import InertiaTensor, MassProperties, combine, point_mass
    from .thinwall import PrintedPart, printed_part, shell_mass_properties

__all__ = ["mass_properties", "assembly", "resolve_density", "DEFAULT_DENSITY", "MassProperties", "InertiaTensor",
           "combine", "point_mass", "PrincipalAxes", "principal_axes", "shell_mass_properties", "printed_part",
           "PrintedPart", "equivalent_ellipsoid_semi_axes", "shapes"]

#: The module of each name above; they load on first use (PEP 562), so that a module of this layer can be
#: imported alone (``inertia-tool analyze`` needs neither the thin-wall models nor the reference solids).
_PUBLIC = {
    "mass_properties": ".pipeline", "assembly": ".pipeline", "resolve_density": ".pipeline",
    "DEFAULT_DENSITY": ".pipeline",
    "MassProperties": ".properties", "InertiaTensor": ".properties", "combine": ".properties",
    "point_mass": ".properties",
    "PrincipalAxes": ".principal", "principal_axes": ".principal",
    "shell_mass_properties": ".thinwall", "printed_part": ".thinwall", "PrintedPart": ".thinwall",
    "equivalent_ellipsoid_semi_axes": ".ellipsoid",
    "shapes": ".shapes",                      # the module itself
}


__getattr__, __dir__ = _lazy_names(__name__, _PUBLIC, globals())
