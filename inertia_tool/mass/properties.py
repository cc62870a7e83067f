"""Mass properties of a rigid body: the frozen result object and its algebra.

``MassProperties`` holds mass, volume, centre of mass and the inertia tensor about the centre of mass
(mesh axes, SI, tensor convention: off-diagonals −∫xy dm).  Everything else is derived on demand:
inertia about another point (parallel-axis theorem, Eqs. 4.16–4.17), moment about an axis, principal axes
(Eq. 4.25), a rigidly moved copy, sums of bodies and point masses.  See ``docs/conventions.md``.
"""

from __future__ import annotations

import sys
from dataclasses import field
from functools import cached_property
from typing import TYPE_CHECKING, Iterable, Optional

import numpy as np

from ..values import frozen_value
from ..errors import NonFiniteResultError, UsageError
from ..tolerances import FAR_POINT_RATIO, ROTATION_ATOL
from .principal import DEFAULT_EQUAL_RTOL, PrincipalAxes, principal_axes

if TYPE_CHECKING:     # annotations only: numpy.typing is not loaded at run time
    from numpy.typing import ArrayLike, DTypeLike, NDArray

if TYPE_CHECKING:  # pragma: no cover
    from ..mesh.checks import MeshReport

__all__ = ["MassProperties", "InertiaTensor", "point_mass", "combine", "parallel_axis_shift"]


def warn_far_point(props: "MassProperties", point: NDArray[np.float64], ratio: float, *, stacklevel: int = 2,
                   what: str = "the point") -> None:
    """:class:`ImplausiblePointWarning` when ``point`` lies more than ``ratio`` × ``props.size`` from the centre
    of mass (see :meth:`MassProperties.inertia_about`)."""
    size = props.size
    distance = float(np.linalg.norm(point - props.center_of_mass))
    if size > 0 and distance > ratio * size:
        import warnings

        from ..errors import ImplausiblePointWarning
        warnings.warn(f"{props.name or 'body'}: {what} ({', '.join(f'{x:.6g}' for x in point)}) m is "
                      f"{distance / size:.3g} part sizes ({distance:.4g} m) from the centre of mass of a "
                      f"{size:.4g} m part: were its coordinates meant in another unit (millimetres read as "
                      "metres)?", ImplausiblePointWarning, stacklevel=stacklevel + 1)


def as_vector3(x: ArrayLike, name: str) -> NDArray[np.float64]:
    """A fresh (3,) float64 copy of ``x``, or a UsageError naming ``name`` (shape or non-finite values).

    The one input check for 3-vectors of the public API (points, directions, angular velocities, impulses).
    """
    a = np.array(x, dtype=np.float64)
    if a.shape != (3,):
        raise UsageError(f"Expected `{name}` to have shape (3,), got {a.shape}")
    if not np.all(np.isfinite(a)):
        raise UsageError(f"Expected `{name}` to be finite, got {a.tolist()}")
    return a


def parallel_axis_shift(mass: float, offset: ArrayLike) -> np.ndarray:
    """Inertia of a point mass ``mass`` at ``offset`` from the reference point, (3, 3) kg·m².

    ``M [(b·b) δ_ij − b_i b_j]``: the term added to the central tensor by the parallel-axis theorem,
    Eq. (4.16) with ``b = point − centre of mass`` (the sign of ``b`` does not matter).
    """
    b = np.asarray(offset, dtype=np.float64)
    return mass * ((b @ b) * np.eye(3) - np.outer(b, b))


@frozen_value
class InertiaTensor:
    """An inertia tensor together with the point it is taken about.

    Attributes
    ----------
    tensor : (3, 3) float
        kg·m², mesh axes, tensor convention (off-diagonals −∫xy dm).
    reference_point : (3,) float
        m, mesh axes.
    """

    tensor: NDArray[np.float64]
    reference_point: NDArray[np.float64]

    def __array__(self, dtype: DTypeLike | None = None, copy: bool | None = None) -> np.ndarray:
        return np.asarray(self.tensor, dtype=dtype)

    def moment_about(self, direction: ArrayLike) -> float:
        """Moment of inertia ``n̂·I·n̂`` about the line through ``reference_point`` along ``direction``, kg·m²."""
        n = as_vector3(direction, "direction")
        norm = np.linalg.norm(n)
        if norm == 0:
            raise UsageError("Expected a non-zero `direction`, got (0, 0, 0)")
        n = n / norm
        return float(n @ self.tensor @ n)

    def principal(self, *, rtol: float = DEFAULT_EQUAL_RTOL) -> PrincipalAxes:
        """Principal moments and axes about ``reference_point``."""
        return principal_axes(self.tensor, reference_point=self.reference_point, rtol=rtol)


