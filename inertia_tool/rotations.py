"""Rotation representations of the chapter: z-y-z Euler angles, axis-angle, unit quaternions.

Pure functions on numpy arrays (leading dimensions broadcast).  Conventions (``docs/conventions.md``):

* ``A`` is the chapter's **passive** matrix mapping space components to body components, ``V' = A V``
  (Eq. 4.3); its rows are the body axes in space coordinates (Eq. 4.2).
* Euler angles are the chapter's z-y-z sequence ``A(φ, θ, ψ) = R_z(ψ) R_y(θ) R_z(φ)`` (Eq. 4.31) with the
  passive ``R_z``, ``R_y`` of Eqs. (4.29)-(4.30); ``θ ∈ [0, π]``, ``φ, ψ ∈ [0, 2π)``.
* The **orientation** of a body is the active rotation ``Q = Aᵀ`` (body components → space components),
  stored as a scalar-first unit quaternion ``q = (w, x, y, z)`` with ``w ≥ 0`` where a sign must be chosen.
  In scipy's language ``Q = Rotation.from_euler("ZYZ", [φ, θ, ψ]).as_matrix()`` (intrinsic z-y'-z'') and
  ``Rotation.from_quat(np.roll(q, -1))`` (scipy is scalar-last).

The conversions between representations are scipy's (:class:`scipy.spatial.transform.Rotation`, imported on
first use so that ``analyze`` does not pay for it); this module only states the chapter's conventions and
translates to and from them.  The chapter's own formulas (Eqs. 4.29–4.33, exercise 4.5) are kept where they
are the definition (``rotation_z``, ``rotation_y``, ``euler_rates_to_angular_velocity``) and checked against
scipy in ``tests/test_rotations.py``.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np

from .errors import UsageError

if TYPE_CHECKING:                       # scipy has no type information: Rotation is Any to the checker
    from numpy.typing import ArrayLike, NDArray      # annotations only: not loaded at run time
    from scipy.spatial.transform import Rotation

__all__ = [
    "perpendicular_basis",
    "rotation_z",
    "rotation_y",
    "euler_to_matrix",
    "matrix_to_euler",
    "euler_rates_to_angular_velocity",
    "axis_angle_to_matrix",
    "matrix_to_axis_angle",
    "quaternion_to_matrix",
    "matrix_to_quaternion",
    "quaternion_multiply",
    "quaternion_conjugate",
    "rotation_vector_to_quaternion",
    "euler_to_quaternion",
    "quaternion_to_euler",
    "skew",
]

_TWO_PI = 2.0 * np.pi


def _as_quaternion(q: ArrayLike, name: str = "q") -> NDArray[np.float64]:
    a = np.asarray(q, dtype=np.float64)
    if a.shape[-1:] != (4,):
        raise UsageError(f"Expected `{name}` to have shape (..., 4), got {a.shape}")
    if not np.all(np.isfinite(a)):
        raise UsageError(f"Expected `{name}` to be finite")
    return a


def _as_matrix(m: ArrayLike, name: str = "matrix") -> NDArray[np.float64]:
    a = np.asarray(m, dtype=np.float64)
    if a.shape[-2:] != (3, 3):
        raise UsageError(f"Expected `{name}` to have shape (..., 3, 3), got {a.shape}")
    if not np.all(np.isfinite(a)):
        raise UsageError(f"Expected `{name}` to be finite")
    return a


def skew(vector: ArrayLike) -> np.ndarray:
    """Cross-product matrix ``[v]×`` with ``[v]× b = v × b``; (..., 3) → (..., 3, 3).

    In the chapter's notation ``Ω'_ij = Σ_k ε_ijk ω'_k`` (§4.2) is ``−[ω']×``.
    """
    v = np.asarray(vector, dtype=np.float64)
    z = np.zeros_like(v[..., 0])
    return np.stack([np.stack([z, -v[..., 2], v[..., 1]], -1),
                     np.stack([v[..., 2], z, -v[..., 0]], -1),
                     np.stack([-v[..., 1], v[..., 0], z], -1)], -2)


def rotation_z(angle: ArrayLike) -> np.ndarray:
    """Passive rotation about z, Eq. (4.29): ``[[c, s, 0], [−s, c, 0], [0, 0, 1]]``; (...) → (..., 3, 3)."""
    a = np.asarray(angle, dtype=np.float64)
    c, s, o, z = np.cos(a), np.sin(a), np.ones_like(a), np.zeros_like(a)
    return np.stack([np.stack([c, s, z], -1), np.stack([-s, c, z], -1), np.stack([z, z, o], -1)], -2)


def rotation_y(angle: ArrayLike) -> np.ndarray:
    """Passive rotation about y, Eq. (4.30): ``[[c, 0, −s], [0, 1, 0], [s, 0, c]]``; (...) → (..., 3, 3)."""
    a = np.asarray(angle, dtype=np.float64)
    c, s, o, z = np.cos(a), np.sin(a), np.ones_like(a), np.zeros_like(a)
    return np.stack([np.stack([c, z, -s], -1), np.stack([z, o, z], -1), np.stack([s, z, c], -1)], -2)


def _rotation(active_matrices: np.ndarray | None = None, *, quaternions: np.ndarray | None = None,
              rotvecs: np.ndarray | None = None, euler: np.ndarray | None = None) -> Rotation:
    """scipy ``Rotation`` of a stack of active matrices / scalar-first quaternions / rotation vectors / angles."""
    from scipy.spatial.transform import Rotation
    if active_matrices is not None:
        stack = active_matrices.reshape(-1, 3, 3)
        if not np.all(np.linalg.det(stack) > 0):
            raise UsageError("Expected proper rotation matrices (det +1), got a reflection or a singular matrix")
        return Rotation.from_matrix(stack)
    if quaternions is not None:
        return Rotation.from_quat(np.roll(quaternions.reshape(-1, 4), -1, axis=-1))
    if rotvecs is not None:
        return Rotation.from_rotvec(rotvecs.reshape(-1, 3))
    assert euler is not None, "_rotation needs one of its four arguments"   # internal: callers pass one
    return Rotation.from_euler("ZYZ", euler.reshape(-1, 3))


def euler_to_matrix(phi: ArrayLike, theta: ArrayLike, psi: ArrayLike) -> np.ndarray:
    """The chapter's ``A(φ, θ, ψ) = R_z(ψ) R_y(θ) R_z(φ)``, Eq. (4.31) (space → body components).

    ``A`` is the transpose of scipy's intrinsic ``Rotation.from_euler("ZYZ", [φ, θ, ψ])``.

    Parameters
    ----------
    phi, theta, psi : array_like, broadcastable
        Euler angles in radians.

    Returns
    -------
    (..., 3, 3) float
    """
    angles = np.stack(np.broadcast_arrays(*(np.asarray(x, dtype=np.float64) for x in (phi, theta, psi))), -1)
    if not np.all(np.isfinite(angles)):
        raise UsageError("Expected finite Euler angles")
    active: np.ndarray = _rotation(euler=angles).as_matrix()
    return np.swapaxes(active, -1, -2).reshape(angles.shape[:-1] + (3, 3))


def matrix_to_euler(matrix: ArrayLike, *, gimbal_atol: float = 1e-12) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Euler angles ``(φ, θ, ψ)`` of a passive matrix ``A`` (inverse of :func:`euler_to_matrix`).

    From Eq. (4.31): ``cos θ = A33``, ``(A31, A32) = sin θ (cos φ, sin φ)``,
    ``(−A13, A23) = sin θ (cos ψ, sin ψ)``.  Ranges: ``θ ∈ [0, π]``, ``φ, ψ ∈ [0, 2π)`` (§4.4.2).

    Gimbal cases (footnote 16: only ``φ ± ψ`` is defined when ``sin θ ≤ gimbal_atol``): we return
    ``ψ = 0`` and, for ``θ = 0`` (``A = R_z(φ + ψ)``), ``φ = atan2(A12, A11)``; for ``θ = π``
    (``A = R_z(ψ − φ) R_y(π)``), ``φ = atan2(−A12, −A11)``.

    Parameters
    ----------
    matrix : (..., 3, 3) array_like
        Proper rotation matrices ``A``.
    gimbal_atol : float
        ``sin θ`` at or below which the gimbal branch is used.

    Returns
    -------
    phi, theta, psi : (...) float arrays, radians
    """
    a = _as_matrix(matrix)
    sin_theta = np.hypot(a[..., 2, 0], a[..., 2, 1])
    theta = np.arctan2(sin_theta, a[..., 2, 2])
    phi = np.arctan2(a[..., 2, 1], a[..., 2, 0])
    psi = np.arctan2(a[..., 1, 2], -a[..., 0, 2])
    gimbal = sin_theta <= gimbal_atol
    up = a[..., 2, 2] > 0
    phi = np.where(gimbal & up, np.arctan2(a[..., 0, 1], a[..., 0, 0]), phi)
    phi = np.where(gimbal & ~up, np.arctan2(-a[..., 0, 1], -a[..., 0, 0]), phi)
    psi = np.where(gimbal, 0.0, psi)
    return np.mod(phi, _TWO_PI), theta, np.mod(psi, _TWO_PI)


