"""The result of a rigid-body simulation, and how a "body" argument becomes principal moments and axes.

Frames (``docs/conventions.md``): *mesh axes* are the body-fixed axes of the input (the body frame of every
vector in a :class:`Trajectory` that says "body"); the *principal frame* has the columns of ``axes`` as its
axes; the *space frame* is inertial and coincides with the mesh axes when the orientation is the identity.
"""

from __future__ import annotations



import numpy as np

from ..values import frozen_value
from ..errors import UsageError
from ..mass.principal import PrincipalAxes, principal_axes
from ..rotations import quaternion_to_matrix

__all__ = ["Trajectory", "resolve_body"]


@frozen_value
class Trajectory:
    """Motion of a rigid body about its centre of mass, sampled at the requested times.

    Attributes
    ----------
    t : (N,) float
        Times, s (the initial state holds at ``t[0]``).
    angular_velocity : (N, 3) float
        Body angular velocity in the body's **mesh axes**, rad/s.
    orientation : (N, 4) float
        Scalar-first unit quaternions ``(w, x, y, z)``, ``w ≥ 0``, of the active rotation body (mesh axes) →
        space, ``r_space = Q r_body``; the chapter's ``A`` (Eq. 4.31) is ``Qᵀ``.
    angular_momentum : (N, 3) float
        ``L = Q I ω`` about the centre of mass, **space frame**, kg·m²/s.
    energy : (N,) float
        Rotational kinetic energy ``½ ω·I·ω`` (Eq. 4.14), J.
    method : str
        ``"exact:<case>"`` (closed form, case from ``torque_free.FREE_CASES``), ``"numerical:gbs"`` or
        ``"splitting:<scheme>"`` (scheme from ``splitting.SCHEMES``).
    moments : (3,) float
        Principal moments used, ascending, kg·m².
    axes : (3, 3) float
        Principal axes used, as columns in mesh axes (proper rotation, principal → mesh components).
    """

    t: np.ndarray
    angular_velocity: np.ndarray
    orientation: np.ndarray
    angular_momentum: np.ndarray
    energy: np.ndarray
    method: str
    moments: np.ndarray
    axes: np.ndarray

    @property
    def rotation_matrices(self) -> np.ndarray:
        """(N, 3, 3): active rotations ``Q`` (body mesh axes → space) of :attr:`orientation`."""
        return quaternion_to_matrix(self.orientation)

    @property
    def tensor(self) -> np.ndarray:
        """(3, 3) kg·m²: inertia tensor about the centre of mass in mesh axes, ``axes · diag(moments) · axesᵀ``."""
        return self.axes @ np.diag(self.moments) @ self.axes.T

    @property
    def angular_velocity_principal(self) -> np.ndarray:
        """(N, 3) rad/s: body angular velocity in the principal frame."""
        return self.angular_velocity @ self.axes

    @property
    def angular_velocity_space(self) -> np.ndarray:
        """(N, 3) rad/s: angular velocity in the space frame, ``Q ω``."""
        return np.einsum("nij,nj->ni", self.rotation_matrices, self.angular_velocity)


def resolve_body(body) -> PrincipalAxes:
    """Principal moments and axes of a ``body`` argument.

    Parameters
    ----------
    body : MassProperties, PrincipalAxes, (3,) array_like or (3, 3) array_like
        A ``MassProperties`` (its ``principal``), a ``PrincipalAxes``, three principal moments along the mesh
        x, y, z axes (kg·m², any order), or a symmetric inertia tensor about the centre of mass (kg·m²).

    Returns
    -------
    PrincipalAxes
        Moments ascending, axes a proper rotation (mesh ← principal).  For three moments or a tensor the
        moments are the exact eigenvalues (``rtol = 0``: no two are merged).
    """
    if isinstance(body, PrincipalAxes):
        result = body
    elif hasattr(body, "principal") and isinstance(body.principal, PrincipalAxes):
        result = body.principal
    else:
        arr = np.asarray(body, dtype=np.float64)
        if arr.shape == (3,):
            if not np.all(np.isfinite(arr)):
                raise UsageError("Expected finite principal moments")
            order = np.argsort(arr, kind="stable")
            axes = np.eye(3)[:, order]
            if np.linalg.det(axes) < 0:
                axes[:, 2] = -axes[:, 2]
            result = PrincipalAxes(moments=arr[order], axes=axes, reference_point=np.zeros(3),
                                   mass=float("nan"), equal_pairs=(), rtol=0.0)
        elif arr.shape == (3, 3):
            if not np.allclose(arr, arr.T, rtol=1e-12, atol=0.0):
                raise UsageError("Expected a symmetric inertia tensor")
            result = principal_axes(arr, rtol=0.0)
        else:
            raise UsageError("Expected `body` to be MassProperties, PrincipalAxes, 3 moments or a (3, 3) tensor, "
                             f"got shape {arr.shape}")
    moments = np.asarray(result.moments, dtype=np.float64)
    if not (np.all(np.isfinite(moments)) and moments[0] > 0):
        raise UsageError(f"Expected positive principal moments, got {moments.tolist()}")
    return result
