"""A sudden blow: the change of linear and angular velocity from an impulse at a point (exercise 4.6(c)).

An impulse ``P`` (N·s) applied at ``point`` changes the momentum by ``P`` and the angular momentum about the
centre of mass by ``r × P`` with ``r = point − R_cm`` (the impulsive limit of ``dP/dt = F`` and
``dL/dt = τ``, Eq. 4.26 about the centre of mass), while the body has no time to move::

    ΔV = P / M,        Δω = I⁻¹ (r × P)       (I about the centre of mass, mesh axes)

The body is taken to be at its reference orientation (body axes = mesh axes) at the instant of the blow.
What follows is torque-free motion, which :mod:`inertia_tool.dynamics` integrates; see
:meth:`ImpulseResult.motion`.  All quantities SI, mesh axes (= space axes at the instant of the blow).
"""

from __future__ import annotations



import numpy as np

from ..values import frozen_value
from ..errors import PhysicsError, UsageError
from ..mass.properties import MassProperties, as_vector3

__all__ = ["ImpulseResult", "apply_impulse"]


@frozen_value
class ImpulseResult:
    """State of a body just after an impulse.

    Attributes
    ----------
    body : MassProperties
        The body (mesh axes).
    impulse : (3,) float
        ``P`` in N·s, mesh axes.
    point : (3,) float
        Point of application, m, mesh axes.
    lever_arm : (3,) float
        ``r = point − centre of mass``, m.
    velocity : (3,) float
        Velocity of the centre of mass after the blow, m/s (``V0 + P/M``).
    angular_velocity : (3,) float
        Angular velocity after the blow, rad/s, mesh axes (``ω0 + I⁻¹ (r × P)``).
    delta_velocity, delta_angular_velocity : (3,) float
        The changes ``P/M`` (m/s) and ``I⁻¹ (r × P)`` (rad/s).
    angular_momentum : (3,) float
        ``I ω`` about the centre of mass after the blow, kg·m²/s, mesh (= space) axes; conserved afterwards.
    kinetic_energy : float
        ``½ M V² + ½ ω·I·ω`` after the blow, J.
    energy_change : float
        Kinetic energy gained from the blow, J (``P·(V0 + ΔV/2) + (r×P)·(ω0 + Δω/2)``).
    """

    body: MassProperties
    impulse: np.ndarray
    point: np.ndarray
    lever_arm: np.ndarray
    velocity: np.ndarray
    angular_velocity: np.ndarray
    delta_velocity: np.ndarray
    delta_angular_velocity: np.ndarray
    angular_momentum: np.ndarray
    kinetic_energy: float
    energy_change: float

    def position_of(self, point, t, trajectory) -> np.ndarray:
        """Space-frame path of a body point after the blow, (N, 3) m.

        ``x(t) = R_cm + V t + Q(t) (point − R_cm)`` with ``Q(t)`` the body→space rotation of ``trajectory``
        (scalar-first quaternions ``trajectory.orientation``, see ``docs/conventions.md``).
        """
        from scipy.spatial.transform import Rotation
        p = as_vector3(point, "point") - np.array(self.body.center_of_mass)
        t = np.asarray(t, dtype=float).reshape(-1)
        q = np.asarray(trajectory.orientation, dtype=float)
        rotated = Rotation.from_quat(np.roll(q, -1, axis=1)).apply(p)
        return self.body.center_of_mass + np.outer(t, self.velocity) + rotated

    def motion(self, t, **options):
        """The ensuing torque-free motion, integrated by ``inertia_tool.dynamics.simulation``.

        Parameters
        ----------
        t : (N,) array_like
            Times after the blow, s (starting at 0).
        **options
            Passed to ``simulate`` (tolerances).

        Returns
        -------
        Trajectory
            Angular velocity (body axes = mesh axes), orientation (body→space quaternions), angular
            momentum (space) and energy at ``t``; the centre of mass moves uniformly at ``velocity``.
        """
        from .simulation import simulate
        return simulate(self.body, self.angular_velocity, t, **options)


def apply_impulse(props: MassProperties, impulse, point, *, angular_velocity=(0.0, 0.0, 0.0),
                  velocity=(0.0, 0.0, 0.0)) -> ImpulseResult:
    """Velocity and angular velocity of a free body just after an impulse ``impulse`` at ``point``.

    Parameters
    ----------
    props : MassProperties
        The body (inertia about its centre of mass, mesh axes).
    impulse : (3,) array_like
        ``P = ∫ F dt`` in N·s, mesh axes.
    point : (3,) array_like
        Where the impulse acts, m, mesh axes (any point on its line of action gives the same result).
    angular_velocity : (3,) array_like
        ``ω0`` before the blow, rad/s, mesh axes.
    velocity : (3,) array_like
        ``V0`` of the centre of mass before the blow, m/s.

    Returns
    -------
    ImpulseResult
        ``ΔV = P/M`` and ``Δω = I⁻¹ (r × P)``, ``r = point − R_cm`` (exercise 4.6(c)).

    Raises
    ------
    PhysicsError
        For a body with zero mass or a singular inertia tensor (a point or a line).
    """
    if not isinstance(props, MassProperties):
        raise UsageError(f"Expected MassProperties, got {type(props).__name__}")
    p = as_vector3(impulse, "impulse")
    x = as_vector3(point, "point")
    w0 = as_vector3(angular_velocity, "angular_velocity")
    v0 = as_vector3(velocity, "velocity")
    if not props.mass > 0:
        raise PhysicsError(f"Expected a body with positive mass, got {props.mass} kg")
    inertia = np.asarray(props.inertia, dtype=float)
    moments = np.linalg.eigvalsh(inertia)
    if not moments[0] > 1e-12 * moments[-1]:
        raise PhysicsError(f"The inertia tensor is singular (principal moments {moments.tolist()} kg·m²): "
                           "a point or a line has no unique response to an angular impulse")
    r = x - props.center_of_mass
    torque_impulse = np.cross(r, p)
    dv = p / props.mass
    dw = np.linalg.solve(inertia, torque_impulse)
    v1, w1 = v0 + dv, w0 + dw
    big_l = inertia @ w1
    energy = 0.5 * props.mass * float(v1 @ v1) + 0.5 * float(w1 @ big_l)
    gained = float(p @ (v0 + 0.5 * dv) + torque_impulse @ (w0 + 0.5 * dw))
    arrays = [p, x, r, v1, w1, dv, dw, big_l]
    for a in arrays:
        a.flags.writeable = False
    return ImpulseResult(body=props, impulse=p, point=x, lever_arm=r, velocity=v1, angular_velocity=w1,
                         delta_velocity=dv, delta_angular_velocity=dw, angular_momentum=big_l,
                         kinetic_energy=energy, energy_change=gained)