@frozen_value
class MassProperties:
    """Mass properties of a rigid body, SI, mesh axes.

    Attributes
    ----------
    mass : float
        kg.
    volume : float
        m³ of material (0 for point masses).
    center_of_mass : (3,) float
        m, mesh axes.
    inertia : (3, 3) float
        kg·m² about ``center_of_mass``, mesh axes, tensor convention (off-diagonals −∫xy dm).
    surface_area : float
        m² of the bounding surface (0 for point masses; the sum over parts for an assembly).
    density : float
        kg/m³: ``mass / volume`` for a homogeneous body; the mean for an assembly; ``nan`` without volume.
    name : str
        Label for reports (file name, part name); informational.
    mesh : MeshReport or None
        Mesh diagnostics (``inertia_tool.mesh.checks.MeshReport``) when the body came from a mesh.
    parts : tuple of MassProperties
        The bodies this one was combined from (disconnected shells of a mesh, parts of an assembly).
    material : str
        The material's name, for reports: ``"steel"``, a 3MF base material, a slicer's filament type; empty
        when the density was given as a number or for a combination.
    """

    mass: float
    volume: float
    center_of_mass: NDArray[np.float64]
    inertia: NDArray[np.float64]
    surface_area: float = 0.0
    density: float = float("nan")
    name: str = ""
    mesh: Optional["MeshReport"] = field(default=None, repr=False, compare=False)
    parts: tuple[MassProperties, ...] = field(default=(), repr=False, compare=False)
    material: str = field(default="", repr=False, compare=False)

    def __post_init__(self) -> None:
        com = np.array(self.center_of_mass, dtype=np.float64).reshape(3)
        ten = np.array(self.inertia, dtype=np.float64).reshape(3, 3)
        com.setflags(write=False)
        ten.setflags(write=False)
        mass, volume, area = float(self.mass), float(self.volume), float(self.surface_area)
        stored = self.__dict__              # a frozen value: its fields are set once, here, before anyone sees it
        stored.update(center_of_mass=com, inertia=ten, mass=mass, volume=volume, surface_area=area,
                      density=float(self.density))
        # one finite sum says all are finite (a NaN or an infinity makes it non-finite; so may an overflow of
        # finite values, which the checks one by one then let through): a body made every few hundred µs
        # pays one test, not five array checks
        total = mass + volume + area + sum(com.tolist()) + sum(ten.ravel().tolist())
        if not total - total == 0.0:
            for what, value in (("mass", mass), ("volume", volume), ("centre of mass", com),
                                ("inertia tensor", ten), ("surface area", area)):
                NonFiniteResultError.check(f"{self.name or 'body'}: the {what}", value)
        if volume > 0 and self.density > 0 and mass < sys.float_info.min:
            raise NonFiniteResultError(f"{self.name or 'body'}: the mass underflows to {self.mass:g} kg (density "
                                       f"{self.density:g} kg/m³ times volume {self.volume:g} m³): the density "
                                       "is outside any physically meaningful range")

    # -- derived quantities -------------------------------------------------------------------------
    @cached_property
    def principal(self) -> PrincipalAxes:
        """Principal moments (ascending) and right-handed axes about the centre of mass (Eq. 4.25).

        Equal moments are judged with :data:`~inertia_tool.tolerances.EQUAL_MOMENTS_RTOL`; for another
        tolerance call :func:`~inertia_tool.mass.principal.principal_axes` on ``inertia`` (its arrays are
        read-only, so caching it is safe)."""
        return principal_axes(self.inertia, reference_point=self.center_of_mass, mass=self.mass)

    @property
    def central_inertia(self) -> InertiaTensor:
        """The inertia tensor about the centre of mass, with its reference point."""
        return InertiaTensor(self.inertia, self.center_of_mass)

    @property
    def size(self) -> float:
        """A length scale of the body, m: the mesh's bounding-box diagonal, else twice the radius of gyration
        ``√(tr I / 2M)`` (0 for a point mass)."""
        if self.mesh is not None:
            return float(np.linalg.norm(np.asarray(self.mesh.bbox_max) - np.asarray(self.mesh.bbox_min)))
        if not self.mass > 0:
            return 0.0
        return float(2.0 * np.sqrt(max(np.trace(self.inertia), 0.0) / (2.0 * self.mass)))

    def inertia_about(self, point: ArrayLike, *, far_point_ratio: float | None = FAR_POINT_RATIO) -> InertiaTensor:
        """Inertia tensor about ``point`` (m, mesh axes) by the parallel-axis theorem, Eq. (4.16).

        ``I^(p) = I^(cm) + M [(p−R)² δ_ij − (p−R)_i (p−R)_j]``.  The result converts to a (3, 3) array with
        ``np.asarray`` and carries ``reference_point``.

        A point farther than ``far_point_ratio`` sizes (:attr:`size`) from the centre of mass is most likely a
        units slip (millimetres given as metres): :class:`~inertia_tool.errors.ImplausiblePointWarning` says
        so, and the result is computed as asked.  ``None`` skips the check.
        """
        p = as_vector3(point, "point")
        if far_point_ratio is not None:
            warn_far_point(self, p, far_point_ratio, stacklevel=2)
        return InertiaTensor(self.inertia + parallel_axis_shift(self.mass, p - self.center_of_mass), p)

    def moment_about_axis(self, direction: ArrayLike, point: ArrayLike | None = None) -> float:
        """Moment of inertia about the line through ``point`` along ``direction``, kg·m² (Eq. 4.17).

        ``n̂·I^(cm)·n̂ + M |n̂ × (p − R)|²``; ``point`` defaults to the centre of mass.
        """
        n = as_vector3(direction, "direction")
        norm = np.linalg.norm(n)
        if norm == 0:
            raise UsageError("Expected a non-zero `direction`, got (0, 0, 0)")
        n = n / norm
        p = self.center_of_mass if point is None else as_vector3(point, "point")
        d = np.cross(n, p - self.center_of_mass)
        return float(n @ self.inertia @ n + self.mass * (d @ d))

    def transformed(self, rotation: ArrayLike | None = None, translation: ArrayLike | None = None) -> "MassProperties":
        """The same body moved rigidly: ``x ↦ R x + t``.

        Parameters
        ----------
        rotation : (3, 3) array_like, optional
            Proper rotation (active).  Default identity.
        translation : (3,) array_like, optional
            m.  Default zero.

        Returns
        -------
        MassProperties
            A new body with ``center_of_mass = R c + t`` and ``inertia = R I Rᵀ``.
        """
        r = np.eye(3) if rotation is None else np.asarray(rotation, dtype=np.float64)
        if r.shape != (3, 3):
            raise UsageError(f"Expected `rotation` to have shape (3, 3), got {r.shape}")
        if not np.allclose(r @ r.T, np.eye(3), atol=ROTATION_ATOL) or np.linalg.det(r) < 0:
            raise UsageError("Expected `rotation` to be a proper rotation matrix (orthogonal, det +1)")
        t = np.zeros(3) if translation is None else as_vector3(translation, "translation")
        return MassProperties(mass=self.mass, volume=self.volume, center_of_mass=r @ self.center_of_mass + t,
                              inertia=r @ self.inertia @ r.T, surface_area=self.surface_area,
                              density=self.density, name=self.name)

    def with_mass(self, mass: float) -> "MassProperties":
        """The same geometry with its density scaled so that the total mass is ``mass`` kg."""
        if not (np.isfinite(mass) and mass > 0):
            raise UsageError(f"Expected a positive finite mass, got {mass}")
        if not self.mass > 0:
            raise UsageError("Cannot rescale a body of zero mass")
        k = mass / self.mass
        return MassProperties(mass=mass, volume=self.volume, center_of_mass=self.center_of_mass,
                              inertia=self.inertia * k, surface_area=self.surface_area,
                              density=self.density * k, name=self.name, mesh=self.mesh,
                              parts=tuple(p.with_mass(p.mass * k) for p in self.parts if p.mass > 0),
                              material=self.material)

    def __add__(self, other: "MassProperties") -> "MassProperties":
        if not isinstance(other, MassProperties):
            return NotImplemented
        return combine([self, other])

    def __radd__(self, other: object) -> MassProperties:
        if other == 0:        # allows sum([...])
            return self
        return NotImplemented


