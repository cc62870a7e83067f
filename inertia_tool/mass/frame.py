"""Mass properties in a chosen coordinate system (SolidWorks' "output coordinate system").

A coordinate system is an origin ``O`` (m, mesh axes) and a rotation ``R`` whose columns are its axes in mesh
coordinates (so a frame vector ``u`` is the mesh vector ``R u``).  In it the centre of mass is
``Rᵀ (c − O)``, the inertia about ``O`` is ``Rᵀ I^(O) R`` with ``I^(O)`` from the parallel-axis theorem,
Eq. (4.16) of Chapter 4 ("Rigid Body Motion"), and the central tensor is ``Rᵀ I^(cm) R`` (Eq. 4.20: a tensor
rotates as ``R I Rᵀ`` under the active rotation ``R``; here the passive change of basis takes ``Rᵀ``).
See ``docs/conventions.md`` for signs (tensor elements: off-diagonals are ``−∫xy dm``).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from ..errors import UsageError
from ..tolerances import FAR_POINT_RATIO, ROTATION_ATOL
from ..values import frozen_value
from .properties import MassProperties, as_vector3, warn_far_point

__all__ = ["FrameInertia", "inertia_in_frame"]


@frozen_value
class FrameInertia:
    """A body's mass properties expressed in a coordinate system.

    Attributes
    ----------
    origin : (3,) float
        ``O``, m, mesh axes.
    rotation : (3, 3) float
        Columns: the system's x, y, z axes in mesh coordinates (proper rotation).
    mass : float
        kg.
    center_of_mass : (3,) float
        m, in the system's coordinates: ``Rᵀ (c − O)``.
    inertia : (3, 3) float
        kg·m², about ``O``, the system's axes (tensor convention).
    central_inertia : (3, 3) float
        kg·m², about the centre of mass, the system's axes (tensor convention).
    """

    origin: np.ndarray
    rotation: np.ndarray
    mass: float
    center_of_mass: np.ndarray
    inertia: np.ndarray
    central_inertia: np.ndarray


def inertia_in_frame(props: MassProperties, origin: ArrayLike, rotation: ArrayLike | None = None, *,
                     far_point_ratio: float | None = FAR_POINT_RATIO,
                     rotation_atol: float = ROTATION_ATOL) -> FrameInertia:
    """``props`` in the coordinate system with ``origin`` (m, mesh axes) and axes the columns of ``rotation``.

    Parameters
    ----------
    props : MassProperties
    origin : (3,) array_like
        m, mesh axes.
    rotation : (3, 3) array_like, optional
        Proper rotation, columns the system's axes in mesh coordinates; default identity (mesh axes).
    far_point_ratio : float or None
        Warn (``ImplausiblePointWarning``) for an origin farther than this many part sizes from the centre
        of mass; None skips the check.
    rotation_atol : float
        ``‖R Rᵀ − 1‖∞`` allowed.

    Returns
    -------
    FrameInertia

    Raises
    ------
    UsageError
        For an origin that is not a finite 3-vector or a rotation that is not proper.
    """
    o = as_vector3(origin, "origin")
    r = np.eye(3) if rotation is None else np.asarray(rotation, dtype=np.float64)
    if r.shape != (3, 3) or not np.all(np.isfinite(r)):
        raise UsageError(f"Expected `rotation` to be a finite (3, 3) matrix, got shape {r.shape}")
    if np.max(np.abs(r @ r.T - np.eye(3))) > rotation_atol or np.linalg.det(r) <= 0:
        raise UsageError("Expected `rotation` to be a proper rotation (orthonormal columns, determinant +1), got "
                         f"R Rᵀ off the identity by {np.max(np.abs(r @ r.T - np.eye(3))):.3g} and det "
                         f"{np.linalg.det(r):.6g}")
    if far_point_ratio is not None:
        warn_far_point(props, o, far_point_ratio, stacklevel=2, what="the origin")
    about = np.asarray(props.inertia_about(o, far_point_ratio=None))
    return FrameInertia(origin=o, rotation=r, mass=props.mass, center_of_mass=r.T @ (props.center_of_mass - o),
                        inertia=r.T @ about @ r, central_inertia=r.T @ props.inertia @ r)
