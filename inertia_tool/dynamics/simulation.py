"""``simulate``: the public entry point of rigid-body dynamics (routes to the exact or numerical stage)."""

from __future__ import annotations

import numpy as np

from ..errors import UsageError
from ..mass.properties import as_vector3
from ..rotations import matrix_to_quaternion, quaternion_multiply, quaternion_to_matrix
from .integrate import DEFAULT_COLUMNS, integrate_rigid_body
from .splitting import DEFAULT_SCHEME, SCHEMES, integrate_splitting
from .torque_free import ELLIPTIC_M1_FLOOR, free_body_parameters, torque_free_motion
from .trajectory import Trajectory, resolve_body

__all__ = ["simulate", "METHODS"]

#: Accepted values of ``simulate(method=...)``.
METHODS = ("auto", "exact", "numerical", "splitting")


def _check_times(t) -> np.ndarray:
    times = np.atleast_1d(np.asarray(t, dtype=np.float64))
    if times.ndim != 1 or times.size == 0:
        raise UsageError(f"Expected `t` to be a non-empty 1-D array of times, got shape {times.shape}")
    if not np.all(np.isfinite(times)):
        raise UsageError("Expected finite times `t`")
    if np.any(np.diff(times) <= 0):
        raise UsageError("Expected strictly increasing times `t`")
    return times


def _check_orientation(orientation) -> np.ndarray:
    if orientation is None:
        return np.array([1.0, 0.0, 0.0, 0.0])
    q = np.asarray(orientation, dtype=np.float64)
    if q.shape != (4,) or not np.all(np.isfinite(q)):
        raise UsageError(f"Expected `orientation` to be a finite scalar-first quaternion of shape (4,), got {q}")
    norm = np.linalg.norm(q)
    if abs(norm - 1.0) > 1e-6:
        raise UsageError(f"Expected a unit quaternion `orientation`, got norm {norm:.9g}")
    return q / norm


def _check_no_angular_velocity_dependence(torque, t0, q0, omega0):
    """Evaluate the torque at the initial time and orientation with two different angular velocities."""
    probe = 2.0 * omega0 + np.array([1.0, -0.5, 0.25])
    first = np.asarray(torque(t0, q0.copy(), omega0.copy()), dtype=np.float64)
    second = np.asarray(torque(t0, q0.copy(), probe), dtype=np.float64)
    if first.shape != (3,) or second.shape != (3,):
        raise UsageError(f"Expected `torque` to return shape (3,), got {first.shape}")
    if not np.array_equal(first, second):
        raise UsageError("method='splitting' needs a torque that depends on time and orientation only, but "
                         f"torque(t, q, ω) changed with ω at t={t0:g} s ({first.tolist()} vs {second.tolist()}); "
                         "use method='numerical'")


