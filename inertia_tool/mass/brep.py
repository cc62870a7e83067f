"""Exact mass properties of a STEP/IGES B-rep (OpenCASCADE) and how far its tessellation is from them.

Reading and tessellating are in :mod:`inertia_tool.mesh.cad` (its docstring states the error bound
``A·δ/V``).  ``BRepGProp.VolumeProperties_s`` integrates the solid on its B-rep faces; its
``MatrixOfInertia`` is about the centre of mass in the tensor convention, ``Ixy = −∫xy dm`` (checked in the
tests against this package's integration of an exact, planar tessellation).
"""

from __future__ import annotations

import os
from typing import TYPE_CHECKING, Any

import numpy as np

from ..errors import MeshReadError
from ..mesh.cad import DEFAULT_ANGULAR_DEFLECTION, brep_integrals, read_cad
from ..values import frozen_value
from .properties import MassProperties

if TYPE_CHECKING:  # pragma: no cover
    from ..isolate import Limits
    from OCP.TopoDS import TopoDS_Shape     # OCP has no type information: Any to the checker

__all__ = ["exact_mass_properties", "BrepComparison", "compare"]


def exact_mass_properties(shape: TopoDS_Shape, *, name: str = "") -> MassProperties:
    """Unit-density mass properties of the B-rep solid (``BRepGProp.VolumeProperties_s``), metres.

    Runs OpenCASCADE in this process: for shapes the caller built or trusts (files go through :func:`compare`,
    which reads them in a child process with limits).
    """
    return _properties(brep_integrals(shape), name)


def _properties(integrals: tuple[Any, ...], name: str) -> MassProperties:
    volume, com, tensor, area = integrals
    return MassProperties(mass=volume, volume=volume, center_of_mass=np.asarray(com), inertia=np.asarray(tensor),
                          surface_area=area, density=1.0, name=name)


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
        rad, of the tessellation compared (finer than asked when the mesher left the first one open).
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
    solids : int
        Solids in the file.
    fusion : str
        :data:`~inertia_tool.mesh.cad.FUSIONS`: ``"fused"`` when several solids were fused into their union
        (OpenCASCADE's boolean) before integrating and tessellating (``exact`` is the union, not the sum);
        ``"apart"`` when no two of them meet (the sum is the union); ``"failed"`` when a boolean failed
        (``exact`` is the sum, shared volume counted twice).
    overlap_volume : float
        m³ the solids shared (their summed volume minus the union's); 0 for one solid.
    first_open_edges : int
        Open edges the mesher left at the angular deflection asked (then tessellated again finer); 0 if none.
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
    solids: int = 1
    fusion: str = "one solid"
    overlap_volume: float = 0.0
    first_open_edges: int = 0

    def scaled(self, like: MassProperties, *, target_mass: float | None = None) -> MassProperties:
        """The exact B-rep properties at the density of ``like`` (the tessellation's result), or scaled to
        ``target_mass`` kg when the density came from a target mass; ``like``'s name and mesh report are kept.

        This is the headline a CAD user expects: the solid of the file, not its tessellation (whose
        difference :attr:`volume_error` etc. state).
        """
        e = self.exact
        density = target_mass / e.volume if target_mass is not None else like.density
        return MassProperties(mass=density * e.volume, volume=e.volume, center_of_mass=e.center_of_mass,
                              inertia=density * e.inertia, surface_area=e.surface_area, density=density,
                              name=like.name, mesh=like.mesh)


def compare(path: str | os.PathLike[str], *, chord: float | None = None,
            angular_deflection: float = DEFAULT_ANGULAR_DEFLECTION, limits: Limits | None = None) -> BrepComparison:
    """Read a STEP/IGES part with OCP, integrate the B-rep exactly and its tessellation, and compare.

    OpenCASCADE runs in a child process under ``limits`` (:func:`inertia_tool.mesh.cad.read_cad`); several
    solids are fused into their union first (:func:`inertia_tool.mesh.cad.solids_fused`).  The tessellation's
    own warnings (welded vertices ...) are those of reading the file as a mesh and are not repeated here.
    """
    import warnings
    from .pipeline import mass_properties
    path = os.fsdecode(os.fspath(path))
    reading = read_cad(path, chord=chord, angular_deflection=angular_deflection, limits=limits)
    if reading.integrals is None:
        raise MeshReadError(f"{path}: exact B-rep properties need OCP (pip install cadquery-ocp-novtk)")
    exact = _properties(reading.integrals, path)
    if not exact.volume > 0:
        raise MeshReadError(f"{path}: the B-rep encloses no volume ({exact.volume:g} m³)")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        mesh = mass_properties((reading.vertices, reading.faces), density=1.0, name=path)
    tol = reading.chord
    overlap = max(0.0, reading.summed_volume - exact.volume) if reading.fusion == "fused" else 0.0
    return BrepComparison(
        exact=exact, mesh=mesh, chord=tol, angular_deflection=reading.angular_deflection, faces=len(reading.faces),
        volume_error=abs(mesh.volume - exact.volume) / exact.volume,
        volume_bound=exact.surface_area * tol / exact.volume,
        com_error=float(np.linalg.norm(mesh.center_of_mass - exact.center_of_mass)),
        inertia_error=float(np.linalg.norm(mesh.inertia - exact.inertia) / np.linalg.norm(exact.inertia)),
        solids=max(reading.solids, 1), fusion=reading.fusion, overlap_volume=overlap,
        first_open_edges=reading.first_open_edges)