def euler_rates_to_angular_velocity(phi: ArrayLike, theta: ArrayLike, psi: ArrayLike, phi_dot: ArrayLike,
                                    theta_dot: ArrayLike, psi_dot: ArrayLike) -> np.ndarray:
    """Body components of the angular velocity from Euler angles and rates, Eq. (4.33).

    ``ω'_1 = θ̇ sin ψ − φ̇ sin θ cos ψ``, ``ω'_2 = θ̇ cos ψ + φ̇ sin θ sin ψ``, ``ω'_3 = ψ̇ + φ̇ cos θ``;
    these are the components of ``Ω' = −A d(A⁻¹)/dt`` (Eq. 4.32, §4.2).

    Returns
    -------
    (..., 3) float, rad/s, body axes.
    """
    phi, theta, psi, phi_dot, theta_dot, psi_dot = np.broadcast_arrays(
        *(np.asarray(x, dtype=np.float64) for x in (phi, theta, psi, phi_dot, theta_dot, psi_dot)))
    return np.stack([theta_dot * np.sin(psi) - phi_dot * np.sin(theta) * np.cos(psi),
                     theta_dot * np.cos(psi) + phi_dot * np.sin(theta) * np.sin(psi),
                     psi_dot + phi_dot * np.cos(theta)], -1)