def point_mass(mass: float, position: ArrayLike, *, name: str = "point mass") -> MassProperties:
    """A point mass as ``MassProperties``: zero volume and zero central inertia.

    Parameters
    ----------
    mass : float
        kg, non-negative.
    position : (3,) array_like
        m, mesh axes.
    name : str
        Label in reports.
    """
    if not (np.isfinite(mass) and mass >= 0):
        raise UsageError(f"Expected a non-negative finite mass, got {mass}")
    return MassProperties(mass=mass, volume=0.0, center_of_mass=as_vector3(position, "position"),
                          inertia=np.zeros((3, 3)), name=name)


def combine(bodies: Iterable[MassProperties], *, name: str = "assembly") -> MassProperties:
    """Rigidly join bodies (and point masses) into one: masses add, the centre of mass is the mass-weighted
    mean, and each central tensor is moved to the common centre of mass by the parallel-axis theorem (Eq. 4.16).

    Parameters
    ----------
    bodies : iterable of MassProperties
        With negative masses allowed (removed material), as long as the total is positive.
    name : str
        Label of the combined body in reports.
    """
    bodies = list(bodies)
    if not bodies:
        raise UsageError("Expected at least one body to combine, got none")
    total = sum(b.mass for b in bodies)
    if not total > 0:
        raise UsageError(f"Expected a positive total mass, got {total}")
    # the start values are the zeros sum() would add anyway (as int 0); as arrays they keep the type an array
    com = sum((b.mass * b.center_of_mass for b in bodies), np.zeros(3)) / total
    ten = sum((b.inertia + parallel_axis_shift(b.mass, b.center_of_mass - com) for b in bodies), np.zeros((3, 3)))
    volume = sum(b.volume for b in bodies)
    density = total / volume if volume > 0 else float("nan")
    return MassProperties(mass=total, volume=volume, center_of_mass=com, inertia=0.5 * (ten + ten.T),
                          surface_area=sum(b.surface_area for b in bodies), density=density, name=name,
                          parts=tuple(bodies))