def simulate(body, angular_velocity, t, *, torque=None, method: str = "auto", orientation=None,
             rtol: float = 1e-12, atol: float = 1e-12, columns: int = DEFAULT_COLUMNS,
             max_steps: int = 1_000_000, torque_depends_on_angular_velocity: bool = True,
             scheme: str = DEFAULT_SCHEME, max_step: float | None = None) -> Trajectory:
    """Rotational motion of a rigid body about its centre of mass.

    Parameters
    ----------
    body : MassProperties, PrincipalAxes, (3,) or (3, 3) array_like
        The body: ``MassProperties`` (its principal moments and axes are used), ``PrincipalAxes``, three
        moments along the mesh x, y, z axes, or the central inertia tensor in mesh axes; kg·m².
    angular_velocity : (3,) array_like
        Body angular velocity at ``t[0]`` in the body's mesh axes, rad/s.
    t : (N,) array_like
        Strictly increasing output times, s; the initial state holds at ``t[0]``.
    torque : callable, optional
        ``torque(t, orientation, angular_velocity) -> (3,)``: external torque about the centre of mass in
        N·m, **body (mesh) axes**, given the time (s), the scalar-first quaternion (4,) of body → space and
        the body angular velocity (3,) in mesh axes, rad/s.  ``None``: torque-free.
    method : {"auto", "exact", "numerical", "splitting"}
        ``"exact"``: closed form (Landau–Lifshitz §37 / Celledoni et al. 2008; torque-free only);
        ``"numerical"``: extrapolated midpoint integration (:mod:`.integrate`), any torque;
        ``"splitting"``: composition of the exact free flow with exact torque kicks (:mod:`.splitting`;
        symplectic, ``|q| = 1`` exactly, order 6 by default), only for torques independent of ω;
        ``"auto"``: exact when ``torque`` is None (except within ~1e-14 of the separatrix,
        ``1 − m < torque_free.ELLIPTIC_M1_FLOOR``, where the closed-form orientation loses accuracy),
        splitting when ``torque_depends_on_angular_velocity=False``, else numerical.
    orientation : (4,) array_like, optional
        Scalar-first unit quaternion of body (mesh axes) → space at ``t[0]``; default identity (space frame
        = mesh axes at ``t[0]``).
    rtol, atol : float
        Local error tolerances per step of the numerical and splitting methods (ignored by the exact one).
    columns : int
        Extrapolation columns of the numerical method (order ``2·columns``).
    max_steps : int
        Step bound of the numerical and splitting methods.
    torque_depends_on_angular_velocity : bool
        ``False`` declares that ``torque(t, orientation, angular_velocity)`` ignores its third argument (gravity,
        gravity gradient, a magnetic dipole in a field, springs on orientation), which makes the torque kick of
        the splitting method exact; ``method="auto"`` then selects ``"splitting"``.  The declaration is checked
        once (two calls at ``t[0]`` with different ω must agree).
    scheme : str
        Composition of the splitting method, a key of :data:`.splitting.SCHEMES` (default ``"blanes-moan6"``).
    max_step : float, optional
        Upper bound on the splitting method's step, s.

    Returns
    -------
    Trajectory

    Raises
    ------
    UsageError
        Malformed arguments, ``method="exact"`` with a torque, or ``method="splitting"`` with a torque that
        depends (or is not declared not to depend) on the angular velocity: the kick would then not be exact
        (use ``method="numerical"``).
    """
    if method not in METHODS:
        raise UsageError(f"Expected `method` in {METHODS}, got {method!r}")
    if torque is not None and not callable(torque):
        raise UsageError(f"Expected `torque` to be callable or None, got {type(torque).__name__}")
    if method == "exact" and torque is not None:
        raise UsageError("method='exact' is only available without a torque")
    if scheme not in SCHEMES:
        raise UsageError(f"Expected `scheme` in {tuple(SCHEMES)}, got {scheme!r}")
    if method == "splitting" and torque is not None and torque_depends_on_angular_velocity:
        raise UsageError("method='splitting' needs a torque that depends on time and orientation only: pass "
                         "torque_depends_on_angular_velocity=False if it does, else use method='numerical'")
    principal = resolve_body(body)
    moments = np.asarray(principal.moments, dtype=np.float64)
    axes = np.asarray(principal.axes, dtype=np.float64)
    omega_mesh = as_vector3(angular_velocity, "angular_velocity")
    times = _check_times(t)
    q0 = _check_orientation(orientation)
    tensor = axes @ np.diag(moments) @ axes.T
    use_splitting = method == "splitting" or (method == "auto" and torque is not None
                                              and not torque_depends_on_angular_velocity)
    if use_splitting and torque is not None:
        _check_no_angular_velocity_dependence(torque, float(times[0]), q0, omega_mesh)
    use_exact = method == "exact" or (method == "auto" and torque is None)
    if method == "auto" and use_exact:
        params = free_body_parameters(moments, axes.T @ omega_mesh)
        if params.case == "elliptic" and params.complementary_parameter < ELLIPTIC_M1_FLOOR:
            use_exact = False  # see torque_free.ELLIPTIC_M1_FLOOR
    if use_exact:
        q_axes = matrix_to_quaternion(axes)  # principal → mesh
        omega_p, q_p, case = torque_free_motion(moments, axes.T @ omega_mesh, times,
                                                orientation=quaternion_multiply(q0, q_axes))
        omega = omega_p @ axes.T
        q = quaternion_multiply(q_p, q_axes * np.array([1.0, -1.0, -1.0, -1.0]))
        used = f"exact:{case}"
    elif use_splitting:
        omega, q, _ = integrate_splitting(moments, axes, omega_mesh, q0, times, torque, scheme=scheme, rtol=rtol,
                                          atol=atol, max_step=max_step, max_steps=max_steps)
        used = f"splitting:{scheme}"
    else:
        omega, q = integrate_rigid_body(tensor, omega_mesh, q0, times, torque, rtol=rtol, atol=atol,
                                        columns=columns, max_steps=max_steps)
        used = "numerical:gbs"
    q = q / np.linalg.norm(q, axis=1, keepdims=True)
    q = np.where(q[:, :1] < 0, -q, q)
    body_l = omega @ tensor.T
    angular_momentum = np.einsum("nij,nj->ni", quaternion_to_matrix(q), body_l)
    energy = 0.5 * np.einsum("ni,ni->n", omega, body_l)
    return Trajectory(t=times, angular_velocity=omega, orientation=q, angular_momentum=angular_momentum,
                      energy=energy, method=used, moments=moments.copy(), axes=axes.copy())