def _unit_axis(axis: ArrayLike) -> np.ndarray:
    n = np.asarray(axis, dtype=np.float64)
    if n.shape[-1:] != (3,):
        raise UsageError(f"Expected `axis` to have shape (..., 3), got {n.shape}")
    norm: NDArray[np.float64] = np.linalg.norm(n, axis=-1, keepdims=True)
    if not np.all(norm > 0) or not np.all(np.isfinite(norm)):
        raise UsageError("Expected a finite non-zero `axis`")
    return n / norm


def axis_angle_to_matrix(axis: ArrayLike, angle: ArrayLike) -> np.ndarray:
    """Passive matrix ``A`` of a counter-clockwise rotation by ``angle`` about ``axis`` (exercise 4.5).

    ``A_ij = δ_ij cos θ + n_i n_j (1 − cos θ) − ε_ijk n_k sin θ``: the transpose of scipy's
    ``Rotation.from_rotvec(θ n̂)`` (the active rotation, body → space).

    Parameters
    ----------
    axis : (..., 3) array_like
        Rotation axis (normalised here).
    angle : (...) array_like
        Radians.

    Returns
    -------
    (..., 3, 3) float
    """
    n = _unit_axis(axis)
    th = np.asarray(angle, dtype=np.float64)
    rotvec = n * th[..., None]
    active: np.ndarray = _rotation(rotvecs=rotvec).as_matrix()
    return np.swapaxes(active, -1, -2).reshape(rotvec.shape[:-1] + (3, 3))


