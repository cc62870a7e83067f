"""Exact mass properties of a STEP/IGES B-rep (OpenCASCADE) and how far its tessellation is from them.

Reading and tessellating are in :mod:`inertia_tool.mesh.cad` (its docstring states the error bound
``A·δ/V``).  ``BRepGProp.VolumeProperties_s`` integrates the solid on its B-rep faces; its
``MatrixOfInertia`` is about the centre of mass in the tensor convention, ``Ixy = −∫xy dm`` (checked in the
tests against this package's integration of an exact, planar tessellation).
"""

from __future__ import annotations

import os
from typing import TYPE_CHECKING

import numpy as np

from ..errors import InvalidMeshError
from ..mesh.cad import DEFAULT_ANGULAR_DEFLECTION, chord_tolerance, read_brep, tessellate
from ..values import frozen_value
from .properties import MassProperties

if TYPE_CHECKING:  # pragma: no cover
    from OCP.TopoDS import TopoDS_Shape     # OCP has no type information: Any to the checker

__all__ = ["exact_mass_properties", "BrepComparison", "compare"]


def exact_mass_properties(shape: TopoDS_Shape, *, name: str = "") -> MassProperties:
    """Unit-density mass properties of the B-rep solid (``BRepGProp.VolumeProperties_s``), metres."""
    from OCP.BRepGProp import BRepGProp
    from OCP.GProp import GProp_GProps
    props = GProp_GProps()
    BRepGProp.VolumeProperties_s(shape, props)
    volume = props.Mass()
    matrix = props.MatrixOfInertia()
    tensor = np.array([[matrix.Value(i, j) for j in (1, 2, 3)] for i in (1, 2, 3)])
    area_props = GProp_GProps()
    BRepGProp.SurfaceProperties_s(shape, area_props)
    return MassProperties(mass=volume, volume=volume, center_of_mass=np.array(props.CentreOfMass().Coord()),
                          inertia=0.5 * (tensor + tensor.T), surface_area=area_props.Mass(), density=1.0, name=name)


@frozen_value
class BrepComparison:
    """Exact B-rep mass properties against those of its tessellation (both unit density, metres).

    Attributes
    ----------
    exact : MassProperties
        From the B-rep (OpenCASCADE's Gauss integration).
    mesh : MassProperties
        From the tessellation, by this package's exact polyhedron integration.
    chord : float
        Chord tolerance of the tessellation, m.
    angular_deflection : float
        rad.
    faces : int
        Triangles of the tessellation.
    volume_error : float
        ``|V_mesh − V_exact| / V_exact``.
    volume_bound : float
        ``A·δ / V``: the largest relative volume error the tolerance allows (module docstring).
    com_error : float
        ``|c_mesh − c_exact|`` in m.
    inertia_error : float
        ``‖I_mesh − I_exact‖_F / ‖I_exact‖_F`` (about each one's centre of mass).
    """

    exact: MassProperties
    mesh: MassProperties
    chord: float
    angular_deflection: float
    faces: int
    volume_error: float
    volume_bound: float
    com_error: float
    inertia_error: float


def compare(path: str | os.PathLike[str], *, chord: float | None = None,
            angular_deflection: float = DEFAULT_ANGULAR_DEFLECTION) -> BrepComparison:
    """Read a STEP/IGES part with OCP, integrate the B-rep exactly and its tessellation, and compare."""
    from .pipeline import mass_properties
    path = os.fsdecode(os.fspath(path))
    shape = read_brep(path)
    try:
        tol = chord_tolerance(shape, chord)
    except InvalidMeshError as exc:     # a shape without a bounding box: name the file
        raise InvalidMeshError(f"{os.fsencode(path).decode('utf-8', 'replace')}: {exc}") from None
    exact = exact_mass_properties(shape, name=path)
    vertices, faces = tessellate(shape, chord=tol, angular_deflection=angular_deflection)
    mesh = mass_properties((vertices, faces), density=1.0, name=path)
    return BrepComparison(
        exact=exact, mesh=mesh, chord=tol, angular_deflection=float(angular_deflection), faces=len(faces),
        volume_error=abs(mesh.volume - exact.volume) / exact.volume,
        volume_bound=exact.surface_area * tol / exact.volume,
        com_error=float(np.linalg.norm(mesh.center_of_mass - exact.center_of_mass)),
        inertia_error=float(np.linalg.norm(mesh.inertia - exact.inertia) / np.linalg.norm(exact.inertia)))