def matrix_to_axis_angle(matrix: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
    """Axis and angle of a passive matrix ``A`` (inverse of :func:`axis_angle_to_matrix`).

    Returns ``(axis (..., 3), angle (...) ∈ [0, π])``; for the identity the axis is ``(0, 0, 1)``.
    """
    a = _as_matrix(matrix)
    rotvec: np.ndarray = _rotation(np.swapaxes(a, -1, -2)).as_rotvec().reshape(a.shape[:-2] + (3,))
    angle = np.linalg.norm(rotvec, axis=-1)
    safe = np.where(angle > 0, angle, 1.0)[..., None]
    axis = np.where(angle[..., None] > 0, rotvec / safe, np.array([0.0, 0.0, 1.0]))
    return axis, angle


def quaternion_to_matrix(quaternion: ArrayLike) -> np.ndarray:
    """Active rotation matrix ``Q`` (body → space) of scalar-first quaternions (normalised here); ``A = Qᵀ``.

    ``Q = (w² − v·v) 𝟙 + 2 v vᵀ + 2 w [v]×`` for ``q = (w, v)``: scipy's ``Rotation.from_quat`` after moving
    the scalar last.

    Returns
    -------
    (..., 3, 3) float
    """
    q = _as_quaternion(quaternion, "quaternion")
    if not np.all(np.linalg.norm(q, axis=-1) > 0):
        raise UsageError("Expected non-zero quaternions")
    active: np.ndarray = _rotation(quaternions=q).as_matrix()
    return active.reshape(q.shape[:-1] + (3, 3))


def matrix_to_quaternion(matrix: ArrayLike) -> np.ndarray:
    """Scalar-first unit quaternion (``w ≥ 0``) of an active rotation matrix ``Q`` (scipy's, canonical).

    Returns
    -------
    (..., 4) float
    """
    m = _as_matrix(matrix)
    q: np.ndarray = np.roll(_rotation(m).as_quat(canonical=True), 1, axis=-1)
    return q.reshape(m.shape[:-2] + (4,))


def quaternion_multiply(p: ArrayLike, q: ArrayLike) -> np.ndarray:
    """Hamilton product ``p ⊗ q`` of scalar-first quaternions (matrix of ``p ⊗ q`` = ``Q_p Q_q``)."""
    p = _as_quaternion(p, "p")
    q = _as_quaternion(q, "q")
    pw, pv = p[..., :1], p[..., 1:]
    qw, qv = q[..., :1], q[..., 1:]
    w = pw * qw - np.sum(pv * qv, axis=-1, keepdims=True)
    v = pw * qv + qw * pv + np.cross(pv, qv)
    return np.concatenate([w, v], -1)


def quaternion_conjugate(q: ArrayLike) -> np.ndarray:
    """``(w, −x, −y, −z)``: the inverse rotation for a unit quaternion."""
    q = _as_quaternion(q)
    return q * np.array([1.0, -1.0, -1.0, -1.0], dtype=np.float64)


def rotation_vector_to_quaternion(rotation_vector: ArrayLike) -> np.ndarray:
    """Quaternion ``exp(v/2) = (cos(|v|/2), sin(|v|/2) v/|v|)`` of an active rotation by ``|v|`` about ``v``.

    Uses the series of ``sin(x/2)/x`` below ``|v| = 1e-4`` (exact to round-off).
    """
    v = np.asarray(rotation_vector, dtype=np.float64)
    if v.shape[-1:] != (3,):
        raise UsageError(f"Expected `rotation_vector` to have shape (..., 3), got {v.shape}")
    angle: NDArray[np.float64] = np.linalg.norm(v, axis=-1, keepdims=True)
    small = angle < 1e-4
    safe = np.where(small, 1.0, angle)
    half_sinc = np.where(small, 0.5 - angle * angle / 48.0, np.sin(0.5 * safe) / safe)
    return np.concatenate([np.cos(0.5 * angle), half_sinc * v], -1)


def euler_to_quaternion(phi: ArrayLike, theta: ArrayLike, psi: ArrayLike) -> np.ndarray:
    """Quaternion of the orientation ``Q = A(φ, θ, ψ)ᵀ`` (Eq. 4.31); (...) → (..., 4)."""
    return matrix_to_quaternion(np.swapaxes(euler_to_matrix(phi, theta, psi), -1, -2))


def quaternion_to_euler(quaternion: ArrayLike, *,
                        gimbal_atol: float = 1e-12) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Euler angles ``(φ, θ, ψ)`` of the orientation quaternion (``A = Qᵀ``); see :func:`matrix_to_euler`."""
    return matrix_to_euler(np.swapaxes(quaternion_to_matrix(quaternion), -1, -2), gimbal_atol=gimbal_atol)


def perpendicular_basis(normal: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
    """Deterministic orthonormal basis ``(e1, e2)`` of the plane ⟂ the unit vector ``normal``.

    ``e1`` is the coordinate axis most orthogonal to ``normal`` (smallest ``|normal_k|``, the first on a tie),
    projected into the plane and normalised; ``e2 = normal × e1``, so ``(e1, e2, normal)`` is right-handed.
    Used wherever a free choice of axes must be reproducible (equal principal moments, the shaft frame,
    the invariant plane); see ``docs/conventions.md``.
    """
    arr = np.asarray(normal, dtype=np.float64)
    if arr.shape != (3,):
        raise UsageError(f"Expected `normal` to have shape (3,), got {arr.shape}")
    # on Python floats: numpy's per-call overhead on 3-vectors was ~30 times the arithmetic (principal axes of
    # every axisymmetric part come here); the same operations as the array form, norms to the last unit
    n = arr.tolist()
    k = min(range(3), key=lambda i: abs(n[i]))        # the first on a tie, as argmin
    e1 = [-n[k] * x for x in n]
    e1[k] += 1.0
    norm = math.sqrt(e1[0] * e1[0] + e1[1] * e1[1] + e1[2] * e1[2])
    e1 = [x / norm for x in e1]
    e2 = [n[1] * e1[2] - n[2] * e1[1], n[2] * e1[0] - n[0] * e1[2], n[0] * e1[1] - n[1] * e1[0]]
    return np.array(e1), np.array(e2)


# ---------------------------------------------------------------------------------------------------------------
# Cayley–Klein parameters and the SU(2) → SO(3) double cover (Chapter 4, "Rigid Body Motion", exercise 4.11).
#
# A rotation of the unit sphere, seen through the stereographic projection from the north pole
# ``ξ = (x + i y)/(1 − z)`` (exercise 4.11a), is the Möbius map ``ξ ↦ (α ξ + β)/(γ ξ + δ)`` (4.11b) with
# ``U = [[α, β], [γ, δ]]`` in SU(2): ``δ = ᾱ``, ``γ = −β̄``, ``|α|² + |β|² = 1``.  Composition of maps is the matrix
# product (4.11c), and ``U`` and ``−U`` give the same map: SU(2) covers SO(3) twice.
#
# For the active rotation ``Q`` of the scalar-first unit quaternion ``(w, x, y, z)`` (module conventions):
#     α = w + i z,   β = −y + i x,   γ = y + i x,   δ = w − i z,
# i.e. ``U = conj(w 𝟙 − i (x σ_x + y σ_y + z σ_z))`` with the Pauli matrices σ.  These are the Cayley–Klein
# parameters of ``Q`` for this projection (Goldstein's α…δ describe the passive ``A`` with another projection and
# differ by conjugations).  ``Q`` is read back from ``U`` without quaternions, as
#     Q_ij = ½ tr(σ_i V σ_j V†),   V = conj(U).
# ---------------------------------------------------------------------------------------------------------------

__all__ += ["quaternion_to_cayley_klein", "cayley_klein_to_quaternion", "cayley_klein_to_matrix",
            "stereographic_projection", "inverse_stereographic_projection", "moebius_transform"]

_PAULI = np.array([[[0, 1], [1, 0]], [[0, -1j], [1j, 0]], [[1, 0], [0, -1]]], dtype=np.complex128)


def _as_su2(matrix: ArrayLike, atol: float) -> NDArray[np.complex128]:
    u = np.asarray(matrix, dtype=np.complex128)
    if u.shape[-2:] != (2, 2):
        raise UsageError(f"Expected `cayley_klein` to have shape (..., 2, 2), got {u.shape}")
    if not np.all(np.isfinite(u)):
        raise UsageError("Expected `cayley_klein` to be finite")
    alpha, beta, gamma, delta = u[..., 0, 0], u[..., 0, 1], u[..., 1, 0], u[..., 1, 1]
    deviation = np.max(np.abs(np.stack([delta - np.conj(alpha), gamma + np.conj(beta),
                                        alpha * delta - beta * gamma - 1.0])))
    if deviation > atol:
        raise UsageError(f"Expected a matrix of SU(2) (δ = conj α, γ = −conj β, αδ − βγ = 1 within {atol:g}), "
                         f"got a deviation of {deviation:.3g}")
    return u


def quaternion_to_cayley_klein(quaternion: ArrayLike) -> np.ndarray:
    """Cayley–Klein matrix ``U = [[α, β], [γ, δ]]`` ∈ SU(2) of the rotation of a scalar-first quaternion.

    ``α = w + i z``, ``β = −y + i x``, ``γ = y + i x``, ``δ = w − i z`` (see the block comment above): the
    Möbius map of ``U`` acting on ``ξ = (x + i y)/(1 − z)`` rotates the unit sphere by the active ``Q`` of the
    quaternion (exercise 4.11).  ``q`` and ``−q`` give ``U`` and ``−U``.

    Returns
    -------
    (..., 2, 2) complex
    """
    q = _as_quaternion(quaternion, "quaternion")
    q = q / np.linalg.norm(q, axis=-1, keepdims=True)
    w, x, y, z = q[..., 0], q[..., 1], q[..., 2], q[..., 3]
    return np.stack([np.stack([w + 1j * z, -y + 1j * x], -1), np.stack([y + 1j * x, w - 1j * z], -1)], -2)


def cayley_klein_to_quaternion(cayley_klein: ArrayLike, *, atol: float = 1e-9) -> np.ndarray:
    """Scalar-first unit quaternion of a Cayley–Klein matrix; ``U`` and ``−U`` give the same one.

    The sign is fixed by the first non-zero component of ``(w, x, y, z)`` being positive (``w > 0`` unless the
    rotation is a half turn).

    Parameters
    ----------
    cayley_klein : (..., 2, 2) complex
        A matrix of SU(2), checked to ``atol``.
    """
    u = _as_su2(cayley_klein, atol)
    alpha, beta = u[..., 0, 0], u[..., 0, 1]
    q = np.stack([alpha.real, beta.imag, -beta.real, alpha.imag], -1)
    q = q / np.linalg.norm(q, axis=-1, keepdims=True)
    tiny = np.abs(q) <= 1e-15
    first = np.argmax(~tiny, axis=-1)[..., None]
    sign = np.sign(np.take_along_axis(q, first, axis=-1))
    quaternion: NDArray[np.float64] = np.where(tiny, 0.0, q) * sign
    return quaternion


def cayley_klein_to_matrix(cayley_klein: ArrayLike, *, atol: float = 1e-9) -> np.ndarray:
    """Active rotation ``Q`` of a Cayley–Klein matrix: ``Q_ij = ½ tr(σ_i V σ_j V†)``, ``V = conj(U)``.

    The map SU(2) → SO(3) is a homomorphism (``Q(U1 U2) = Q(U1) Q(U2)``) and two-to-one (``Q(−U) = Q(U)``).

    Returns
    -------
    (..., 3, 3) float
    """
    v = np.conj(_as_su2(cayley_klein, atol))
    v_dagger = np.conj(np.swapaxes(v, -1, -2))
    # (σ_i V σ_j V†) traced: sum over the 2×2 indices
    m: NDArray[np.complex128] = np.einsum("iab,...bc,jcd,...da->...ij", _PAULI, v, _PAULI, v_dagger)
    return 0.5 * m.real


def stereographic_projection(points: ArrayLike) -> np.ndarray:
    """``ξ = (x + i y)/(1 − z)`` of points on the unit sphere (exercise 4.11a); the north pole maps to ``inf``.

    Parameters
    ----------
    points : (..., 3) array_like
        Unit vectors.

    Returns
    -------
    (...) complex
    """
    p = np.asarray(points, dtype=np.float64)
    if p.shape[-1:] != (3,):
        raise UsageError(f"Expected `points` to have shape (..., 3), got {p.shape}")
    with np.errstate(divide="ignore", invalid="ignore"):
        xi: np.ndarray = (p[..., 0] + 1j * p[..., 1]) / (1.0 - p[..., 2])
    return xi


def inverse_stereographic_projection(xi: ArrayLike) -> np.ndarray:
    """Point of the unit sphere whose projection is ``ξ``: ``(2 Re ξ, 2 Im ξ, |ξ|² − 1)/(|ξ|² + 1)``."""
    xi = np.asarray(xi, dtype=np.complex128)
    r2 = np.abs(xi) ** 2
    point: NDArray[np.float64] = np.stack([2 * xi.real, 2 * xi.imag, r2 - 1.0], -1) / (r2 + 1.0)[..., None]
    return point


def moebius_transform(cayley_klein: ArrayLike, xi: ArrayLike) -> np.ndarray:
    """``(α ξ + β)/(γ ξ + δ)`` (exercise 4.11b); ``cayley_klein`` (2, 2), ``xi`` any shape of complex."""
    u = np.asarray(cayley_klein, dtype=np.complex128)
    if u.shape != (2, 2):
        raise UsageError(f"Expected `cayley_klein` to have shape (2, 2), got {u.shape}")
    xi = np.asarray(xi, dtype=np.complex128)
    image: NDArray[np.complex128] = (u[0, 0] * xi + u[0, 1]) / (u[1, 0] * xi + u[1, 1])
    return image
